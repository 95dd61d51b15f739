"""Independent references: closed-form Hertz, rigid-body impulse limits with the lever-arm
correction, the spec's restitution table, and the digitized curves of the paper."""
import math
import os

import numpy as np

from .cases import ROOT
from .trajectory import num

PUBLISHED = os.path.join(ROOT, "reference_runs", "chung_ooi", "published")

# jiang_model.md 13.4 Test 3: output e_n of the seed's damping (eq. 30, C_n = 2 gamma sqrt(m K_n))
# with the collision ending at F_n = 0 (Luding), for input e.
JIANG2021_RESTITUTION = {1.0: 1.000, 0.9: 0.912, 0.8: 0.826, 0.7: 0.742, 0.6: 0.661, 0.5: 0.582,
                         0.4: 0.506, 0.3: 0.431, 0.2: 0.358, 0.1: 0.283}

HERTZ_TIME_FACTOR = 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)
# t_c = HERTZ_TIME_FACTOR * delta_max / v: twice int_0^1 du / sqrt(1 - u^(5/2)) = (4/5) B(2/5, 1/2)
HERTZ_MEAN_OVERLAP = 0.5 * math.gamma(1.4) * math.gamma(0.5) / math.gamma(1.9)
# int F delta dt / (delta_max int F dt) of an elastic Hertz impact: with F = k delta^(3/2),
# k delta_max^(5/2) = (5/4) m v^2 and int F dt = 2 m v, it is (5/4) int_0^1 u^(5/2) du /
# sqrt(1 - u^(5/2)) = (5/4)(2/5) B(7/5, 1/2)


def hertz_effective(run):
    """E*, R*, m* of the impact from the scene's materials (rigid wall: E/(1-nu^2), R, m)."""
    mats = run.scene["materials"]
    parts = run.scene["particles"]

    def compliance(p):
        m = mats[p["material"]]
        return (1 - num(m["poisson_ratio"]) ** 2) / num(m["youngs_modulus"])

    r = [num(p["radius"]) for p in parts]
    rho = [num(mats[p["material"]]["density"]) for p in parts]
    m = [4.0 / 3.0 * math.pi * ri ** 3 * di for ri, di in zip(r, rho)]
    if run.two_spheres:
        return (1 / (compliance(parts[0]) + compliance(parts[1])), r[0] * r[1] / (r[0] + r[1]),
                m[0] * m[1] / (m[0] + m[1]))
    return 1 / compliance(parts[0]), r[0], m[0]


def hertz_closed_form(e_star, r_star, m_star, v):
    """Peak overlap [m], peak force [N], contact duration [s] of an elastic Hertz impact."""
    k = 4.0 / 3.0 * e_star * math.sqrt(r_star)
    delta = (15.0 * m_star * v ** 2 / (16.0 * e_star * math.sqrt(r_star))) ** 0.4
    return delta, k * delta ** 1.5, HERTZ_TIME_FACTOR * delta / v


def hertz_force_history(e_star, r_star, m_star, v, samples=4000):
    """Analytic F(t) of the same impact (RK4 on the dimensionless x'' = -(5/4) x^1.5)."""
    delta, f_max, t_c = hertz_closed_form(e_star, r_star, m_star, v)
    tau_end = t_c * v / delta
    h = tau_end / samples
    x, y, xs = 0.0, 1.0, [0.0]

    def acc(xx):
        return -1.25 * max(xx, 0.0) ** 1.5

    for _ in range(samples):
        k1x, k1y = y, acc(x)
        k2x, k2y = y + 0.5 * h * k1y, acc(x + 0.5 * h * k1x)
        k3x, k3y = y + 0.5 * h * k2y, acc(x + 0.5 * h * k2x)
        k4x, k4y = y + h * k3y, acc(x + h * k3x)
        x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        y += h / 6 * (k1y + 2 * k2y + 2 * k3y + k4y)
        xs.append(x)
    xs = np.clip(np.array(xs), 0.0, None)
    return np.linspace(0.0, t_c, samples + 1), f_max * xs ** 1.5


def rigid_body_limit(pre, e_n, mu, m1, m2, r1, regime, lever=1.0):
    """Post-impact state of solid spheres (I = 2/5 m R^2) for a Coulomb impact.

    Normal impulse P = m* (1 + e_n) V_cn.  'sliding': tangential impulse mu P throughout;
    'stick': the tangential impulse that brings the contact slip to zero.  m2 = inf for a wall.
    lever: mean lever arm of the tangential force about sphere 1's centre over R1 (rigid: 1).
    """
    inv_m = 1.0 / m1 + 1.0 / m2
    slip_per_impulse = (1.0 + 2.5 * lever) / m1 + 3.5 / m2
    p_n = (1.0 + e_n) * pre["V_cn"] / inv_m
    p_t = mu * p_n if regime == "sliding" else pre["V_st"] / slip_per_impulse
    return {"V_cn": e_n * pre["V_cn"], "V_ct": pre["V_ct"] - p_t / m1,
            "w": pre["w"] - 2.5 * lever * p_t / (m1 * r1),
            "V_st": pre["V_st"] - p_t * slip_per_impulse}


def lever_arm(run, v_cn):
    """Mean lever arm (over R1) of the tangential force of a sphere on a rigid plane.

    The contact lies on the plane, R - delta from the centre.  Weighted by the force (in gross
    sliding mu F_n), the mean overlap of an elastic Hertz impact is HERTZ_MEAN_OVERLAP delta_max,
    so the arm is 1 - HERTZ_MEAN_OVERLAP delta_max/R (exact for e = 1; for the damped impacts
    of Tests 4 and 6 delta_max/R <= 0.6 %, so the elastic weighting is ample).  Sphere pairs:
    1 (delta_max/R1 <= 0.1 % in Tests 7-8).
    """
    if run.two_spheres:
        return 1.0
    delta_max, _, _ = hertz_closed_form(*hertz_effective(run), v_cn)
    return 1.0 - HERTZ_MEAN_OVERLAP * delta_max / run.radius[0]


def sliding_parameter(pre, e_n, mu):
    """X = 3.5 mu (1 + e_n) V_cn / V_st: rigid-body gross sliding for X < 1."""
    return 3.5 * mu * (1.0 + e_n) * pre["V_cn"] / pre["V_st"]


def published_curve(test, quantity, material):
    """Digitized Chung & Ooi (2011) curve (x, y) from reference_runs/chung_ooi/published, or None."""
    path = os.path.join(PUBLISHED, f"test{test}_{quantity}_{material}.csv")
    if not os.path.exists(path):
        return None
    data = np.loadtxt(path, delimiter=",", comments="#")
    return data[:, 0], data[:, 1]
