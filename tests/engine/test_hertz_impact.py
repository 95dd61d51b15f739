#!/usr/bin/python3
"""Engine test 3: Chung & Ooi (2011) test 1, elastic head-on impact of two glass spheres
(R = 0.01 m, E = 4.8e10 Pa, nu = 0.2, rho = 2800 kg/m^3) at +-10 m/s, ~400 steps per contact.
Checks against the analytic Hertz impact (the formulas of kernel/jdem_kernel.c
jd_hertz_peak_force, jd_hertz_contact_time): peak force, contact duration, peak overlap,
rebound speed (e = 1) and momentum; again with nu = 1/2 (tests/engine/scenes/hertz_nu_half.yaml).

Run:  /usr/bin/python3 tests/engine/test_hertz_impact.py     (JDEM=path/to/jdem to override)
"""
from math import gamma, pi, sqrt

from tests.engine.engine_common import Checks, load, np, run

R, E, rho, v = 0.01, 4.8e10, 2800.0, 20.0  # v: approach speed
m = 4.0 * pi / 3.0 * R**3 * rho
m_eff = m / 2


def check_impact(c, scene, nu, tag):
    G = E / (2 * (1 + nu))
    k_n = 2 * G * sqrt(2 * R) / (3 * (1 - nu))  # harmonic mean of two equal k_p
    d_max = (1.25 * m_eff * v * v / k_n) ** 0.4
    f_max = k_n * d_max**1.5
    t_c = (2 * 1.25**0.4 * 0.4 * gamma(0.4) * gamma(0.5) / gamma(0.9) * (m_eff / k_n) ** 0.4 *
           v**-0.2)
    _, out = run(scene)
    t = load(out)
    fx = t["force"][:, 1, 0]  # force on the right sphere (+x when pushed apart)
    dt = t["force_time"][1] - t["force_time"][0]
    c.close_to(tag + "peak_force", fx.max(), f_max, 5e-3)
    c.close_to(tag + "contact_duration", np.count_nonzero(fx > 0) * dt, t_c, 5e-3)
    gap = t["position"][:, 1, 0] - t["position"][:, 0, 0]
    c.close_to(tag + "peak_overlap", 2 * R - gap.min(), d_max, 5e-3)
    c.close_to(tag + "rebound_speed", t["velocity"][-1, 1, 0], 10.0, 1e-4)
    p = np.sum(t["velocity"][-1, :, 0] * t["mass"])
    c.check(tag + "momentum_conserved", abs(p) < 1e-14 * m * 10, f"total momentum {p:.3g}")
    c.check(tag + "no_rotation", np.all(t["angular_velocity"] == 0),
            "spin appeared in a head-on impact")
    c.close_to(tag + "kinetic_energy_recovered", t["obs"]["kinetic_energy"][-1],
               t["obs"]["kinetic_energy"][0], 1e-6)


c = Checks()
check_impact(c, "chung_ooi_1", 0.2, "")
# poisson_ratio 1/2 (incompressible, e.g. rubber), the upper end of the valid range
check_impact(c, "hertz_nu_half", 0.5, "nu_half_")
c.exit()
