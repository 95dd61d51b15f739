#!/usr/bin/python3
"""Engine test: a wall that vanishes (walls[].until, stepper/walls.c sim_walls_retire).

tests/liggghts/scenes/mpi_wall_vanishes.yaml (also run by the cross-engine suite against
LIGGGHTS' fix wall/jiang until_step on 1 and 2 ranks): three spheres come to rest on a floor,
which vanishes at 0.03 s, step S = 15000, with a cylinder they never touch.  References:
  - the resolved scene: until 0.03 s at dt 2e-6 s is step ceil(0.03/dt) = 15000;
  - after S the spheres fly freely: velocity Verlet under gravity alone is exact, so every later
    frame is x_S + v_S t + g t^2/2 (t = time since S), their spin constant;
  - the floor carries them up to the last sample before S, and nothing from S on;
  - the energy balance across the removal: the elastic energy the floor's contacts held leaves
    with it as the wall's work; unbooked, the balance would jump by that energy (2.2e-8 J).

Run:  /usr/bin/python3 tests/engine/test_wall_vanishes.py        (JDEM=path/to/jdem to override)
"""
import os
import tempfile

import h5py
import yaml

from tests.engine.engine_common import JDEM, Checks, energy_total, load, np
from scripts import engines

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "tests", "liggghts", "scenes", "mpi_wall_vanishes.yaml")
G = np.array([0.0, 0.0, -9.81])
DT, S = 2.0e-6, 15000

c = Checks()
resolved = yaml.safe_load(engines.jdem("resolve", SCENE, binary=JDEM).stdout)
c.check("until: 0.03 s resolves to until_step 15000 on both walls",
        [w.get("until_step") for w in resolved["walls"]] == [S, S],
        str([w.get("until_step") for w in resolved["walls"]]))
out = os.path.join(tempfile.mkdtemp(prefix="jdem_engine_"), "wall_vanishes.h5")
p = engines.jdem("run", SCENE, "-o", out, "--quiet", binary=JDEM)
if not c.check("jdem runs the scene", p.returncode == 0, p.stderr.strip()):
    c.exit()
t = load(out)
steps = t["position_step"]
k = int(np.flatnonzero(steps == S)[0])
x, v, w = t["position"], t["velocity"], t["angular_velocity"]
worst_x = worst_w = 0.0
for f in range(k + 1, len(steps)):
    tt = (steps[f] - S) * DT
    free = x[k] + v[k] * tt + 0.5 * G * tt * tt
    worst_x = max(worst_x, float(np.max(np.abs(x[f] - free))))
    worst_w = max(worst_w, float(np.max(np.abs(w[f] - w[k]))))
c.check("after the removal every sphere is in free flight (largest departure from the parabola "
        "below 1e-12 m)", worst_x <= 1e-12, f"{worst_x:.3g} m")
c.check("after the removal the spins stay constant (to 1e-12 rad/s)", worst_w <= 1e-12, f"{worst_w:.3g} rad/s")

o = t["obs"]
with h5py.File(out, "r") as f:
    ostep = f["observables/wall_contacts/step"][()]
i = int(np.flatnonzero(ostep == S)[0])
c.check("the floor carries the three spheres at the last sample before the removal",
        o["wall_contacts"][i - 1] == 3, str(o["wall_contacts"][i - 1]))
c.check("no wall contact from the removal on", np.all(o["wall_contacts"][i:] == 0),
        str(o["wall_contacts"][i:]))
E = energy_total(o)
jump, held = abs(E[i] - E[i - 1]), o["elastic_energy"][i - 1]
c.check("the energy balance across the removal: its change below 1e-3 of the elastic energy the "
        "floor held", held > 0 and jump <= 1e-3 * held, f"change {jump:.3g} J, held {held:.3g} J")
c.check("the wall's work takes that energy: the elastic energy of the step before the removal, "
        "within 2 % of that at the sample 500 steps before", abs((o["wall_work"][i] - o["wall_work"][i - 1]) + held) <= 0.02 * held,
        f"wall work change {o['wall_work'][i] - o['wall_work'][i - 1]:.4g} J, held {held:.4g} J")
c.exit()
