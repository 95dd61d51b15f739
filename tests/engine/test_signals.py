#!/usr/bin/python3
"""Engine test: a run stopped by SIGTERM (SIGINT) exits 143 (130) with a message naming the step,
and leaves a readable, closed OUT.part whose last frame is that step; nothing under OUT.

Run:  /usr/bin/python3 tests/engine/test_signals.py           (JDEM=path/to/jdem to override)
"""
import os
import re
import signal
import subprocess
import tempfile
import time

import h5py

from tests.engine.engine_common import JDEM, Checks, scene

c = Checks()


def stop_run(sig, status, word):
    out = os.path.join(tempfile.mkdtemp(prefix="jdem_signals_"), "long_run.h5")
    p = subprocess.Popen([JDEM, "run", scene("long_run"), "-o", out, "--quiet"],
                         stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    p.send_signal(sig)
    try:
        _, err = p.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        p.kill()
        _, err = p.communicate()
    name = sig.name
    c.check(f"{name}_exit_{status}", p.returncode == status, f"exit {p.returncode}: {err.strip()!r}")
    m = re.search(rf"jdem: {word} \({name}\) at step (\d+); .* as {re.escape(out)}\.part", err)
    if not c.check(f"{name}_message", m is not None, f"stderr: {err.strip()!r}"):
        return
    c.check(f"{name}_no_final_file", not os.path.exists(out), "a file under the final name")
    try:
        with h5py.File(out + ".part", "r") as f:
            steps = f["particles/all/position/step"][()]
    except OSError as e:
        c.check(f"{name}_part_readable", False, str(e))
        return
    c.check(f"{name}_frames", len(steps) >= 1 and steps[-1] == int(m.group(1)),
            f"frame steps {steps}, stopped at {m.group(1)}")


stop_run(signal.SIGTERM, 143, "terminated")
stop_run(signal.SIGINT, 130, "interrupted")
c.exit()
