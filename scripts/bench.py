#!/usr/bin/python3
"""bench.py — the performance benchmark of issue 6 (`make bench`).

    scripts/bench.py [--sizes 5k,20k] [--variants all] [--engines jdem,liggghts-jdem,liggghts]
                     [--repeats 3] [--ranks-size 20k] [--out out/bench] [--fresh] [--report-only]
                     [--prepare-only] [--timeout 3600] [--keep-files]

Dense beds of spheres settled under gravity in an open box (reference_runs/bench/README.md):
monodisperse R = 1 mm or bidisperse 1 mm / 2 mm (half and half by number), soft (E = 1e7 Pa) or
stiff (E = 7e10 Pa), with or without rolling resistance; nu = 0.3, rho = 2500, e = 0.5, mu = 0.5.

1. Beds (once per size and dispersity, reused by every variant, engine and repeat; kept in
   OUT/beds/, regenerated only when missing): build/jdem settles a jittered lattice of soft
   spheres (reference_runs/bench/settle.yaml.in).  build/jdem refuses scenes whose spheres
   overlap by more than 1e-6 R at the start, so the settled bed is then relaxed until every
   contact overlaps by exactly 5e-10 m (damped Gauss-Newton least squares, CGLS, numpy only):
   the settled contact network with nearly zero forces, which gravity loads again in the timed
   run.  Soft and stiff variants start from the same bed (settling at the stiff time step would
   take ~1e6 steps).  80k, 320k and 1M are 2 x 2, 4 x 4 and 7 x 7 copies of the 20k bed side by
   side (bench_tiling.py; settling 1M spheres would take ~1.5 h), checked against the
   stepper's start-overlap rule.
   The bonded variants (*_bonded) are the same beds with a parallel bond between every touching
   pair, formed at step 0 by a bond rule; stock LIGGGHTS has no parallel bonds (n/a).
2. Scenes: reference_runs/bench/bench.yaml.in + the bed as explicit particles at rest; dt is the
   stepper's largest safe dt (its guard at max_impact_speed 1 m/s), rounded down; frames only
   at step 0 and the last step.
3. Timings, each repeated --repeats times (median reported):
   * jdem: its timer of the time loop (`--timing`, loop=: the S steps, their two frames and the
     per-step checks), the counterpart of LIGGGHTS' "Loop time";
   * liggghts-jdem and stock liggghts: LIGGGHTS' "Loop time of ..." (the run loop only).  The
     decks come from scene_to_liggghts.py (stock: --builtin, dump removed).
   The throughput tables, ratios and flatness use that loop time less its output (jdem: the
   `output=` part, frames and observables; LIGGGHTS: its "Outpt" share), because the engines
   write different output: jdem and liggghts-jdem write two full frames, stock LIGGGHTS (which
   has no dump h5md/jdem) only thermo lines.  At 1M the frames are 12 % of jdem's loop, at 20k
   1 %.  The loop with its output is kept as well (loop_seconds_with_output).
   Until 2026-11-22 jdem's wall time was a run of S steps minus a run of 1 step, which should
   cancel the set-up but does not reliably: the set-up (scene parsing, ~1 s at 80k, ~15 s at
   1M) varies by more than the loop takes, and the difference was off by up to 30 % at 80k and
   50 % at 1M (in the bench of that day, in both directions across repeats).  It is still
   recorded (diff_wall_s), and the CPU time below is taken that way for every engine.
   Also the CPU time of the loop (GNU time's user+sys of the S-step run minus that of a 1-step
   run, for every engine on 1 rank): steadier than wall time when other jobs share the machine.
   The LIGGGHTS decks get `processors * * 1` (the box is twice the bed's height: a z split
   would leave one rank empty); 2 MPI ranks are timed at --ranks-size.
   Peak resident memory is GNU time's maximum RSS (for MPI runs: of the largest process).
   Average contacts per particle = 2 x particle-particle contacts / N at the last step (jdem and
   liggghts-jdem: the trajectory's /observables/contacts; stock: compute contact/atom).
4. A callgrind profile of a 200-step jdem run (if valgrind is installed; OUT/profile.json).
5. OUT/summary.json, OUT/runs.jsonl (every single timing), OUT/report.md with plots; with the
   flatness of jdem's cost per particle-step over N (max/min, target 1.25), its engine memory
   against 300 B/particle + 100 B/contact, and ns per bond-step of the bonded variants.

Timing results are appended to OUT/runs.jsonl and reused (a run already measured is not run
again) unless --fresh; so an interrupted bench continues where it stopped.
"""
import argparse
import json
import math
import os
import re
import shutil
import signal
import statistics
import string
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
TEMPLATES = os.path.join(ROOT, "reference_runs", "bench")
JDEM = os.path.join(ROOT, "build", "jdem")
LIGGGHTS_JDEM = os.path.join(ROOT, "build", "liggghts-jdem")
LIGGGHTS = "/usr/bin/liggghts"
GNU_TIME = "/usr/bin/time"

E_SOFT, E_STIFF = 1.0e7, 7.0e10
R_SMALL, R_LARGE = 1.0e-3, 2.0e-3
LAYERS = 20                       # lattice layers before settling
TOUCH = 5e-7                      # contact overlap of the bench beds, fraction of the smallest radius
ETA_ROLL = 0.1                    # rolling-friction coefficient of the "roll" variants
SIZES = {"5k": 5000, "20k": 20000, "80k": 80000, "320k": 320000, "1M": 1000000}
# The large beds are k x k lateral copies of the settled, relaxed 20k bed (bench_tiling.py):
# settling 1M spheres would take ~1.5 h.  N: 81 920, 327 680 and 1 003 520.
TILES = {"80k": ("20k", 2), "320k": ("20k", 4), "1M": ("20k", 7)}
STEPS = {"5k": 2000, "20k": 500, "80k": 200, "320k": 100, "1M": 50}
SETTLE_TIME = {"mono": 0.12, "bi": 0.15}
VARIANTS = [(stiff, disp, roll) for stiff in ("soft", "stiff") for disp in ("mono", "bi")
            for roll in ("", "_roll")]
# The bonded beds: the same beds with a parallel bond between every touching pair, formed at
# step 0 (no rolling resistance; stock LIGGGHTS has no parallel bonds: jdem and liggghts-jdem only)
BONDED_VARIANTS = ["%s_%s_bonded" % (stiff, disp) for stiff in ("soft", "stiff") for disp in ("mono", "bi")]
VARIANT_NAMES = ["%s_%s%s" % v for v in VARIANTS] + BONDED_VARIANTS
ENGINES = ("jdem", "liggghts-jdem", "liggghts")
# Bonds of the bonded variants: axial stiffness per area kn = E / (2 R_small) (a bond as stiff as
# a column of the grains' material between the two centres), kt = kn / (2 (1 + nu)) (the shear
# modulus' ratio), strengths 1e9 Pa: ~1e5 x the stresses a 4 cm bed's weight puts on a bond, so
# the bed stays intact while the failure test is still evaluated every step.  The bond rule
# bonds pairs whose surfaces are at most BOND_MAX_GAP x the smaller radius apart: the relaxed
# beds' contacts all overlap (by TOUCH), so these are exactly the pairs in contact at step 0.
BOND_STRENGTH = 1.0e9
BOND_MAX_GAP = 1.0e-9
# A single engine run that takes longer than this is reported as failed (and the bench goes on)
RUN_TIMEOUT_S = 3600.0
PROFILE_MAX_SIZE = "20k"          # the callgrind profile runs on the smallest size, if not above this
FLATNESS_TARGET = 1.25            # issue 6: jdem's cost per particle-step within 1.25x from 5k to 1M


def is_bonded(variant):
    return variant.endswith("_bonded")


def variant_dispersity(variant):
    return variant.split("_")[1]


def log(msg):
    sys.stderr.write("[bench %s] %s\n" % (time.strftime("%H:%M:%S"), msg))
    sys.stderr.flush()


def num(x):
    return repr(float(x))


# ---------------------------------------------------------------------------------------------
# Geometry of a bed

def bed_geometry(size, disp):
    n = SIZES[size]
    rmax = R_LARGE if disp == "bi" else R_SMALL
    spacing = 2.05 * rmax
    k = max(2, int(round(math.sqrt(n / LAYERS))))
    side = k * spacing
    height = 2.0 * LAYERS * spacing
    return dict(n=k * k * LAYERS, k=k, spacing=spacing, side=side, height=height, rmax=rmax)


def walls_yaml(side, height):
    L, H = num(side), num(height)
    rows = [("floor", "[[0, 0, 0], [%s, 0, 0], [%s, %s, 0], [0, %s, 0]]" % (L, L, L, L)),
            ("x_low", "[[0, 0, 0], [0, %s, 0], [0, %s, %s], [0, 0, %s]]" % (L, L, H, H)),
            ("x_high", "[[%s, 0, 0], [%s, 0, %s], [%s, %s, %s], [%s, %s, 0]]" % (L, L, H, L, L, H, L, L)),
            ("y_low", "[[0, 0, 0], [0, 0, %s], [%s, 0, %s], [%s, 0, 0]]" % (H, L, H, L)),
            ("y_high", "[[0, %s, 0], [%s, %s, 0], [%s, %s, %s], [0, %s, %s]]" % (L, L, L, L, L, H, L, H))]
    return "\n".join("  - {name: %s, type: plane, corners: %s, material: wall}" % r for r in rows)


def fill(template, **kw):
    with open(os.path.join(TEMPLATES, template)) as f:
        return string.Template(f.read()).substitute(**{k: str(v) for k, v in kw.items()})


def guard_dt(scene_path):
    """The stepper's largest safe dt for this scene, from its guard message (6 digits): the
    scene's own dt must exceed it (bench.py and accuracy.py first write dt = 1 s)."""
    r = subprocess.run([JDEM, "run", scene_path, "-o", "/dev/null/x.h5"], capture_output=True, text=True)
    m = re.search(r"largest safe dt = ([0-9.eE+-]+)", r.stderr)
    if not m:
        raise RuntimeError("no safe dt in the stepper's message:\n" + r.stderr)
    return float(m.group(1))


def safe_dt(scene_path):
    """guard_dt() rounded down to two significant digits."""
    v = guard_dt(scene_path)
    e = math.floor(math.log10(v)) - 1
    return math.floor(v / 10.0 ** e) * 10.0 ** e


# ---------------------------------------------------------------------------------------------
# Beds

def h5_last_frame(path):
    import h5py
    with h5py.File(path, "r") as f:
        p = f["particles/all"]
        obs = f["observables"]
        return dict(id=p["id"][...].astype(np.int64), radius=p["radius"][...].astype(float),
                    x=p["position/value"][-1].astype(float),
                    contacts=float(obs["contacts/value"][-1]),
                    # intact bonds at the first and the last frame (None without bonds)
                    bonds_start=int(obs["bonds/value"][0]) if "bonds" in obs else None,
                    bonds=int(obs["bonds/value"][-1]) if "bonds" in obs else None,
                    wall_contacts=float(f["observables/wall_contacts/value"][-1]),
                    kinetic_energy=float(f["observables/kinetic_energy/value"][-1]))


def find_contacts(x, r, side):
    """Overlapping pairs (i < j) with unit normals from i to j and overlaps; wall contacts of the
    open box (floor and four sides) with the wall normal pointing into the box."""
    n = len(r)
    h = 2.0 * r.max()
    c = np.floor(x / h).astype(np.int64)
    c -= c.min(axis=0)
    nc = c.max(axis=0) + 3
    key = (c[:, 2] * nc[1] + c[:, 1]) * nc[0] + c[:, 0]
    order = np.argsort(key, kind="stable")
    skey = key[order]
    I, J = [], []
    for dz in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                nk = key + (dz * nc[1] + dy) * nc[0] + dx
                lo = np.searchsorted(skey, nk, "left")
                hi = np.searchsorted(skey, nk, "right")
                cnt = hi - lo
                ii = np.repeat(np.arange(n), cnt)
                start = np.repeat(lo - np.concatenate(([0], np.cumsum(cnt)[:-1])), cnt)
                jj = order[np.arange(cnt.sum()) + start]
                keep = ii < jj
                I.append(ii[keep])
                J.append(jj[keep])
    I, J = np.concatenate(I), np.concatenate(J)
    d = x[J] - x[I]
    dist = np.sqrt((d * d).sum(axis=1))
    ov = r[I] + r[J] - dist
    m = ov > 0
    I, J, dist, ov, d = I[m], J[m], dist[m], ov[m], d[m]
    nrm = d / dist[:, None]
    WI, WN, WO = [], [], []
    for axis, pos, sgn in ((2, 0.0, 1.0), (0, 0.0, 1.0), (0, side, -1.0), (1, 0.0, 1.0), (1, side, -1.0)):
        gap = sgn * (x[:, axis] - pos)
        ovw = r - gap
        m = ovw > 0
        idx = np.nonzero(m)[0]
        nv = np.zeros((len(idx), 3))
        nv[:, axis] = sgn
        WI.append(idx)
        WN.append(nv)
        WO.append(ovw[m])
    return I, J, nrm, ov, np.concatenate(WI), np.concatenate(WN), np.concatenate(WO)


def cgls(A, AT, b, shape, tol, maxit, damp):
    """Damped least squares: minimise |A u - b|^2 + damp^2 |u|^2 (CGLS).  The damping keeps
    near-singular directions (rattlers, nearly collinear contacts) from blowing up."""
    u = np.zeros(shape)
    res = b.copy()
    s = AT(res)
    p = s.copy()
    gamma = (s * s).sum()
    s0 = np.sqrt(gamma)
    it = 0
    for it in range(maxit):
        q = A(p)
        delta = (q * q).sum() + damp * damp * (p * p).sum()
        if delta == 0.0:
            break
        alpha = gamma / delta
        u += alpha * p
        res -= alpha * q
        s = AT(res) - damp * damp * u
        g2 = (s * s).sum()
        if np.sqrt(g2) < tol * s0:
            break
        p = s + (g2 / gamma) * p
        gamma = g2
    return u, it + 1


def relax_to_touching(x, r, side, target, tol=1e-10, maxit=5000, passes=80, damp=1e-3):
    """Move the particles of a settled bed so that every contact overlaps by exactly `target`
    (Gauss-Newton: linearised constraints n_ij . (u_j - u_i) = ov_ij - target for the pairs in
    contact and n_w . u_i = ov_w - target for the wall contacts, solved by least squares; the
    normals and overlaps are re-evaluated at the moved positions each pass).  Pairs and wall
    contacts that the displacement creates are added to the constraints.  Stops when every
    overlap is within [0.5, 1.5] target."""
    n = len(r)
    I, J, _, _, WI, WN, _ = find_contacts(x, r, side)
    _, _, _, ov0, _, _, WO0 = find_contacts(x, r, side)
    xc = x.copy()
    it_total, worst, npass = 0, float("inf"), 0
    for npass in range(passes):
        d = xc[J] - xc[I]
        dist = np.sqrt((d * d).sum(axis=1))
        nrm = d / dist[:, None]
        ov = r[I] + r[J] - dist
        ax = np.argmax(np.abs(WN), axis=1)
        sg = WN[np.arange(len(WI)), ax]
        wo = r[WI] - sg * (xc[WI, ax] - np.where(sg > 0, 0.0, side))
        b = np.concatenate((ov - target, wo - target))

        def A(u):
            return np.concatenate((((u[J] - u[I]) * nrm).sum(axis=1), (u[WI] * WN).sum(axis=1)))

        def AT(v):
            vp, vw = v[:len(I)], v[len(I):]
            g = np.zeros((n, 3))
            for k in range(3):
                g[:, k] = (np.bincount(J, vp * nrm[:, k], n) - np.bincount(I, vp * nrm[:, k], n)
                           + np.bincount(WI, vw * WN[:, k], n))
            return g

        # Levenberg-Marquardt: heavy damping while the errors are large (near-singular
        # directions would blow up), light damping near the solution (or the soft modes of a
        # wide bed converge too slowly)
        err = np.abs(b).max()
        lm = damp if err > 1e-6 else damp * 1e-2 if err > 1e-8 else damp * 1e-4
        u, it = cgls(A, AT, b, (n, 3), tol, maxit, lm)
        it_total += it
        xc = xc + u
        I2, J2, _, ov2, WI2, WN2, WO2 = find_contacts(xc, r, side)
        # every current overlap, including the constrained ones' errors
        d = xc[J] - xc[I]
        ovc = r[I] + r[J] - np.sqrt((d * d).sum(axis=1))
        worst = max(ov2.max() if len(ov2) else 0.0, WO2.max() if len(WO2) else 0.0)
        lowest = min(ovc.min() if len(ovc) else target, 1.0)
        log("relax pass %d: %d + %d constraints, %d iterations, overlaps in [%.3g, %.3g] m"
            % (npass, len(I), len(WI), it, lowest, worst))
        if worst <= 1.8 * target and lowest >= -20.0 * target:  # jdem accepts <= 2 target; gaps < 10 nm are harmless
            break
        have = set(zip(I.tolist(), J.tolist()))
        add = [(i, j) for i, j, o in zip(I2.tolist(), J2.tolist(), ov2.tolist())
               if o > 1.5 * target and (i, j) not in have]
        if add:
            ai, aj = np.array(add).T
            I, J = np.concatenate((I, ai)), np.concatenate((J, aj))
        haveW = set(zip(WI.tolist(), map(tuple, WN.tolist())))
        for k, nv, o in zip(WI2.tolist(), map(tuple, WN2.tolist()), WO2.tolist()):
            if o > 1.5 * target and (k, nv) not in haveW:
                WI = np.append(WI, k)
                WN = np.vstack((WN, np.array(nv)[None, :]))
    info = dict(pairs=int(len(I)), wall_contacts=int(len(WI)), cgls_iterations=it_total, passes=npass + 1,
                max_overlap_settled=float(max(ov0.max(), WO0.max())), max_overlap_after=float(worst),
                max_displacement=float(np.abs(xc - x).max()))
    return xc, info


def make_bed(out, size, disp):
    """OUT/beds/SIZE_DISP.npz (ids, radii, positions): the settled bed, relaxed so that every
    contact overlaps by TOUCH x the smallest radius (build/jdem refuses scenes whose particles
    overlap by more than 1e-6 of the smaller radius at the start).  Returns its path."""
    beds = os.path.join(out, "beds")
    os.makedirs(beds, exist_ok=True)
    base = os.path.join(beds, "%s_%s" % (size, disp))
    path = base + ".npz"
    if os.path.exists(path):
        return path
    if size in TILES:
        return make_tiled_bed(out, size, disp, path)
    g = bed_geometry(size, disp)
    radius_line = ("radii: {values: [%s, %s], fractions: [0.5, 0.5]}" % (num(R_SMALL), num(R_LARGE))
                   if disp == "bi" else "radius: %s" % num(R_SMALL))
    kw = dict(name="bed_%s_%s" % (size, disp), dispersity=disp, n=g["n"], radius_line=radius_line,
              half=num(0.5 * g["spacing"]), spacing=num(g["spacing"]), k=g["k"], layers=LAYERS,
              walls=walls_yaml(g["side"], g["height"]), settle_time=SETTLE_TIME[disp])
    scene = base + "_settle.yaml"
    with open(scene, "w") as f:
        f.write(fill("settle.yaml.in", dt=1.0, settle_steps=1, **kw))
    dt = safe_dt(scene)
    steps = int(math.ceil(SETTLE_TIME[disp] / dt))
    with open(scene, "w") as f:
        f.write(fill("settle.yaml.in", dt=num(dt), settle_steps=steps, **kw))
    traj = base + "_settle.jdem.h5"
    if not os.path.exists(traj):
        log("settling %s %s: %d spheres, %d steps of %g s" % (size, disp, g["n"], steps, dt))
        t0 = time.time()
        r = subprocess.run([JDEM, "run", scene, "-o", traj, "--quiet"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("settling failed:\n" + r.stderr)
        log("settled in %.0f s" % (time.time() - t0))
    fr = h5_last_frame(traj)
    info = dict(size=size, dispersity=disp, n=g["n"], side=g["side"], height=g["height"],
                settle_dt=dt, settle_steps=steps,
                settled_contacts_per_particle=2.0 * fr["contacts"] / g["n"],
                settled_kinetic_energy=fr["kinetic_energy"])
    x2, st = relax_to_touching(fr["x"], fr["radius"], g["side"], TOUCH * fr["radius"].min())
    info["relaxed"] = st
    log("bed %s %s: settled %.2f contacts/particle, KE %.3g J; relaxed to touching: %s"
        % (size, disp, info["settled_contacts_per_particle"], fr["kinetic_energy"], json.dumps(st)))
    np.savez(path, id=fr["id"], radius=fr["radius"], x=x2, info=json.dumps(info))
    return path


def contact_counts(x, r, side):
    """Pair and wall contacts per particle of a bed (every overlapping pair / wall contact), and
    the contacts themselves."""
    c = find_contacts(x, r, side)
    return dict(pairs_per_particle=2.0 * len(c[0]) / len(r), wall_contacts_per_particle=len(c[4]) / len(r)), c


def make_tiled_bed(out, size, disp, path):
    """OUT/beds/SIZE_DISP.npz for the sizes of TILES: k x k copies of the base bed side by side,
    the seams spaced by bench_tiling.seam_gap (no pair across a seam overlaps by more than the
    bed's contact overlap), in a box of side k side + (k - 1) gap.  The whole tiled bed is then
    checked against the stepper's start-overlap rule (every pair and wall contact, cell search)
    and its contacts per particle compared with the base bed's.  Returns its path."""
    from scripts import bench_tiling
    base_size, k = TILES[size]
    base = np.load(make_bed(out, base_size, disp))
    binfo = json.loads(str(base["info"]))
    t0 = time.time()
    target = TOUCH * base["radius"].min()
    gap = bench_tiling.seam_gap(base["x"], base["radius"], binfo["side"], target)
    x, r, ids, side = bench_tiling.tile(base["x"], base["radius"], base["id"], binfo["side"], k, gap)
    stats_base, _ = contact_counts(base["x"], base["radius"], binfo["side"])
    stats, (I, J, _, ov, WI, _, WO) = contact_counts(x, r, side)
    bad, badw = bench_tiling.start_overlap_violations(r, I, J, ov, WI, WO)
    if bad or badw:
        raise RuntimeError("tiled bed %s %s: %d pairs and %d wall contacts overlap by more than %g of the "
                           "radius (worst: %s %s); build/jdem would refuse it"
                           % (size, disp, len(bad), len(badw), bench_tiling.START_OVERLAP_TOL, bad[:1], badw[:1]))
    info = dict(size=size, dispersity=disp, n=len(r), side=side, height=binfo["height"],
                tiled_from=base_size, tiles=[k, k], seam_gap=gap, base_side=binfo["side"],
                base=stats_base, tiled=stats,
                pairs_per_particle_ratio=stats["pairs_per_particle"] / stats_base["pairs_per_particle"],
                contacts_per_particle_ratio=(stats["pairs_per_particle"] + stats["wall_contacts_per_particle"])
                / (stats_base["pairs_per_particle"] + stats_base["wall_contacts_per_particle"]),
                max_overlap=float(max(ov.max(), WO.max())), generation_seconds=time.time() - t0)
    log("bed %s %s: %d x %d tiles of %s, seam gap %.3g m, %d spheres: %s"
        % (size, disp, k, k, base_size, gap, len(r), json.dumps(info)))
    tmp = path[:-4] + ".part.npz"
    np.savez(tmp, id=ids, radius=r, x=x, info=json.dumps(info))
    os.replace(tmp, path)
    return path


# ---------------------------------------------------------------------------------------------
# Scenes

def scene_path(out, size, variant):
    return os.path.join(out, "scenes", "%s_%s.yaml" % (size, variant))


def bonds_yaml(E, r_small):
    """The bonded variants' bond type and the rule that bonds every touching pair at step 0."""
    kn = E / (2.0 * r_small)
    return ("bond_types:\n  bench: {normal_stiffness: %s, shear_stiffness: %s, tensile_strength: %s, "
            "shear_strength: %s}\nbond_rules:\n  - {type: bench, time: 0.0, max_gap: %s}\n"
            % (num(kn), num(kn / (2.0 * (1.0 + 0.3))), num(BOND_STRENGTH), num(BOND_STRENGTH), num(BOND_MAX_GAP)))


def make_scene(out, size, variant, bed_path, steps):
    """The bench scene of a variant on a bed; dt is the guard's (rounded down): for the bonded
    variants that includes the bonds' bound."""
    stiff, roll = variant.split("_")[0], variant.endswith("_roll")
    path = scene_path(out, size, variant)
    bed = np.load(bed_path)
    info = json.loads(str(bed["info"]))
    E = E_STIFF if stiff == "stiff" else E_SOFT
    kw = dict(name="bench_%s_%s" % (size, variant), variant=variant, n=len(bed["id"]),
              E=num(E), eta=num(ETA_ROLL if roll else 0.0), walls=walls_yaml(info["side"], info["height"]),
              bonds=bonds_yaml(E, float(bed["radius"].min())) if is_bonded(variant) else "")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    head = fill("bench.yaml.in", dt=1.0, steps=1, **kw)
    lines = ["  - {id: %d, material: grain, radius: %s, position: [%s, %s, %s]}\n"
             % (i, num(r), num(p[0]), num(p[1]), num(p[2]))
             for i, r, p in zip(bed["id"], bed["radius"], bed["x"])]
    with open(path, "w") as f:
        f.write(head + "".join(lines))
    dt = safe_dt(path)
    with open(path, "w") as f:
        f.write(fill("bench.yaml.in", dt=num(dt), steps=steps, **kw) + "".join(lines))
    return path, dt


def resolved_scene(scene, bed_path, d):
    """The resolved scene of `scene` (what `jdem resolve` prints) as the dict that
    scene_to_liggghts.write_deck reads, without loading the resolved YAML of every particle and
    bond: at 1M that is ~25 million YAML nodes, ~14 GB and minutes per deck.  The full resolved
    text still goes to D/resolved.yaml (the LIGGGHTS trajectory keeps it in /parameters).  Parsed
    as YAML: `jdem resolve` of the scene cut to its first particle (materials, walls, time, bond
    types: everything but the particles and bonds).  The particles are the bed's, the values the
    scene lists, in the resolved schema of that first particle; the bonds are those jdem forms at
    step 0 (/connectivity/bonds of a 1-step run), so the deck gets exactly jdem's.
    tests/engine/test_bench_tiling.py checks that the decks equal those scene_to_liggghts.py
    writes from the whole resolved YAML."""
    import h5py
    import yaml
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "resolved.yaml"), "w") as f:
        r = subprocess.run([JDEM, "resolve", scene], stdout=f, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise RuntimeError("jdem resolve %s failed:\n%s" % (scene, r.stderr))
    with open(scene) as f:
        text = f.read()
    first = text.index("\nparticles:\n") + len("\nparticles:\n")
    head = os.path.join(d, "first_particle.yaml")
    with open(head, "w") as f:
        f.write(text[:text.index("\n", first) + 1])
    r = subprocess.run([JDEM, "resolve", head], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("jdem resolve %s failed:\n%s" % (head, r.stderr))
    sc = yaml.load(r.stdout, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    p0 = sc["particles"][0]
    bed = np.load(bed_path)
    sc["particles"] = [dict(p0, id=int(i), radius=float(rad), position=[float(c) for c in x])
                       for i, rad, x in zip(bed["id"], bed["radius"], bed["x"])]
    if sc.get("bond_types"):
        one = os.path.join(d, "bonds_step0.yaml")
        with open(one, "w") as f:
            f.write(re.sub(r"(?m)^  steps: \d+", "  steps: 1", text))
        h5 = os.path.join(d, "bonds_step0.h5")
        r = subprocess.run([JDEM, "run", one, "-o", h5, "--quiet", "--force"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("jdem run %s failed:\n%s" % (one, r.stderr))
        names = list(sc["bond_types"])
        with h5py.File(h5, "r") as f:
            g = f["jdem/bonds"]
            step0 = g["formed_step"][...] == 0
            ids, types = g["ids"][...][step0], g["type"][...][step0]
        sc["bonds"] = [{"ids": [int(a), int(b)], "type": names[t]} for (a, b), t in zip(ids.tolist(), types.tolist())]
        for f in (one, h5, h5[:-3] + ".xdmf"):
            os.remove(f)
    return sc


def link_or_copy(src, dst):
    if os.path.exists(dst):
        os.remove(dst)
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)


def adapt_deck(text, engine, steps):
    """The bench's edits of a deck from scene_to_liggghts: thermo at the last step only, no
    domain split along z, and for stock LIGGGHTS its own contact count instead of our dump."""
    text = re.sub(r"(?m)^thermo\s+\d+\s*$", "thermo          %d" % steps, text)
    # the box reaches twice the bed's height (the walls' extent): never split it along z,
    # or one rank would own every particle
    text = re.sub(r"(?m)^(boundary .*)$", r"\1\nprocessors      * * 1", text, count=1)
    if engine == "liggghts":
        # stock LIGGGHTS has no dump h5md/jdem: count contacts with its own computes instead
        text = re.sub(r"(?m)^dump .*$\n", "", text)
        text = text.replace("\nrun ", "\ncompute cc all contact/atom\ncompute csum all reduce sum c_cc\n"
                            "thermo_style    custom step atoms ke c_csum\nrun ", 1)
    return text


def deck_dir(out, size, variant):
    return os.path.join(out, "decks", "%s_%s" % (size, variant))


def make_decks(out, size, variant, scene, bed_path, steps, engines=ENGINES):
    """The LIGGGHTS decks (ours and stock) of `engines` in OUT/decks/SIZE_VARIANT/ENGINE/in.bench,
    from resolved_scene() of the bench scene on its bed."""
    from scripts import scene_to_liggghts
    d = deck_dir(out, size, variant)
    wanted = [e for e in ("liggghts-jdem", "liggghts") if e in engines
              and not (e == "liggghts" and is_bonded(variant))]  # stock LIGGGHTS has no parallel bonds
    if not wanted:
        return {}
    sc = resolved_scene(scene, bed_path, d)
    decks = {}
    for engine in wanted:
        dd = os.path.join(d, engine)
        os.makedirs(dd, exist_ok=True)
        deck = os.path.join(dd, "in.bench")
        link_or_copy(os.path.join(d, "resolved.yaml"), os.path.join(dd, "resolved.yaml"))  # 270 MB at 1M bonded
        try:
            scene_to_liggghts.write_deck(sc, os.path.join(dd, "resolved.yaml"), deck, os.path.join(dd, "out.h5"),
                                         builtin=engine == "liggghts")
        except SystemExit:  # scene_to_liggghts.fail() has printed the reason
            raise RuntimeError("deck generation failed for %s (%s)" % (scene, engine))
        with open(deck) as f:
            text = adapt_deck(f.read(), engine, steps)
        with open(deck, "w") as f:
            f.write(text)
        decks[engine] = deck
    return decks


# ---------------------------------------------------------------------------------------------
# Timed runs

def timed(cmd, cwd):
    """Run cmd under GNU time; returns (wall s, cpu s, peak RSS bytes, stdout, stderr, rc).  After
    RUN_TIMEOUT_S (--timeout) the whole process group (GNU time, mpirun, the engine) is killed and
    RuntimeError raised."""
    tf = os.path.join(cwd, ".time")
    full = [GNU_TIME, "-o", tf, "-f", "%e %U %S %M"] + cmd
    p = subprocess.Popen(full, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    try:
        so, se = p.communicate(timeout=RUN_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        raise RuntimeError("no result after %.0f s (--timeout), killed: %s" % (RUN_TIMEOUT_S, " ".join(cmd)))
    r = subprocess.CompletedProcess(full, p.returncode, so, se)
    try:
        e, u, s, m = open(tf).read().split()[-4:]
        wall, cpu, rss = float(e), float(u) + float(s), int(m) * 1024
    except (OSError, ValueError):
        wall, cpu, rss = float("nan"), float("nan"), 0
    return wall, cpu, rss, r.stdout, r.stderr, r.returncode


def mpi_prefix(ranks):
    if ranks <= 1:
        return []
    flags = ["--allow-run-as-root", "--oversubscribe"] if os.geteuid() == 0 else []
    return [shutil.which("mpirun") or "mpirun"] + flags + ["-np", str(ranks), "--bind-to", "none"]


def calibrate_liggghts(deck, engine):
    """CPU seconds of a 1-step run of the same deck (reading the data file, set-up, one step):
    subtracted from the S-step run's CPU time it leaves the CPU time of the loop, a measure that
    other jobs on the machine disturb less than wall time."""
    d = os.path.dirname(deck)
    one = os.path.join(d, "in.bench1")
    with open(deck) as f:
        text = f.read()
    with open(one, "w") as f:
        f.write(re.sub(r"(?m)^run\s+\d+\s*$", "run             1", text))
    exe = LIGGGHTS_JDEM if engine == "liggghts-jdem" else LIGGGHTS
    w, c, rss, so, se, rc = timed([exe, "-in", "in.bench1", "-log", "log.calib", "-screen", "none"], d)
    remove_files(os.path.join(d, "out.h5"))
    if rc:
        raise RuntimeError("%s 1-step calibration failed:\n%s" % (engine, se[-2000:]))
    return dict(wall_s=w, cpu_s=c, peak_rss=rss)


TIMING_RE = re.compile(r"jdem-timing: (.*)")
LOOP_PARTS = ("neighbour", "pairs", "walls", "integration", "output")  # jdem --timing's parts of the loop


def jdem_split(stderr):
    """The time loop's parts from `jdem run --timing` (seconds, and the counts it prints)."""
    m = TIMING_RE.findall(stderr)
    if not m:
        return None
    return {k: float(v) for k, v in (kv.split("=") for kv in m[-1].split())}


def jdem_loop_seconds(split):
    """jdem's wall time of the time loop: its loop timer (loop=), or for runs recorded before
    jdem printed one, the sum of the loop's parts (which leaves out only the per-step checks)."""
    return split["loop"] if "loop" in split else sum(split[k] for k in LOOP_PARTS)


def loop_of(r):
    """The wall time of a timing's loop, output included: LIGGGHTS' Loop time, jdem's loop timer
    (also for runs recorded with the older run(S) - run(1) as wall_s)."""
    if r["engine"] == "jdem" and r.get("jdem_split"):
        return jdem_loop_seconds(r["jdem_split"])
    return r["wall_s"]


def output_of(r):
    """The part of a timing's loop spent writing output: jdem's `output=`, LIGGGHTS' "Outpt"
    share of its Loop time (0 for records without a split)."""
    if r["engine"] == "jdem":
        return (r.get("jdem_split") or {}).get("output", 0.0)
    return r["wall_s"] * (r.get("liggghts_split_percent") or {}).get("outpt", 0.0) / 100.0


def wall_of(r):
    """The throughput tables' measure: the loop's wall time less its output (see the module
    docstring, 3), so that the engines are timed on the same work."""
    return loop_of(r) - output_of(r)


def remove_files(*paths):
    """Delete the large files of a finished timing (at 1M a trajectory of two frames is ~240 MB, a
    scene copy 125 MB: a full sweep would otherwise fill the disk)."""
    for p in paths:
        for q in (p, p[:-3] + ".xdmf" if p.endswith(".h5") else None):
            if q and os.path.exists(q):
                os.remove(q)


def run_jdem(out, size, variant, scene, steps, n, threads=1, extra=(), tag="", keep_trajectory=False):
    """Time `jdem run SCENE --threads T [extra]`: wall time by jdem's loop timer, CPU time as
    run(S) - run(1); returns the record.  The trajectories and the 1-step scene are deleted once
    read unless keep_trajectory."""
    d = os.path.join(out, "runs", "%s_%s" % (size, variant), "jdem%s_t%d" % (tag, threads))
    os.makedirs(d, exist_ok=True)
    one = os.path.join(d, "one.yaml")
    with open(scene) as f:
        text = f.read()
    text = re.sub(r"(?m)^  steps: \d+", "  steps: 1", text)
    text = re.sub(r"(?m)^  (every|observables_every): \d+", r"  \1: 1", text)
    with open(one, "w") as f:
        f.write(text)
    opts = ["--quiet", "--timing", "--threads", str(threads)] + list(extra)
    w1, c1, _, _, e1, rc1 = timed([JDEM, "run", one, "-o", os.path.join(d, "one.h5")] + opts, d)
    traj = os.path.join(d, "out.h5")
    w, c, rss, _, e, rc = timed([JDEM, "run", scene, "-o", traj] + opts, d)
    if rc or rc1:
        raise RuntimeError("jdem failed:\n" + e + e1)
    fr = h5_last_frame(traj)
    remove_files(one, os.path.join(d, "one.h5"))
    if not keep_trajectory:
        remove_files(traj)
    split = jdem_split(e)
    if not split:
        raise RuntimeError("jdem printed no --timing line:\n" + e)
    return dict(wall_s=jdem_loop_seconds(split), diff_wall_s=w - w1, cpu_s=c - c1, total_wall_s=w,
                setup_wall_s=w1, peak_rss=rss, contacts_per_particle=2.0 * fr["contacts"] / n,
                timing="jdem loop timer", bonds_start=fr["bonds_start"], bonds_end=fr["bonds"],
                jdem_split=split, trajectory=traj if keep_trajectory else None)


LOOP_RE = re.compile(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms")


def run_liggghts(out, size, variant, deck, engine, ranks, steps, n):
    d = os.path.dirname(deck)
    exe = LIGGGHTS_JDEM if engine == "liggghts-jdem" else LIGGGHTS
    cmd = mpi_prefix(ranks) + [exe, "-in", os.path.basename(deck), "-log", "log.%d" % ranks, "-screen", "none"]
    w, c, rss, so, se, rc = timed(cmd, d)
    logtext = open(os.path.join(d, "log.%d" % ranks), errors="replace").read()
    m = LOOP_RE.findall(logtext)
    if rc or not m:
        raise RuntimeError("%s failed (exit %d):\n%s\n%s" % (engine, rc, logtext[-3000:], se[-2000:]))
    loop, procs, nsteps, natoms = m[-1]
    if int(natoms) != n:
        raise RuntimeError("%s lost atoms: %s of %d" % (engine, natoms, n))
    bonds = (None, None)
    if engine == "liggghts-jdem":
        fr = h5_last_frame(os.path.join(d, "out.h5"))
        cpp = 2.0 * fr["contacts"] / n
        bonds = (fr["bonds_start"], fr["bonds"])
        remove_files(os.path.join(d, "out.h5"))
    else:  # thermo: step atoms ke c_csum  (contact/atom counts each contact at both atoms)
        rows = re.findall(r"(?m)^\s*(\d+)\s+(\d+)\s+\S+\s+(\S+)\s*$", logtext)
        cpp = float(rows[-1][2]) / n if rows else float("nan")
    tail = logtext[logtext.rfind("Loop time of"):]
    split = {k.strip().lower(): float(v) for k, v in
             re.findall(r"(?m)^(Pair|Neigh|Comm|Outpt|Other|Modify)\s+time \(%\) = \S+ \(([0-9.eE+-]+)\)", tail)}
    return dict(wall_s=float(loop), cpu_s=c, total_wall_s=w, peak_rss=rss, contacts_per_particle=cpp,
                bonds_start=bonds[0], bonds_end=bonds[1],
                timing="LIGGGHTS loop time", liggghts_split_percent=split)


def same_final_state(a, b):
    """1 when two trajectories end in bit-identical positions, velocities and spins."""
    import h5py
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        return all(np.array_equal(fa["particles/all/%s/value" % k][-1], fb["particles/all/%s/value" % k][-1])
                   for k in ("position", "velocity", "angular_velocity"))


# The bonds of the feature check's general scene: every touching pair bonded at step 0 (as in the
# bonded variants) by springs of zero stiffness, which carry no load.
IDLE_BONDS = """bond_types:
  idle: {normal_stiffness: 0.0, shear_stiffness: 0.0, tensile_strength: 1.0e9, shear_strength: 1.0e9}
bond_rules:
  - {type: idle, time: 0.0, max_gap: 1e-09}

"""


def feature_check(out, size, steps, repeats):
    """The scene-specialisation check of issue 6: the soft monodisperse bed without damping,
    rolling resistance and bonds (restitution 1, rolling friction 0), run by the loop
    specialised for it, against the same scene with those laws enabled at zero coefficients:
    the general contact loop (--all-laws: damping, rolling and mu_R evaluated with zero
    coefficients) and zero-stiffness bonds between all touching pairs.  Also against the general
    contact loop alone (no bonds), which shows what the contact loop's specialisation saves by
    itself.  Speed ratios (medians of `repeats` timings, 1 thread, runs alternated: wall by jdem's
    loop timer less its output, CPU as run(S) - run(1)) and whether the trajectories are
    identical bit for bit.  Writes OUT/feature_check.json (kept: delete it to re-measure)."""
    path = os.path.join(out, "feature_check.json")
    if os.path.exists(path):
        return
    src = scene_path(out, size, "soft_mono")
    with open(src) as f:
        text = f.read()
    plain = re.sub(r"restitution: 0\.5", "restitution: 1.0", text)
    if plain.count("restitution: 1.0") != 2 or plain.count("\nparticles:\n") != 1 or "bond_" in plain:
        raise RuntimeError("feature check: cannot switch off the damping in " + src)
    scenes = {"plain": scene_path(out, size, "soft_mono_plain"),
              "idle_bonds": scene_path(out, size, "soft_mono_plain_idle_bonds")}
    for key, body in (("plain", plain), ("idle_bonds", plain.replace("\nparticles:\n", "\n" + IDLE_BONDS + "particles:\n"))):
        with open(scenes[key], "w") as f:
            f.write(body)
    n = int(np.load(make_bed(out, size, "mono"))["id"].shape[0])
    loops = (("specialised", "plain", []), ("general_contact_laws", "plain", ["--all-laws"]),
             ("general", "idle_bonds", ["--all-laws"]))
    # alternately, so that a change in the machine's load falls on every loop alike
    timed = {tag: [] for tag, _, _ in loops}
    for _ in range(repeats):
        for tag, key, extra in loops:
            timed[tag].append(run_jdem(out, size, "soft_mono_plain", scenes[key], steps, n, extra=extra,
                                       tag="_" + tag, keep_trajectory=True))
    res = {}
    for tag, key, _ in loops:
        runs = timed[tag]
        walls = [r["wall_s"] - r["jdem_split"].get("output", 0.0) for r in runs]
        res[tag] = dict(scene=os.path.relpath(scenes[key], out), wall_s=walls, cpu_s=[r["cpu_s"] for r in runs],
                        wall_s_median=statistics.median(walls),
                        cpu_s_median=statistics.median(r["cpu_s"] for r in runs),
                        bonds=runs[-1]["bonds_start"], trajectory=runs[-1]["trajectory"])
        log("feature check %s: %.3f s" % (tag, res[tag]["wall_s_median"]))
    spec = res["specialised"]
    fc = dict(scene=os.path.relpath(scenes["plain"], out), size=size, N=n, steps=steps, repeats=repeats,
              description="soft_mono with restitution 1, rolling friction 0 and no bonds: the loop specialised "
                          "for friction only, against the same scene with damping, rolling and mu_R evaluated "
                          "at zero coefficients (--all-laws) and zero-stiffness bonds between all touching pairs "
                          "(general), and against --all-laws without the bonds (general_contact_laws)",
              specialised=spec, general=res["general"], general_contact_laws=res["general_contact_laws"])
    for tag in ("general", "general_contact_laws"):
        sfx = "" if tag == "general" else "_contact_laws"
        fc["speed_ratio_wall" + sfx] = res[tag]["wall_s_median"] / spec["wall_s_median"]
        fc["speed_ratio_cpu" + sfx] = res[tag]["cpu_s_median"] / spec["cpu_s_median"]
        fc["identical_trajectory" + sfx] = bool(same_final_state(spec["trajectory"], res[tag]["trajectory"]))
    with open(path, "w") as f:
        json.dump(fc, f, indent=1)


# ---------------------------------------------------------------------------------------------

def load_runs(path):
    runs = []
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                line = line.strip()
                if line:
                    runs.append(json.loads(line))
    return runs


def summarise(runs):
    groups = {}
    calib = {}
    for r in runs:
        if r["engine"].endswith("/calib"):
            calib.setdefault((r["size"], r["variant"], r["engine"][:-6], r["steps"]), []).append(r["cpu_s"])
    runs = [r for r in runs if not r["engine"].endswith("/calib")]
    for r in runs:
        groups.setdefault((r["size"], r["variant"], r["engine"], r["ranks"], r.get("threads", 1)), []).append(r)
    rows = []
    for (size, variant, engine, ranks, threads), rs in sorted(groups.items(), key=lambda kv: (
            SIZES.get(kv[0][0], 0), VARIANT_NAMES.index(kv[0][1]) if kv[0][1] in VARIANT_NAMES else 99,
            ENGINES.index(kv[0][2]), kv[0][3], kv[0][4])):
        walls = [wall_of(r) for r in rs]
        wall = statistics.median(walls)
        loop_with_output = statistics.median(loop_of(r) for r in rs)
        n, steps = rs[0]["n"], rs[0]["steps"]
        rss = max(r["peak_rss"] for r in rs)
        cpu = statistics.median(r["cpu_s"] for r in rs)
        if engine == "jdem":
            cpu_loop = cpu if threads == 1 else None  # already run(S) - run(1); threads add up CPU
        elif ranks == 1 and (size, variant, engine, steps) in calib:
            cpu_loop = cpu - statistics.median(calib[(size, variant, engine, steps)])
        else:
            cpu_loop = None  # MPI ranks busy-wait: CPU time is not work
        cpp = statistics.median(r["contacts_per_particle"] for r in rs)
        splits = [r["jdem_split"] for r in rs if r.get("jdem_split")]
        split = ({k: statistics.median(s[k] for s in splits) for k in splits[0]} if splits else None)
        engine_bytes = split.get("engine_bytes") if split else None
        # the sum of jdem's --timing parts but the output (the loop timer less the per-step checks)
        timer = sum(split[k] for k in LOOP_PARTS if k != "output") if split else None
        bonds = rs[0].get("bonds_start")
        # a bond is a per-pair record like a contact's history: the bonded beds' budget counts
        # the bonds at the start as contacts too
        budget = 300.0 * n + 100.0 * (0.5 * cpp * n + (bonds or 0))
        rows.append(dict(scene="%s_%s" % (size, variant), size=size, variant=variant, engine=engine,
                         threads=threads, ranks=ranks, N=n, steps=steps, dt=rs[0]["dt"], repeats=len(rs),
                         wall_seconds=wall, wall_seconds_all=walls,
                         loop_seconds_with_output=loop_with_output,
                         cpu_seconds_loop=cpu_loop,
                         particle_steps_per_cpu_second=(n * steps / cpu_loop) if cpu_loop and cpu_loop > 0 else None,
                         particle_steps_per_second=n * steps / wall if wall > 0 else float("nan"),
                         particle_steps_per_second_best=n * steps / min(walls) if min(walls) > 0 else None,
                         contacts_per_particle=cpp,
                         ns_per_particle_step=1e9 * wall / (n * steps),
                         jdem_timer_seconds=timer,
                         ns_per_particle_step_timer=1e9 * timer / (n * steps) if timer else None,
                         bonds=bonds, bonds_intact_end=min((r.get("bonds_end") for r in rs), default=None)
                         if bonds is not None else None,
                         ns_per_bond_step=1e9 * wall / (bonds * steps) if bonds else None,
                         peak_rss_bytes=rss, bytes_per_particle=rss * ranks / n,
                         memory_budget_bytes=budget,
                         engine_bytes=engine_bytes,
                         engine_bytes_per_particle=engine_bytes / n if engine_bytes else None,
                         engine_memory_within_budget=engine_bytes <= budget if engine_bytes else None,
                         timing="jdem loop timer" if engine == "jdem" else rs[0]["timing"], jdem_split_seconds=split,
                         liggghts_split_percent=rs[0].get("liggghts_split_percent"),
                         load_average=statistics.median(r.get("load_average", 0.0) for r in rs)))
    # the bonds' own cost: the bonded row against the same bed, engine and threads without bonds
    # (same steps; the bonded dt may be shorter, which does not change the work per step)
    ix = {(r["size"], r["variant"], r["engine"], r["ranks"], r["threads"]): r for r in rows}
    for r in rows:
        plain = ix.get((r["size"], r["variant"][:-len("_bonded")], r["engine"], r["ranks"], r["threads"]))
        if r["bonds"] and is_bonded(r["variant"]) and plain:
            r["bond_marginal_ns_per_bond_step"] = (1e9 * (r["wall_seconds"] - plain["wall_seconds"])
                                                   / (r["bonds"] * r["steps"]))
    return rows


def flatness(rows):
    """Issue 6's scaling target: jdem's ns per particle-step, max / min over the sizes run, per
    variant and thread count (1 process), from wall time and (1 thread) from CPU time."""
    groups = {}
    for r in rows:
        if r["engine"] == "jdem" and r["ranks"] == 1:
            groups.setdefault((r["variant"], r["threads"]), []).append(r)
    out = []
    for (variant, threads), rs in groups.items():
        if len(rs) < 2:
            continue
        rs.sort(key=lambda r: r["N"])
        wall = [r["ns_per_particle_step"] for r in rs]
        timer = [r["ns_per_particle_step_timer"] for r in rs if r.get("ns_per_particle_step_timer")]
        cpu = [1e9 / r["particle_steps_per_cpu_second"] for r in rs if r.get("particle_steps_per_cpu_second")]
        out.append(dict(variant=variant, threads=threads, sizes=[r["size"] for r in rs], N=[r["N"] for r in rs],
                        ns_per_particle_step=wall, ratio_wall=max(wall) / min(wall),
                        timer_ns_per_particle_step=timer if len(timer) == len(rs) else None,
                        ratio_timer=max(timer) / min(timer) if len(timer) == len(rs) else None,
                        cpu_ns_per_particle_step=cpu if len(cpu) == len(rs) else None,
                        ratio_cpu=max(cpu) / min(cpu) if len(cpu) == len(rs) else None,
                        target=FLATNESS_TARGET, met_wall=max(wall) / min(wall) <= FLATNESS_TARGET,
                        met_timer=max(timer) / min(timer) <= FLATNESS_TARGET if len(timer) == len(rs) else None))
    out.sort(key=lambda f: (VARIANT_NAMES.index(f["variant"]) if f["variant"] in VARIANT_NAMES else 99, f["threads"]))
    return out


def bed_infos(out):
    """The generation record of every bed in OUT/beds (tiling: seam gap, contacts per particle
    against the base bed's, generation seconds)."""
    d = os.path.join(out, "beds")
    infos = {}
    for name in sorted(os.listdir(d)) if os.path.isdir(d) else []:
        if name.endswith(".npz") and not name.endswith(".part.npz"):
            infos[name[:-4]] = json.loads(str(np.load(os.path.join(d, name))["info"]))
    return infos


def main():
    global RUN_TIMEOUT_S
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default=os.environ.get("BENCH_SIZES", "5k,20k"))
    ap.add_argument("--variants", default=os.environ.get("BENCH_VARIANTS", "all"))
    ap.add_argument("--engines", default=os.environ.get("BENCH_ENGINES", ",".join(ENGINES)))
    ap.add_argument("--repeats", type=int, default=int(os.environ.get("BENCH_REPEATS", "3")))
    ap.add_argument("--ranks-size", default=os.environ.get("BENCH_RANKS_SIZE", "20k"),
                    help="size at which the LIGGGHTS engines also run on 2 MPI ranks ('' for none)")
    ap.add_argument("--steps", default=os.environ.get("BENCH_STEPS", ""),
                    help="override steps per size, e.g. 5k=1000,20k=300")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench"))
    ap.add_argument("--fresh", action="store_true", help="forget earlier timings (beds are kept)")
    ap.add_argument("--threads", default=os.environ.get("BENCH_THREADS", "1,2"),
                    help="OpenMP thread counts of the jdem runs (default 1,2)")
    ap.add_argument("--threads-variants", default=os.environ.get("BENCH_THREADS_VARIANTS", "soft_mono"),
                    help="variants whose jdem runs use every --threads count ('all' for every variant); "
                         "the others run on 1 thread (default soft_mono: the beds issue 6 sets the "
                         "thread target on; keeps make bench short)")
    ap.add_argument("--timeout", type=float, default=RUN_TIMEOUT_S,
                    help="seconds after which one engine run is killed and recorded as failed")
    ap.add_argument("--keep-files", action="store_true",
                    help="keep the LIGGGHTS decks of the tiled sizes after their timings (~0.5 GB per variant at 1M)")
    ap.add_argument("--report-only", action="store_true")
    ap.add_argument("--prepare-only", action="store_true",
                    help="generate the beds, scenes and decks only (no timings, no report)")
    ap.add_argument("--no-profile", action="store_true", help="skip the callgrind profile of jdem")
    a = ap.parse_args()
    RUN_TIMEOUT_S = a.timeout
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    runs_path = os.path.join(out, "runs.jsonl")
    if a.fresh and os.path.exists(runs_path):
        os.remove(runs_path)
    steps_of = dict(STEPS)
    for item in filter(None, a.steps.split(",")):
        k, v = item.split("=")
        steps_of[k] = int(v)
    sizes = [s for s in a.sizes.split(",") if s]
    for s in sizes:
        if s not in SIZES:
            ap.error("unknown size %s (valid: %s)" % (s, ", ".join(SIZES)))
    variants = VARIANT_NAMES if a.variants == "all" else a.variants.split(",")
    for v in variants:
        if v not in VARIANT_NAMES:
            ap.error("unknown variant %s (valid: all, %s)" % (v, ", ".join(VARIANT_NAMES)))
    engines = a.engines.split(",")
    threads = [int(t) for t in a.threads.split(",") if t]

    if not a.report_only:
        done = {}
        for r in load_runs(runs_path):
            if r.get("failed"):
                continue  # a failed run is tried again
            key = (r["size"], r["variant"], r["engine"], r["ranks"], r.get("threads", 1), r["steps"])
            done[key] = done.get(key, 0) + 1
        for size in sizes:
            beds = {disp: make_bed(out, size, disp) for disp in ("mono", "bi")
                    if any(variant_dispersity(v) == disp for v in variants)}
            steps = steps_of[size]
            for variant in variants:
                disp = variant_dispersity(variant)
                t0 = time.time()
                scene, dt = make_scene(out, size, variant, beds[disp], steps)
                t_scene = time.time() - t0
                n = int(np.load(beds[disp])["id"].shape[0])
                t0 = time.time()
                decks = make_decks(out, size, variant, scene, beds[disp], steps, engines)
                log("%s %s: scene and decks ready (%.0f s)" % (size, variant, time.time() - t0 + t_scene))
                if a.prepare_only:
                    continue
                jobs = []
                for engine in engines:
                    if engine == "jdem":
                        many = a.threads_variants == "all" or variant in a.threads_variants.split(",")
                        jobs += [(engine, 1, t) for t in (threads if many else [1])]
                        continue
                    if engine not in decks:
                        continue  # bonded variant: stock LIGGGHTS has no parallel bonds (n/a)
                    jobs.append((engine, 1, 1))
                    if size == a.ranks_size:
                        jobs.append((engine, 2, 1))
                for rep in range(a.repeats):
                    for engine, ranks, nt in jobs:
                        key = (size, variant, engine, ranks, nt, steps)
                        if done.get(key, 0) > rep:
                            continue
                        try:
                            if engine == "jdem":
                                res = run_jdem(out, size, variant, scene, steps, n, threads=nt)
                            else:
                                res = run_liggghts(out, size, variant, decks[engine], engine, ranks, steps, n)
                        except RuntimeError as e:  # timeouts, crashes: recorded, the bench goes on
                            log("%s %s %s np=%d threads=%d rep %d FAILED: %s"
                                % (size, variant, engine, ranks, nt, rep, str(e)[-2000:]))
                            with open(runs_path, "a") as f:
                                f.write(json.dumps(dict(size=size, variant=variant, engine=engine, ranks=ranks,
                                                        threads=nt, n=n, steps=steps, repeat=rep,
                                                        failed=str(e)[-2000:])) + "\n")
                            continue
                        res.update(size=size, variant=variant, engine=engine, ranks=ranks, threads=nt,
                                   n=n, steps=steps, dt=dt, repeat=rep, when=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                                   load_average=os.getloadavg()[0],
                                   binary_mtime=time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(os.path.getmtime(
                                       JDEM if engine == "jdem" else LIGGGHTS_JDEM if engine == "liggghts-jdem"
                                       else LIGGGHTS))))
                        log("%s %s %s np=%d threads=%d rep %d: %.3f s, %.3g particle-steps/s, %.2f contacts/particle"
                            % (size, variant, engine, ranks, nt, rep, res["wall_s"], n * steps / res["wall_s"],
                               res["contacts_per_particle"]))
                        with open(runs_path, "a") as f:
                            f.write(json.dumps(res) + "\n")
                for rep in range(a.repeats):  # CPU-time calibration of the LIGGGHTS engines (1 rank)
                    for engine in engines:
                        key = (size, variant, engine + "/calib", 1, 1, steps)
                        if engine == "jdem" or engine not in decks or done.get(key, 0) > rep:
                            continue
                        try:
                            res = calibrate_liggghts(decks[engine], engine)
                        except RuntimeError as e:
                            log("%s %s %s 1-step calibration FAILED: %s" % (size, variant, engine, str(e)[-2000:]))
                            continue
                        res.update(size=size, variant=variant, engine=engine + "/calib", ranks=1, n=n,
                                   steps=steps, dt=dt, repeat=rep, load_average=os.getloadavg()[0])
                        with open(runs_path, "a") as f:
                            f.write(json.dumps(res) + "\n")
                if size in TILES and not a.keep_files and os.path.isdir(deck_dir(out, size, variant)):
                    shutil.rmtree(deck_dir(out, size, variant))  # ~0.5 GB per variant at 1M
    if a.prepare_only:
        return 0
    # the feature check and the profile on the smallest size run (callgrind is ~50x slower than
    # the run itself: never above PROFILE_MAX_SIZE)
    small = min(sizes, key=SIZES.get)
    if not a.report_only and "jdem" in engines and "soft_mono" in variants:
        feature_check(out, small, steps_of[small], a.repeats)
    if not a.report_only and not a.no_profile and not os.path.exists(os.path.join(out, "profile.json")):
        from scripts import bench_report
        sc = scene_path(out, small, "soft_mono")
        if SIZES[small] > SIZES[PROFILE_MAX_SIZE]:
            log("no callgrind profile: the smallest size run (%s) is above %s" % (small, PROFILE_MAX_SIZE))
        elif os.path.exists(sc):
            log("profiling jdem (callgrind) on %s" % sc)
            bench_report.profile_jdem(out, sc, int(np.load(make_bed(out, small, "mono"))["id"].shape[0]))
    all_runs = load_runs(runs_path)
    rows = summarise([r for r in all_runs if not r.get("failed")])
    failures = [r for r in all_runs if r.get("failed")]
    fc_path = os.path.join(out, "feature_check.json")
    fc = json.load(open(fc_path)) if os.path.exists(fc_path) else None
    beds = bed_infos(out)
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(dict(generated=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                       machine=machine_info(), runs=rows, flatness=flatness(rows), beds=beds,
                       failures=failures, feature_check=fc), f, indent=1)
    from scripts import bench_report
    bench_report.write_report(out, rows, machine_info(), fc, flatness(rows), beds, failures)
    log("wrote %s and %s" % (os.path.join(out, "summary.json"), os.path.join(out, "report.md")))
    return 0


def machine_info():
    info = {"cpus": os.cpu_count()}
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                info["cpu"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return info


if __name__ == "__main__":
    sys.exit(main())
