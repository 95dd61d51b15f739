#!/usr/bin/python3
"""test_mesh_liggghts.py — `fix wall/jiang mesh` (STL walls through the kernel) in liggghts-jdem.

    tests/mesh/test_mesh_liggghts.py

Builds nothing (run `make build/liggghts-jdem` first).  Each check runs a small deck twice: once
with an STL mesh written here (fix mesh/surface + fix wall/jiang mesh), once with the same
surface built from our plane primitive (fix wall/jiang plane), whose geometry is a closed form
(kernel/jdem_geometry.h).  The meshes are grids of right triangles whose sides are powers of two
(2^-7 m), so a face's foot, an edge's point and a vertex are exact in floating point and the
plane and the mesh must give the same bits:

- flat floor: spheres resting on a vertex, on an axis edge, on a diagonal edge and inside a face;
- sliding: spheres launched across the floor cross edges and vertices (the contact's history
  must follow it from triangle to triangle, or the friction force would differ), and on 2
  ranks the same bits as on 1 (the history migrates with the atom, ghost triangles count);
- concave corner: a floor and a wall meeting at 90 degrees, a sphere pressed into the corner
  while sliding along it (two contacts at once, each with its own history slot), against two
  plane walls;
- conveyor: fix mesh/surface surface_vel against a plane translating in its own plane;
- fix move/mesh linear against a plane wall with the same velocity: round-off only (the two
  move their geometry by different, equally exact-in-intent, sums), relative 1e-9;
- fix move/mesh rotate: a sphere at rest on a turning disc is dragged along omega x r at the
  first contact step (the wall velocity at the contact point enters the law);
- bad input: the exact messages for a missing mesh fix, a fix of another style, a wrong count.
One PASS/FAIL line per check.
"""
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
from tests.engine.engine_common import Checks
from tests.liggghts.liggghts_common import granular_deck_head
from tests.mesh.stl_files import write_ascii_stl_double

LIG = os.path.join(ROOT, "build", "liggghts-jdem")
H = 2.0 ** -7   # grid spacing [m]
R = 0.005       # sphere radius [m]

DECK = granular_deck_head("-0.1 0.1 -0.1 0.1 -0.01 0.2") + """pair_style gran/jiang
pair_coeff * *
timestep 1.0e-5
{atoms}
set group all diameter 0.01 density 2500
{velocity}
{walls}
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
dump d all custom 50 traj.txt id x y z vx vy vz fx fy fz omegax omegay omegaz
dump_modify d format "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g" sort id
run {steps}
"""
FLOOR_PLANE = "fix floor all wall/jiang plane corners -0.1 -0.1 0 0.1 -0.1 0 0.1 0.1 0 -0.1 0.1 0 type 2"
MESH = "fix cad all mesh/surface file wall.stl type 2{extra}\n{move}fix floor all wall/jiang mesh n_meshes 1 meshes cad"


def floor_triangles(n=16, x0=-0.0625, z=0.0):
    """An n x n grid of squares of side H in the plane z, two triangles each, diagonals alternating."""
    tris = []
    for i in range(n):
        for j in range(n):
            a = (x0 + i * H, x0 + j * H, z)
            b = (x0 + (i + 1) * H, x0 + j * H, z)
            c = (x0 + (i + 1) * H, x0 + (j + 1) * H, z)
            d = (x0 + i * H, x0 + (j + 1) * H, z)
            tris += [(a, b, c), (a, c, d)] if (i + j) % 2 == 0 else [(a, b, d), (b, c, d)]
    return tris


def wall_triangles(xw, n=16, y0=-0.0625, nz=4):
    """The plane x = xw, z in [0, nz H], as the floor's grid turned upright."""
    tris = []
    for j in range(n):
        for k in range(nz):
            a = (xw, y0 + j * H, k * H)
            b = (xw, y0 + (j + 1) * H, k * H)
            c = (xw, y0 + (j + 1) * H, (k + 1) * H)
            d = (xw, y0 + j * H, (k + 1) * H)
            tris += [(a, b, c), (a, c, d)] if (j + k) % 2 == 0 else [(a, b, d), (b, c, d)]
    return tris


def run(tmp, name, tris=None, ranks=1, **fields):
    d = os.path.join(tmp, name)
    os.mkdir(d)
    if tris is not None:
        write_ascii_stl_double(os.path.join(d, "wall.stl"), tris)
    fields.setdefault("velocity", "")
    fields.setdefault("steps", 3000)
    # LIGGGHTS' STL reader prints to the screen: -screen none would crash it
    mpi = [] if ranks == 1 else ["mpirun", "-np", str(ranks)] + (
        ["--allow-run-as-root", "--oversubscribe"] if os.geteuid() == 0 else [])
    deck = DECK.format(**fields)
    if ranks > 1:
        deck = deck.replace("boundary f f f", "boundary f f f\nprocessors %d 1 1" % ranks)
    with open(os.path.join(d, "in.deck"), "w") as f:
        f.write(deck)
    r = subprocess.run(mpi + [LIG, "-in", "in.deck", "-log", "log.lammps"], cwd=d,
                       capture_output=True, text=True)
    traj = os.path.join(d, "traj.txt")
    rows = None
    if r.returncode == 0 and os.path.exists(traj):
        rows = np.array([l.split() for l in open(traj) if len(l.split()) == 13
                         and not l.startswith("ITEM")], dtype=float)
    return r.returncode, r.stdout + r.stderr, rows


def atoms(*xyz):
    return "\n".join("create_atoms 1 single %r %r %r units box" % p for p in xyz)


def mesh(extra="", move=""):
    return MESH.format(extra=extra, move=move)


def same_bits(c, name, a, b):
    ok = a is not None and b is not None and a.shape == b.shape and np.array_equal(a, b)
    detail = "a run failed" if a is None or b is None else (
        "max |diff| %.3g" % np.abs(a - b).max() if a.shape == b.shape else "shapes differ")
    c.check(name, ok, detail)


def check_floor(c, tmp):
    z = R - 1e-6
    placed = atoms((0.0, 0.0, z), (0.03, H, z), (-0.02, -0.02 + 1e-3, z), (0.011, -0.013, z))
    _, _, a = run(tmp, "floor_mesh", floor_triangles(), atoms=placed, walls=mesh())
    _, _, b = run(tmp, "floor_plane", atoms=placed, walls=FLOOR_PLANE)
    same_bits(c, "resting on a vertex, an edge, a diagonal and a face: mesh = plane, every bit", a, b)


def check_slide(c, tmp):
    z = R - 1e-6
    placed = atoms((0.0, 0.0, z), (0.03, H, z), (-0.02, 0.013, z))
    vel = "velocity all set 0.5 0.3 0"
    _, _, a = run(tmp, "slide_mesh", floor_triangles(), atoms=placed, velocity=vel, walls=mesh())
    _, _, b = run(tmp, "slide_plane", atoms=placed, velocity=vel, walls=FLOOR_PLANE)
    same_bits(c, "sliding across edges and vertices (history follows the contact): mesh = plane", a, b)
    _, _, a2 = run(tmp, "slide_mesh_2ranks", floor_triangles(), ranks=2, atoms=placed,
                   velocity=vel, walls=mesh())
    same_bits(c, "... the same on 2 ranks (sphere 1 starts on the ranks' boundary x = 0)", a2, a)
    if a is not None:
        travelled = np.hypot(a[-3, 1] - 0.0, a[-3, 2] - 0.0)
        c.check("... sphere 1 crossed at least one cell (%.4f m > %.4f m)" % (travelled, H),
                travelled > H)


def check_corner(c, tmp):
    xw = 2.0 ** -6
    z = R - 1e-6
    placed = atoms((xw - R + 1e-6, 0.001, z))
    vel = "velocity all set 0.05 0.4 0"
    wall_plane = ("fix side all wall/jiang plane corners %r -0.1 0 %r -0.1 0.1 %r 0.1 0.1 %r 0.1 0 type 2"
                  % (xw, xw, xw, xw))
    _, _, a = run(tmp, "corner_mesh", floor_triangles() + wall_triangles(xw), atoms=placed,
                  velocity=vel, walls=mesh())
    _, _, b = run(tmp, "corner_plane", atoms=placed, velocity=vel, walls=FLOOR_PLANE + "\n" + wall_plane)
    same_bits(c, "a concave corner (two contacts, two history slots): mesh = two planes", a, b)
    if a is not None:
        c.check("... the side wall pushed back (min fx %.3g N < 0)" % a[:, 7].min(), a[:, 7].min() < 0)


def check_conveyor(c, tmp):
    placed = atoms((0.0, 0.0, R - 1e-6), (0.03, H, R - 1e-6))
    _, _, a = run(tmp, "belt_mesh", floor_triangles(), atoms=placed,
                  walls=mesh(extra=" surface_vel 0.2 0 0"))
    _, _, b = run(tmp, "belt_plane", atoms=placed, walls=FLOOR_PLANE + " velocity 0.2 0 0")
    same_bits(c, "conveyor (surface_vel 0.2 0 0) = plane translating at 0.2 m/s in its plane", a, b)


def check_move_linear(c, tmp):
    placed = atoms((0.0, 0.0, R + 1e-5), (0.03, H, R + 1e-5))
    move = "fix mv all move/mesh mesh cad linear 0.1 0.05 0.02\n"
    _, _, a = run(tmp, "lin_mesh", floor_triangles(), atoms=placed, walls=mesh(move=move))
    _, _, b = run(tmp, "lin_plane", atoms=placed, walls=FLOOR_PLANE + " velocity 0.1 0.05 0.02")
    if a is None or b is None or a.shape != b.shape:
        c.check("move/mesh linear = moving plane", False, "a run failed")
        return
    scale = np.maximum(np.abs(b).max(axis=0), 1e-300)
    err = (np.abs(a - b).max(axis=0) / scale)[1:].max()
    c.check("move/mesh linear 0.1 0.05 0.02 = plane velocity 0.1 0.05 0.02 to round-off "
            "(max rel. %.2g <= 1e-9)" % err, err <= 1e-9)
    lifted = a[-2, 3] - (R + 1e-5)
    c.check("... the floor lifted the spheres (z gain %.4f m, wall moved %.4f m)" % (lifted, 0.02 * 0.03),
            lifted > 0.5 * 0.02 * 0.03)


def check_rotation(c, tmp):
    # a disc of radius 4 cells about the origin, turning at omega about z; a sphere at rest at
    # (r, 0): the wall moves at omega r along +y under it, so friction pushes it along +y
    r0 = 0.03
    placed = atoms((r0, 0.0, R - 1e-6))
    move = "fix mv all move/mesh mesh cad rotate origin 0 0 0 axis 0 0 1 period 1.0\n"
    d, out, a = run(tmp, "turn_mesh", floor_triangles(), atoms=placed, walls=mesh(move=move), steps=50)
    if a is None:
        c.check("move/mesh rotate: the run completes", False, out[-1500:])
        return
    fx, fy = a[-1, 7], a[-1, 8]
    c.check("move/mesh rotate: the drag on a sphere at rest points along omega x r "
            "(fy %.3g N > 0, |fx/fy| %.2g < 1e-3)" % (fy, abs(fx / fy) if fy else np.inf),
            fy > 0 and abs(fx / fy) < 1e-3)


def check_bad_input(c, tmp):
    placed = atoms((0.0, 0.0, R))
    cases = [
        ("nosuch", "fix floor all wall/jiang mesh n_meshes 1 meshes nosuch",
         "ERROR: fix wall/jiang mesh: 'nosuch' is not the ID of a fix mesh/surface defined before this fix"),
        ("notmesh", "fix floor all wall/jiang mesh n_meshes 1 meshes m1",
         "ERROR: fix wall/jiang mesh: 'm1' is not the ID of a fix mesh/surface defined before this fix"),
        ("count", "fix cad all mesh/surface file wall.stl type 2\n"
                  "fix floor all wall/jiang mesh n_meshes 2 meshes cad",
         "ERROR: Illegal fix wall/jiang mesh command: fix ID group wall/jiang mesh n_meshes N meshes "
         "ID1 ... IDN (IDs of fix mesh/surface, all of the same type)"),
    ]
    for name, walls, want in cases:
        rc, out, _ = run(tmp, "bad_" + name, floor_triangles(2), atoms=placed, walls=walls, steps=1)
        lines = [re.sub(r" \([^()]*:\d+\)$", "", l) for l in out.splitlines()]
        c.check("bad input (%s): exit %d != 0 and the message %r" % (name, rc, want),
                rc != 0 and want in lines, out[-800:])


def check_drawn_rotation(c, tmp):
    """dump h5md/jdem draws a mesh that fix move/mesh rotate turns where it is at every frame:
    the STL's triangles turned by 2 pi t / period about z (to 1e-12 m: move/mesh turns the
    nodes by an increment each step), and a static mesh's triangles as the STL gives them."""
    tris = floor_triangles()
    move = "fix mv all move/mesh mesh cad rotate origin 0 0 0 axis 0 0 1 period 1.0\n"
    walls = mesh(move=move) + "\ndump h all h5md/jdem 10 drawn.h5"
    d, out, a = run(tmp, "drawn_turning_mesh", tris, atoms=atoms((0.03, 0.0, R - 1e-6)), walls=walls, steps=50)
    path = os.path.join(tmp, "drawn_turning_mesh", "drawn.h5")
    if not c.check("drawn mesh: the turning run writes its trajectory", a is not None and os.path.exists(path),
                   out[-1500:]):
        return
    import h5py
    with h5py.File(path, "r") as f:
        types = list(f["jdem/walls/type"][()])
        quads = f["jdem/walls/mesh/quads"][()]
        pos = f["jdem/walls/mesh/vertex_position"][()] if "vertex_position" in f["jdem/walls/mesh"] else None
        t = f["particles/all/position/time"][()]
    want0 = np.array(tris, float)
    if not c.check("drawn mesh: a moved mesh's vertices are stored per frame (type 2, %d frames)" % len(t),
                   types == [2] and pos is not None and len(pos) == len(t) == 6, "types %s" % types):
        return
    worst = 0.0
    for f_, time in enumerate(t):
        ph = 2.0 * np.pi * time / 1.0
        rot = np.array([[np.cos(ph), -np.sin(ph), 0.0], [np.sin(ph), np.cos(ph), 0.0], [0.0, 0.0, 1.0]])
        drawn = pos[f_][quads[:, :3]]
        worst = max(worst, float(np.abs(drawn - want0 @ rot.T).max()))
    c.check("drawn mesh: every frame's triangles = the STL's turned by 2 pi t / period "
            "(max |diff| %.2g m <= 1e-12 m, turned by up to %.3g rad)" % (worst, 2 * np.pi * t[-1]),
            worst <= 1e-12 and t[-1] > 0)


def main():
    c = Checks()
    if not os.access(LIG, os.X_OK):
        c.check("build/liggghts-jdem exists (make build/liggghts-jdem)", False)
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        check_floor(c, tmp)
        check_slide(c, tmp)
        check_corner(c, tmp)
        check_conveyor(c, tmp)
        check_move_linear(c, tmp)
        check_rotation(c, tmp)
        check_drawn_rotation(c, tmp)
        check_bad_input(c, tmp)
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
