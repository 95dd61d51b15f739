#!/usr/bin/python3
"""test_drum.py — a rotating drum built from primitives (a cylinder wall with `angular_velocity`,
docs/scenes.md "Walls") against a closed form and against the same drum as a turning STL mesh.

    tests/mesh/test_drum.py

Builds nothing (make build/jdem build/liggghts-jdem first).  The drum: radius 50 mm, 30 mm
long along y, closed by two still plane walls; gravity along -z.

- one sphere in the spinning cylinder is carried up the side the wall moves to and rocks, as a
  rolling pendulum, about the angle where its rolling resistance holds it: the tangential force
  m g sin(theta) acts at the arm r = R - delta and balances the capped rolling moment
  eta R m g cos(theta), so tan(theta0) = eta R / r (delta: Hertz's overlap under m g cos(theta));
  the cap dissipates nothing, so the rocking keeps its amplitude, and its angular frequency is
  w^2 = g (cos(theta0) + eta (R/r) sin(theta0)) / (Lc (1 + 2/5 R^2/r^2)) (Lc = RC - R + delta:
  the centre's circle; the cap's cos(theta) stiffens the pendulum).  A least-squares fit
  theta0 + a cos(w t) + b sin(w t) gives theta0 to 1e-6 and w to 5e-4 (the tangential spring's
  compliance, m w^2 / k_t ~ 1e-4, is left out of the closed form);
  jdem == liggghts-jdem (fix wall/jiang cylinder ... omega W) bit for bit, on 1 and 2 ranks;
  the energy balance closes to 1e-3 with the spinning wall's work booked;
- the same drum as 128 still mesh facets whose surface spins (surface_angular_velocity, LIGGGHTS'
  surface_ang_vel): three spheres dropped onto it, apart, for 0.3 s, jdem == liggghts-jdem on 1
  and 2 ranks, bit for bit to step 7600 and within 1e-10 after;
- a bed of 80 spheres in the primitive drum, in a drum of 128 turning mesh facets and in the still
  spinning-surface mesh drum (the same end planes; the mesh's side only): the bed's mean angle of
  repose over the last second (the angle of its centre of mass from the bottom, about the axis)
  agrees within 3 standard errors of the primitive drum's two realisations (the bed started 1 um
  apart) and its own.
One PASS/FAIL line per check.
"""
import math
import os
import sys
import tempfile

import h5py
import numpy as np

from scripts import engines
from tests.engine.engine_common import Checks, energy_total
from tests.mesh.stl_files import f32, write_binary_stl
from tests.mesh.test_mesh_engines import particle, run_jdem, same_bits, states
from tests.mesh.test_mesh_motion import run_liggghts

RC, L, OMEGA = 0.05, 0.03, 2.0          # drum radius [m], length [m], spin [rad/s]
E, NU, RHO, ETA, MU, G = 1.0e7, 0.3, 2500.0, 0.1, 0.5, 9.81

HEAD = """jdem_scene: 1
name: {name}
time: {{dt: 1.0e-5, steps: {steps}}}
output: {{every: {every}}}
gravity: [0, 0, -9.81]
materials:
  glass: {{youngs_modulus: {E}, poisson_ratio: {NU}, density: {RHO}, restitution: 0.5, friction: {MU},
          rolling_friction: {ETA}}}
  steel: {{restitution: 0.5, friction: {MU}, rolling_friction: {ETA}}}
particles:
{particles}
walls:
  - {{name: front, type: plane, material: steel, corners: [[-0.06, {y0}, -0.06], [-0.06, {y0}, 0.06], [0.06, {y0}, 0.06], [0.06, {y0}, -0.06]]}}
  - {{name: back, type: plane, material: steel, corners: [[-0.06, {y1}, -0.06], [0.06, {y1}, -0.06], [0.06, {y1}, 0.06], [-0.06, {y1}, 0.06]]}}
{drum}
"""
PRIMITIVE = ("  - {name: drum, type: cylinder, axis: [[0, %r, 0], [0, %r, 0]], radius: %r, side: inside, "
             "material: steel, angular_velocity: %r}" % (-L, L, RC, OMEGA))
MESHED = ("  - {name: drum, type: mesh, file: drum.stl, material: steel, "
          "rotation: {origin: [0, 0, 0], axis: [0, 1, 0], period: %r}}" % (2 * math.pi / OMEGA))
SPUN = ("  - {name: drum, type: mesh, file: drum.stl, material: steel, "
        "surface_angular_velocity: {origin: [0, 0, 0], axis: [0, 1, 0], omega: %r}}" % OMEGA)


def write_scene(tmp, name, particles, drum, steps, every, tris=None):
    d = os.path.join(tmp, name)
    os.makedirs(d, exist_ok=True)
    if tris is not None:
        write_binary_stl(os.path.join(d, "drum.stl"), tris)
    path = os.path.join(d, "scene.yaml")
    with open(path, "w") as f:
        f.write(HEAD.format(name=name, steps=steps, every=every, E=E, NU=NU, RHO=RHO, ETA=ETA, MU=MU,
                            particles="\n".join(particles), y0=-0.5 * L, y1=0.5 * L, drum=drum))
    return path


def drum_side(n, radius, length):
    """The drum's side as n facets (2 triangles each) between y = -length/2 and +length/2,
    corners on radius (float32); wound so that the inside faces the axis."""
    ring = lambda y: [(f32(radius * math.cos(2 * math.pi * k / n)), f32(y),
                       f32(radius * math.sin(2 * math.pi * k / n))) for k in range(n)]
    a, b = ring(-0.5 * length), ring(0.5 * length)
    tris = []
    for k in range(n):
        m = (k + 1) % n
        tris += [(a[k], b[m], a[m]), (a[k], b[k], b[m])]
    return tris


def hertz_overlap(R, force):
    return (force / (4.0 / 3.0 * E / (1.0 - NU * NU) * math.sqrt(R))) ** (2.0 / 3.0)


def carried_angle(x, z):
    """The angle from the bottom about the axis, positive towards -x (where the bottom of a drum
    spinning at OMEGA > 0 about +y moves: OMEGA y x (0, 0, -RC) = (-OMEGA RC, 0, 0))."""
    return np.arctan2(-x, -z)


def rocking_fit(t, theta, w0):
    """theta0, w of the least-squares fit theta0 + a cos(w t) + b sin(w t), w searched on a grid
    of 1e-5 w0 within 1 % of w0."""
    def fit(w):
        a = np.c_[np.ones_like(t), np.cos(w * t), np.sin(w * t)]
        coef = np.linalg.lstsq(a, theta, rcond=None)[0]
        return coef, float(((a @ coef - theta) ** 2).sum())
    ws = w0 * np.linspace(0.99, 1.01, 2001)
    best = ws[int(np.argmin([fit(w)[1] for w in ws]))]
    return float(fit(best)[0][0]), float(best)


def check_closed_form(c, tmp):
    R = 0.004
    m = 4.0 / 3.0 * math.pi * R ** 3 * RHO
    want = math.atan(ETA)
    for _ in range(20):
        delta = hertz_overlap(R, m * G * math.cos(want))
        want = math.atan(ETA * R / (R - delta))
    r = R - delta
    w_want = math.sqrt(G * (math.cos(want) + ETA * R / r * math.sin(want))
                       / ((RC - R + delta) * (1.0 + 0.4 * R * R / (r * r))))
    # set 0.1 um off the wall at the rest angle, spinning so that its contact point goes with
    # the wall: the tangential spring starts at zero, so the sphere rocks about the rest angle
    d = RC - R - 1e-7
    sphere = "  - {material: glass, radius: %r, position: [%r, 0, %r], angular_velocity: [0, %r, 0]}" % (
        R, -d * math.sin(want), -d * math.cos(want), OMEGA * RC / R)
    dt, every = 1.0e-5, 100
    scene = write_scene(tmp, "one_sphere", [sphere], PRIMITIVE, 150000, every)
    jd = os.path.join(os.path.dirname(scene), "jdem.h5")
    rc, err = run_jdem(scene, jd)
    if not c.check("one sphere: jdem runs the spinning cylinder", rc == 0, err):
        return
    for n in (1, 2):
        lg = os.path.join(os.path.dirname(scene), "liggghts_np%d.h5" % n)
        rc, err = run_liggghts(scene, lg, n)
        if c.check("one sphere: liggghts-jdem runs the generated deck (omega) on %d rank(s)" % n, rc == 0, err):
            same_bits(c, "one sphere: jdem == liggghts-jdem on %d rank(s), bit for bit" % n, jd, lg)
    x = states(jd)["position"][:, 0]
    theta = carried_angle(x[:, 0], x[:, 2])
    got, w_got = rocking_fit(np.arange(len(theta)) * dt * every, theta, w_want)
    c.check("one sphere: carried up the side the wall moves to, it rocks about tan(theta0) = eta R / "
            "(R - delta): theta0 = %.9g rad against %.9g (error %.2g <= 1e-6; rocking amplitude "
            "%.2g rad)" % (got, want, abs(got - want) / want, 0.5 * np.ptp(theta[len(theta) // 2:])),
            abs(got - want) <= 1e-6 * want)
    c.check("one sphere: the rocking's angular frequency %.6g rad/s = the rolling pendulum's %.6g "
            "(error %.2g <= 5e-4)" % (w_got, w_want, abs(w_got - w_want) / w_want),
            abs(w_got - w_want) <= 5e-4 * w_want)
    with h5py.File(jd, "r") as f:
        obs = {k: f["observables"][k]["value"][()] for k in f["observables"] if "value" in f["observables"][k]}
    total = energy_total(obs)
    drift = np.abs(total - total[0]).max() / abs(total[0])
    c.check("one sphere: energy balance with the spinning wall's work booked, max |E - E0| / |E0| = "
            "%.3g <= 1e-3 (wall work %.3g J)" % (drift, obs["wall_work"][-1]),
            drift <= 1e-3 and abs(obs["wall_work"][-1]) > 0.0)


def bed(shift):
    """80 spheres of radius 3.5-4.5 mm on a loose lattice in the lower half of the drum."""
    rng = np.random.default_rng(7)
    out = []
    for i in range(8):
        for j in range(2):
            for k in range(5):
                x, z = -0.035 + 0.01 * i, -0.042 + 0.0095 * k
                if x * x + z * z < (RC - 0.006) ** 2:
                    r = float(rng.uniform(0.0035, 0.0045))
                    out.append(particle((x + shift, -0.0075 + 0.015 * j, z), r=min(r, 0.0047)))
    return out


def bed_angle(path, t_from):
    """The mean and the block-averaged standard error over t >= t_from of the angle of the bed's
    centre of mass about the axis."""
    with h5py.File(path, "r") as f:
        t = f["particles/all/position/time"][()]
    x = states(path)["position"]
    keep = t >= t_from
    cm = x[keep].mean(axis=1)
    a = carried_angle(cm[:, 0], cm[:, 2])
    blocks = np.array_split(a, 5)
    means = np.array([b.mean() for b in blocks])
    return float(a.mean()), float(means.std(ddof=1) / math.sqrt(len(means)))


def check_meshed_vs_primitive(c, tmp):
    steps, every, t_from = 200000, 500, 1.0
    runs = {}
    for name, drum, shift, tris in (("primitive", PRIMITIVE, 0.0, None),
                                    ("primitive_shifted", PRIMITIVE, 1e-6, None),
                                    ("meshed", MESHED, 0.0, drum_side(128, RC, L)),
                                    ("spun", SPUN, 0.0, drum_side(128, RC, L))):
        scene = write_scene(tmp, "bed_" + name, bed(shift), drum, steps, every, tris)
        out = os.path.join(os.path.dirname(scene), "jdem.h5")
        rc, err = run_jdem(scene, out)
        if not c.check("bed: jdem runs the %s drum" % name, rc == 0, err):
            return
        runs[name] = bed_angle(out, t_from)
    (a, sa), (b, sb) = runs["primitive"], runs["primitive_shifted"]
    p, sp = 0.5 * (a + b), 0.5 * math.hypot(sa, sb)
    # the facets' centres lie RC (1 - cos(pi/128)) = 15 um inside the circle: far below the noise
    for name, what in (("meshed", "turning mesh drum"), ("spun", "still mesh drum with a spinning surface")):
        m, sm = runs[name]
        tol = 3.0 * math.hypot(sm, sp)
        c.check("bed: the %s's mean angle of repose %.2f deg (+- %.2f) = the primitive drum's "
                "%.2f deg (+- %.2f; realisations %.2f and %.2f) within 3 standard errors (%.2f deg)"
                % ((what,) + tuple(math.degrees(v) for v in (m, sm, p, sp, a, b, tol))), abs(m - p) <= tol)
    c.check("bed: the drum carries the bed up the side its bottom moves to (angle %.1f deg > 10 deg)"
            % math.degrees(p), p > math.radians(10.0))


def check_spun_mesh_cross_engine(c, tmp):
    """The still 128-facet drum with a spinning surface (fix mesh/surface surface_ang_vel): three
    spheres dropped onto its side, 14 mm apart, carried up and rolling across the facets for
    0.3 s, in jdem and liggghts-jdem on 1 and 2 ranks: bit for bit until step 7694, where a
    sphere crossing the diagonal edge between a facet's two triangles gets forces 1e-17 N apart
    (the turning mesh drum does the same at the same step; docs/model.md §11), so the states are
    compared within the cross-engine tolerance 1e-10 (scaled by R, the drum's speed and its
    speed over R), and bit for bit up to step 7600."""
    R = 0.004
    spheres = ["  - {material: glass, radius: %r, position: [%r, 0, %r]}"
               % (R, -(RC - R - 0.002) * math.sin(a), -(RC - R - 0.002) * math.cos(a)) for a in (-0.3, 0.0, 0.3)]
    scene = write_scene(tmp, "spun_cross", spheres, SPUN, 30000, 100, drum_side(128, RC, L))
    jd = os.path.join(os.path.dirname(scene), "jdem.h5")
    rc, err = run_jdem(scene, jd)
    if not c.check("spun mesh: jdem runs the surface_angular_velocity drum", rc == 0, err):
        return
    speed = OMEGA * RC
    scales = {"position": R, "velocity": speed, "angular_velocity": speed / R}
    for n in (1, 2):
        lg = os.path.join(os.path.dirname(scene), "liggghts_np%d.h5" % n)
        rc, err = run_liggghts(scene, lg, n)
        if not c.check("spun mesh: liggghts-jdem runs the generated deck (surface_ang_vel) on %d rank(s)" % n,
                       rc == 0, err):
            continue
        a, b = states(jd), states(lg)
        early = all(np.array_equal(a[k][:77], b[k][:77]) for k in scales)
        worst = max(float(np.abs(a[k] - b[k]).max()) / s for k, s in scales.items())
        c.check("spun mesh: jdem == liggghts-jdem on %d rank(s): bit for bit to step 7600, within "
                "1e-10 scaled to 0.3 s (largest %.2g)" % (n, worst), early and worst <= 1e-10)


def main():
    c = Checks()
    if not c.built(engines.JDEM, engines.LIGGGHTS_JDEM):
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        check_closed_form(c, tmp)
        check_spun_mesh_cross_engine(c, tmp)
        check_meshed_vs_primitive(c, tmp)
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
