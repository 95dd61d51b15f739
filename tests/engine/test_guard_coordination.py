#!/usr/bin/python3
"""Engine test: the coordination term of the time-step guard (kernel/jdem_guard.h) against the
exact stability limit of velocity Verlet, 2/omega_max, with omega_max^2 the largest eigenvalue of
the mass-scaled stiffness matrix assembled here independently with numpy (6 degrees of freedom
per sphere; normal tangent stiffness 3/2 K, tangential spring K at the lever arm R, rolling
spring K r_roll^2 on the relative rotation; K = k_n sqrt(delta) at the peak overlap of a Hertz
impact at max_impact_speed).  The guard must never exceed the exact limit (it is a bound), and
must not be needlessly small (ratio >= 0.7 for two spheres and a sphere on a wall, >= 0.45 for
the 12 contacts of a close-packed cluster).  The same with Mindlin's tangential stiffness
(model.tangential_stiffness: mindlin): K_t = 8 G* sqrt(R* delta), G* from LIGGGHTS' formula
1/G* = 2(2-nu)(1+nu)/E per elastic body (a rigid wall adds nothing), R* = R/2 for two spheres
and R on a wall, in place of K in the tangential spring.

Run:  /usr/bin/python3 tests/engine/test_guard_coordination.py     (JDEM=... to override)
"""
import math
import os
import re
import tempfile

import numpy as np
import yaml

from scripts import engines
from tests.engine.engine_common import JDEM, Checks

E, NU, RHO, R, V = 4.8e10, 0.2, 2800.0, 0.01, 20.0
MASS = 4.0 / 3.0 * math.pi * R ** 3 * RHO
INERTIA = 0.4 * MASS * R * R


def guard_limit(particles, walls, coordination, tangential="jiang2021"):
    """The stepper's coordination bound, read from its summary line."""
    sc = {"jdem_scene": 1, "name": "guard_coord", "model": {"tangential_stiffness": tangential},
          "time": {"dt": 1e-9, "steps": 1, "max_impact_speed": V, "coordination_number": coordination},
          "materials": {"glass": {"youngs_modulus": E, "poisson_ratio": NU, "density": RHO},
                        "wall": {}},
          "particles": [{"material": "glass", "radius": R, "position": [float(x) for x in p]} for p in particles],
          "walls": walls}
    d = tempfile.mkdtemp(prefix="jdem_guard_")
    path = os.path.join(d, "scene.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(sc, f)
    p = engines.jdem("run", path, "-o", os.path.join(d, "out.h5"), binary=JDEM)
    m = re.search(r"Verlet limit at coordination number (\S+) = (\S+) s", p.stderr)
    if p.returncode != 0 or not m:
        raise RuntimeError(f"jdem run failed ({p.returncode}): {p.stderr.strip()}")
    return float(m.group(2))


def peak_overlap(m_eff, k_n):
    return (1.25 * m_eff * V * V / k_n) ** 0.4  # 1/2 m v^2 = 2/5 k_n delta^2.5


def secant_stiffness(m_eff, k_n):
    return k_n * math.sqrt(peak_overlap(m_eff, k_n))


def mindlin_stiffness(m_eff, k_n, g_star, r_star):
    return 8.0 * g_star * math.sqrt(r_star * peak_overlap(m_eff, k_n))


def skew(r):
    return np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])


def assemble(n_particles, contacts, K, Kt):
    """Stiffness matrix; contacts are (a, b, n) with b = None for a wall (n from a to b)."""
    dof = 6 * n_particles
    S = np.zeros((dof, dof))
    P = lambda n: 1.5 * K * np.outer(n, n) + Kt * (np.eye(3) - np.outer(n, n))
    for a, b, n in contacts:
        n = np.asarray(n, float) / np.linalg.norm(n)
        B = np.zeros((3, dof))  # relative displacement at the contact point, b minus a
        C = np.zeros((3, dof))  # relative rotation, b minus a
        B[:, 6 * a:6 * a + 3] = -np.eye(3)
        B[:, 6 * a + 3:6 * a + 6] = skew(R * n)  # -(theta_a x r_a) = [r_a]x theta_a
        C[:, 6 * a + 3:6 * a + 6] = -np.eye(3)
        r_roll = R
        if b is not None:
            B[:, 6 * b:6 * b + 3] = np.eye(3)
            B[:, 6 * b + 3:6 * b + 6] = -skew(-R * n)
            C[:, 6 * b + 3:6 * b + 6] = np.eye(3)
            r_roll = R / 2
        S += B.T @ P(n) @ B + K * r_roll ** 2 * C.T @ C
    return S


def exact_limit(n_particles, contacts, K, Kt=None):
    w = np.tile([MASS] * 3 + [INERTIA] * 3, n_particles)
    A = assemble(n_particles, contacts, K, K if Kt is None else Kt) / np.sqrt(np.outer(w, w))
    return 2.0 / math.sqrt(np.linalg.eigvalsh(A).max())


k_p = 2 * E / (2 * (1 + NU)) * math.sqrt(2 * R) / (3 * (1 - NU))
c = Checks()

# two spheres, one contact
K_pair = secant_stiffness(MASS / 2, k_p)
exact = exact_limit(2, [(0, 1, (1, 0, 0))], K_pair)
got = guard_limit([(-0.0101, 0, 0), (0.0101, 0, 0)], [], 1)
c.check("pair_bound_safe", got <= exact, f"guard {got:.6g} s > exact {exact:.6g} s")
c.check("pair_bound_tight", got >= 0.7 * exact, f"guard {got:.6g} s < 0.7 x exact {exact:.6g} s")
print(f"(pair: guard {got:.6g} s, exact {exact:.6g} s, ratio {got / exact:.3f})")

# a sphere on a wall (exact Hertz wall stiffness 4/3 E/(1-nu^2) sqrt(R))
K_wall = secant_stiffness(MASS, 4.0 / 3.0 * E / (1 - NU * NU) * math.sqrt(R))
exact = exact_limit(1, [(0, None, (0, 0, -1))], K_wall)
floor = [{"name": "floor", "type": "plane", "material": "wall",
          "corners": [[-1, -1, -0.0101], [1, -1, -0.0101], [1, 1, -0.0101], [-1, 1, -0.0101]]}]
got = guard_limit([(0, 0, 0)], floor, 1)
c.check("wall_bound_safe", got <= exact, f"guard {got:.6g} s > exact {exact:.6g} s")
c.check("wall_bound_tight", got >= 0.7 * exact, f"guard {got:.6g} s < 0.7 x exact {exact:.6g} s")
print(f"(wall: guard {got:.6g} s, exact {exact:.6g} s, ratio {got / exact:.3f})")

# a close-packed cluster: a centre sphere with its 12 neighbours (cuboctahedron), every touching
# pair in contact (12 centre-shell and 24 shell-shell contacts)
shell = [np.array(v, float) for v in
         [(1, 1, 0), (1, -1, 0), (-1, 1, 0), (-1, -1, 0), (1, 0, 1), (1, 0, -1), (-1, 0, 1),
          (-1, 0, -1), (0, 1, 1), (0, 1, -1), (0, -1, 1), (0, -1, -1)]]
pos = [np.zeros(3)] + [v / np.linalg.norm(v) * 2 * R for v in shell]
contacts = [(i, j, pos[j] - pos[i]) for i in range(13) for j in range(i + 1, 13)
            if np.linalg.norm(pos[j] - pos[i]) < 2 * R * 1.001]
c.check("cluster_contacts", len(contacts) == 36, f"{len(contacts)} contacts")
exact = exact_limit(13, contacts, K_pair)
got = guard_limit([tuple(p) for p in pos], [], 12)
c.check("cluster_bound_safe", got <= exact, f"guard {got:.6g} s > exact {exact:.6g} s")
c.check("cluster_bound_tight", got >= 0.45 * exact, f"guard {got:.6g} s < 0.45 x exact {exact:.6g} s")
print(f"(cluster: guard {got:.6g} s, exact {exact:.6g} s, ratio {got / exact:.3f})")

# Mindlin: the stiffer tangential spring (K_t/K = 3(1-nu)/(2-nu) = 1.33 here) must be bounded
g_sphere = 1.0 / (2.0 * (2.0 - NU) * (1.0 + NU) / E)  # G* against a rigid body
for name, n, contacts, parts, walls, C, K, Kt in [
        ("pair", 2, [(0, 1, (1, 0, 0))], [(-0.0101, 0, 0), (0.0101, 0, 0)], [], 1, K_pair,
         mindlin_stiffness(MASS / 2, k_p, g_sphere / 2, R / 2)),
        ("wall", 1, [(0, None, (0, 0, -1))], [(0, 0, 0)], floor, 1, K_wall,
         mindlin_stiffness(MASS, 4.0 / 3.0 * E / (1 - NU * NU) * math.sqrt(R), g_sphere, R)),
        ("cluster", 13, contacts, [tuple(p) for p in pos], [], 12, K_pair,
         mindlin_stiffness(MASS / 2, k_p, g_sphere / 2, R / 2))]:
    exact = exact_limit(n, contacts, K, Kt)
    got = guard_limit(parts, walls, C, "mindlin")
    tight = 0.45 if name == "cluster" else 0.7
    c.check(f"mindlin_{name}_bound_safe", got <= exact, f"guard {got:.6g} s > exact {exact:.6g} s")
    c.check(f"mindlin_{name}_bound_tight", got >= tight * exact,
            f"guard {got:.6g} s < {tight} x exact {exact:.6g} s")
    print(f"(mindlin {name}: K_t/K = {Kt / K:.4f}, guard {got:.6g} s, exact {exact:.6g} s, "
          f"ratio {got / exact:.3f})")
c.exit()
