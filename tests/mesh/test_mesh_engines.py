#!/usr/bin/python3
"""test_mesh_engines.py — STL mesh walls (walls of type mesh) in build/jdem, against closed forms,
against our plane primitive, against build/liggghts-jdem and across thread counts.

    tests/mesh/test_mesh_engines.py

Builds nothing (make build/jdem build/liggghts-jdem first).  The STL files are written here from
closed-form vertices whose coordinates are float32 values (admesh stores float32; LIGGGHTS reads
binary STL as float32 too), so both engines see the same triangles:

- flat square (two triangles) against the plane primitive over the same square, in jdem: a
  sphere dropped onto it slides across the diagonal edge: the same bits (positions, velocities,
  angular velocities at every frame);
- a frictionless sphere at rest on a face: Hertz's overlap (m g / k_n)^(2/3), k_n = (4/3)
  E / (1 - nu^2) sqrt(R) (the default wall rule), to 1e-9 of the overlap as the servo wall's rest
  test (tests/engine/test_servo.py);
- jdem against liggghts-jdem (scripts/liggghts_run.py: the deck from scene_to_liggghts.py), bit for bit: a sphere
  sliding across the edges of a triangulated floor, a sphere rolling over the apex of a shallow
  pyramid (a vertex contact), a few spheres dropped into a meshed funnel;
- jdem on 1 and 2 threads on the funnel: the same bits; its energy balance closes to 1e-3 (the
  plane walls' standard, tests/engine/test_energy_balance.py) with the mesh's dissipation;
- the candidates from the triangle grid give the same bits as every triangle taken as a
  candidate (JDEM_NEIGHBOUR=allpairs), for the funnel and for spheres sliding across a wide floor;
- the watchdog's overlap trip names the mesh wall (checkpoints with mesh walls:
  tests/checkpoint/test_checkpoint.py);
- the funnel's trajectories draw the mesh (/jdem/walls, docs/output.md): type 2, one
  quadrilateral per triangle whose corners are the STL's triangle (the last one twice), in both
  engines, equal to the triangles this script wrote.
One PASS/FAIL line per check.
"""
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
from scripts import engines
from tests.engine.engine_common import Checks, energy_total
from tests.mesh.stl_files import f32, write_ascii_stl_float32, write_binary_stl

JDEM = engines.JDEM
LIG = engines.LIGGGHTS_JDEM
PY = sys.executable

HEAD = """jdem_scene: 1
name: {name}
time: {{dt: 1.0e-5, steps: {steps}}}
output: {{every: 50}}
gravity: [0, 0, -9.81]
materials:
  glass: {{youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500, restitution: {e}, friction: {mu}}}
  plate: {{restitution: {e}, friction: {mu}}}
particles:
{particles}
walls:
{walls}
"""


def square(h):
    a, b, c, d = (-h, -h, 0.0), (h, -h, 0.0), (h, h, 0.0), (-h, h, 0.0)
    return [(a, b, c), (a, c, d)]


def floor_grid(n, h):
    """n x n squares of side h around the origin in z = 0, diagonals alternating."""
    x0 = -0.5 * n * h
    tris = []
    for i in range(n):
        for j in range(n):
            a = (x0 + i * h, x0 + j * h, 0.0)
            b = (x0 + (i + 1) * h, x0 + j * h, 0.0)
            c = (x0 + (i + 1) * h, x0 + (j + 1) * h, 0.0)
            d = (x0 + i * h, x0 + (j + 1) * h, 0.0)
            tris += [(a, b, c), (a, c, d)] if (i + j) % 2 == 0 else [(a, b, d), (b, c, d)]
    return tris


def pyramid(a, h):
    """Four triangles from the square of half-side a in z = 0 up to the apex (0, 0, h)."""
    top = (0.0, 0.0, h)
    c = [(-a, -a, 0.0), (a, -a, 0.0), (a, a, 0.0), (-a, a, 0.0)]
    return [(c[k], c[(k + 1) % 4], top) for k in range(4)]


def funnel(n, r0, r1, z1):
    """A cone from radius r0 at z = 0 to r1 at z1 (n segments) closed by a flat fan at z = 0;
    every corner rounded to float32 once, so shared corners are the same numbers."""
    ring = lambda r, z: [(f32(r * math.cos(2 * math.pi * k / n)), f32(r * math.sin(2 * math.pi * k / n)),
                          f32(z)) for k in range(n)]
    lo, hi = ring(r0, 0.0), ring(r1, z1)
    tris = []
    for k in range(n):
        m = (k + 1) % n
        tris += [(lo[k], lo[m], hi[m]), (lo[k], hi[m], hi[k]), ((0.0, 0.0, 0.0), lo[m], lo[k])]
    return tris


def particle(x, v=(0.0, 0.0, 0.0), r=0.005):
    return "  - {material: glass, radius: %r, position: [%r, %r, %r], velocity: [%r, %r, %r]}" % (
        r, *x, *v)


def write_case(tmp, name, particles, walls, tris=None, steps=3000, e=0.5, mu=0.3, ascii=False, extra=""):
    d = os.path.join(tmp, name)
    os.makedirs(d, exist_ok=True)
    if tris is not None:
        (write_ascii_stl_float32 if ascii else write_binary_stl)(os.path.join(d, "mesh.stl"), tris)
    path = os.path.join(d, "scene.yaml")
    with open(path, "w") as f:
        f.write(HEAD.format(name=name, steps=steps, e=e, mu=mu, particles="\n".join(particles),
                            walls="\n".join(walls)) + extra)
    return path


MESH_WALL = "  - {name: cad, type: mesh, file: mesh.stl, material: plate}"


def run_jdem(scene, out, *args, env=None):
    r = subprocess.run([JDEM, "run", scene, "-o", out, "--quiet", *args], capture_output=True, text=True,
                       env={**os.environ, **(env or {})})
    return r.returncode, r.stderr


ALL_TRIANGLES = {"JDEM_NEIGHBOUR": "allpairs"}   # every triangle a candidate of every particle


def check_cells_vs_all_triangles(c, tmp, funnel_scene):
    """The candidates from the triangle grid (stepper/mesh_cells.h) against every triangle as a
    candidate: the same bits, for the funnel and for 25 spheres sliding fast across a floor of
    2048 triangles (about 40 x 40 cells), apart from each other (the reference option also
    lists every particle pair unsorted, which changes the order of sphere-sphere sums)."""
    cases = [("funnel", funnel_scene)]
    spheres = [particle((-0.2 + 0.08 * i, -0.2 + 0.08 * j, 0.0051 + 0.0002 * (i + j)), (2.0, 1.2, 0.0))
               for i in range(5) for j in range(5)]
    cases.append(("wide floor", write_case(tmp, "wide_floor", spheres, [MESH_WALL], floor_grid(32, 2.0 ** -6),
                                           steps=3000)))
    for name, scene in cases:
        d = os.path.dirname(scene)
        cells, every = os.path.join(d, "cells.h5"), os.path.join(d, "all_triangles.h5")
        rc = [run_jdem(scene, cells), run_jdem(scene, every, env=ALL_TRIANGLES)]
        if c.check("%s: jdem runs with the grid's candidates and with every triangle" % name,
                   rc[0][0] == 0 and rc[1][0] == 0, rc[0][1] + rc[1][1]):
            same_bits(c, "%s: candidates from the triangle grid == every triangle a candidate, bit "
                      "for bit" % name, cells, every)


def run_liggghts(scene, out):
    """The scene in liggghts-jdem through scripts/liggghts_run.py (jdem resolve, the deck from
    scene_to_liggghts.py, the run; with the screen kept, as LIGGGHTS' STL reader needs)."""
    r = subprocess.run([PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), scene, "-o", out],
                       capture_output=True, text=True)
    return r.returncode, (r.stdout + r.stderr)[-1500:]


def states(path):
    with h5py.File(path, "r") as f:
        g = f["particles/all"]
        ids = g["id"][()]
        order = np.argsort(ids[0] if ids.ndim > 1 else ids)
        return {k: g[k]["value"][()][:, order] for k in ("position", "velocity", "angular_velocity")}


def same_bits(c, name, a_path, b_path):
    try:
        a, b = states(a_path), states(b_path)
    except (OSError, KeyError) as exc:
        return c.check(name, False, "cannot read a trajectory: %s" % exc)
    for k in a:
        if a[k].shape != b[k].shape:
            return c.check(name, False, "%s: shapes %s and %s" % (k, a[k].shape, b[k].shape))
        if not np.array_equal(a[k], b[k]):
            return c.check(name, False, "%s: max |diff| %.3g" % (k, np.abs(a[k] - b[k]).max()))
    return c.check(name, True)


def check_square_vs_plane(c, tmp):
    h = 2.0 ** -5
    p = [particle((-0.01, -0.008, 0.005001), (0.3, 0.2, 0.0))]
    plane = ("  - {name: cad, type: plane, material: plate, corners: [[%r,%r,0],[%r,%r,0],[%r,%r,0],[%r,%r,0]]}"
             % (-h, -h, h, -h, h, h, -h, h))
    # two triangles are 184 bytes in binary, fewer than admesh reads: ASCII
    mesh = write_case(tmp, "square_mesh", p, [MESH_WALL], square(h), ascii=True)
    prim = write_case(tmp, "square_plane", p, [plane])
    outs = [os.path.join(os.path.dirname(s), "jdem.h5") for s in (mesh, prim)]
    rc = [run_jdem(s, o) for s, o in zip((mesh, prim), outs)]
    if not c.check("flat square: both runs succeed", rc[0][0] == 0 and rc[1][0] == 0, str(rc)):
        return
    x = states(outs[0])["position"][:, 0]
    crossed = (x[0, 1] - x[0, 0]) * (x[-1, 1] - x[-1, 0]) < 0 and np.all(np.abs(x[10:, 2] - 0.005) < 1e-4)
    c.check("flat square: the sphere slides across the diagonal edge (y - x changes sign in contact)",
            crossed, "first %s, last %s" % (x[0], x[-1]))
    same_bits(c, "flat square mesh == plane primitive, bit for bit (x, v, omega at every frame)", *outs)


def check_rest(c, tmp):
    R, E, NU, RHO, g = 0.005, 1.0e7, 0.3, 2500.0, 9.81
    m = 4.0 / 3.0 * math.pi * R ** 3 * RHO
    kn = 4.0 / 3.0 * E / (1.0 - NU * NU) * math.sqrt(R)
    delta = (m * g / kn) ** (2.0 / 3.0)
    scene = write_case(tmp, "rest", [particle((0.003, 0.002, R - delta * 0.5))], [MESH_WALL],
                       floor_grid(4, 2.0 ** -6), steps=20000, e=0.1, mu=0.0)
    out = os.path.join(os.path.dirname(scene), "jdem.h5")
    rc, err = run_jdem(scene, out)
    if not c.check("rest on a face: the run succeeds", rc == 0, err):
        return
    z = states(out)["position"][-1, 0, 2]
    got = R - z
    c.check("rest on a face: overlap = Hertz (m g / k_n)^(2/3) to 1e-9 of it",
            abs(got - delta) <= 1e-9 * delta, "overlap %.12g m, closed form %.12g m" % (got, delta))


def check_funnel_path(c, jd, R):
    """What the funnel case is meant to exercise: the spheres reach the floor fan and its crease
    with the cone, and never touch each other (sphere-sphere contacts are not bitwise across
    the engines: docs/model.md section 11)."""
    x = states(jd)["position"]
    n = x.shape[1]
    gap = min(np.linalg.norm(x[:, i] - x[:, j], axis=1).min() for i in range(n) for j in range(i))
    c.check("funnel: the spheres never touch each other (closest centres %.4g m > 2 R)" % gap, gap > 2 * R)
    c.check("funnel: every sphere reaches the bottom (its centre within R of the floor)",
            np.all(x[:, :, 2].min(axis=0) < 2 * R), "lowest centres %s" % x[:, :, 2].min(axis=0))
    # the mesh contacts' energy accounts close the balance as the plane walls' do
    # (tests/engine/test_energy_balance.py: 1e-3 of the initial total)
    with h5py.File(jd, "r") as f:
        obs = {k: f["observables"][k]["value"][()] for k in f["observables"] if "value" in f["observables"][k]}
    total = energy_total(obs)
    drift = np.abs(total - total[0]).max() / abs(total[0])
    c.check("funnel: energy balance with mesh contacts, max |E - E0| / E0 = %.3g <= 1e-3" % drift,
            drift <= 1e-3)
    c.check("funnel: the mesh contacts dissipate (damping and friction > 1e-2 of E0)",
            min(obs["damping_dissipation"][-1], obs["friction_dissipation"][-1]) > 1e-2 * abs(total[0]),
            "damping %.3g J, friction %.3g J" % (obs["damping_dissipation"][-1], obs["friction_dissipation"][-1]))


def check_refusals(c, tmp):
    """The watchdog's overlap trip names the mesh wall (a sphere of radius R placed 0.2 R into the
    floor: the fraction is 0.2 at step 0)."""
    scene = write_case(tmp, "overlap", [particle((0.001, 0.001, 0.004))], [MESH_WALL],
                       floor_grid(4, 2.0 ** -6), steps=10,
                       extra="watchdog: {enabled: true, max_overlap_fraction: 0.1}\n")
    out = os.path.join(os.path.dirname(scene), "jdem.h5")
    rc, err = run_jdem(scene, out)
    want = "overlap fraction 0.2 for particle(s) 1 against wall 'cad' exceeds 0.1"
    c.check("watchdog: an overlap with a mesh wall trips naming the wall (%r)" % want,
            rc != 0 and want in err, "exit %d: %s" % (rc, err))


def cross_engine(c, tmp, name, particles, tris, steps, what, threads=False):
    scene = write_case(tmp, name, particles, [MESH_WALL], tris, steps=steps)
    d = os.path.dirname(scene)
    jd, lg = os.path.join(d, "jdem.h5"), os.path.join(d, "liggghts.h5")
    rc, err = run_jdem(scene, jd)
    if not c.check("%s: jdem runs" % name, rc == 0, err):
        return None
    rc, err = run_liggghts(scene, lg)
    if c.check("%s: liggghts-jdem runs the generated deck" % name, rc == 0, err):
        same_bits(c, "%s: jdem == liggghts-jdem bit for bit (%s)" % (name, what), jd, lg)
    if threads:
        j2 = os.path.join(d, "jdem_2threads.h5")
        rc, err = run_jdem(scene, j2, "--threads", "2")
        if c.check("%s: jdem runs on 2 threads" % name, rc == 0, err):
            same_bits(c, "%s: jdem 1 thread == 2 threads bit for bit" % name, jd, j2)
    return jd


def drawn_triangles(path):
    """(wall types, [T][3][3] the mesh's triangles as /jdem/walls/mesh draws them)."""
    with h5py.File(path, "r") as f:
        types = f["jdem/walls/type"][()]
        quads = f["jdem/walls/mesh/quads"][()]
        vert = f["jdem/walls/mesh/vertices"][()]
        wall = f["jdem/walls/mesh/wall"][()]
    mesh = [k for k, t in enumerate(types) if t == 2]
    q = quads[np.isin(wall, mesh)]
    degenerate = bool(np.all(q[:, 2] == q[:, 3]))
    return types, vert[q[:, :3]], degenerate


def check_drawn_mesh(c, name, tris, paths):
    want = np.array(tris, float)
    for engine, path in paths:
        try:
            types, drawn, degenerate = drawn_triangles(path)
        except (OSError, KeyError) as exc:
            c.check("%s: %s draws the mesh in /jdem/walls" % (name, engine), False, str(exc))
            continue
        c.check("%s: %s draws the mesh in /jdem/walls: %d triangles (type 2, quads with the last "
                "corner twice) = the STL's %d exactly" % (name, engine, len(drawn), len(want)),
                list(types) == [2] and degenerate and drawn.shape == want.shape and np.array_equal(drawn, want),
                "types %s, degenerate %s, shapes %s %s" % (list(types), degenerate, drawn.shape, want.shape))


def main():
    c = Checks()
    if not c.built(JDEM, LIG):
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        check_square_vs_plane(c, tmp)
        check_rest(c, tmp)
        check_refusals(c, tmp)
        cross_engine(c, tmp, "slide_edges", [particle((-0.012, -0.01, 0.005001), (0.4, 0.3, 0.0))],
                     floor_grid(8, 2.0 ** -6), 3000, "a sphere sliding across triangle edges")
        jd = cross_engine(c, tmp, "roll_vertex", [particle((-0.01, 0.0, 0.005001 + 0.0007), (0.4, 0.0, 0.0))],
                          pyramid(0.03125, 0.001), 5000, "a sphere rolling over the pyramid's apex")
        if jd:
            x = states(jd)["position"][:, 0]
            c.check("roll_vertex: the sphere passes over the apex (x from - to +, y = 0 throughout)",
                    x[0, 0] < 0 < x[-1, 0] and np.all(x[:, 1] == 0.0), "first %s, last %s" % (x[0], x[-1]))
        # five spheres dropped onto the cone, sliding down across its edges into the crease
        # with the floor, apart from each other (they meet after about 8400 steps)
        drops = [particle((0.018 * math.cos(2 * math.pi * k / 5 + 0.3),
                           0.018 * math.sin(2 * math.pi * k / 5 + 0.3), 0.014 + 0.001 * k), r=0.003)
                 for k in range(5)]
        tris = funnel(16, 0.008, 0.03, 0.02)
        jd = cross_engine(c, tmp, "funnel", drops, tris, 8000,
                          "five spheres dropped into a meshed funnel", threads=True)
        if jd:
            check_funnel_path(c, jd, 0.003)
            check_cells_vs_all_triangles(c, tmp, os.path.join(os.path.dirname(jd), "scene.yaml"))
            check_drawn_mesh(c, "funnel", tris, [("jdem", jd), ("liggghts-jdem",
                                                               os.path.join(os.path.dirname(jd), "liggghts.h5"))])
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
