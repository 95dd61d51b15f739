#!/usr/bin/python3
"""Run every test suite of jdem and print one closing line "N passed, N failed".

Each suite is a command.  Suites print one line per check, "PASS name" or "FAIL name: detail";
cmocka suites print their own "[       OK ]" / "[  FAILED  ]" lines.  A suite that exits non-zero
without reporting a failed check counts as one failed check, so a crash can never pass.

Suites run side by side on the machine's cores (JDEM_TEST_JOBS overrides the count): a suite
whose checks run 2 MPI ranks (WIDE) takes two cores, so it runs alone on a 2-core machine.
Each suite's lines are printed together when it ends.

Usage: tests/run_tests.py [SUITE ...]     (default: all)
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

PY = "/usr/bin/python3"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

ENGINE_TESTS = ["wall_vanishes", "neighbour", "fastpaths", "free_flight", "hertz_impact", "energy_balance", "guard",
                "guard_coordination", "dt_auto", "watchdog",
                "signals", "bench_tiling", "deposit", "servo", "domain"]
SANITIZED = {"JDEM": "build/san/jdem"}

# name, command, output style, extra environment.  Sanitizer builds run the same checks.
SUITES = [
    ("unit", ["build/test_unit"], "cmocka", {}),
    ("unit-sanitized", ["build/san/test_unit"], "cmocka", {}),
    ("scenes", ["build/scene_check", "tests/scenes"], "lines", {}),
    ("scenes-sanitized", ["build/san/scene_check", "tests/scenes"], "lines", {}),
]
SUITES += [(f"engine-{t}", [PY, f"tests/engine/test_{t}.py"], "lines", {}) for t in ENGINE_TESTS]
SUITES += [(f"engine-{t}-sanitized", [PY, f"tests/engine/test_{t}.py"], "lines", SANITIZED)
           for t in ENGINE_TESTS]
# The conveyor inlet: the stream against its closed form, the growing trajectory, the energy.
SUITES += [("inlet", [PY, "tests/inlet/test_inlet.py"], "lines", {})]
# Bonded blocks in the inlet's section (Ch. 5): insertion at the block's first crossing, the
# bonds of each copy (count, ids, order, unstressed), free fall whole, breakage on the floor,
# the long axis, and the sanitizer build on the same scene.
SUITES += [("inlet-bonded", [PY, "tests/inlet/test_bonded_section.py"], "lines", {})]
# The bonded section in liggghts-jdem (fix jdem/inlet's section bonds) against jdem, 1 and 2
# ranks: the same stream, bonds and breaks, states within 1e-10; restart continuation bit for bit;
# the guard; bad section lines.
SUITES += [("inlet-bonded-cross-engine", [PY, "tests/inlet/test_bonded_inlet_liggghts.py"], "lines", {})]
# The inlet in both engines: the same insertion stream bit for bit on 1 and 2 ranks, the same
# particles and states at every frame, the inflow energy, fix jdem/inlet's bad arguments.
SUITES += [("inlet-cross-engine", [PY, "tests/inlet/test_inlet_liggghts.py"], "lines", {})]
# Insertion into an occupied place: which particles the inlet skips (closed form), the literal
# rule's ram, both engines' records and skip counts on 1 and 2 ranks.
SUITES += [("inlet-occupied", [PY, "tests/inlet/test_occupied.py"], "lines", {})]
# The two engines on the same scenes (bitwise or 1e-10), and LIGGGHTS on 1 vs 2 MPI ranks.
SUITES += [("cross-engine", [PY, "tests/liggghts/check_liggghts.py"], "lines", {})]
# The /observables cadence (output.observables_every below, at and not dividing every) in both engines.
SUITES += [("observables-cadence", [PY, "tests/liggghts/check_observables_cadence.py"], "lines", {})]
# STL mesh walls in LIGGGHTS (fix wall/jiang mesh) against our plane primitive, bit for bit:
# resting, sliding across edges, a concave corner, a conveyor; move/mesh motion; bad input.
SUITES += [("mesh-liggghts", [PY, "tests/mesh/test_mesh_liggghts.py"], "lines", {})]
# STL mesh walls in build/jdem: against the plane primitive and Hertz at rest, against
# liggghts-jdem bit for bit (edges, a vertex, a funnel), 1 vs 2 threads.
SUITES += [("mesh-engines", [PY, "tests/mesh/test_mesh_engines.py"], "lines", {}),
           ("mesh-engines-sanitized", [PY, "tests/mesh/test_mesh_engines.py"], "lines", SANITIZED)]
# Moving meshes (velocity, rotation) and conveyor surfaces: jdem against closed forms and
# against liggghts-jdem's fix move/mesh and surface_vel, bit for bit on 1 and 2 ranks.
SUITES += [("mesh-motion", [PY, "tests/mesh/test_mesh_motion.py"], "lines", {}),
           ("mesh-motion-sanitized", [PY, "tests/mesh/test_mesh_motion.py"], "lines", SANITIZED)]
# A drum from primitives (a cylinder with angular_velocity, fix wall/jiang ... omega): one
# sphere against the rolling pendulum's closed form and liggghts-jdem bit for bit on 1 and 2
# ranks; a bed's angle of repose against the same drum as 128 turning mesh facets.
SUITES += [("drum", [PY, "tests/mesh/test_drum.py"], "lines", {})]
# The law set (kernel/jdem_laws.h) each engine selects, for every scene of reference_runs/ and
# tests/, and hand-written decks that leave out `rolling on`.
SUITES += [("law-sets", [PY, "tests/liggghts/check_law_sets.py"], "lines", {})]
# compute pair/gran/local with gran/jiang: our contacts' forces, against build/jdem's.
SUITES += [("liggghts-pair-local", [PY, "tests/liggghts/check_pair_local.py"], "lines", {})]
# A hand-written script: warnings for a stock wall/gran and foreign material properties.
SUITES += [("liggghts-script-warnings", [PY, "tests/liggghts/check_script_warnings.py"], "lines", {})]
# LIGGGHTS' public tutorials converted to gran/jiang and wall/jiang, shortened, against stock's
# (reference_runs/liggghts_tutorials/); the guard, the watchdog and the plane walls with insertion.
SUITES += [("liggghts-tutorials", [PY, "tests/liggghts/check_tutorials.py"], "lines", {})]
# The watchdog in LIGGGHTS (fix jdem/watchdog): the same trips as the stepper's.
SUITES += [("liggghts-watchdog", [PY, "tests/liggghts/check_watchdog.py"], "lines", {})]
# Restart files in LIGGGHTS: continued runs == the uninterrupted run bit for bit on 1 and 2 ranks
# (history, bonds, servo, kill -9), and restart files across stock and our pair styles.
SUITES += [("liggghts-restart", [PY, "tests/liggghts/check_restart.py"], "lines", {})]
# scripts/liggghts_run.py --checkpoint-every/--resume: a killed or stopped run continued from its
# restart files equals the uninterrupted run bit for bit (1 and 2 ranks)
SUITES += [("liggghts-runner-resume", [PY, "tests/liggghts/check_runner_resume.py"], "lines", {})]
# jdem checkpoints: kill -9 after a checkpoint, resume, == the uninterrupted run bit for bit on
# 1 and 2 threads (bed, servo, inlet, bonds); SIGTERM; refused checkpoints; a failed write.
SUITES += [("checkpoint", [PY, "tests/checkpoint/test_checkpoint.py"], "lines", {})]
# SIGINT/SIGTERM stop liggghts-jdem cleanly (exit 130/143, OUT.part kept), on 1 and 2 ranks.
SUITES += [("liggghts-signals", [PY, "tests/liggghts/check_signals.py"], "lines", {})]
# Parallel bonds in LIGGGHTS (fix bond/jiang): 1 vs 2 MPI ranks, the ghost-cutoff guard, bad input.
SUITES += [("liggghts-bonds", [PY, "tests/liggghts/check_bonds.py"], "lines", {})]
# The pour (576 spheres, walls, a cylinder): round-off horizons and settled statistics.
SUITES += [("pour", [PY, "tests/liggghts/check_pour.py"], "lines", {})]
# The stability suite (make stability), reduced: the harshest one-contact cases and the damped,
# tip-loaded stiff bonded beam at their own dt and at 10x the guard's dt, in both engines and in
# the sanitized stepper.
STABILITY_CASES = ("restitution/e0p01,grazing/a89p9,friction/mu10,impact_speed/v100,"
                   "scale/E1e12_R10um,scale/co5_polyethylene,rolling/eta1,bonded_beam/tip_load,"
                   "friction_mindlin/mu10")
SUITES += [
    ("stability", [PY, "scripts/stability.py", "--out", "out/test/stability", "--cases",
                   STABILITY_CASES, "--factors", "10"], "lines", {}),
    ("stability-sanitized", [PY, "scripts/stability.py", "--out", "out/test/stability-san", "--cases",
                             STABILITY_CASES, "--factors", "10", "--engines", "jdem",
                             "--jdem", "build/san/jdem"], "lines", {}),
]
# Parallel bonds: the checks of `make bonds`, shortened, in both engines (liggghts-jdem's
# block drop is compared with jdem's) and in the stepper's sanitized build.
SUITES += [("bonds", [PY, "scripts/bond_checks.py", "--quick", "--engines", "jdem,liggghts-jdem",
                      "--out", "out/test/bonds"], "lines", {}),
           ("bonds-sanitized", [PY, "scripts/bond_checks.py", "--quick", "--out",
                                "out/test/bonds-san"], "lines", SANITIZED)]
# Del Cid's MEPA drop test (make mepa), its first impacts: the branches' closed forms, the energy
# balance's peak overlap and the engines' agreement.
SUITES += [("mepa", [PY, "scripts/mepa_drop.py", "--quick", "--out", "out/test/mepa"], "lines", {})]
# The sandpile campaign's angle of repose (scripts/sandpile/angle.py) on synthetic piles of known
# angle: symmetric, asymmetric, flat-topped, with spheres beside and below the plate.
SUITES += [("sandpile", [PY, "tests/sandpile/test_angle.py"], "lines", {})]
# ParaView (Debian's, `make paraview-deps`) opens both engines' sidecars with its default reader:
# points, cells, arrays and time steps against the .h5, and a rendered PNG with content.
SUITES += [("paraview", [PY, "tests/paraview/test_paraview.py"], "lines", {})]
# Fault injection (tests/faults/, run as root in CI: tmpfs, read-only mounts, ulimit -v):
# hostile names, signals at each phase, disk full, memory limits; exit code, message, files left.
SUITES += [("faults", [PY, "tests/faults/run_faults.py"], "lines", {})]
# The Chung–Ooi benchmark, a representative subset of every test in both engines (--quick);
# `make demo` runs the full sweeps.
CHUNG_OOI = "out/test/chung_ooi"
SUITES += [
    ("chung-ooi", ["sh", "-c", f"{PY} scripts/chung_ooi.py run --quick --engines jdem,liggghts "
                   f"--out {CHUNG_OOI} && {PY} scripts/chung_ooi.py check --out {CHUNG_OOI}"],
     "lines", {}),
]
# Tests 5 and 8 with Mindlin's tangential stiffness: the same checks, the engines against each
# other (engine_difference, 1e-10) among them.
CHUNG_OOI_MINDLIN = "out/test/chung_ooi_mindlin"
SUITES += [
    ("chung-ooi-mindlin", ["sh", "-c", f"{PY} scripts/chung_ooi.py run --quick --tests 5,8 "
                           f"--engines jdem,liggghts --model tangential_stiffness=mindlin "
                           f"--out {CHUNG_OOI_MINDLIN} && {PY} scripts/chung_ooi.py check "
                           f"--out {CHUNG_OOI_MINDLIN}"], "lines", {}),
]

# The work-precision study reduced to Test 1 in the two engines of the Jiang kernel (`make
# accuracy` runs all of it): observed order against velocity Verlet's 2, engines against each other.
ACCURACY = "out/test/accuracy"
SUITES += [
    ("accuracy", ["sh", "-c", f"{PY} scripts/accuracy.py run --items test1_glass --engines jdem,liggghts-jdem "
                  f"--repeats 1 --out {ACCURACY} && {PY} scripts/accuracy.py check --out {ACCURACY}"],
     "lines", {}),
]

# The Ch. 4 mixing analysis (scripts/mixing) on synthetic deposits, the seed's claims on
# hand-made results, its pictures, the generator of the second pass and the cubes (reference_runs/mixing/ch4/generate.py),
# the report's merge of local and committed results (scripts/mixing/report_ch4.py) and the
# cross-engine horizon on a synthetic pair of trajectories, and the Ch. 5 horizon's break-by-break
# comparison on hand-made bond records.
SUITES += [("mixing-analysis", ["sh", "-c", f"{PY} tests/mixing/test_analysis.py; a=$?; "
                                f"{PY} tests/mixing/test_pictures.py; b=$?; "
                                f"{PY} tests/mixing/test_generate.py; c=$?; "
                                f"{PY} tests/mixing/test_claims.py; d=$?; "
                                f"{PY} tests/mixing/test_report.py; e=$?; "
                                f"{PY} tests/mixing/test_horizon.py; f=$?; "
                                f"{PY} tests/mixing/test_outflow.py; g=$?; "
                                f"{PY} tests/mixing/test_fill_ch5.py; h=$?; "
                                f"{PY} tests/mixing/test_horizon_ch5.py; i=$?; "
                                f"exit $((a | b | c | d | e | f | g | h | i))"],
            "lines", {})]
# This runner on dummy suites: every check counted once, the 2-rank suites alone, two others at once.
SUITES += [("runner", [PY, "tests/runner/test_run_tests.py"], "lines", {})]
# The campaign driver (scripts/campaign.py) with dummy units, a killed run resumed.
SUITES += [("campaign", [PY, "tests/mixing/test_campaign.py"], "lines", {})]
# A reduced Chapter 4 fill in jdem (3 sections, 0.8 s): stream, free fall, energy, and the
# analysis on its deposit against Monte Carlo and all-pairs counts.
SUITES += [("mixing-fill", [PY, "tests/mixing/test_fill.py"], "lines", {})]
# Runs from a settled deposit (particles_from, an inlet's from_deposit) in both engines.
SUITES += [("mixing-settled", [PY, "tests/mixing/test_settled.py"], "lines", {})]

# The suites that run 2 MPI ranks in some check.  They run alone on 2 cores: next to another
# suite, Open MPI's ranks (each run of scripts/engines.py in a session of its own, which Linux
# schedules as one group) poll for each other on one core and crawl (docs/liggghts.md).  The
# stepper's 2-thread runs share the cores: their OpenMP threads wait passively at a barrier
# (OMP_WAIT_POLICY, below), which changes no result.
WIDE = {"inlet-bonded-cross-engine", "inlet-cross-engine", "inlet-occupied", "cross-engine",
        "observables-cadence", "mesh-liggghts", "mesh-motion", "mesh-motion-sanitized", "drum",
        "liggghts-watchdog", "liggghts-restart", "liggghts-runner-resume", "liggghts-signals",
        "liggghts-bonds", "faults", "pour"}
# The longest one-core suites (docs/performance.md, "make test on 2 cores"), started first among
# them so that the last to end is a short one.
LONG = ("law-sets", "chung-ooi", "paraview", "stability", "engine-neighbour-sanitized",
        "engine-neighbour", "checkpoint")
assert WIDE | set(LONG) <= {s[0] for s in SUITES}, (WIDE | set(LONG)) - {s[0] for s in SUITES}

# Open MPI's start, for the suites' hundreds of short LIGGGHTS runs (each suite's environment;
# a variable already set wins).  A one-rank run is an MPI singleton, which starts an orted of its
# own unless isolated, and every run probed the fabrics' transports (PSM calibrates its timer for
# 0.2 s) before settling on ob1, the one it uses on one machine: 0.88 s to start liggghts-jdem,
# 0.30 s with both set (docs/performance.md, "make test on 2 cores").  Neither changes a result:
# the same point-to-point layer is chosen, and a singleton sends no messages.
MPI_STARTUP = {"OMPI_MCA_ess_singleton_isolated": "1", "OMPI_MCA_pml": "ob1"}

CMOCKA_OK = re.compile(r"^\[\s+OK\s+\] (\S+)")
CMOCKA_FAIL = re.compile(r"^\[\s+FAILED\s+\] (\S+)$")


def count(style, text):
    """Return (passed, failed, failure lines) found in a suite's output."""
    passed, failed = 0, []
    for line in text.splitlines():
        if style == "cmocka":
            if CMOCKA_OK.match(line):
                passed += 1
            elif CMOCKA_FAIL.match(line) and "test(s)" not in line:
                failed.append(line)
        elif line.startswith("PASS "):
            passed += 1
        elif line.startswith("FAIL "):
            failed.append(line)
    return passed, failed


def run_suite(name, cmd, style, env, report=print):
    # Each suite writes its scratch files (tempfile in Python, mpirun's session files) into a
    # directory of its own (TMPDIR), removed when the suite passes and kept for a look when it
    # fails.
    tmp = tempfile.mkdtemp(prefix="jdem_suite_")  # (no suite name: tests match words in paths)
    start = time.monotonic()
    # From the repository root, which is also the module path: scripts/ and tests/ are packages
    # (scripts/__init__.py), imported as scripts.NAME and tests.SUITE.NAME.
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=ROOT,
                          env={**MPI_STARTUP, "OMP_WAIT_POLICY": "passive", **os.environ, **env, "TMPDIR": tmp,
                               "PYTHONPATH": ROOT})
    elapsed = time.monotonic() - start
    passed, failed = count(style, proc.stdout)
    if proc.returncode != 0 and not failed:
        tail = "\n".join(proc.stdout.splitlines()[-15:])
        failed.append(f"FAIL {name}: exit status {proc.returncode}\n{tail}")
    lines = [f"== {name}: {passed} passed, {len(failed)} failed ({elapsed:.1f} s)"]
    lines += ["   " + line for line in failed]
    if failed:
        lines.append(f"   (its scratch files are kept in {tmp})")
    else:
        shutil.rmtree(tmp, ignore_errors=True)
    report("\n".join(lines))
    return passed, len(failed)


def cores():
    """The cores the suites may use: JDEM_TEST_JOBS, else the CPUs this process may run on."""
    jobs = os.environ.get("JDEM_TEST_JOBS", "")
    if jobs:
        if not jobs.isdigit() or int(jobs) < 1:
            raise SystemExit(f"JDEM_TEST_JOBS={jobs!r}: valid is a whole number from 1")
        return int(jobs)
    return len(os.sched_getaffinity(0))


def start_order(suite):
    """The WIDE suites first, then the LONG ones longest first, then the rest (a stable sort
    keeps their listed order)."""
    name = suite[0]
    return 0 if name in WIDE else 1 + LONG.index(name) if name in LONG else 1 + len(LONG)


def run_side_by_side(suites, jobs, emit=print):
    """Run the suites, each once `width` cores are free (WIDE: 2, others 1; never more than
    jobs): the wide ones first, then the LONG ones, then the rest in order, so that the one-core
    suites fill the cores at the end.  Each suite's lines go to emit at its end.  Returns
    (passed, failed) summed."""
    free = [jobs]
    totals = [0, 0]
    turn = threading.Condition()

    def report(text):
        with turn:
            emit(text)
            sys.stdout.flush()

    def run(suite, width):
        try:
            p, f = run_suite(*suite, report=report)
        except Exception as e:  # a runner fault is a failed check, never a silent pass
            report(f"== {suite[0]}: 0 passed, 1 failed\n   FAIL {suite[0]}: runner error: {e!r}")
            p, f = 0, 1
        with turn:
            totals[0] += p
            totals[1] += f
            free[0] += width
            turn.notify_all()

    threads = []
    for suite in sorted(suites, key=start_order):
        width = min(jobs, 2 if suite[0] in WIDE else 1)
        with turn:
            turn.wait_for(lambda: free[0] >= width)
            free[0] -= width
        t = threading.Thread(target=run, args=(suite, width))
        t.start()
        threads.append(t)
    for t in threads:
        t.join()
    return totals[0], totals[1]


def main(argv):
    wanted = set(argv[1:])
    unknown = wanted - {s[0] for s in SUITES}
    if unknown:
        print(f"unknown suite(s): {', '.join(sorted(unknown))}; "
              f"valid: {', '.join(s[0] for s in SUITES)}", file=sys.stderr)
        return 2
    chosen = [s for s in SUITES if not wanted or s[0] in wanted]
    total_pass, total_fail = run_side_by_side(chosen, cores())
    print(f"{total_pass} passed, {total_fail} failed")
    return 1 if total_fail else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
