#!/usr/bin/python3
"""test_mesh_motion.py — moving mesh walls and conveyor surfaces (walls of type mesh with
`velocity`, `rotation` or `surface_velocity`, docs/scenes.md "Mesh walls") in build/jdem against
closed forms, and against build/liggghts-jdem running the generated deck (fix move/mesh linear
and rotate, fix mesh/surface surface_vel) bit for bit.

    tests/mesh/test_mesh_motion.py

Builds nothing (make build/jdem build/liggghts-jdem first).  The cases, each with spheres that
never touch each other (sphere-sphere contacts are not bitwise across the engines,
docs/model.md section 11) and none touching a moving mesh at time 0 (LIGGGHTS' set-up sees a
moving mesh at rest, kernel/jdem_mesh_motion.h):

- drum: four spheres in a closed meshed drum turning about an axis through its off-origin
  centre (axis given with length 2, negative period): jdem == liggghts-jdem on 1 and 2 MPI
  ranks and jdem on 2 threads, bit for bit; the spheres are dragged the way the wall turns;
  the drawn mesh at the last frame is the STL turned by omega T (Rodrigues) to 1e-9 m in both
  engines; the energy balance closes to 1e-3 with the wall's work booked;
- piston: a meshed plate moving up at U under a sphere that falls onto it: the sphere ends up
  riding at U (to 1e-6 of U), the plate drawn at U T; bit for bit across the engines;
- strike: no gravity, a plate moving at 0.5 m/s towards a sphere at rest 10 mm away (nothing
  but the mesh moves, so only the mesh's own displacement can refresh its candidates): the
  sphere is struck and leaves at V + the speed at which a sphere arriving at V rebounds from
  the plate at rest (Galilean invariance), to 1e-9; bit for bit;
- belt: a sphere at rest on a still conveyor whose surface moves at U: it ends rolling without
  slipping at U / (1 + 5/2 (1 - delta/R)^2), 2 U / 7 to first order in its static overlap delta
  (its angular momentum about the contact line stays zero), to 1e-9; bit for bit.
One PASS/FAIL line per check.
"""
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from scripts import engines
from tests.engine.engine_common import Checks, energy_total
from tests.mesh.stl_files import f32, write_binary_stl
from tests.mesh.test_mesh_engines import floor_grid, particle, run_jdem, same_bits, states

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PY = sys.executable

HEAD = """jdem_scene: 1
name: {name}
time: {{dt: 1.0e-5, steps: {steps}}}
output: {{every: 500}}
gravity: {gravity}
materials:
  glass: {{youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500, restitution: {e}, friction: 0.3}}
  plate: {{restitution: {e}, friction: 0.3}}
particles:
{particles}
walls:
  - {{name: cad, type: mesh, file: mesh.stl, material: plate, {motion}}}
"""

CENTRE = (0.01, 0.0, 0.02)


def drum(n, R, L, c):
    """A closed drum of n segments, radius R, length L along y, centred at c (float32 corners)."""
    ring = lambda y: [(f32(c[0] + R * math.cos(2 * math.pi * k / n)), f32(c[1] + y),
                       f32(c[2] + R * math.sin(2 * math.pi * k / n))) for k in range(n)]
    a, b = ring(-0.5 * L), ring(0.5 * L)
    ca, cb = (f32(c[0]), f32(c[1] - 0.5 * L), f32(c[2])), (f32(c[0]), f32(c[1] + 0.5 * L), f32(c[2]))
    tris = []
    for k in range(n):
        m = (k + 1) % n
        tris += [(a[k], a[m], b[m]), (a[k], b[m], b[k]), (ca, a[m], a[k]), (cb, b[k], b[m])]
    return tris


def write_case(tmp, name, tris, particles, motion, steps, gravity="[0, 0, -9.81]", e=0.5):
    d = os.path.join(tmp, name)
    os.makedirs(d, exist_ok=True)
    write_binary_stl(os.path.join(d, "mesh.stl"), tris)
    path = os.path.join(d, "scene.yaml")
    with open(path, "w") as f:
        f.write(HEAD.format(name=name, steps=steps, gravity=gravity, e=e, particles="\n".join(particles),
                            motion=motion))
    return path


def run_liggghts(scene, out, ranks=1):
    r = subprocess.run([PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), scene, "-o", out,
                        "--np", str(ranks)], capture_output=True, text=True)
    return r.returncode, (r.stdout + r.stderr)[-1500:]


def cross_engine(c, scene, what, ranks=(1,), threads=False):
    """jdem, then liggghts-jdem on each rank count (and jdem on 2 threads): the same bits."""
    d = os.path.dirname(scene)
    name = os.path.basename(d)
    jd = os.path.join(d, "jdem.h5")
    rc, err = run_jdem(scene, jd)
    if not c.check("%s: jdem runs" % name, rc == 0, err):
        return None
    for n in ranks:
        lg = os.path.join(d, "liggghts_np%d.h5" % n)
        rc, err = run_liggghts(scene, lg, n)
        if c.check("%s: liggghts-jdem runs the generated deck on %d rank(s)" % (name, n), rc == 0, err):
            same_bits(c, "%s: jdem == liggghts-jdem on %d rank(s), bit for bit (%s)" % (name, n, what), jd, lg)
    if threads:
        j2 = os.path.join(d, "jdem_2threads.h5")
        rc, err = run_jdem(scene, j2, "--threads", "2")
        if c.check("%s: jdem runs on 2 threads" % name, rc == 0, err):
            same_bits(c, "%s: jdem 1 thread == 2 threads bit for bit" % name, jd, j2)
    return jd


def drawn_last(path):
    """The mesh's triangles [T][3][3] as /jdem/walls/mesh draws them at the last frame."""
    with h5py.File(path, "r") as f:
        quads = f["jdem/walls/mesh/quads"][()]
        vert = f["jdem/walls/mesh/vertex_position"][-1]
    return vert[quads[:, :3]]


def rodrigues(p, o, a, angle):
    r = p - o
    return o + r * math.cos(angle) + np.cross(a, r) * math.sin(angle) + np.outer(r @ a, a) * (1 - math.cos(angle))


def never_touch(c, name, path, R):
    x = states(path)["position"]
    n = x.shape[1]
    gap = min(np.linalg.norm(x[:, i] - x[:, j], axis=1).min() for i in range(n) for j in range(i))
    c.check("%s: the spheres never touch each other (closest centres %.4g m > 2 R)" % (name, gap), gap > 2 * R)


def check_drum(c, tmp):
    R, steps, period = 0.004, 40000, -0.8
    tris = drum(32, 0.05, 0.06, CENTRE)
    # below the axis, dropped from different heights (they land at different times)
    spheres = [particle((CENTRE[0], CENTRE[1] + y, CENTRE[2] - z), r=R)
               for y, z in ((-0.021, 0.03), (-0.007, 0.025), (0.007, 0.02), (0.021, 0.035))]
    motion = "rotation: {origin: [%r, %r, %r], axis: [0, 2, 0], period: %r}" % (*CENTRE, period)
    scene = write_case(tmp, "drum", tris, spheres, motion, steps)
    jd = cross_engine(c, scene, "four spheres in a turning drum", ranks=(1, 2), threads=True)
    if not jd:
        return
    never_touch(c, "drum", jd, R)
    # omega along -y: at the bottom the wall moves along +x, and drags each sphere that way
    # from where it landed, below the axis (gravity alone would keep it there)
    dx = states(jd)["position"][:, :, 0] - CENTRE[0]
    first = [d[np.argmax(np.abs(d) > 0.002)] for d in dx.T]
    c.check("drum: each sphere is first dragged the way the wall turns (+x at the bottom): its "
            "first excursion beyond 2 mm from below the axis is at %s mm" % np.round(np.array(first) * 1e3, 2),
            all(f > 0.002 for f in first))
    T = steps * 1.0e-5
    want = np.array([rodrigues(np.array(t, float), np.array(CENTRE), np.array([0.0, 1.0, 0.0]),
                               2 * math.pi / period * T) for t in tris])
    for engine, path in (("jdem", jd), ("liggghts-jdem", os.path.join(os.path.dirname(jd), "liggghts_np1.h5"))):
        try:
            got = drawn_last(path)
        except (OSError, KeyError) as exc:
            c.check("drum: %s draws the turning mesh" % engine, False, str(exc))
            continue
        err = np.abs(got - want).max() if got.shape == want.shape else math.inf
        c.check("drum: %s draws the mesh at the last frame turned by omega T about the axis "
                "(Rodrigues), max error %.3g m <= 1e-9" % (engine, err), err <= 1e-9)
    with h5py.File(jd, "r") as f:
        obs = {k: f["observables"][k]["value"][()] for k in f["observables"] if "value" in f["observables"][k]}
    total = energy_total(obs)
    drift = np.abs(total - total[0]).max() / abs(total[0])
    c.check("drum: energy balance with the turning wall's work booked, max |E - E0| / E0 = %.3g "
            "<= 1e-3 (wall work %.3g J)" % (drift, obs["wall_work"][-1]),
            drift <= 1e-3 and abs(obs["wall_work"][-1]) > 1e-2 * abs(total[0]))


def check_piston(c, tmp):
    U, R, steps = 0.02, 0.005, 30000
    scene = write_case(tmp, "piston", floor_grid(4, 2.0 ** -6), [particle((0.003, 0.002, R + 3e-4), r=R)],
                       "velocity: [0, 0, %r]" % U, steps)
    jd = cross_engine(c, scene, "a sphere riding a rising plate", ranks=(1, 2))
    if not jd:
        return
    vz = states(jd)["velocity"][-1, 0, 2]
    c.check("piston: the sphere ends riding the plate at U = %g m/s: v_z = %.9g (error %.2g of U "
            "<= 1e-6)" % (U, vz, abs(vz - U) / U), abs(vz - U) <= 1e-6 * U)
    z = drawn_last(jd)[..., 2]
    c.check("piston: the plate is drawn at U T = %.6g m at the last frame (max error %.2g m <= "
            "1e-12)" % (U * steps * 1e-5, np.abs(z - U * steps * 1e-5).max()),
            np.abs(z - U * steps * 1e-5).max() <= 1e-12)


def check_strike(c, tmp):
    V, R = 0.5, 0.005
    floor = floor_grid(4, 2.0 ** -6)
    scene = write_case(tmp, "strike", floor, [particle((0.003, 0.002, R + 0.01), r=R)],
                       "velocity: [0, 0, %r]" % V, 4000, gravity="[0, 0, 0]")
    jd = cross_engine(c, scene, "a plate striking a sphere at rest")
    # Galilean invariance: the same impact seen from the plate, a sphere at -V onto the plate
    # at rest, rebounds at v_r; the struck sphere must leave at V + v_r
    still = write_case(tmp, "strike_still", floor, [particle((0.003, 0.002, R + 0.01), (0.0, 0.0, -V), r=R)],
                       "velocity: [0, 0, 0]", 4000, gravity="[0, 0, 0]")
    ref = os.path.join(os.path.dirname(still), "jdem.h5")
    rc, err = run_jdem(still, ref)
    if not jd or not c.check("strike: jdem runs the impact on the plate at rest", rc == 0, err):
        return
    vz, vr = states(jd)["velocity"][-1, 0, 2], states(ref)["velocity"][-1, 0, 2]
    c.check("strike: the moving plate strikes the resting sphere, which leaves at %.9g m/s = V + "
            "the rebound speed from the plate at rest (%.9g m/s), to 1e-9" % (vz, V + vr),
            vr > 0.1 * V and abs(vz - (V + vr)) <= 1e-9 * (V + vr))


def check_belt(c, tmp):
    U, R, steps, E, NU, RHO, g = 0.1, 0.005, 30000, 1.0e7, 0.3, 2500.0, 9.81
    # at rest on the belt with the static overlap (test_mesh_engines.check_rest), so that it
    # never leaves it: the normal force stays m g and the angular momentum about the contact
    # line stays zero, I omega = -m (R - delta) v, until the contact point moves with the belt,
    # v - omega (R - delta) = U: v = U / (1 + 5/2 (1 - delta/R)^2), 2 U / 7 to first order
    m = 4.0 / 3.0 * math.pi * R ** 3 * RHO
    delta = (m * g / (4.0 / 3.0 * E / (1.0 - NU * NU) * math.sqrt(R))) ** (2.0 / 3.0)
    scene = write_case(tmp, "belt", floor_grid(8, 2.0 ** -5), [particle((0.003, 0.002, R - delta), r=R)],
                       "surface_velocity: [%r, 0, 0]" % U, steps)
    jd = cross_engine(c, scene, "a sphere dropped onto a conveyor", ranks=(1, 2))
    if not jd:
        return
    s = states(jd)
    vx, wy = s["velocity"][-1, 0, 0], s["angular_velocity"][-1, 0, 1]
    want = U / (1.0 + 2.5 * (1.0 - delta / R) ** 2)
    c.check("belt: the sphere ends rolling without slipping at U / (1 + 5/2 (1 - delta/R)^2) = "
            "%.9g m/s (2 U / 7 = %.6g): v_x = %.9g (error %.2g <= 1e-9)" % (want, 2 * U / 7, vx, abs(vx - want) / want),
            abs(vx - want) <= 1e-9 * want)
    c.check("belt: its contact point moves with the belt, v_x - omega_y (R - delta) = %.9g = U to "
            "1e-9" % (vx - wy * (R - delta)), abs(vx - wy * (R - delta) - U) <= 1e-9 * U)


def main():
    c = Checks()
    if not c.built(engines.JDEM, engines.LIGGGHTS_JDEM):
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        check_drum(c, tmp)
        check_piston(c, tmp)
        check_strike(c, tmp)
        check_belt(c, tmp)
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
