#!/usr/bin/python3
"""Engine test: the default time step.  A scene without time.dt, or with `dt: auto`, runs at
DT_AUTO_FACTOR x the guard's safe dt (docs/scenes.md "Time step", docs/model.md "Default time
step"); `jdem resolve` writes that dt, and end_time counts in steps of it.  The references are
computed here from the closed forms: 1/50 of the Hertz contact time of two equal spheres, and
20 % of the Rayleigh time step.  A malformed dt gives the exact message.

Run:  /usr/bin/python3 tests/engine/test_dt_auto.py            (JDEM=path/to/jdem to override)
"""
import math
import os
import tempfile

import yaml

from scripts import engines
from tests.engine.engine_common import JDEM, Checks, run, scene

DT_AUTO_FACTOR = 1.0  # the documented default: the guard's safe dt itself


def resolve(path):
    p = engines.resolve(path, binary=JDEM)
    return p, (yaml.load(p.stdout, Loader=yaml.CSafeLoader) if p.returncode == 0 else None)


def hertz_contact_time(E, nu, rho, R, v):
    """Two equal spheres: E* = E / (2 (1 - nu^2)), R* = R/2, m* = m/2, approach speed v."""
    e_star, r_star, m_star = E / (2 * (1 - nu * nu)), R / 2, 4 / 3 * math.pi * R ** 3 * rho / 2
    delta = (15 * m_star * v * v / (16 * e_star * math.sqrt(r_star))) ** 0.4
    return 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9) * delta / v


def rayleigh_step(E, nu, rho, R):
    return math.pi * R * math.sqrt(rho * 2 * (1 + nu) / E) / (0.1631 * nu + 0.876605)


c = Checks()
want = DT_AUTO_FACTOR * hertz_contact_time(4.8e10, 0.2, 2800, 0.01, 20.0) / 50
p, doc = resolve(scene("dt_auto"))
if c.check("omitted_dt_resolves", doc is not None, p.stderr.strip()):
    c.close_to("omitted_dt_is_contact_bound", float(doc["time"]["dt"]), want, 1e-9)
    c.check("end_time_in_auto_steps", int(doc["time"]["steps"]) == math.ceil(6.0e-5 / float(doc["time"]["dt"]) - 1e-9),
            f"steps {doc['time']['steps']}")

p, doc = resolve(scene("dt_auto_rest"))
if c.check("auto_dt_resolves", doc is not None, p.stderr.strip()):
    c.close_to("auto_dt_is_rayleigh_bound", float(doc["time"]["dt"]),
               DT_AUTO_FACTOR * 0.2 * rayleigh_step(2.1e11, 0.3, 7800, 0.002), 1e-9)

p, out = run("dt_auto", check=False)
c.check("auto_dt_passes_the_guard", p.returncode == 0 and os.path.exists(out), f"exit {p.returncode}: {p.stderr.strip()!r}")
p, out = run("dt_auto", "--quiet", check=False)
c.check("auto_dt_runs_quietly", p.returncode == 0 and p.stderr == "", f"stderr {p.stderr!r}")
p = engines.jdem("run", scene("dt_auto"), "-o", out + ".2.h5", binary=JDEM)
c.check("summary_says_auto", "(auto: %g x the guard's safe dt)" % DT_AUTO_FACTOR in p.stderr, f"stderr {p.stderr!r}")

with tempfile.TemporaryDirectory() as d:
    bad = os.path.join(d, "bad.yaml")
    with open(scene("dt_auto")) as f:
        text = f.read().replace("time:\n", "time:\n  dt: -auto\n")
    with open(bad, "w") as f:
        f.write(text)
    p, _ = resolve(bad)
    c.check("malformed_dt_message", p.returncode == 2 and p.stderr ==
            "jdem: %s:8: key 'time.dt': '-auto' is not a number; valid: a number > 0, or auto\n" % bad,
            f"exit {p.returncode}, stderr {p.stderr!r}")
c.exit()
