#!/usr/bin/python3
"""Engine test 5: the time-step guard refuses dt = 2e-6 s for Chung & Ooi test 1 (1/50 of the
contact time is 8.07e-7 s) with exit status 2, names the bound and the largest safe dt, writes no
output; --force runs it with a warning.

Run:  /usr/bin/python3 tests/engine/test_guard.py            (JDEM=path/to/jdem to override)
"""
import os

from tests.engine.engine_common import Checks, run

c = Checks()
p, out = run("guard_unsafe", check=False)
c.check("refused_exit_2", p.returncode == 2, f"exit status {p.returncode}")
msg = p.stderr
c.check("message_names_bound", "time step 2e-06 s is unsafe" in msg and "contact time" in msg
        and "largest safe dt = 8.06" in msg and "--force" in msg, f"stderr: {msg.strip()!r}")
c.check("no_output_when_refused", not os.path.exists(out) and not os.path.exists(out + ".part"),
        "an output file was written")
p, out = run("guard_unsafe", "--force", check=False)
c.check("force_runs", p.returncode == 0 and os.path.exists(out), f"exit {p.returncode}: {p.stderr.strip()!r}")
c.check("force_warns", "warning" in p.stderr, f"stderr: {p.stderr.strip()!r}")
p, _ = run("chung_ooi_1", check=False)
c.check("safe_dt_accepted", p.returncode == 0, f"exit {p.returncode}: {p.stderr.strip()!r}")
c.exit()
