"""bench_beds.py — the bench's beds (scripts/bench.py, step 1): a lattice settled by build/jdem
and relaxed until every contact overlaps by TOUCH x the smallest radius, or k x k tiles of the
20k bed (scripts/bench_tiling.py); kept in OUT/beds/SIZE_DISP.npz."""
import json
import math
import os
import time

import numpy as np

from scripts import bench_tiling, engines
from scripts.bench_config import (LAYERS, R_LARGE, R_SMALL, SETTLE_TIME, SIZES, TILES, TOUCH, fill, log, num,
                                  safe_dt, walls_yaml)


def bed_geometry(size, disp):
    n = SIZES[size]
    rmax = R_LARGE if disp == "bi" else R_SMALL
    spacing = 2.05 * rmax
    k = max(2, int(round(math.sqrt(n / LAYERS))))
    side = k * spacing
    height = 2.0 * LAYERS * spacing
    return dict(n=k * k * LAYERS, k=k, spacing=spacing, side=side, height=height, rmax=rmax)


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
        r = engines.jdem("run", scene, "-o", traj, "--quiet")
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


def bed_infos(out):
    """The generation record of every bed in OUT/beds (tiling: seam gap, contacts per particle
    against the base bed's, generation seconds)."""
    d = os.path.join(out, "beds")
    infos = {}
    for name in sorted(os.listdir(d)) if os.path.isdir(d) else []:
        if name.endswith(".npz") and not name.endswith(".part.npz"):
            infos[name[:-4]] = json.loads(str(np.load(os.path.join(d, name))["info"]))
    return infos
