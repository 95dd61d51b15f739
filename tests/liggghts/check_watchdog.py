#!/usr/bin/python3
"""check_watchdog.py — the run-time watchdog in LIGGGHTS (fix jdem/watchdog) against build/jdem's.

    tests/liggghts/check_watchdog.py [--keep]

For each case of tests/engine/scenes/watchdog_blowup.yaml (an overlap trip, an energy-jump
trip) both engines must stop at the same step with the same message "jdem: watchdog: step N:
QUANTITY VALUE for particle(s) IDS exceeds LIMIT" (LIGGGHTS through error->all, on 1 and on 2
MPI ranks), exit non-zero, and leave a readable OUT.part (nothing under OUT) whose last frame is
that step with finite values.  An infinite force injected at step 1 (fix addforce; particle 2,
on rank 1 of 2 too) must stop the run at step 1 with the stepper's message for a non-finite
state, the file ending at step 0.  A resolved impact (Chung & Ooi test 1) must run to the end in
LIGGGHTS with the watchdog in its deck.  Prints one PASS/FAIL line per check; exit 1 on failure.
"""
import argparse
import os
import re
import sys
import tempfile

from tests.liggghts.liggghts_common import (ROOT, Checks, edit_deck, finish, jdem_run, liggghts_run,
                                            liggghts_run_log, make_deck, part_frames, run_deck)

SCENE = os.path.join(ROOT, "tests", "engine", "scenes", "watchdog_blowup.yaml")
TRIP = re.compile(r"jdem: watchdog: step (\d+): [^;]*")
CHECKS = Checks()
check = CHECKS.check


def check_part(name, out, step):
    """OUT.part readable, OUT absent, last frame at `step`, every value finite."""
    check(name + "_no_final_file", not os.path.exists(out), "a file under the final name")
    try:
        steps, finite, _ = part_frames(out)
    except OSError as e:
        return check(name + "_part_readable", False, str(e))
    check(name + "_last_frame", len(steps) > 0 and steps[-1] == step, "frame steps %s, trip at %d" % (steps, step))
    check(name + "_finite", finite, "non-finite values in the trajectory")


def liggghts(tmp, case, np_):
    out = os.path.join(tmp, "%s_np%d.h5" % (case, np_))
    rc, _ = liggghts_run(SCENE, out, "--force", case=case, ranks=np_)
    return rc, liggghts_run_log(out), out


def nonfinite_force(tmp, np_):
    """The `energy` case with an infinite force on particle 2 from step 1 on (fix addforce of
    step x 1e300 x 1e300: 0 at set-up, inf at step 1), on rank 1 of 2 with np_ = 2: the watchdog
    must stop at step 1 naming the force of particle 2 (the stepper's message for a non-finite
    state), before the integrator moves it, and keep the file with the frames up to step 0."""
    name = "liggghts_nonfinite_np%d" % np_
    d = os.path.join(tmp, name)
    os.makedirs(d)
    out = os.path.join(d, "out.h5")
    make_deck(SCENE, d, "--force", case="energy", trajectory=out)

    def boom(deck):
        deck = deck.replace("\nrun ", "\ngroup boom id 2\nvariable fx equal step*1e300*1e300\n"
                            "fix boom boom addforce v_fx 0 0\nrun ", 1)
        if np_ > 1:  # particle 2 (x > 0) on rank 1
            deck = re.sub(r"(?m)^(boundary .*)$", r"\1\nprocessors 2 1 1", deck, count=1)
        return deck
    edit_deck(d, boom)
    rc, log, _ = run_deck(d, ranks=np_)
    check(name + "_fails", rc != 0, "exit status 0")
    want = ("jdem: watchdog: step 1: force inf for particle(s) 2 is not finite; the trajectory up to step 0 "
            "is kept, closed, as %s.part (the run failed)" % out)
    if check(name + "_message", want in log, "expected %r in the log: %r" % (want, log[-1500:])):
        check_part(name, out, 0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--keep", action="store_true", help="keep the runs (printed directory)")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="jdem_watchdog_")
    for case, ranks in (("overlap", (1, 2)), ("energy", (1,))):
        out = os.path.join(tmp, case + ".jdem.h5")
        rc, said = jdem_run(SCENE, out, "--case", case, "--force", "--quiet")
        m = TRIP.search(said)
        if not check("jdem_%s_trips" % case, rc == 4 and m, "exit %d: %r" % (rc, said)):
            continue
        for n in ranks:
            name = "liggghts_%s_np%d" % (case, n)
            rc, log, lout = liggghts(tmp, case, n)
            lm = TRIP.search(log)
            check(name + "_fails", rc != 0, "exit status 0")
            if check(name + "_same_message", lm is not None and lm.group(0) == m.group(0),
                     "jdem: %r, LIGGGHTS: %r" % (m.group(0), lm.group(0) if lm else log[-1500:])):
                check(name + "_names_part", lout + ".part" in log, "the message does not name %s.part" % lout)
                check_part(name, lout, int(lm.group(1)))
    for n in (1, 2):
        nonfinite_force(tmp, n)
    out = os.path.join(tmp, "impact.h5")
    rc, said = liggghts_run(os.path.join(ROOT, "tests", "engine", "scenes", "chung_ooi_1.yaml"), out)
    check("liggghts_resolved_impact_does_not_trip", rc == 0 and os.path.exists(out),
          "exit %d: %s" % (rc, said[-1500:]))
    return finish(CHECKS, tmp, a.keep)


if __name__ == "__main__":
    sys.exit(main())
