#!/usr/bin/python3
"""check_runner_resume.py — scripts/liggghts_run.py continues an interrupted run from its
restart files (--checkpoint-every N --resume; docs/liggghts.md "Restarts").

    tests/liggghts/check_runner_resume.py [--keep]

The case is the conveyor fill of tests/checkpoint/scenes/inlet_stream.yaml (12 sections on a
belt, 120,000 steps, a frame every 5000 and observables every 1000 steps; its domain deletes 76
spheres from step 44500 on, so the files resumed from carry deletions), with a restart file
every 6000 steps, so that a run resumes between two frames.  The reference of every check is the same run uninterrupted: a continued run
must equal it bit for bit (==, NaN == NaN in the empty rows of the growing set) in every dataset
of its trajectory but /h5md (the file's author and creator), on 1 and 2 MPI ranks:
  killed   the runner and LIGGGHTS killed with SIGKILL once the restart file of step 60000
           exists, then run again with --resume: it continues from the older of the two newest
           files, the one that is complete however the run ended;
  stopped  the runner sent SIGTERM once that file exists: LIGGGHTS stops at its next step and
           keeps OUT.h5.part with a last frame after the restart file's step, which the
           continued trajectory must leave out.
  sorted   as killed, with LIGGGHTS sorting the atoms in space every 1000 steps (--sort-every,
           a divisor of the cadence): the sorts fall on the restart steps, so the continued
           run is again the uninterrupted one (which must differ from the unsorted run: the
           sums' order changed).
Also: a completed run leaves no restart file; a --resume after the scene changed starts from
the beginning and says so; --resume without --checkpoint-every is refused (exit 2).
Prints one PASS/FAIL line per check; exit 1 if any fails.
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np
from tests.engine.engine_common import Checks

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(ROOT, "tests", "checkpoint", "scenes", "inlet_stream.yaml")
RUNNER = [sys.executable, os.path.join(ROOT, "scripts", "liggghts_run.py")]
EVERY, KILL_AFTER = 6000, 60000
SORT = ["--sort-every", "1000"]

checks = Checks()
check = checks.check


def runner(scene, out, np_, *extra):
    return RUNNER + [scene, "-o", out, "--checkpoint-every", str(EVERY), "--np", str(np_), *extra]


def restart_steps(deck_dir):
    names = os.listdir(deck_dir) if os.path.isdir(deck_dir) else []
    return sorted(int(n.split(".")[1]) for n in names if n.startswith("restart.") and n.split(".")[1].isdigit())


def kill_session(proc):
    """SIGKILL to every process of the session of PROC (started with start_new_session), then
    PROC's exit status once no process of that session is left: the runner passes its deck lock
    on to LIGGGHTS, which holds it until it has exited, and a SIGKILLed rank of a loaded machine
    can outlive the runner by a moment (a resume started then is refused)."""
    subprocess.run(["pkill", "-KILL", "-s", str(proc.pid)])
    rc = proc.wait()
    deadline = time.time() + 60
    while session_alive(proc.pid) and time.time() < deadline:
        time.sleep(0.01)
    return rc


def session_alive(sid):
    """Whether a process of session SID is still running (zombies, which hold no files, aside)."""
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open("/proc/%s/stat" % pid) as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            return True
    return False


def interrupted(out, np_, how, *extra):
    """The run into OUT, interrupted (`kill`: SIGKILL to the runner and everything it started;
    `term`: SIGTERM to the runner) once the restart file of step KILL_AFTER exists."""
    deck = out[:-3] + ".deck"
    proc = subprocess.Popen(runner(SCENE, out, np_, *extra), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.time() + 300
    while proc.poll() is None and time.time() < deadline and max(restart_steps(deck) or [0]) < KILL_AFTER:
        time.sleep(0.001)
    if how == "kill":
        # the runner was started in a session of its own, and everything it started is in it:
        # LIGGGHTS or mpirun (in a process group of its own) and Open MPI's ranks (each in one
        # of its own), so a kill of the session leaves no rank running on
        return kill_session(proc), restart_steps(deck)
    os.kill(proc.pid, signal.SIGTERM)
    return proc.wait(), restart_steps(deck)


def datasets(path):
    found = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: found.__setitem__(n, o[()]) if isinstance(o, h5py.Dataset)
                     and not n.startswith("h5md") else None)
    return found


def same_bits(a, b):
    if isinstance(a, np.ndarray) and a.dtype.kind == "f":
        return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)
    return np.array_equal(a, b)


def positions_equal(a, b):
    """Whether the two trajectories' particle positions are the same bits in every frame."""
    pa, pb = datasets(a), datasets(b)
    names = [n for n in pa if n.endswith("position/value") and n.startswith("particles")]
    return bool(names) and all(n in pb and same_bits(pa[n], pb[n]) for n in names)


def same_trajectory(name, ref, cont):
    if not check(name + "_complete", os.path.exists(cont), "no %s" % cont):
        return
    a, b = datasets(ref), datasets(cont)
    check(name + "_same_datasets", sorted(a) == sorted(b), "only in the reference: %s; only continued: %s"
          % (sorted(set(a) - set(b)), sorted(set(b) - set(a))))
    differ = [n for n in a if n in b and not same_bits(a[n], b[n])]
    check(name + "_bit_for_bit", not differ and len(a) > 40,
          "%d datasets compared, differing: %s" % (len(a), differ[:8]))


def continued(tmp, np_, how, ref, *extra):
    name = "%s_np%d" % (how if not extra else "sorted", np_)
    out = os.path.join(tmp, name + ".h5")
    rc, steps = interrupted(out, np_, how, *extra)
    want = -signal.SIGKILL if how == "kill" else 128 + signal.SIGTERM
    if not check(name + "_was_interrupted", rc == want and len(steps) >= 2 and not os.path.exists(out),
                 "exit %s (want %s), restart files at steps %s" % (rc, want, steps)):
        return
    r = subprocess.run(runner(SCENE, out, np_, "--resume", *extra), capture_output=True, text=True)
    expect = "--resume: continuing from %s/restart.%d" % (out[:-3] + ".deck", steps[-2])
    check(name + "_continues_from_the_older_file", r.returncode == 0 and expect in r.stderr,
          "exit %d, want %r in:\n%s" % (r.returncode, expect, r.stderr[-1500:]))
    same_trajectory(name, ref, out)
    check(name + "_no_restart_file_left", restart_steps(out[:-3] + ".deck") == [],
          "left: %s" % restart_steps(out[:-3] + ".deck"))


def changed_scene(tmp):
    """An interrupted run resumed with a different scene starts again and says so."""
    out = os.path.join(tmp, "changed.h5")
    rc, _ = interrupted(out, 1, "kill")
    with open(SCENE) as f:
        text = f.read()
    scene = os.path.join(tmp, "changed.yaml")
    with open(scene, "w") as f:
        f.write(text.replace("end_time: 1.2", "end_time: 1.1"))
    r = subprocess.run(runner(scene, out, 1, "--resume"), capture_output=True, text=True)
    msg = "--resume: the scene differs from the interrupted run's; starting from the beginning"
    check("changed_scene_starts_again", rc == -signal.SIGKILL and r.returncode == 0 and msg in r.stderr,
          "kill exit %s, resume exit %d:\n%s" % (rc, r.returncode, r.stderr[-1000:]))


def resume_without_cadence(tmp):
    r = subprocess.run(RUNNER + [SCENE, "-o", os.path.join(tmp, "x.h5"), "--resume"], capture_output=True, text=True)
    msg = "liggghts_run: --resume needs --checkpoint-every N > 0, the cadence of the interrupted run's restart files"
    check("resume_needs_a_cadence", r.returncode == 2 and msg in r.stderr, "exit %d: %s" % (r.returncode, r.stderr))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="jdem_runner_resume_")
    try:
        resume_without_cadence(tmp)
        for np_ in (1, 2):
            ref = os.path.join(tmp, "ref_np%d.h5" % np_)
            r = subprocess.run(runner(SCENE, ref, np_), capture_output=True, text=True)
            if not check("reference_np%d_runs" % np_, r.returncode == 0, r.stderr[-1500:]):
                continue
            check("reference_np%d_no_restart_file_left" % np_, restart_steps(ref[:-3] + ".deck") == [],
                  "left: %s" % restart_steps(ref[:-3] + ".deck"))
            for how in ("kill", "term"):
                continued(tmp, np_, how, ref)
            sorted_ref = os.path.join(tmp, "ref_sorted_np%d.h5" % np_)
            r = subprocess.run(runner(SCENE, sorted_ref, np_, *SORT), capture_output=True, text=True)
            if check("reference_sorted_np%d_runs" % np_, r.returncode == 0, r.stderr[-1500:]):
                check("sorted_np%d_differs_from_unsorted" % np_, not positions_equal(ref, sorted_ref),
                      "the sorted run is the unsorted one bit for bit: did LIGGGHTS sort?")
                continued(tmp, np_, "kill", sorted_ref, *SORT)
        changed_scene(tmp)
    finally:
        if args.keep:
            print("kept %s" % tmp)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    print("%d failed" % checks.failed)
    return 1 if checks.failed else 0


if __name__ == "__main__":
    sys.exit(main())
