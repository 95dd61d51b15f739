#!/usr/bin/python3
"""bond_bench.py — nanoseconds per bond per step, next to the LAMMPS bpm/rotational
anchor of about 228 ns per bond-step on one core (shared/spec/anchors.md §2.1).

    scripts/bond_bench.py [--engines jdem] [--counts 20,20,20] [--steps 400] [--repeats 3]
                          [--out out/bonds] [--no-profile]

Scene: a bonded block (bonded_block generator, simple cubic, R = 1 mm, every face neighbour
bonded: 3n^3 - 3n^2 bonds) at rest without gravity.  The bond loop costs the same whatever the
values (no early exit), and the touching spheres carry no contact force.  The bonds' share is
isolated by running the same particles twice, with and without bonds, each as an S-step run
minus a 1-step run (set-up, parsing and output cancel):

    ns per bond-step = ((T_S - T_1)_bonds - (T_S - T_1)_no bonds) / (bonds x (S - 1))

medians over --repeats.  Wall time is noisy on a shared machine, so the deterministic measure is
reported too: callgrind's instruction count of the bond loop per bond-step on a small block
(inclusive: sim_bonds_forces in jdem, FixBondJiang::post_force in liggghts-jdem, which includes
its ghost-force buffer and reverse communication; needs valgrind).  For liggghts-jdem the times
are LIGGGHTS' "Loop time" of each run (the deck generation is not timed).

Writes OUT/bench.json: records {"check": "ns_per_bond_step" | "instructions_per_bond_step",
"engine", "value", "reference", "rel_error", "tolerance", "pass", "detail"}.  Timings are
measurements, not checks: their "pass" is null (false only when the measurement itself failed).
Prints one line per record.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys

import yaml

from scripts import engines

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
ANCHOR_NS = 228.0   # LAMMPS bpm/rotational, examples/bpm/impact log, 1 core (anchors.md §2.1)


def block_scene(counts, steps, bonds):
    s = {"jdem_scene": 1, "name": "bond_bench",
         "time": {"dt": 2.0e-8, "steps": steps, "max_impact_speed": 0.1},
         "output": {"every": steps},
         "watchdog": {"enabled": False},
         "materials": {"glass": {"youngs_modulus": 7.0e10, "poisson_ratio": 0.3, "density": 2600}},
         "bond_types": {"cement": {"normal_stiffness": 2.0e12, "shear_stiffness": 1.0e12,
                                   "tensile_strength": 5.0e6, "shear_strength": 8.0e6}},
         "generate": [{"bonded_block": {"material": "glass", "radius": 1.0e-3,
                                        "origin": [0, 0, 0], "counts": list(counts),
                                        "bond_type": "cement"}}]}
    if not bonds:  # the same spheres as a plain lattice (touching, no bonds)
        s.pop("bond_types")
        s["generate"] = [{"lattice": {"material": "glass", "radius": 1.0e-3, "origin": [0, 0, 0],
                                      "spacing": 2.0e-3, "counts": list(counts)}}]
    return s


def write(path, sc):
    with open(path, "w") as f:
        f.write("# written by scripts/bond_bench.py\n")
        yaml.safe_dump(sc, f, sort_keys=False)


def run_seconds(engine, scene_path, out_h5):
    """Wall time of the run: for jdem the whole process, for liggghts-jdem LIGGGHTS' own "Loop
    time" (the run without set-up; the deck generation in Python would add seconds of noise)."""
    if engine == "jdem":
        cmd = [engines.JDEM, "run", scene_path, "-o", out_h5, "--quiet", "--force"]
    else:
        cmd = engines.script("liggghts_run", scene_path, "-o", out_h5)
    r, t = engines.timed(cmd)
    if r.returncode != 0:
        raise RuntimeError("%s failed: %s" % (" ".join(cmd), (r.stderr or r.stdout)[-800:]))
    if engine != "jdem":
        t = engines.liggghts_loop_seconds(engines.liggghts_log(out_h5))
    return t


def loop_seconds(engine, d, counts, steps, bonds, repeats):
    times = []
    for rep in range(repeats):
        t = {}
        for s in (1, steps):
            p = os.path.join(d, "%s_%s_%d.yaml" % (engine, "bonds" if bonds else "plain", s))
            write(p, block_scene(counts, s, bonds))
            t[s] = run_seconds(engine, p, p[:-5] + ".h5")
        times.append(t[steps] - t[1])
    return statistics.median(times), times


# The function that holds each engine's bond loop (inclusive), for callgrind.
BOND_LOOP = {"jdem": "sim_bonds_forces", "liggghts-jdem": "FixBondJiang::post_force"}


class NotMeasured(Exception):
    """The measurement cannot be taken on this build (not a failure)."""


# Valgrind decodes at most AVX2: a build for a CPU with AVX-512 (the default ARCH=-march=native)
# cannot be profiled.
VALGRIND_ISA = ("not measured: valgrind cannot decode this build's AVX-512 instructions "
                "(profile a build made with `make ARCH=-march=x86-64-v3`)")


def callgrind_instructions(d, engine="jdem", counts=(8, 8, 8), steps=50):
    """Inclusive instructions of the engine's bond loop per bond-step (deterministic)."""
    d = os.path.abspath(d)  # LIGGGHTS runs in its deck directory
    p = os.path.join(d, "callgrind_%s.yaml" % engine)
    write(p, block_scene(counts, steps, True))
    out = os.path.join(d, "callgrind_%s.out" % engine)
    if engine == "jdem":
        cmd, cwd = [engines.JDEM, "run", p, "-o", p[:-5] + ".h5", "--quiet", "--force"], None
    else:  # generate the deck by running it once, then profile LIGGGHTS alone on it
        run_seconds(engine, p, p[:-5] + ".h5")
        cwd = p[:-5] + ".deck"
        cmd = engines.liggghts_command("in.jdem", log="none")
    r = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + out] + cmd,
                       capture_output=True, text=True, cwd=cwd)
    if "unhandled instruction" in r.stderr:
        raise NotMeasured(VALGRIND_ISA)
    if r.returncode != 0:
        raise RuntimeError("callgrind failed: " + r.stderr[-500:])
    r = subprocess.run(["callgrind_annotate", "--inclusive=yes", out], capture_output=True,
                       text=True)
    for line in r.stdout.splitlines():
        if BOND_LOOP[engine] in line:
            ir = int(re.sub(r"[,\s].*$", "", line.strip().replace(",", "", 10).split()[0]))
            n = counts[0]
            bonds = 3 * n ** 3 - 3 * n ** 2
            # steps evaluations plus the step-0 one
            return ir / (bonds * (steps + 1)), bonds
    raise RuntimeError("sim_bonds_forces not in the callgrind profile")


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--engines", default="jdem")
    ap.add_argument("--counts", default="20,20,20")
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bonds"))
    ap.add_argument("--no-profile", action="store_true")
    a = ap.parse_args(argv)
    counts = tuple(int(c) for c in a.counts.split(","))
    n = counts[0] * counts[1] * counts[2]
    n_bonds = (3 * n - counts[0] * counts[1] - counts[1] * counts[2] - counts[0] * counts[2])
    d = os.path.join(a.out, "bench")
    os.makedirs(d, exist_ok=True)
    records = []
    for engine in a.engines.split(","):
        try:
            tb, all_b = loop_seconds(engine, d, counts, a.steps, True, a.repeats)
            tp, all_p = loop_seconds(engine, d, counts, a.steps, False, a.repeats)
            ns = (tb - tp) / (n_bonds * (a.steps - 1)) * 1e9
            records.append({"check": "ns_per_bond_step", "engine": engine, "value": ns,
                            "reference": ANCHOR_NS, "rel_error": abs(ns - ANCHOR_NS) / ANCHOR_NS,
                            "tolerance": None, "pass": None,
                            "detail": "%d spheres, %d bonds, %d steps; loop s with bonds %s, "
                                      "without %s (wall time, median of %d; anchor: LAMMPS "
                                      "bpm/rotational)" % (n, n_bonds, a.steps,
                                                           [round(x, 3) for x in all_b],
                                                           [round(x, 3) for x in all_p],
                                                           a.repeats)})
        except (RuntimeError, OSError) as e:
            records.append({"check": "ns_per_bond_step", "engine": engine, "value": None,
                            "reference": ANCHOR_NS, "rel_error": None, "tolerance": None,
                            "pass": False, "detail": str(e)})
    for engine in ([] if a.no_profile else a.engines.split(",")):
        try:
            ipb, nb = callgrind_instructions(d, engine)
            records.append({"check": "instructions_per_bond_step", "engine": engine, "value": ipb,
                            "reference": None, "rel_error": None, "tolerance": None, "pass": None,
                            "detail": "callgrind, inclusive instructions of %s per bond-step, "
                                      "8x8x8 block (%d bonds), 50 steps" % (BOND_LOOP[engine], nb)})
        except NotMeasured as e:
            records.append({"check": "instructions_per_bond_step", "engine": engine, "value": None,
                            "reference": None, "rel_error": None, "tolerance": None,
                            "pass": None, "detail": str(e)})
        except (RuntimeError, OSError, ValueError) as e:
            records.append({"check": "instructions_per_bond_step", "engine": engine, "value": None,
                            "reference": None, "rel_error": None, "tolerance": None,
                            "pass": False, "detail": str(e)})
    for r in records:
        print("%s: %s %s (anchor %s) %s" % (r["check"], r["engine"], r["value"], r["reference"],
                                            r["detail"]))
    with open(os.path.join(a.out, "bench.json"), "w") as f:
        json.dump(records, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
