#!/usr/bin/python3
"""check_signals.py — liggghts-jdem stopped by SIGINT or SIGTERM (liggghts_plugin/jdem_stop.h).

    tests/liggghts/check_signals.py [--keep]

Runs the deck of tests/liggghts/signals_scene.yaml (a sphere settling on a floor for 2e9 steps,
a frame every 20000 steps), waits until the run has written frames for a second, and sends:
  * SIGINT to liggghts-jdem on 1 rank: exit status 130;
  * SIGTERM to liggghts-jdem on 1 rank: exit status 143;
  * SIGTERM to both ranks of a 2-rank mpirun (as a batch system does): mpirun's status 143.
Each time, as build/jdem (tests/engine/test_signals.py): the message "jdem: interrupted (SIGINT)
at step N; the trajectory up to step N is kept, closed, as OUT.part" (terminated (SIGTERM) ...),
a readable OUT.part whose frames are the multiples of 20000 below N and then N, with finite
values, and nothing under OUT.  Prints one PASS/FAIL line per check; exit 1 on failure.
LIGGGHTS_JDEM selects the binary (default build/liggghts-jdem).
"""
import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

from scripts import engines
from tests.liggghts.liggghts_common import HERE, LIGGGHTS_JDEM, Checks, finish, make_deck, part_frames

SCENE = os.path.join(HERE, "signals_scene.yaml")
EVERY = 20000
CHECKS = Checks()
check = CHECKS.check


def children(pid):
    try:
        with open("/proc/%d/task/%d/children" % (pid, pid)) as f:
            return [int(c) for c in f.read().split()]
    except OSError:
        return []


def stop_run(tmp, name, sig, ranks, status):
    d = os.path.join(tmp, name)
    os.makedirs(d)
    out = os.path.join(d, "out.h5")
    make_deck(SCENE, d, trajectory=out)
    # started here, not by engines.run: the check signals it while it runs
    p = subprocess.Popen(engines.liggghts_command("in.jdem", ranks, binary=LIGGGHTS_JDEM), cwd=d,
                         stderr=subprocess.PIPE, text=True)
    # the run has started once the dump created OUT.part (at set-up); then let it write frames
    # (one every 20000 steps, dozens per second on one core)
    t0 = time.time()
    while time.time() - t0 < 60 and p.poll() is None and not os.path.exists(out + ".part"):
        time.sleep(0.1)
    time.sleep(1.0)
    # a batch system signals every process of the job: the ranks, not mpirun
    targets = [p.pid] if ranks == 1 else children(p.pid)
    for pid in targets:
        os.kill(pid, sig)
    try:
        _, err = p.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        p.kill()
        _, err = p.communicate()
    check(name + "_exit_%d" % status, p.returncode == status, "exit %s: %r" % (p.returncode, err[-1500:]))
    word = "interrupted (SIGINT)" if sig == signal.SIGINT else "terminated (SIGTERM)"
    m = re.search(r"jdem: %s at step (\d+); the trajectory up to step (\d+) is kept, closed, as %s\.part"
                  % (re.escape(word), re.escape(out)), err)
    if not check(name + "_message", m is not None and m.group(1) == m.group(2), "stderr: %r" % err[-1500:]):
        return
    step = int(m.group(1))
    check(name + "_no_final_file", not os.path.exists(out), "a file under the final name")
    try:
        steps, finite, obs_steps = part_frames(out)
    except OSError as e:
        check(name + "_part_readable", False, str(e))
        return
    want = list(range(0, step, EVERY)) + [step]
    check(name + "_frames", list(steps) == want and list(obs_steps) == want,
          "frames %s..., observables %s..., expected %s...%s" % (list(steps[:3]), list(obs_steps[:3]), want[:3], want[-2:]))
    check(name + "_finite", finite, "non-finite values in the trajectory")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--keep", action="store_true", help="keep the runs (printed directory)")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="jdem_lig_signals_")
    stop_run(tmp, "sigint_np1", signal.SIGINT, 1, 130)
    stop_run(tmp, "sigterm_np1", signal.SIGTERM, 1, 143)
    stop_run(tmp, "sigterm_np2", signal.SIGTERM, 2, 143)
    return finish(CHECKS, tmp, a.keep)


if __name__ == "__main__":
    sys.exit(main())
