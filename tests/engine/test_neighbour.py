#!/usr/bin/python3
"""Engine test 1: the cell-list / Verlet-list path against the O(N^2) all-pairs reference.

216 jittered spheres (two radii) settle on a floor inside a cylinder with damping, friction and
rolling resistance; the Verlet list is rebuilt many times on the way.  The Verlet run keeps the
scene's particle order (--no-sort), and the all-pairs list is built again at the same steps,
its entries split alike (touching first), so both paths evaluate the same contacts in the same
order and the trajectories should agree to round-off (in fact bit for bit).  The sorted path
is checked against the unsorted one in test_fastpaths.py.  The all-pairs references run on the
optimised build (build/jdem) also when JDEM is the sanitized one: they are the same bits (the
builds differ in code generation only, never in arithmetic), and under the sanitizers their
O(N^2) lists took 200 of the suite's 230 s.

Run:  /usr/bin/python3 tests/engine/test_neighbour.py        (JDEM=path/to/jdem to override)
"""
import os
import re
import tempfile

import yaml

from scripts import engines
from tests.engine.engine_common import JDEM, JDEM_OPTIMISED, Checks, load, np, run, scene

c = Checks()
_, verlet = run("lattice_floor", "--no-sort")
_, allpairs = run("lattice_floor", env={"JDEM_NEIGHBOUR": "allpairs"}, binary=JDEM_OPTIMISED)
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
# One sphere 50 m above a settling bed: the grid covers the bulk and bins the far sphere into
# its edge cells; the list must still hold every pair within range (same trajectory as all-pairs).
_, far_verlet = run("far_particle", "--no-sort")
_, far_sorted = run("far_particle")
_, far_all = run("far_particle", env={"JDEM_NEIGHBOUR": "allpairs"}, binary=JDEM_OPTIMISED)
fa, fb, fs = load(far_verlet), load(far_all), load(far_sorted)
c.check("far_particle_verlet_vs_allpairs_bitwise",
        np.array_equal(fa["position"], fb["position"]) and np.array_equal(fa["velocity"], fb["velocity"]),
        "positions or velocities differ")
c.check("far_particle_bed_has_contacts", fa["obs"]["contacts"][-1] > 100,
        f"{fa['obs']['contacts'][-1]:g} contacts at the end")
order = np.argsort(fs["id"])
c.check("far_particle_sorted_vs_allpairs", np.max(np.abs(fs["position"][-1][order] - fb["position"][-1][np.argsort(fb["id"])])) <= 1e-12,
        "the sorted run's final positions differ from the all-pairs run's by more than 1e-12 m")
# Per-particle half skins: spheres raining at 5 m/s onto a bed get half skins of 2.2 mm against
# the bed's 0.5 mm.  Every pair and wall contact must be in the lists (bit for bit the all-pairs
# run, which rebuilds at the same steps; renumbered, to round-off, with the same contacts), and
# the fast spheres' own skins must spare rebuilds (the same scene with one skin for all,
# skin_steps: 0, rebuilds at least twice as often).
def against_allpairs(name):
    """The scene's Verlet run (scene order, --timing) bit for bit against the all-pairs run, and
    its renumbered run to round-off with the same contact counts; (Verlet run, its trajectory)."""
    verlet_run, verlet = run(name, "--no-sort", "--timing")
    _, allpairs = run(name, env={"JDEM_NEIGHBOUR": "allpairs"}, binary=JDEM_OPTIMISED)
    va, vb = load(verlet), load(allpairs)
    c.check(f"{name}_verlet_vs_allpairs_bitwise",
            np.array_equal(va["position"], vb["position"]) and np.array_equal(va["velocity"], vb["velocity"]),
            "positions or velocities differ: a contact was missed by the lists")
    vs = load(run(name)[1])
    order_s, order_b = np.argsort(vs["id"]), np.argsort(vb["id"])
    dx = np.max(np.abs(vs["position"][:, order_s] - vb["position"][:, order_b])) / np.max(np.abs(vb["position"]))
    c.check(f"{name}_sorted_vs_allpairs", dx <= 1e-12 and np.array_equal(vs["obs"]["contacts"], vb["obs"]["contacts"]),
            f"the renumbered run's positions differ from the all-pairs run's by {dx:.3g} of the largest, or "
            "its contact counts differ (the half skins must follow the particles' new numbers)")
    return verlet_run, va


rain_run, ra = against_allpairs("shower")
c.check("shower_has_impacts", ra["obs"]["contacts"].max() > 200 and ra["obs"]["wall_contacts"].max() > 50,
        f"{ra['obs']['contacts'].max():g} contacts, {ra['obs']['wall_contacts'].max():g} wall contacts at most")
# Partial builds: a sparse rain onto the bed, so that at most builds fewer than half the spheres
# have moved and only theirs are searched again (stepper/neighbour.c); the kept entries must
# still hold every pair that comes into contact.
drizzle_run, da = against_allpairs("drizzle")
timing = engines.jdem_timing(drizzle_run.stderr) or {}
c.check("drizzle_builds_are_mostly_partial",
        timing.get("partial_builds", 0) > timing.get("builds", 0) / 2 and
        da["obs"]["contacts"].max() > 50 and da["obs"]["wall_contacts"].max() > 50,
        f"{timing.get('partial_builds')} partial of {timing.get('builds')} builds, "
        f"{da['obs']['contacts'].max():g} contacts, {da['obs']['wall_contacts'].max():g} wall contacts "
        "at most (the scene must exercise the partial path and the walls)")

# A partial build's range for a kept partner: a sphere still behind its reference position turns
# back towards a moved one; the pair must be in the list (drift_partner.yaml says how).
drift_run, dr = against_allpairs("drift_partner")
timing = engines.jdem_timing(drift_run.stderr) or {}
c.check("drift_partner_contact_after_partial_build",
        timing.get("partial_builds", 0) >= 1 and dr["obs"]["contacts"].max() == 1,
        f"{timing.get('partial_builds')} partial builds, {dr['obs']['contacts'].max():g} contacts at most "
        "(the scene must touch after a partial build)")


def builds(stderr):
    found = re.search(r"(\d+) neighbour builds", stderr)
    return int(found.group(1)) if found else None


tmp = tempfile.mkdtemp(prefix="jdem_shower_")
with open(scene("shower")) as f:
    one_skin = yaml.load(f, Loader=yaml.CSafeLoader)
one_skin["neighbour"] = {"skin_steps": 0}
with open(os.path.join(tmp, "one_skin.yaml"), "w") as f:
    yaml.safe_dump(one_skin, f)
one_skin_run = engines.jdem("run", os.path.join(tmp, "one_skin.yaml"), "-o", os.path.join(tmp, "b.h5"),
                            "--no-sort", binary=JDEM)
own, common = builds(rain_run.stderr), builds(one_skin_run.stderr) if one_skin_run.returncode == 0 else None
c.check("shower_own_skins_spare_rebuilds", own and common and 2 * own <= common,
        f"{own} neighbour builds with skin_steps 50, {common} with one skin")
c.exit()
