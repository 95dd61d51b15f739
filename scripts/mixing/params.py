"""Mixing parameters of Jiang (2021) Ch. 2.8.1 / 4.3.3 in a measuring sphere (spec §2.1).

phi_v = V_big / V_small, phi_m = M_big / M_small, e = V_v / V_s, n = V_v / V_t,
rho_b = M_s / V_t and Z = 2 N_c / N_p, with V_i the exact lens volume of each particle inside
the sphere (lens.py).  Big and small are told apart by radius.  Z counts the particles whose
centre lies inside the sphere and the contacts (|x_i - x_j| < R_i + R_j) between two of them
(docs/mixing.md, "Coordination number").
"""
import math

import numpy as np

from .lens import lens_volume

# Table 4-2: the nine measuring points (x, y, z) [m]; spheres r = 0.1 m, cubes 0.2 m.
POINTS_TABLE_4_2 = np.array([[x, 0.5, z] for z in (0.2, 0.5, 0.7) for x in (0.25, 0.5, 0.75)])
MEASURING_RADIUS = 0.1
# Table 5-2: the 27 points of Ch. 5, three rows of 9 at y = 0.25, 0.5 and 0.75 m (points 1-9,
# 10-18, 19-27), each row's z = 0.2, 0.3, 0.4 m by x = 0.25, 0.5, 0.75 m; the middle row is the
# seed's middle clip (Table 5-3, the compression cubes' centres).
TABLE_5_2_ROWS = ((0.25, slice(0, 9)), (0.5, slice(9, 18)), (0.75, slice(18, 27)))
POINTS_TABLE_5_2 = np.array([[x, y, z] for y, _ in TABLE_5_2_ROWS for z in (0.2, 0.3, 0.4)
                             for x in (0.25, 0.5, 0.75)])
MIDDLE_CLIP = TABLE_5_2_ROWS[1][1]
IDEAL_PHI_V = 4 * 0.03 ** 3 / (512 * 0.015 ** 3)  # 0.0625


def big_mask(radius, threshold=None):
    """Big particles: radius above `threshold` (default: halfway between the smallest and the
    largest radius)."""
    if threshold is None:
        threshold = 0.5 * (radius.min() + radius.max())
    return radius > threshold


def contacts_among(position, radius):
    """Number of touching pairs (|x_i - x_j| < R_i + R_j) among the given particles."""
    if len(radius) < 2:
        return 0
    from scipy.spatial import cKDTree
    pairs = cKDTree(position).query_pairs(2.0 * radius.max(), output_type="ndarray")
    if len(pairs) == 0:
        return 0
    gap = np.linalg.norm(position[pairs[:, 0]] - position[pairs[:, 1]], axis=1)
    return int(np.count_nonzero(gap < radius[pairs[:, 0]] + radius[pairs[:, 1]]))


def mixing_parameters(dep, centre, r=MEASURING_RADIUS, threshold=None):
    """The parameters at one point, as a dict (volumes m^3, masses kg, rho_b kg/m^3)."""
    d = np.linalg.norm(dep.position - np.asarray(centre, dtype=float), axis=1)
    near = d < dep.radius + r
    vol = lens_volume(d[near], dep.radius[near], r)
    big = big_mask(dep.radius, threshold)[near]
    mass = vol * dep.density[near]
    v_t = 4.0 / 3.0 * math.pi * r ** 3
    v_big, v_small = float(vol[big].sum()), float(vol[~big].sum())
    m_big, m_small = float(mass[big].sum()), float(mass[~big].sum())
    v_s = v_big + v_small
    members = d < r
    n_p = int(np.count_nonzero(members))
    n_c = contacts_among(dep.position[members], dep.radius[members])
    with np.errstate(divide="ignore", invalid="ignore"):
        return {
            "phi_v": np.float64(v_big) / v_small, "phi_m": np.float64(m_big) / m_small,
            "e": np.float64(v_t - v_s) / v_s, "n": (v_t - v_s) / v_t,
            "rho_b": (m_big + m_small) / v_t, "Z": np.float64(2 * n_c) / n_p,
            "V_big": v_big, "V_small": v_small, "N_p": n_p, "N_c": n_c,
        }


def at_points(dep, points=POINTS_TABLE_4_2, r=MEASURING_RADIUS, threshold=None):
    """mixing_parameters at each point: a list of dicts, in the order of `points`."""
    return [mixing_parameters(dep, c, r, threshold) for c in points]
