#!/usr/bin/python3
"""Engine test: the run-time watchdog (docs/scenes.md "Watchdog").

A run that goes wrong on purpose (scenes/watchdog_blowup.yaml, dt ~100x too large, --force) must
stop at step 1 with "jdem: watchdog: step 1: overlap fraction ... for particle(s) 1, 2 exceeds
0.1", exit status 4, and leave a readable, closed OUT.part (nothing under OUT) whose last frame is
step 1 with finite values; with the overlap limit lifted the energy jump trips instead.  A
position that overflows (scenes/watchdog_nonfinite.yaml) stops the run at step 1 with "position
inf for particle(s) 1 is not finite", the trajectory ending at step 0.  A resolved impact
(Chung & Ooi test 1) must not trip.

Run:  /usr/bin/python3 tests/engine/test_watchdog.py          (JDEM=path/to/jdem to override)
"""
import os
import re

import h5py

from tests.engine.engine_common import Checks, np, run

PATTERN = (r"jdem: watchdog: step (\d+): {quantity} ([0-9.e+-]+) for particle\(s\) ([0-9, ]+) "
           r"exceeds ([0-9.e+-]+)")

c = Checks()


def check_part(case, out, last_step):
    """OUT.part readable and closed, nothing under OUT, last frame at last_step, all finite."""
    c.check(f"{case}_no_final_file", not os.path.exists(out), "a file under the final name")
    try:
        with h5py.File(out + ".part", "r") as f:
            steps = f["particles/all/position/step"][()]
            finite = all(np.isfinite(f[f"particles/all/{k}/value"][()]).all()
                         for k in ("position", "velocity", "angular_velocity", "force", "torque"))
    except OSError as e:
        c.check(f"{case}_part_readable", False, str(e))
        return
    c.check(f"{case}_last_frame", len(steps) and steps[-1] == last_step,
            f"frame steps {steps}, expected the last at {last_step}")
    c.check(f"{case}_frames_finite", finite, "non-finite values in the trajectory")


def check_trip(case, quantity, ids, limit):
    p, out = run("watchdog_blowup", "--case", case, "--force", check=False)
    c.check(f"{case}_exit_4", p.returncode == 4, f"exit {p.returncode}: {p.stderr.strip()!r}")
    m = re.search(PATTERN.format(quantity=quantity), p.stderr)
    if not c.check(f"{case}_message", m is not None, f"stderr: {p.stderr.strip()!r}"):
        return
    step, value, got_ids, got_limit = int(m.group(1)), float(m.group(2)), m.group(3), float(m.group(4))
    c.check(f"{case}_step_ids_limit", step == 1 and got_ids.strip() == ids and got_limit == limit
            and value > limit, f"step {step}, ids {got_ids!r}, value {value}, limit {got_limit}")
    c.check(f"{case}_message_names_part", f"{out}.part" in p.stderr, f"stderr: {p.stderr.strip()!r}")
    check_part(case, out, step)


check_trip("overlap", "overlap fraction", "1, 2", 0.1)
check_trip("energy", "energy jump", "1", 0.05)

p, out = run("watchdog_nonfinite", "--force", check=False)
c.check("nonfinite_exit_4", p.returncode == 4, f"exit {p.returncode}: {p.stderr.strip()!r}")
c.check("nonfinite_message", "jdem: watchdog: step 1: position inf for particle(s) 1 is not finite; "
        f"the trajectory up to step 0 is kept, closed, as {out}.part" in p.stderr,
        f"stderr: {p.stderr.strip()!r}")
check_part("nonfinite", out, 0)

p, out = run("chung_ooi_1", check=False)
c.check("resolved_impact_does_not_trip", p.returncode == 0 and "jdem: watchdog:" not in p.stderr
        and os.path.exists(out), f"exit {p.returncode}: {p.stderr.strip()!r}")
c.exit()
