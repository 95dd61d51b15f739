"""Effective elastic constants from a servo-controlled confined compression (spec §2.4).

Stresses come from the walls (eq. 45).  Strains, positive in compression like the stresses:
  * best_fit_strain: the seed's least-squares strain of the particle displacements (Ch. 2
    eqs 46-50): relative displacements Delta u_rel = eps_ij x_rel_j fitted by the 3 x 3 normal
    equations (sum x_rel_a x_rel_b) eps_ib = sum Delta u_rel_i x_rel_a, positions at t2;
  * wall_strain: eps_zz = Delta H / H0, eps_xx = eps_yy = 0 (the side walls are fixed).
orthotropic_fit solves eq. (51), with one E, nu_xy and nu_xz = nu_yz, as a linear system in
(1/E, nu_xy/E, nu_xz/E), and reports its condition number; with the wall strain it is singular
(docs/mixing.md, "Elastic constants").  constrained_modulus and k0 are unambiguous.
"""
import numpy as np


def best_fit_strain(x1, x2):
    """(eps, cond): the symmetric strain [3, 3] fitted to the displacements from positions x1 to
    x2 ([N, 3] m, the same particles in the same order), positive in compression, and the
    condition number of the normal-equation matrix sum x_rel x_rel^T."""
    x1, x2 = np.asarray(x1, dtype=float), np.asarray(x2, dtype=float)
    du = x2 - x1
    du_rel = du - du.mean(axis=0)
    x_rel = x2 - x2.mean(axis=0)
    a = x_rel.T @ x_rel             # [a, b] = sum x_rel_a x_rel_b
    b = x_rel.T @ du_rel            # [a, i] = sum x_rel_a du_rel_i
    grad = np.linalg.solve(a, b).T  # grad[i, b] = eps_ib of eq. (48)
    return -0.5 * (grad + grad.T), float(np.linalg.cond(a))


def wall_strain(h0, h):
    """Strain from the top wall: diag(0, 0, (h0 - h) / h0), positive in compression."""
    return np.diag([0.0, 0.0, (h0 - h) / h0])


def box_stress(lo, hi, wall_forces):
    """Diagonal of eq. (45) for a box [lo, hi] from the total force the particles exert on each
    of its six walls (wall_forces[axis][0] on the wall at lo[axis], [1] at hi[axis], [3] N each):
    on a plane wall x_axis is the same at every contact point, so the sum needs only the totals.
    Positive in compression [Pa]."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    volume = float(np.prod(hi - lo))
    centre = 0.5 * (lo + hi)
    return np.array([((lo[i] - centre[i]) * wall_forces[i][0][i]
                      + (hi[i] - centre[i]) * wall_forces[i][1][i]) / volume for i in range(3)])


def fit_matrix(sig):
    """The matrix of eq. (51) as a linear system in (1/E, nu_xy/E, nu_xz/E)."""
    sxx, syy, szz = sig
    return np.array([[sxx, -syy, -szz], [syy, -sxx, -szz], [szz, 0.0, -(sxx + syy)]])


def orthotropic_fit(sig, eps):
    """E [Pa], nu_xy, nu_xz from the normal stresses sig and strains eps (3 each, both positive
    in compression), with the fit's condition number; NaNs when the system is singular."""
    m = fit_matrix(np.asarray(sig, dtype=float))
    cond = float(np.linalg.cond(m))
    if not np.isfinite(cond) or cond > 1e12:
        return {"E": float("nan"), "nu_xy": float("nan"), "nu_xz": float("nan"), "cond": cond,
                "degenerate": True}
    a, b, c = np.linalg.solve(m, np.asarray(eps, dtype=float))
    return {"E": 1.0 / a, "nu_xy": b / a, "nu_xz": c / a, "cond": cond, "degenerate": False}


def constrained_modulus(szz, ezz):
    """M = sigma_zz / eps_zz [Pa] (uniaxial strain: the side walls fixed)."""
    return szz / ezz


def k0(sxx, syy, szz):
    """Coefficient of lateral stress K0 = (sigma_xx + sigma_yy) / (2 sigma_zz)."""
    return (sxx + syy) / (2.0 * szz)


def compression_result(sig, x1, x2, h0, h):
    """Everything the tables report for one cube: both strains, both fits, M and K0."""
    eps_fit, cond_normal = best_fit_strain(x1, x2)
    eps_wall = wall_strain(h0, h)
    fit = orthotropic_fit(sig, np.diag(eps_fit))
    wall = orthotropic_fit(sig, np.diag(eps_wall))
    return {"best_fit": fit, "wall": wall, "eps_best_fit": np.diag(eps_fit).tolist(),
            "eps_wall": np.diag(eps_wall).tolist(), "cond_normal_equations": cond_normal,
            "M_best_fit": constrained_modulus(sig[2], eps_fit[2, 2]),
            "M_wall": constrained_modulus(sig[2], eps_wall[2, 2]),
            "K0": k0(sig[0], sig[1], sig[2])}
