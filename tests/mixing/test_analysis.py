#!/usr/bin/python3
"""The mixing analysis (scripts/mixing) on synthetic deposits with known answers."""
import math
import os
import tempfile

import numpy as np
from scipy import integrate

from tests.mixing.common import check, close, finish
from scripts.mixing import deposit, elastic, lens, params, stats

# ------------------------------------------------------------------------------------------
# Lens volume against quadrature: slices normal to the line of centres are two concentric
# discs, so V = int pi min(R^2 - z^2, r^2 - (z - d)^2) dz over the common range.


def lens_by_quadrature(d, R, r):
    lo, hi = max(-R, d - r), min(R, d + r)
    if hi <= lo:
        return 0.0
    f = lambda z: math.pi * max(0.0, min(R * R - z * z, r * r - (z - d) ** 2))  # noqa: E731
    knee = (d * d + R * R - r * r) / (2 * d) if d > 0 else lo  # where the two discs are equal
    pts = [p for p in (knee,) if lo < p < hi]
    val, err = integrate.quad(f, lo, hi, points=pts or None, epsabs=1e-16, epsrel=1e-12, limit=200)
    return val


def lens_by_monte_carlo(d, R, r, n=400_000, seed=12345):
    """Fraction of uniform points of the particle inside the measuring sphere, times its volume;
    returns (estimate, 4-sigma bound)."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-R, R, (n, 3))
    p = p[np.einsum("ij,ij->i", p, p) <= R * R]
    inside = np.linalg.norm(p - [d, 0, 0], axis=1) <= r
    frac = inside.mean()
    vp = 4 / 3 * math.pi * R ** 3
    return frac * vp, 4 * vp * math.sqrt(frac * (1 - frac) / len(p))


def test_lens():
    # every size ratio of the campaign: R = 0.015, 0.03 against r = 0.1, and the radii 0.05 and
    # 0.2 that the seed also tried
    for R in (0.015, 0.03):
        for r in (0.05, 0.1, 0.2):
            vp = 4 / 3 * math.pi * R ** 3
            ds = np.linspace(0.0, R + r + 0.01, 41)
            worst = max(abs(float(lens.lens_volume(d, R, r)) - lens_by_quadrature(d, R, r))
                        for d in ds)
            check(f"lens_vs_quadrature_R{R}_r{r}", worst <= 1e-9 * vp,
                  f"worst |closed - quad| = {worst:.3g} > 1e-9 of the particle volume")
            d = r  # the centre on the measuring sphere's surface: about half inside
            mc, bound = lens_by_monte_carlo(d, R, r)
            got = float(lens.lens_volume(d, R, r))
            check(f"lens_vs_monte_carlo_R{R}_r{r}", abs(got - mc) <= bound,
                  f"closed {got:.6g}, Monte Carlo {mc:.6g} +- {bound:.3g}")
    close("lens_fully_inside", float(lens.lens_volume(0.05, 0.03, 0.1)),
          4 / 3 * math.pi * 0.03 ** 3, 1e-18)
    close("lens_apart", float(lens.lens_volume(0.13, 0.03, 0.1)), 0.0, 0.0)


# ------------------------------------------------------------------------------------------
# Mixing parameters.


def lattice(counts, pitch, radius, origin, density):
    idx = np.stack(np.meshgrid(*[np.arange(c) for c in counts], indexing="ij"), -1).reshape(-1, 3)
    x = np.asarray(origin) + pitch * idx
    n = len(x)
    r = np.full(n, radius)
    return deposit.Deposit(np.arange(1, n + 1), np.zeros(n, np.int32), r,
                           density * 4 / 3 * math.pi * r ** 3, x)


def join(a, b):
    return deposit.Deposit(np.concatenate([a.id, b.id + len(a.id)]),
                           np.concatenate([a.species, b.species + 1]),
                           np.concatenate([a.radius, b.radius]), np.concatenate([a.mass, b.mass]),
                           np.concatenate([a.position, b.position]))


def test_cluster_exact():
    """A 2 x 2 x 2 cluster of touching small spheres (4000 kg/m^3) with a big sphere (3600)
    0.005 m above and below it, all well inside the sphere: every volume is whole, N_c =
    3 n^2 (n - 1) = 12 between the small ones, the big ones touch nothing: Z = 24/10."""
    R, pitch = 0.015, 0.03 * (1 - 1e-9)
    small = lattice((2, 2, 2), pitch, R, (0.485, 0.485, 0.485), 4000.0)
    big = lattice((1, 1, 2), 0.13, 0.03, (0.5, 0.5, 0.435), 3600.0)
    dep = join(small, big)
    c = (0.5, 0.5, 0.5)
    p = params.mixing_parameters(dep, c, r=0.1)
    vs, vb = 8 * 4 / 3 * math.pi * R ** 3, 2 * 4 / 3 * math.pi * 0.03 ** 3
    vt = 4 / 3 * math.pi * 0.1 ** 3
    close("cluster_phi_v", p["phi_v"], vb / vs, 1e-12)
    close("cluster_phi_m", p["phi_m"], 3600 * vb / (4000 * vs), 1e-12)
    close("cluster_e", p["e"], (vt - vs - vb) / (vs + vb), 1e-9)
    close("cluster_n", p["n"], (vt - vs - vb) / vt, 1e-12)
    close("cluster_n_is_e_over_1_plus_e", p["n"], p["e"] / (1 + p["e"]), 1e-12)
    close("cluster_rho_b", p["rho_b"], (4000 * vs + 3600 * vb) / vt, 1e-9)
    check("cluster_counts", (p["N_p"], p["N_c"]) == (10, 12), f"N_p, N_c = {p['N_p']}, {p['N_c']}")
    close("cluster_Z", p["Z"], 2.4, 1e-12)


def test_lattice_packing():
    """Simple cubic packing of touching spheres: solid fraction pi/6 and Z = 6 in the bulk.
    The solid volume in a sphere averaged over sphere centres uniformly in one lattice cell is
    exactly pi/6 V_t; the midpoint rule over the cell converges fast for this periodic C^1
    integrand (error measured: 3.8e-4 at 2^3 points, 1.8e-5 at 4^3, 5.1e-6 at 6^3, 8.9e-7 at
    8^3), hence the bound 1e-5 at 6^3."""
    R = 0.015
    dep = lattice((30, 30, 30), 2 * R, R, (0.05, 0.05, 0.05), 4000.0)
    base = np.array([0.5, 0.5, 0.5]) + R  # a lattice site near the middle
    grid = (np.arange(6) + 0.5) / 6 * 2 * R
    solid = [1 - params.mixing_parameters(dep, base + [a, b, c], 0.1)["n"]
             for a in grid for b in grid for c in grid]
    close("sc_packing_fraction", float(np.mean(solid)), math.pi / 6, 1e-5)
    # Z: every member's six neighbours, less those outside the sphere: count them independently
    # (the pitch shrunk by 1e-9: contacts are counted on an overlap, not at round-off touching)
    c = base.copy()
    dep2 = lattice((30, 30, 30), 2 * R * (1 - 1e-9), R, (0.05, 0.05, 0.05), 4000.0)
    p = params.mixing_parameters(dep2, c, 0.1)
    inside = np.linalg.norm(dep2.position - c, axis=1) < 0.1
    sites = {tuple(np.rint((x - 0.05) / (2 * R)).astype(int)) for x in dep.position[inside]}
    nc = sum((s[0] + dx, s[1] + dy, s[2] + dz) in sites for s in sites
             for dx, dy, dz in ((1, 0, 0), (0, 1, 0), (0, 0, 1)))
    check("sc_contacts_by_enumeration", p["N_c"] == nc and p["N_p"] == len(sites),
          f"N_c {p['N_c']} vs {nc}, N_p {p['N_p']} vs {len(sites)}")
    close("sc_Z_formula", p["Z"], 2 * nc / len(sites), 1e-12)
    check("sc_points_table", params.POINTS_TABLE_4_2.shape == (9, 3)
          and params.POINTS_TABLE_4_2[4].tolist() == [0.5, 0.5, 0.5]
          and params.POINTS_TABLE_4_2[8].tolist() == [0.75, 0.5, 0.7], "Table 4-2")
    close("ideal_phi_v", params.IDEAL_PHI_V, 0.0625, 1e-15)


# ------------------------------------------------------------------------------------------
# Elastic constants.


def test_best_fit_strain():
    """An affine field u = G x + t on scattered particles: the fit returns -sym(G) exactly
    (compression positive), whatever the translation."""
    rng = np.random.default_rng(3)
    x1 = rng.uniform(0.4, 0.6, (300, 3))
    g = np.array([[-0.01, 0.002, 0.0], [0.004, 0.003, -0.001], [0.0, 0.001, -0.05]])
    x2 = x1 + x1 @ g.T + [0.1, -0.2, 0.05]
    eps, cond = elastic.best_fit_strain(x1, x2)
    # the fit uses the positions at t2 (eq. 46), so it recovers the gradient w.r.t. x2:
    # du = G x1 = G (I + G)^-1 x2
    g2 = g @ np.linalg.inv(np.eye(3) + g)
    want = -0.5 * (g2 + g2.T)
    err = float(np.abs(eps - want).max())
    check("best_fit_affine", err <= 1e-12, f"max error {err:.3g}")
    check("best_fit_cond", 1 <= cond < 10, f"condition number {cond:.3g} of a cube of points")
    close("wall_strain", elastic.wall_strain(0.2, 0.19)[2, 2], 0.05, 1e-15)


def hooke(E, nu_xy, nu_xz, sig):
    m = np.array([[1, -nu_xy, -nu_xz], [-nu_xy, 1, -nu_xz], [-nu_xz, -nu_xz, 1]]) / E
    return m @ np.asarray(sig)


def test_orthotropic_fit():
    sig = np.array([420.0, 380.0, 1000.0])
    for label, (E, nxy, nxz) in {"isotropic": (2.0e5, 0.3, 0.3),
                                 "orthotropic": (2500.0, 0.7, 0.3)}.items():
        fit = elastic.orthotropic_fit(sig, hooke(E, nxy, nxz, sig))
        check(f"fit_{label}", abs(fit["E"] / E - 1) < 1e-9 and abs(fit["nu_xy"] - nxy) < 1e-9
              and abs(fit["nu_xz"] - nxz) < 1e-9, f"{fit}")
    # the condition number against the closed determinant (sxx - syy)((sxx + syy)^2 - szz^2)
    det = (sig[0] - sig[1]) * ((sig[0] + sig[1]) ** 2 - sig[2] ** 2)
    close("fit_determinant", float(np.linalg.det(elastic.fit_matrix(sig))), det, 1e-6 * abs(det))
    # fixed side walls: eps_xx = eps_yy = 0 forces nu_xy = -1 when sxx != syy ...
    fit = elastic.orthotropic_fit(sig, [0.0, 0.0, 0.01])
    close("wall_strain_forces_nu_xy_minus_1", fit["nu_xy"], -1.0, 1e-9)
    # ... and is singular when sxx = syy (the case of a symmetric sample)
    fit = elastic.orthotropic_fit([400.0, 400.0, 1000.0], [0.0, 0.0, 0.01])
    check("wall_strain_degenerate", fit["degenerate"] and math.isnan(fit["E"]), f"{fit}")
    # uniaxial strain of an isotropic solid: M = E (1 - nu) / ((1 + nu)(1 - 2 nu)), K0 = nu/(1-nu)
    E, nu, ezz = 1.0e6, 0.25, 0.001
    M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    szz = M * ezz
    sh = nu / (1 - nu) * szz
    close("hooke_uniaxial_strain_check", float(hooke(E, nu, nu, [sh, sh, szz])[0]), 0.0, 1e-15)
    close("constrained_modulus", elastic.constrained_modulus(szz, ezz), M, 1e-6)
    close("k0", elastic.k0(sh, sh, szz), nu / (1 - nu), 1e-15)


def test_box_stress():
    """Six walls of a 0.2 m cube carrying s_ii 0.04 m^2 each: diag(s)."""
    s = [300.0, 500.0, 1000.0]
    lo, hi = [0.4, 0.4, 0.1], [0.6, 0.6, 0.3]
    forces = [[np.eye(3)[i] * -s[i] * 0.04, np.eye(3)[i] * s[i] * 0.04] for i in range(3)]
    got = elastic.box_stress(lo, hi, forces)
    check("box_stress", np.allclose(got, s, rtol=1e-12, atol=0), f"{got}")


def test_stats():
    v = [9.0, 1.0, 5.0, 2.0, 8.0, 3.0, 7.0, 4.0, 6.0]
    close("trimmed_mean", stats.trimmed_mean(v), 5.0, 1e-15)
    close("trimmed_std_over_7", stats.trimmed_std(v), math.sqrt(28 / 6), 1e-15)
    close("std_over_9", stats.summary(v)["std_all"], math.sqrt(60 / 8), 1e-15)
    # winsorised 2, 2, 3, ..., 8, 8: squared deviations 46, std sqrt(46 / 8), over (7/9) 3
    close("trimmed_mean_error", stats.trimmed_mean_error(v), math.sqrt(46 / 8) / (7 / 3), 1e-15)
    close("trimmed_mean_error_two_values", stats.trimmed_mean_error([1.0, 3.0]), 1.0, 1e-15)
    close("trimmed_mean_drops_one_each", stats.trimmed_mean([1, 1, 1, 10, 10]), 4.0, 1e-15)
    close("trimmed_mean_inf_phi_v", stats.trimmed_mean([0.1, 0.2, float("inf")] + [0.3] * 6),
          (0.2 + 0.3 * 6) / 7, 1e-15)


# ------------------------------------------------------------------------------------------
# Reading and cutting.


def write_h5md(path, x_frames, radius):
    import h5py
    n = len(radius)
    with h5py.File(path, "w") as f:
        p = f.create_group("particles/all")
        p["id"] = np.arange(1, n + 1, dtype=np.int64)
        p["species"] = np.zeros(n, np.int32)
        p["radius"] = radius
        p["mass"] = 4000 * 4 / 3 * math.pi * radius ** 3
        p["position/value"] = x_frames
        p["position/step"] = np.arange(len(x_frames), dtype=np.int64) * 10
        p["position/time"] = np.arange(len(x_frames)) * 1e-3


def expect_error(name, fn, message):
    try:
        fn()
    except deposit.DepositError as e:
        check(name, str(e) == message, f"message {str(e)!r}, expected {message!r}")
    else:
        check(name, False, "no error")


def test_reader():
    tmp = tempfile.mkdtemp()
    path = os.path.join(tmp, "d.h5")
    x = np.array([[[0.1, 0.1, 0.1], [0.5, 0.5, 0.5]], [[0.1, 0.1, 0.05], [0.5, 0.5, 0.4]]])
    write_h5md(path, x, np.array([0.015, 0.03]))
    d = deposit.read_frame(path)
    check("read_last_frame", d.step == 10 and np.array_equal(d.position, x[1]), f"{d}")
    close("read_density", float(d.density[1]), 4000.0, 1e-9)
    close("deposit_height", deposit.deposit_height(d), 0.43, 1e-15)
    expect_error("read_missing_frame", lambda: deposit.read_frame(path, 2),
                 f"{path}: frame 2 does not exist; valid: -2 to 1 (2 frames)")
    missing = os.path.join(tmp, "none.h5")
    expect_error("read_missing_file", lambda: deposit.read_frame(missing),
                 f"{missing}: no such file; valid: an H5MD trajectory written by jdem or "
                 f"liggghts-jdem")
    kept = deposit.keep_box(d, [0.07, 0.07, 0.02], [0.3, 0.3, 0.3])
    check("keep_box", kept.id.tolist() == [1], f"{kept.id}")
    expect_error("keep_box_outside", lambda: deposit.keep_box(d, [0.4, 0.4, 0.4], [0.6, 0.6, 1.0]),
                 "region [0.4, 0.4, 0.4]..[0.6, 0.6, 1.0] lies outside the deposit (extent "
                 "[0.07, 0.07, 0.02]..[0.53, 0.53, 0.43]); valid: a region inside it")


for t in (test_lens, test_cluster_exact, test_lattice_packing, test_best_fit_strain,
          test_orthotropic_fit, test_box_stress, test_stats, test_reader):
    t()
finish()
