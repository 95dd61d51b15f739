#!/usr/bin/python3
"""Engine test: the fast paths of the standalone engine against straightforward reference paths
on the same small scene (tests/engine/scenes/fastpaths.yaml: 216 spheres thrown onto a floor in
a cylinder, damping, friction, rolling resistance, ~50 neighbour rebuilds).

* spatial sorting (renumbering in cell order at every rebuild) against the scene's order
  (--no-sort): the contacts are the same, only the order in which forces are summed differs, so
  the trajectories agree to round-off (differences start at 1e-17 and grow through the
  collisions; the bounds below are 1e-12 relative, far below any physical effect: one missed
  contact step changes velocities by ~1e-3 relative) and the contact counts are identical
  (except for pairs exactly at the contact distance, to that round-off: their contact is decided
  by round-off);
* the force loops in SIMD batches against one contact at a time (--plain-loops): each contact's
  arithmetic and the order of the force sums are the same, so the trajectories and every
  observable (energies included) are identical bit for bit; also with a moving floor (the
  walls' work summed across the wall loop's batches), with two particle materials
  (the coefficients read per pair instead of once) and with one radius (the pair constants
  taken once instead of per pair);
* 2 OpenMP threads against 1: the same round-off bounds; two 2-thread runs are identical bit
  for bit (the summation order is fixed for a given thread count), and so are the batched and
  plain loops with 2 threads;
* the scene-specialised force loop against the general one (--all-laws) on the scene without
  damping and rolling resistance (restitution 1, rolling friction 0): the general loop
  evaluates those laws with zero coefficients, which add exact zeros, so the trajectories are
  identical bit for bit, also with bonds of zero stiffness added (bonds enabled at zero
  coefficients: they carry no load and hold no energy);
* energy bookkeeping off (output.energy: false) against on: it never feeds back into the
  forces, so the trajectories are identical bit for bit, and the energy observables are absent;
* the final half kick deferred into the next step's first pass (every step between samples)
  against a sample at every step (no kick deferred): identical bit for bit;
* bonds through the renumbering: the bonded 4x4x4 block of scripts/bond_checks.py dropped onto a
  tilted plate (bonds break progressively), sorted against --no-sort: the bonds are remapped at
  every renumbering, so the same bonds break at the same steps and the trajectories agree to
  round-off;
* the same block without the energy bookkeeping (9 bond state doubles instead of 18), and with
  the bonds' cross-sections computed per bond and step instead of taken per bond type (a lone
  sphere of another radius far away): identical bit for bit;
* the bond loop on 2 threads: a bonded lattice without contacts identical bit for bit to 1 thread,
  the block to round-off with the same breaks, and reproducible.

Run:  /usr/bin/python3 tests/engine/test_fastpaths.py        (JDEM=path/to/jdem to override)
"""
import math
import os
import re
import tempfile


import h5py
import yaml

from scripts import engines
from tests.engine.engine_common import Checks, load, np, scene, JDEM

from scripts import bond_checks  # the bonded-block scene

VECTORS = ("position", "velocity", "angular_velocity")
POS_TOL, VEL_TOL = 1e-12, 1e-10  # relative to the largest |value| of the frame


def run_file(path, *args, env=None):
    out = os.path.join(tempfile.mkdtemp(prefix="jdem_fastpaths_"), "out.h5")
    p = engines.jdem("run", path, "-o", out, "--quiet", "--timing", *args, binary=JDEM, env=env)
    if p.returncode != 0:
        raise RuntimeError(f"jdem run {path} {' '.join(args)} failed: {p.stderr.strip()}")
    m = re.search(r"jdem-timing: .*builds=(\d+) threads=(\d+)", p.stderr)
    t = load(out)
    t["path"] = out
    return t, int(m.group(1)), int(m.group(2))


def variant(text, name):
    path = os.path.join(tempfile.mkdtemp(prefix="jdem_fastpaths_"), name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


def rel_diff(a, b, key):
    """Largest difference over all frames, relative to the frame's largest |value|."""
    A, B = a[key], b[key]
    scale = np.maximum(np.max(np.abs(B), axis=(1, 2)), 1e-300)
    return float(np.max(np.max(np.abs(A - B), axis=(1, 2)) / scale))


def identical(a, b):
    return all(np.array_equal(a[k], b[k]) for k in VECTORS)


def marginal_pairs(a, b):
    """Per frame, the sphere pairs whose surface gap is zero to within the round-off the
    position check allows (2 POS_TOL of the frame's largest |x|, in either run): whether such a
    pair touches is decided by round-off.  A lattice of bonded spheres at exactly 2 R spacing
    has many."""
    r = a["radius"]
    iu = np.triu_indices(len(r), 1)
    radsum = (r[:, None] + r[None, :])[iu]
    counts = []
    for xa, xb in zip(a["position"], b["position"]):
        tol = 2 * POS_TOL * np.max(np.abs(xb))
        near = np.zeros(len(radsum), bool)
        for x in (xa, xb):
            d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)[iu]
            near |= np.abs(d - radsum) <= tol
        counts.append(int(near.sum()))
    return np.array(counts)


def roundoff_equal(c, name, a, b):
    dp, dv = rel_diff(a, b, "position"), max(rel_diff(a, b, "velocity"), rel_diff(a, b, "angular_velocity"))
    c.check(f"{name}_positions", dp <= POS_TOL, f"relative difference {dp:.3g} > {POS_TOL:g}")
    c.check(f"{name}_velocities", dv <= VEL_TOL, f"relative difference {dv:.3g} > {VEL_TOL:g}")
    # pair contacts: equal at every sample, but for pairs at the contact distance to round-off
    # (known only at the samples that have a frame)
    diff = np.abs(a["obs"]["contacts"] - b["obs"]["contacts"])
    frame_of = {t: k for k, t in enumerate(a["position_time"])}
    marginal = marginal_pairs(a, b)
    allowed = np.array([marginal[frame_of[t]] if t in frame_of else 0 for t in a["obs_time"]])
    same = bool(np.all(diff <= allowed)) and \
        np.array_equal(a["obs"]["wall_contacts"], b["obs"]["wall_contacts"])
    c.check(f"{name}_contact_counts", same,
            f"contact counts differ by {diff.tolist()}, pairs at the contact distance to round-off "
            f"{allowed.tolist()}")


c = Checks()
base = scene("fastpaths")
ref, builds, _ = run_file(base, "--no-sort")
c.check("scene_rebuilds_often", builds >= 20, f"only {builds} neighbour builds")
contacts = ref["obs"]["contacts"]
c.check("scene_has_many_contacts", contacts.max() >= 20 and (contacts[1:] > 0).all(),
        f"pair contacts per sample {contacts.tolist()}")

srt, srt_builds, _ = run_file(base)
c.check("sorting_changes_summation_order", not identical(ref, srt),
        "sorted and unsorted runs are identical: was anything renumbered?")
roundoff_equal(c, "sorted_vs_unsorted", srt, ref)

plain, plain_builds, _ = run_file(base, "--plain-loops")
# the plain path checks every step whether to rebuild; the fast one only once the particles
# could have moved half the skin (integrate.c, drift_bound): the rebuilds must be the same
c.check("batched_vs_plain_same_rebuilds", srt_builds == plain_builds,
        f"{srt_builds} neighbour builds against {plain_builds} with the check at every step")
# Two spheres in free flight, each 0.63 of the skin per step (skin 0.2 R, sim.c), with one skin
# for all: every step must rebuild, also the first step after a build, where the fast check's
# bound jumps past its mark in one step and the exact test decides on its own (integrate.c,
# far_check).  With their own half skins (neighbour.skin_steps, docs/scenes.md "Neighbour
# lists"), 20 steps' flight capped at the radius, they rebuild once they have flown one radius:
# every ceil(R / (v dt)) = 8 steps.
STEPS_FAST = 40
FAST_FLIGHT = """jdem_scene: 1
name: fast_flight
description: two spheres each moving more than half the skin per step
time: {{dt: 1.4e-5, steps: {steps}}}
output: {{every: {steps}}}
neighbour: {{skin_steps: {skin_steps}}}
materials:
  soft: {{youngs_modulus: 1.0e5, poisson_ratio: 0.3, density: 2500, restitution: 0.5, friction: 0.5}}
particles:
  - {{material: soft, radius: 0.001, position: [0, 0, 0], velocity: [9.0, 0.0, 0.0]}}
  - {{material: soft, radius: 0.001, position: [0.0, 0.01, 0.0], velocity: [-9.0, 0.0, 0.0]}}
"""
assert 9.0 * 1.4e-5 > 0.5 * 0.2 * 0.001
_, fast_builds, _ = run_file(variant(FAST_FLIGHT.format(steps=STEPS_FAST, skin_steps=0), "fast_flight"))
c.check("fast_flight_rebuilds_every_step", fast_builds == STEPS_FAST + 1,
        f"{fast_builds} neighbour builds in {STEPS_FAST} steps of 0.63 skin each (expected "
        f"{STEPS_FAST + 1}: the set-up build and one per step)")
own_every = math.ceil(0.001 / (9.0 * 1.4e-5))
assert 20 * 9.0 * 1.4e-5 > 0.001 and own_every == 8
_, own_builds, _ = run_file(variant(FAST_FLIGHT.format(steps=STEPS_FAST, skin_steps=20), "fast_flight_own"))
c.check("fast_flight_own_skins_rebuild_every_radius", own_builds == 1 + STEPS_FAST // own_every,
        f"{own_builds} neighbour builds in {STEPS_FAST} steps (expected {1 + STEPS_FAST // own_every}: the "
        f"set-up build and one every {own_every} steps, when a sphere has flown its radius)")
c.check("batched_vs_plain_loops_identical", identical(srt, plain),
        "the SIMD-batched force loops differ from the one-contact-at-a-time loops: position "
        f"{rel_diff(srt, plain, 'position'):.3g}")
c.check("batched_vs_plain_loops_same_observables",
        all(np.array_equal(srt["obs"][k], plain["obs"][k]) for k in srt["obs"]),
        "observables differ between the batched and the plain force loops")

# A moving floor does work (energy bookkeeping), which the wall loop sums contact by contact in
# list order as the plain loop does, also across its batches of 32 contacts: a 7 x 7 layer of
# spheres resting on a floor that rises under them (49 wall contacts).
layer = dict(
    jdem_scene=1, name="moving_floor", description="a layer of spheres lifted by a rising floor",
    time=dict(dt=1.0e-6, steps=2000), output=dict(every=500, observables_every=100),
    gravity=[0.0, 0.0, -9.81],
    materials=dict(grain=dict(youngs_modulus=1.0e8, poisson_ratio=0.3, density=2500, restitution=0.6,
                              friction=0.4, rolling_friction=0.05),
                   steel=dict(restitution=0.6, friction=0.4, rolling_friction=0.05)),
    walls=[dict(name="floor", type="plane", material="steel", velocity=[0.0, 0.0, 0.01],
                corners=[[-0.01, -0.01, 0], [0.02, -0.01, 0], [0.02, 0.02, 0], [-0.01, 0.02, 0]])],
    particles=[dict(id=1 + a + 7 * b, material="grain", radius=1.0e-3,
                    position=[2.2e-3 * a, 2.2e-3 * b, 1.0e-3], velocity=[1.0e-3 * (a - 3), 0.0, 0.0])
               for b in range(7) for a in range(7)])
lift = variant(yaml.safe_dump(layer, sort_keys=False), "moving_floor")
lift_batched, _, _ = run_file(lift)
lift_plain, _, _ = run_file(lift, "--plain-loops")
c.check("moving_floor_many_wall_contacts", lift_batched["obs"]["wall_contacts"].max() > 32 and
        np.any(lift_batched["obs"]["wall_work"] != 0.0),
        f"wall contacts {lift_batched['obs']['wall_contacts'].tolist()}, wall work "
        f"{lift_batched['obs']['wall_work'].tolist()}")
c.check("moving_floor_batched_vs_plain_identical",
        identical(lift_batched, lift_plain) and
        all(np.array_equal(lift_batched["obs"][k], lift_plain["obs"][k]) for k in lift_plain["obs"]),
        "with a moving floor the batched loops differ from the plain ones: "
        + ", ".join(k for k in lift_plain["obs"] if not np.array_equal(lift_batched["obs"][k], lift_plain["obs"][k])))

# Two particle materials: the batches then read each pair's coefficient row through the
# species (one material: the one row, read once per batch).
lattice = "      counts: [6, 6, 6]\n"
mixed_text = open(base).read()
assert mixed_text.count(lattice) == 1
mixed_text = mixed_text.replace(
    "  steel:", "  sand: {youngs_modulus: 5.0e7, poisson_ratio: 0.25, density: 2000, restitution: 0.4,\n"
    "         friction: 0.6, rolling_friction: 0.02}\n  steel:").replace(lattice, "      counts: [6, 6, 3]\n")
mixed_text = mixed_text.replace("generate:", "interactions:\n  - {materials: [grain, sand], restitution: 0.5, "
                                "friction: 0.5, rolling_friction: 0.03}\n"
                                "  - {materials: [sand, steel], restitution: 0.5, friction: 0.5, "
                                "rolling_friction: 0.03}\ngenerate:")
second = mixed_text[mixed_text.index("  - lattice:"):mixed_text.index("walls:")]
mixed_text = mixed_text.replace(second, second + second.replace("material: grain", "material: sand").replace(
    "origin: [-0.00525, -0.00525, 0.00105]", "origin: [-0.00525, -0.00525, 0.00735]"))
mixed = variant(mixed_text, "fastpaths_two_materials")
mixed_batched, _, _ = run_file(mixed)
mixed_plain, _, _ = run_file(mixed, "--plain-loops")
c.check("two_materials_batched_vs_plain_identical", identical(mixed_batched, mixed_plain),
        "with two particle materials the batched loops differ from the plain ones: position "
        f"{rel_diff(mixed_batched, mixed_plain, 'position'):.3g}")
c.check("two_materials_differ_from_one", not identical(mixed_batched, srt), "the second material changed nothing")

# One material and one radius: every pair has the same constants, which the batches then take
# once instead of per pair.
radii = "radii: {values: [0.0008, 0.001], fractions: [0.5, 0.5]}"
assert open(base).read().count(radii) == 1
alike = variant(open(base).read().replace(radii, "radii: {values: [0.001], fractions: [1.0]}"),
                "fastpaths_one_radius")
alike_batched, _, _ = run_file(alike)
alike_plain, _, _ = run_file(alike, "--plain-loops")
c.check("one_radius_batched_vs_plain_identical", identical(alike_batched, alike_plain),
        "with particles all alike the batched loops differ from the plain ones: position "
        f"{rel_diff(alike_batched, alike_plain, 'position'):.3g}")
c.check("one_radius_differs_from_two", not identical(alike_batched, srt), "the single radius changed nothing")

two, _, nt = run_file(base, "--threads", "2")
c.check("two_threads_used", nt == 2, f"{nt} threads")
roundoff_equal(c, "threads2_vs_threads1", two, srt)
two_b, _, _ = run_file(base, env={"OMP_NUM_THREADS": "2"})
c.check("threads2_reproducible", identical(two, two_b), "two 2-thread runs differ")
plain_two, _, _ = run_file(base, "--plain-loops", "--threads", "2")
c.check("threads2_batched_vs_plain_identical", identical(two, plain_two),
        "with 2 threads the batched loops differ from the plain ones (the threads' overflow "
        f"buffers): position {rel_diff(two, plain_two, 'position'):.3g}")

text = open(base).read()
plain = re.sub(r"restitution: 0\.6", "restitution: 1.0", text)
plain = re.sub(r"rolling_friction: 0\.05", "rolling_friction: 0.0", plain)
assert plain.count("restitution: 1.0") == 2 and plain.count("rolling_friction: 0.0") == 2
plain_path = variant(plain, "fastpaths_plain")
spec, _, _ = run_file(plain_path)
general, _, _ = run_file(plain_path, "--all-laws")
c.check("specialised_vs_general_identical", identical(spec, general),
        "the specialised loop differs from the general one at zero coefficients: "
        f"position {rel_diff(spec, general, 'position'):.3g}")
c.check("plain_scene_differs_from_base", not identical(spec, srt), "the variant changed nothing")
# Bonds enabled at zero coefficients as well (the general scene): springs of zero stiffness
# between the pairs within half a radius at the start carry no load, so the trajectory is still the
# specialised loop's bit for bit, no bond breaks, and the bonds hold no energy (0, not 0/0).
assert plain.count("\nwalls:\n") == 1
idle_path = variant(plain.replace("\nwalls:\n", "\nbond_types:\n  idle: {normal_stiffness: 0.0, shear_stiffness: 0.0, "
                                  "tensile_strength: 1.0e6, shear_strength: 1.0e6}\nbond_rules:\n"
                                  "  - {type: idle, time: 0.0, max_gap: 0.5}\nwalls:\n"), "fastpaths_idle_bonds")
idle, _, _ = run_file(idle_path, "--all-laws")
n_idle = idle["obs"]["bonds"]
c.check("idle_bonds_formed_and_kept", n_idle[0] >= 50 and np.all(n_idle == n_idle[0]),
        f"bonds per sample {n_idle.tolist()}")
c.check("specialised_vs_general_with_idle_bonds_identical", identical(spec, idle),
        "zero-stiffness bonds changed the trajectory: position "
        f"{rel_diff(spec, idle, 'position'):.3g}")
e_idle = idle["obs"].get("bond_elastic_energy")
c.check("idle_bonds_hold_no_energy", e_idle is not None and np.all(e_idle == 0.0),
        f"bond elastic energy {None if e_idle is None else e_idle.tolist()}")

no_energy = variant(text.replace("  observables_every: 500\n", "  observables_every: 500\n  energy: false\n"),
                    "fastpaths_no_energy")
ne, _, _ = run_file(no_energy)
c.check("energy_off_same_trajectory", identical(ne, srt), "energy bookkeeping changed the trajectory")
c.check("energy_off_no_energy_observables", "elastic_energy" not in ne["obs"] and "kinetic_energy" in ne["obs"],
        f"observables {sorted(ne['obs'])}")
# Between two samples the engine leaves each step's final half kick to the next step's first
# pass; with an observable sample at every step no kick is ever deferred.  The same half kicks,
# rounded alike, so the frames and the samples both runs have are identical bit for bit.
assert text.count("  observables_every: 500\n") == 1
every = variant(text.replace("  observables_every: 500\n", "  observables_every: 1\n"), "fastpaths_every_step")
ev, _, _ = run_file(every)
common = np.isin(ev["obs_time"], srt["obs_time"])
c.check("deferred_kick_same_trajectory", identical(ev, srt) and len(ev["position_time"]) == len(srt["position_time"]),
        "deferring the final half kick changed the trajectory: position "
        f"{rel_diff(ev, srt, 'position'):.3g}, velocity {rel_diff(ev, srt, 'velocity'):.3g}")
c.check("deferred_kick_same_observables",
        common.sum() == len(srt["obs_time"]) and
        all(np.array_equal(ev["obs"][k][common], srt["obs"][k]) for k in srt["obs"]),
        "observables differ with and without the deferred kick: "
        + ", ".join(k for k in srt["obs"] if not np.array_equal(ev["obs"][k][common], srt["obs"][k])))

# The block's generator numbers its spheres in lattice order, which is already cell order; the
# resolved scene with the ids shuffled (bonds renamed alike) makes the renumbering non-trivial.
gen = variant(yaml.safe_dump(bond_checks.block_scene(True), sort_keys=False), "block_drop_gen")
resolved = yaml.load(engines.resolve(gen, binary=JDEM, check=True).stdout, Loader=yaml.CSafeLoader)
ids = [p["id"] for p in resolved["particles"]]
rename = dict(zip(ids, np.random.default_rng(3).permutation(ids).tolist()))
for p in resolved["particles"]:
    p["id"] = rename[p["id"]]
for b in resolved["bonds"]:
    b["ids"] = sorted(rename[i] for i in b["ids"])
block = variant(yaml.safe_dump(resolved, sort_keys=False), "block_drop")


def breaks(path):
    with h5py.File(path, "r") as f:
        g = f.get("jdem/broken_bonds")
        return [] if g is None else sorted(map(tuple, np.column_stack((g["step"][()], g["ids"][()])).tolist()))


bt_ref, _, _ = run_file(block, "--no-sort")
bt_srt, _, _ = run_file(block)
c.check("bonds_sorting_changes_summation_order", not identical(bt_ref, bt_srt),
        "sorted and unsorted block runs are identical: was anything renumbered?")
roundoff_equal(c, "bonds_sorted_vs_unsorted", bt_srt, bt_ref)
ba, bb = breaks(bt_ref["path"]), breaks(bt_srt["path"])
c.check("bonds_sorted_same_breaks", len(ba) > 0 and ba == bb, f"{len(ba)} and {len(bb)} breaks, equal: {ba == bb}")

# Bonds without the energy bookkeeping keep 9 state doubles instead of 18 and run a loop without
# the accounts, which never feed back into the forces: the same trajectory and breaks, bit for
# bit, and no bond energy observables.
bt_ne, _, _ = run_file(variant(yaml.safe_dump(dict(resolved, output=dict(resolved["output"], energy=False)),
                                              sort_keys=False), "block_drop_no_energy"))
c.check("bonds_energy_off_same_trajectory", identical(bt_ne, bt_srt), "the bond energy bookkeeping changed the trajectory")
c.check("bonds_energy_off_same_breaks", breaks(bt_ne["path"]) == bb, "the bond energy bookkeeping changed the breaks")
c.check("bonds_energy_off_observables",
        "bonds" in bt_ne["obs"] and not any(k.startswith("bond_") for k in bt_ne["obs"]) and
        "bond_elastic_energy" in bt_srt["obs"], f"observables {sorted(bt_ne['obs'])}")

# With all particles of one radius the bond loop takes each bond's cross-section from a table per
# bond type; a free sphere of another radius, far from the block, makes it compute the sections
# per bond and step instead.  Unsorted runs keep every sum in the same order: the block's
# trajectory must be the same bit for bit.
extra_id = max(rename.values()) + 1
lone = dict(resolved, particles=resolved["particles"] + [
    {"id": extra_id, "material": resolved["particles"][0]["material"], "radius": 0.5e-3,
     "position": [0.0, 0.0, 0.05], "velocity": [0.0, 0.0, 0.0]}])
bt_lone, _, _ = run_file(variant(yaml.safe_dump(lone, sort_keys=False), "block_drop_lone_sphere"), "--no-sort")
keep = bt_lone["id"] != extra_id
c.check("bonds_sections_per_step_vs_per_type",
        len(bt_lone["id"]) == len(bt_ref["id"]) + 1 and np.array_equal(bt_lone["id"][keep], bt_ref["id"]) and
        all(np.array_equal(bt_lone[k][:, keep], bt_ref[k]) for k in VECTORS) and breaks(bt_lone["path"]) == ba,
        "the sections computed per bond and step differ from the per-type ones")
# The bond loop with 2 threads evaluates the bonds in parallel and then lets each thread add the
# forces of its own particles in bond order: the serial order.  A lattice of bonded spheres with
# gaps (no contact force; up to 6 bonds per sphere, so the order of a sum shows in its bits),
# damped bonds, set vibrating by random velocities, is then the same bit for bit on 1 and 2
# threads; the dropped block, with contacts, agrees to round-off, breaks the same bonds at the
# same steps, and is reproducible on 2 threads.
L, shape = bond_checks.L, (4, 4, 3)
rng = np.random.default_rng(5)
cells = [(a, b, z) for z in range(shape[2]) for b in range(shape[1]) for a in range(shape[0])]
pid = {c: k + 1 for k, c in enumerate(cells)}
lattice = variant(yaml.safe_dump(bond_checks.scene(
    "lattice", 5.0e-8, 2000,
    [bond_checks.sphere(pid[c], tuple(L * q for q in c), v=tuple(rng.uniform(-0.01, 0.01, 3).tolist()))
     for c in cells],
    bonds=[(pid[c], pid[d]) for c in cells for d in ((c[0] + 1, c[1], c[2]), (c[0], c[1] + 1, c[2]),
                                                    (c[0], c[1], c[2] + 1)) if d in pid],
    every=100, bond=bond_checks.bond_type(math.inf, math.inf, damping=0.2)), sort_keys=False), "lattice")
lat1, _, _ = run_file(lattice)
lat2, _, nt_lat = run_file(lattice, "--threads", "2")
c.check("bonds_threads2_used", nt_lat == 2, f"{nt_lat} threads")
c.check("bonds_threads2_lattice_no_contacts", not lat1["obs"]["contacts"].any(), "the lattice's spheres touched")
c.check("bonds_threads2_lattice_identical", identical(lat1, lat2),
        "the bonded lattice differs between 1 and 2 threads: position "
        f"{rel_diff(lat1, lat2, 'position'):.3g}")
bt_2, _, _ = run_file(block, "--threads", "2")
bt_2b, _, _ = run_file(block, "--threads", "2")
roundoff_equal(c, "bonds_threads2_vs_threads1", bt_2, bt_srt)
c.check("bonds_threads2_same_breaks", breaks(bt_2["path"]) == bb, "2 threads broke other bonds or at other steps")
c.check("bonds_threads2_reproducible", identical(bt_2, bt_2b), "two 2-thread block runs differ")
c.exit()
