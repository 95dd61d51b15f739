#!/usr/bin/python3
"""Engine test 1: the cell-list / Verlet-list path against the O(N^2) all-pairs reference.

216 jittered spheres (two radii) settle on a floor inside a cylinder with damping, friction and
rolling resistance; the Verlet list is rebuilt many times on the way.  The Verlet run keeps the
scene's particle order (--no-sort), and the all-pairs list is built again at the same steps,
its entries split alike (touching first), so both paths evaluate the same contacts in the same
order and the trajectories should agree to round-off (in fact bit for bit).  The sorted path
is checked against the unsorted one in test_fastpaths.py.

Run:  /usr/bin/python3 tests/engine/test_neighbour.py        (JDEM=path/to/jdem to override)
"""
from tests.engine.engine_common import Checks, load, np, run

c = Checks()
_, verlet = run("lattice_floor", "--no-sort")
_, allpairs = run("lattice_floor", env={"JDEM_NEIGHBOUR": "allpairs"})
a, b = load(verlet), load(allpairs)
xa, xb = a["position"][-1], b["position"][-1]
scale = np.max(np.abs(xb))
err = np.max(np.abs(xa - xb)) / scale
c.check("verlet_vs_allpairs_final_positions", err <= 1e-12, f"max relative difference {err:.3g}")
dv = np.max(np.abs(a["velocity"][-1] - b["velocity"][-1])) / np.max(np.abs(b["velocity"][-1]))
c.check("verlet_vs_allpairs_final_velocities", dv <= 1e-9, f"max relative difference {dv:.3g}")
moved = np.max(np.abs(a["position"][-1] - a["position"][0]))
c.check("lattice_actually_moved", moved > 2e-3, f"largest displacement {moved:.3g} m")
contacts = a["obs"]["contacts"][-1] + a["obs"]["wall_contacts"][-1]
c.check("lattice_has_contacts", contacts > 100, f"{contacts:g} contacts at the end")
same_obs = all(np.array_equal(a["obs"][k], b["obs"][k]) for k in ("contacts", "wall_contacts"))
c.check("verlet_vs_allpairs_contact_counts", same_obs, "contact counts differ")
zmin = np.min(a["position"][-1][:, 2] - a["radius"])
c.check("nothing_fell_through_the_floor", zmin > -1e-4, f"lowest surface at z = {zmin:.3g} m")
c.exit()
