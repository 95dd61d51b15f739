#!/usr/bin/python3
"""compare_builds.py — two builds of jdem on every scene, trajectories compared bit for bit.

    scripts/compare_builds.py --base OTHER/build/jdem [--jdem build/jdem] [--max-steps 3000]
                              [--max-particles 20000] [--only GLOB]

Every case of every scene in reference_runs/ and tests/ (the malformed scenes and the fuzz corpus
excepted) is resolved by the base build, shortened to at most --max-steps steps, and run by both
builds on that same resolved scene; every dataset of /particles and /observables of the two
trajectories must be equal byte for byte.  The base resolves, so that a scene key the base does
not know is never written.  For a change that must keep every existing trajectory (a new law
that is off by default: docs/adding_a_law.md).  Prints one PASS/FAIL/SKIP line per case; exits
1 if any case differs.
"""
import argparse
import fnmatch
import glob
import os
import sys
import tempfile

import h5py
import yaml

from scripts import engines

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def scenes(only):
    found = []
    for top in ("reference_runs", "tests"):
        for path in sorted(glob.glob(os.path.join(ROOT, top, "**", "*.yaml"), recursive=True)):
            rel = os.path.relpath(path, ROOT)
            if rel.startswith(("tests/scenes/bad", "tests/fuzz")) or not fnmatch.fnmatch(rel, only):
                continue
            found.append(rel)
    return found


def datasets(path):
    """{name: bytes} of every dataset under /particles and /observables."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                out[name] = obj[()].tobytes() if obj.shape != () else bytes(str(obj[()]), "utf8")
        for top in ("particles", "observables"):
            if top in f:
                f[top].visititems(lambda n, o, t=top: visit(t + "/" + n, o))
    return out


def run(jdem, scene, out):
    r = engines.jdem("run", scene, "--quiet", "--force", "-o", out, binary=jdem, timeout=600)
    return r.returncode, r.stderr[-300:]


def compare_case(a, scene, case, tmp):
    r = engines.resolve(scene, case, binary=a.base, cwd=ROOT)
    if r.returncode != 0:
        return "SKIP", "the base does not resolve it: " + r.stderr.strip()[-200:]
    doc = yaml.load(r.stdout, Loader=yaml.CSafeLoader)
    if len(doc.get("particles") or []) > a.max_particles:
        return "SKIP", "%d particles" % len(doc["particles"])
    doc["time"]["steps"] = min(doc["time"]["steps"], a.max_steps)
    resolved = os.path.join(tmp, "resolved.yaml")
    with open(resolved, "w") as f:
        yaml.safe_dump(doc, f)
    outs = []
    for name, jdem in (("base", a.base), ("new", a.jdem)):
        out = os.path.join(tmp, name + ".h5")
        rc, err = run(jdem, resolved, out)
        outs.append((rc, out, err))
    if outs[0][0] != outs[1][0]:
        return "FAIL", "exit %d (base) vs %d: %s" % (outs[0][0], outs[1][0], outs[1][2])
    if not (os.path.exists(outs[0][1]) and os.path.exists(outs[1][1])):
        return "SKIP", "no trajectory (exit %d): %s" % (outs[0][0], outs[0][2])
    base, new = datasets(outs[0][1]), datasets(outs[1][1])
    differ = sorted(k for k in set(base) | set(new) if base.get(k) != new.get(k))
    if differ:
        return "FAIL", "datasets differ: " + ", ".join(differ[:6])
    return "PASS", "%d datasets, %d steps" % (len(base), doc["time"]["steps"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base", required=True)
    ap.add_argument("--jdem", default=os.path.join(ROOT, "build", "jdem"))
    ap.add_argument("--max-steps", type=int, default=3000)
    ap.add_argument("--max-particles", type=int, default=20000)
    ap.add_argument("--only", default="*")
    a = ap.parse_args()
    counts = {"PASS": 0, "FAIL": 0, "SKIP": 0}
    with tempfile.TemporaryDirectory(prefix="compare_builds_") as tmp:
        for scene in scenes(a.only):
            r = engines.jdem("cases", scene, binary=a.base, cwd=ROOT)
            for case in (r.stdout.split() if r.returncode == 0 else []) or [None]:
                verdict, detail = compare_case(a, scene, case, tmp)
                counts[verdict] += 1
                print("%s %s%s: %s" % (verdict, scene, " --case " + case if case else "", detail),
                      flush=True)
    print("compare_builds: %(PASS)d identical, %(FAIL)d different, %(SKIP)d skipped" % counts)
    return 1 if counts["FAIL"] else 0


if __name__ == "__main__":
    sys.exit(main())
