#!/usr/bin/python3
"""check_liggghts.py — cross-engine checks: build/jdem against build/liggghts-jdem.

    tests/liggghts/check_liggghts.py [--out DIR] [--chung-ooi] [--keep]

Builds nothing (run `make` first).  For every scene in tests/liggghts/scenes/ it runs the
standalone engine (build/jdem run) and LIGGGHTS (scripts/liggghts_run.py) and compares the
trajectories with scripts/compare_trajectories.py (tolerance: the scene's output.compare_tolerance,
default 1e-10, scaled as documented there);
the scenes named mpi_*.yaml are also run on 2 MPI ranks and compared with the 1-rank LIGGGHTS
run.  With
--chung-ooi the cases of reference_runs/chung_ooi/test*/scene.yaml are checked too.
Prints one PASS/FAIL line per check and exits 1 if any check fails.
"""
import argparse
import glob
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
PY = sys.executable
JDEM = os.path.join(ROOT, "build", "jdem")
LIG = os.path.join(ROOT, "build", "liggghts-jdem")


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def last_line(text):
    lines = [l for l in text.strip().splitlines() if l.strip()]
    line = lines[-1] if lines else ""
    for tag in ("PASS ", "FAIL "):  # keep one PASS/FAIL per check (tests/run_tests.py counts them)
        if line.startswith(tag):
            line = line[len(tag):]
    return line


def indented(text):
    return "".join("    " + l + "\n" for l in text.rstrip().splitlines())


def compare(a, b):
    # the tolerance is each scene's output.compare_tolerance (default 1e-10)
    rc, out = run([PY, os.path.join(ROOT, "scripts", "compare_trajectories.py"), a, b])
    return rc == 0, last_line(out), out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=None, help="work directory (default: a temporary one)")
    ap.add_argument("--chung-ooi", action="store_true", help="also check the Chung-Ooi scenes")
    ap.add_argument("--keep", action="store_true", help="keep the temporary work directory")
    a = ap.parse_args()
    for exe in (JDEM, LIG):
        if not os.access(exe, os.X_OK):
            print("FAIL liggghts: %s is missing (run make)" % os.path.relpath(exe, ROOT))
            return 1
    work = a.out or tempfile.mkdtemp(prefix="jdem-liggghts-")
    os.makedirs(work, exist_ok=True)

    cases = [(p, None) for p in sorted(glob.glob(os.path.join(HERE, "scenes", "*.yaml")))]
    if a.chung_ooi:
        for p in sorted(glob.glob(os.path.join(ROOT, "reference_runs", "chung_ooi", "test*", "scene.yaml"))):
            rc, out = run([JDEM, "cases", p])
            if rc != 0:
                print("FAIL %s: jdem cases: %s" % (os.path.relpath(p, ROOT), last_line(out)))
                continue
            cases += [(p, c) for c in out.split()]

    failures = 0
    for scene, case in cases:
        name = os.path.splitext(os.path.basename(scene))[0]
        if os.path.basename(scene) == "scene.yaml":
            name = os.path.basename(os.path.dirname(scene))
        label = name + ("/" + case if case else "")
        stem = os.path.join(work, label.replace("/", "_"))
        caseopt = ["--case", case] if case else []
        rc, out = run([JDEM, "run", scene] + caseopt + ["-o", stem + ".jdem.h5", "--quiet"])
        if rc != 0:
            print("FAIL %s: build/jdem run: %s" % (label, last_line(out)))
            failures += 1
            continue
        rc, out = run([PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), scene] + caseopt +
                      ["-o", stem + ".lig.h5"])
        if rc != 0:
            print("FAIL %s: liggghts_run.py:\n%s" % (label, indented(out.strip()[-1500:])))
            failures += 1
            continue
        ok, summary, full = compare(stem + ".jdem.h5", stem + ".lig.h5")
        print("%s %s: jdem vs liggghts-jdem: %s" % ("PASS" if ok else "FAIL", label, summary))
        if not ok:
            failures += 1
            sys.stdout.write(indented(full))
        if name.startswith("mpi_"):
            rc, out = run([PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), scene] + caseopt +
                          ["-o", stem + ".np2.h5", "--np", "2"])
            if rc != 0:
                print("FAIL %s: liggghts_run.py --np 2:\n%s" % (label, indented(out.strip()[-1500:])))
                failures += 1
                continue
            ok, summary, full = compare(stem + ".lig.h5", stem + ".np2.h5")
            print("%s %s: liggghts-jdem 1 rank vs 2 ranks: %s" % ("PASS" if ok else "FAIL", label, summary))
            if not ok:
                failures += 1
                sys.stdout.write(indented(full))

    print("%d checks failed" % failures if failures else "all checks passed")
    if not a.out and not a.keep and not failures:
        shutil.rmtree(work, ignore_errors=True)
    elif not a.out:
        print("work directory: %s" % work)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
