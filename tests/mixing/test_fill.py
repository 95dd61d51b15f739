#!/usr/bin/python3
"""A reduced first fill of the Chapter 4 campaign scene in jdem, and the analysis on its deposit.

Model 1 of reference_runs/mixing/ch4/models.yaml cut to 3 sections and 0.8 s (generate.py fill,
the same command the campaign uses), at the seed's dt, forced as the campaign runs it.  The
conveyor itself is tested on a small scene by tests/inlet; here the campaign's own section
(516 spheres from two lattices) and its deposit:

* stream: 3 x 516 insertions, the ids first_id .. first_id + 1547 and every crossing step as the
  closed form of the stream gives them (tests/inlet/test_inlet.py's reference_stream).
* free fall: a lone section's centre of mass (a run of 1 section, 0.6 s), in every frame after
  its last particle crossed while all its spheres are clear of the walls, against the
  mass-weighted sum of each particle's x_k + v (t - t_k) + g (t - t_k)^2 / 2 from its insertion
  (the contacts inside the section cancel).
* energy: with the inflow booked the energy balance closes to 1 % of the largest kinetic energy
  (impacts on the floor included).
* analysis, on the last frame: a measuring sphere enclosing the box gives phi_v = 4 R_big^3 /
  (512 R_small^3) = 0.0625 and rho_b = total mass / V_t; at the Table 4-2 points and at points in
  the deposit, the solid fraction 1 - n and phi_v against a Monte Carlo integration over the
  particles (no lens formula), and the coordination number's contact count against an all-pairs
  count.
* the front view (scripts/mixing_views.py) of the last frame draws every sphere, in both colours.
"""
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import yaml
from scipy.spatial import cKDTree

from tests.mixing.common import ROOT, check, finish
from scripts.mixing import deposit, params

from tests.inlet.test_inlet import reference_stream

JDEM = os.environ.get("JDEM", os.path.join(ROOT, "build", "jdem"))
GENERATE = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "generate.py")
SECTIONS, END_TIME, EVERY = 3, 0.8, 500


def reduced_scene(tmp, sections=SECTIONS, end_time=END_TIME):
    """The reduced Model 1 fill with frames every EVERY steps (0.05 s)."""
    path = os.path.join(tmp, f"fill{sections}.yaml")
    subprocess.run([sys.executable, GENERATE, "fill", "--case", "model1", "--sections",
                    str(sections), "--end-time", str(end_time), "-o", path], check=True)
    with open(path) as f:
        doc = yaml.load(f, Loader=yaml.CSafeLoader)
    doc["output"] = {"every": EVERY, "observables_every": 100}
    with open(path, "w") as f:
        yaml.safe_dump(doc, f, sort_keys=False)
    return path


def read_record(path):
    rows = np.genfromtxt(path, delimiter=",", names=True)
    return {int(r["id"]): (int(r["step"]), np.array([r["x"], r["y"], r["z"]]),
                           np.array([r["vx"], r["vy"], r["vz"]])) for r in rows}


def check_stream(sc, rec):
    inlet = sc["inlets"][0]
    n = len(inlet["section"]["particles"])
    steps = sc["time"]["steps"]   # resolved: end_time counted in steps of dt
    ref = reference_stream(sc, inlet, steps)
    first = inlet["first_id"]
    check("fill-section-size", n == 516, f"{n} particles per section, the seed's 516")
    check("fill-inserted-count", len(rec) == SECTIONS * 516,
          f"{len(rec)} inserted, {SECTIONS} x 516 expected")
    check("fill-inserted-ids", sorted(rec) == list(range(first, first + SECTIONS * 516)),
          f"ids {min(rec)}..{max(rec)}, first_id {first}")
    check("fill-crossing-steps", all(rec.get(i, (None,))[0] == k for k, i, _, _ in ref),
          "a crossing step differs from the closed form")


def check_free_fall(h, sc, rec):
    """Centre of mass of a lone section (a run of one section): in every frame after its last
    particle crossed and while every particle is clear of every wall, gravity is the only
    external force, whatever the collisions inside the section (the big spheres land on the
    small ones behind them as the block tips over the plane)."""
    dt, g = sc["time"]["dt"], np.array(sc["gravity"])
    idv = h["/particles/all/id"]  # a growing set: the slots' ids per frame, all live at the end
    ids = idv["value"][-1] if isinstance(idv, h5py.Group) else idv[:]
    m = h["/particles/all/mass"][:]
    k = np.array([rec[i][0] for i in ids])
    x0 = np.array([rec[i][1] for i in ids])
    v0 = np.array([rec[i][2] for i in ids])
    radius = h["/particles/all/radius"][:][:, None]
    worst, frames = 0.0, 0
    for f, s in enumerate(h["/particles/all/position/step"][:]):
        x = h["/particles/all/position/value"][f]
        if not (k.max() < s and np.all(x - radius > 0) and np.all(x + radius < [1, 1, 2])):
            continue
        t = (s - k) * dt
        want = (m[:, None] * (x0 + v0 * t[:, None] + 0.5 * g * (t * t)[:, None])).sum(0) / m.sum()
        got = (m[:, None] * x).sum(0) / m.sum()
        worst, frames = max(worst, float(np.max(np.abs(got - want)))), frames + 1
    check("fill-free-fall-centre-of-mass", frames >= 5 and worst < 1e-9,
          f"{frames} frames clear of the walls, largest error {worst:g} m")


def check_energy(h):
    obs = {k: h[f"/observables/{k}/value"][:] for k in h["/observables"]}
    terms = ["kinetic_energy", "rotational_energy", "elastic_energy", "gravitational_energy",
             "damping_dissipation", "friction_dissipation"]
    total = sum(obs[k] for k in terms) - obs["wall_work"]
    scale = float(np.max(obs["kinetic_energy"]))
    drift = float(np.max(np.abs(total - obs["inlet_energy"]))) / scale
    check("fill-energy-balance", drift < 0.01 and obs["damping_dissipation"][-1] > 0,
          f"drift {drift:g} of the largest kinetic energy; damping {obs['damping_dissipation'][-1]}")


def monte_carlo(dep, centre, r, n=300_000, seed=2021):
    """(solid volume, big volume, 4-sigma bound) inside the sphere by uniform sampling."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-r, r, (n, 3))
    p = p[np.einsum("ij,ij->i", p, p) <= r * r] + centre
    tree = cKDTree(dep.position)
    big = params.big_mask(dep.radius)
    solid = np.zeros(len(p), bool)
    in_big = np.zeros(len(p), bool)
    for i, near in enumerate(tree.query_ball_point(p, dep.radius.max())):
        for j in near:
            if np.sum((p[i] - dep.position[j]) ** 2) <= dep.radius[j] ** 2:
                solid[i] = True
                in_big[i] |= big[j]
    vt = 4 / 3 * math.pi * r ** 3
    bound = lambda frac: 4 * vt * math.sqrt(max(frac * (1 - frac), 1 / len(p)) / len(p))  # noqa: E731
    return vt * solid.mean(), vt * in_big.mean(), bound(solid.mean()), bound(in_big.mean())


def all_pairs_contacts(position, radius):
    d = np.linalg.norm(position[:, None, :] - position[None, :, :], axis=2)
    touching = d < radius[:, None] + radius[None, :]
    return int((np.count_nonzero(touching) - len(radius)) // 2)


def check_analysis(traj):
    dep = deposit.read_frame(traj)
    check("deposit-all-inserted", len(dep.id) == SECTIONS * 516, f"{len(dep.id)} particles")
    whole = params.mixing_parameters(dep, [0.5, 0.5, 1.0], r=1.6)
    check("deposit-phi-v-whole", abs(whole["phi_v"] - params.IDEAL_PHI_V) <= 1e-12,
          f"phi_v {whole['phi_v']!r}, ideal {params.IDEAL_PHI_V!r}")
    vt = 4 / 3 * math.pi * 1.6 ** 3
    check("deposit-rho-b-whole", abs(whole["rho_b"] - dep.mass.sum() / vt) <= 1e-12 * whole["rho_b"],
          f"rho_b {whole['rho_b']!r}, total mass / V_t {dep.mass.sum() / vt!r}")
    inside = dep.position[:, 2] < 0.2   # the deposit proper, not the spheres still bouncing
    base = dep.position[inside].mean(axis=0)
    points = [(f"table4-2-{k + 1}", c, params.MEASURING_RADIUS)
              for k, c in enumerate(params.POINTS_TABLE_4_2)]
    points += [(f"deposit-{k}", base + [dx, 0.0, 0.0], 0.1) for k, dx in enumerate((-0.1, 0, 0.1))]
    for name, c, r in points:
        got = params.mixing_parameters(dep, c, r=r)
        solid, big, b_solid, b_big = monte_carlo(dep, np.asarray(c, float), r)
        vt = 4 / 3 * math.pi * r ** 3
        ok = abs((1 - got["n"]) * vt - solid) <= b_solid and abs(got["V_big"] - big) <= b_big
        check(f"{name}-packing-vs-monte-carlo", ok,
              f"lens: solid {(1 - got['n']) * vt:.6g}, big {got['V_big']:.6g} m^3; Monte Carlo "
              f"{solid:.6g} +- {b_solid:.2g}, {big:.6g} +- {b_big:.2g}")
        members = np.linalg.norm(dep.position - c, axis=1) < r
        want = all_pairs_contacts(dep.position[members], dep.radius[members])
        check(f"{name}-contacts-vs-all-pairs", got["N_c"] == want and got["N_p"] == members.sum(),
              f"N_c {got['N_c']} (all pairs {want}), N_p {got['N_p']}")
    filled = [n for n, c, r in points if params.mixing_parameters(dep, c, r=r)["N_p"] > 0]
    check("deposit-points-hold-particles", sum(n.startswith("deposit") for n in filled) == 3,
          f"points holding particles: {filled}")


def run_fill(tmp, sections, end_time):
    """Run the reduced fill; (resolved scene, insertion record, trajectory) or None."""
    scene = reduced_scene(tmp, sections, end_time)
    traj, rec = os.path.join(tmp, f"fill{sections}.h5"), os.path.join(tmp, f"rec{sections}.csv")
    run = subprocess.run([JDEM, "run", scene, "-o", traj, "--inlet-record", rec, "--quiet",
                          "--force"], capture_output=True, text=True)
    check(f"fill-{sections}-sections-runs", run.returncode == 0, run.stderr.strip())
    if run.returncode:
        return None
    sc = yaml.load(subprocess.run([JDEM, "resolve", scene], capture_output=True,
                                       text=True, check=True).stdout, Loader=yaml.CSafeLoader)
    return sc, read_record(rec), traj


def check_views(traj, tmp):
    """scripts/mixing_views.py on the fill: one front view of the last frame with every live
    sphere drawn, in the cohort colours."""
    import matplotlib.image as mpimg
    r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "mixing_views.py"), traj,
                        "-o", tmp, "--times", "final", "--views", "front"],
                       capture_output=True, text=True)
    png = os.path.join(tmp, f"front_t{END_TIME:g}.png")
    check("views-front-written", r.returncode == 0 and r.stdout.strip() == f"{png}: "
          f"{SECTIONS * 516} spheres", f"{r.stdout}{r.stderr}")
    if os.path.exists(png):
        img = mpimg.imread(png)[:, :, :3]
        red = np.mean(np.all(np.abs(img - [0.839, 0.153, 0.157]) < 0.08, axis=2))
        blue = np.mean(np.all(np.abs(img - [0.122, 0.310, 0.706]) < 0.08, axis=2))
        check("views-front-cohort-colours", red > 0 and blue > red, f"red {red:.4f}, blue {blue:.4f}")


def main():
    with tempfile.TemporaryDirectory() as tmp:
        lone = run_fill(tmp, 1, 0.6)
        if lone:
            with h5py.File(lone[2], "r") as h:
                check_free_fall(h, lone[0], lone[1])
        fill = run_fill(tmp, SECTIONS, END_TIME)
        if fill:
            sc, record, traj = fill
            check_stream(sc, record)
            with h5py.File(traj, "r") as h:
                check_energy(h)
            check_analysis(traj)
            check_views(traj, tmp)


main()
finish()
