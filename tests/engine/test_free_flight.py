#!/usr/bin/python3
"""Engine test 2: a single sphere in free flight under gravity.  Velocity Verlet integrates a
constant force exactly, so x(t) = x0 + v0 t + g t^2/2 and v(t) = v0 + g t hold to round-off, and
the angular velocity stays constant (no torque).  Tolerance: round-off accumulated over
10^4 steps (~1e-16 each).

Run:  /usr/bin/python3 tests/engine/test_free_flight.py      (JDEM=path/to/jdem to override)
"""
from tests.engine.engine_common import Checks, load, np, run

x0, v0, w0 = np.array([0.1, 0.2, 0.3]), np.array([0.3, -0.2, 1.0]), np.array([1.0, 2.0, 3.0])
g = np.array([0.5, -1.0, -9.81])
c = Checks()
_, out = run("drop")
t = load(out)
time = t["position_time"][:, None]
x_exact = x0 + v0 * time + 0.5 * g * time**2
v_exact = v0 + g * t["velocity_time"][:, None]
ex = np.max(np.abs(t["position"][:, 0, :] - x_exact)) / np.max(np.abs(x_exact))
ev = np.max(np.abs(t["velocity"][:, 0, :] - v_exact)) / np.max(np.abs(v_exact))
c.check("frames_written", len(time) == 101, f"{len(time)} frames, want 101 (every 100 of 10000 steps)")
c.check("position_parabola", ex < 2e-12, f"max relative error {ex:.3g}")
c.check("velocity_linear", ev < 2e-12, f"max relative error {ev:.3g}")
c.check("spin_constant", np.all(t["angular_velocity"][:, 0, :] == w0), "angular velocity changed")
m = t["mass"][0]
c.check("force_is_weight", np.allclose(t["force"][:, 0, :], m * g, rtol=1e-15, atol=0), "force != m g")
E = t["obs"]["kinetic_energy"] + t["obs"]["gravitational_energy"]
c.check("energy_conserved", np.ptp(E) / abs(E[0]) < 1e-12, f"drift {np.ptp(E) / abs(E[0]):.3g}")
c.exit()
