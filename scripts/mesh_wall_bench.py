#!/usr/bin/python3
"""mesh_wall_bench.py — mesh-wall contacts per second: the standalone engine's mesh walls, and
liggghts-jdem's fix wall/jiang mesh against stock fix wall/gran, on the same STL floor.

    scripts/mesh_wall_bench.py [--steps N] [--out DIR]

A 64 x 64 grid floor (8192 triangles, 2^-7 m cells) carries 33 x 33 spheres of radius 5 mm on
a 12.5 mm lattice (no sphere touches another, so the pair style has no contacts); one rank,
one thread.  Each LIGGGHTS run's "Other" time (LIGGGHTS 3.8's timing breakdown: the fixes,
where the wall is, with gravity and nve/sphere) and jdem's "wall forces" time (`--timing`: the
mesh walls with their candidate search) give wall contacts x steps / time.  Prints one line per
engine and wall style; a timing, not a test.
"""
import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
from tests.liggghts.liggghts_common import granular_deck_head
from tests.mesh.stl_files import write_binary_stl
from tests.mesh.test_mesh_liggghts import floor_triangles

LIG = os.path.join(ROOT, "build", "liggghts-jdem")
DECK = granular_deck_head("-0.3 0.3 -0.3 0.3 -0.01 0.1") + """{pair}
timestep 1.0e-5
lattice sc 0.0125
region bed block -16 16 -16 16 0 0.5 units lattice
create_atoms 1 region bed
set group all diameter 0.01 density 2500
displace_atoms all move 0.00625 0.00625 0.004999 units box
fix cad all mesh/surface file floor.stl type 2
fix floor all {wall} mesh n_meshes 1 meshes cad
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
run {steps}
"""
SCENE = """jdem_scene: 1
name: mesh_wall_bench
time: {{dt: 1.0e-5, steps: {steps}}}
output: {{every: {steps}}}
gravity: [0, 0, -9.81]
materials:
  glass: {{youngs_modulus: 5.0e6, poisson_ratio: 0.45, density: 2500, restitution: 0.5, friction: 0.5}}
  plate: {{youngs_modulus: 5.0e6, poisson_ratio: 0.45, density: 2500, restitution: 0.5, friction: 0.5}}
generate:
  - lattice: {{material: glass, radius: 0.005, origin: [-0.19375, -0.19375, 0.004999], spacing: 0.0125,
              counts: [33, 33, 1]}}
walls:
  - {{name: cad, type: mesh, file: floor.stl, material: plate}}
"""
STYLES = {
    "wall/jiang mesh": ("pair_style gran/jiang\npair_coeff * *", "wall/jiang"),
    "stock wall/gran mesh (hertz/history)": (
        "pair_style gran model hertz tangential history\npair_coeff * *",
        "wall/gran model hertz tangential history"),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench", "mesh_walls"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    write_binary_stl(os.path.join(a.out, "floor.stl"), floor_triangles(64, -0.25))
    for name, (pair, wall) in STYLES.items():
        with open(os.path.join(a.out, "in.deck"), "w") as f:
            f.write(DECK.format(pair=pair, wall=wall, steps=a.steps))
        r = subprocess.run([LIG, "-in", "in.deck", "-log", "log.lammps"], cwd=a.out,
                           capture_output=True, text=True)
        log = open(os.path.join(a.out, "log.lammps")).read()
        if r.returncode != 0:
            sys.exit("%s failed:\n%s" % (name, (r.stdout + r.stderr)[-1500:]))
        natoms = int(re.search(r"Created (\d+) atoms", log).group(1))
        modify = float(re.search(r"^Other time \(%\) = ([0-9.eE+-]+)", log, re.M).group(1))
        rate = natoms * a.steps / modify
        print("%-40s %d spheres x %d steps, fixes %.3f s: %.3g wall contacts/s"
              % (name, natoms, a.steps, modify, rate))
    jdem_line(a)


def jdem_line(a):
    """The same floor and spheres as a scene (lattice generator: the deck's positions) in jdem."""
    scene = os.path.join(a.out, "scene.yaml")
    with open(scene, "w") as f:
        f.write(SCENE.format(steps=a.steps))
    r = subprocess.run([os.path.join(ROOT, "build", "jdem"), "run", scene, "-o",
                        os.path.join(a.out, "jdem.h5"), "--quiet", "--timing", "--threads", "1"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("jdem failed:\n%s" % r.stderr[-1500:])
    t = dict(kv.split("=") for kv in re.search(r"^jdem-timing: (.*)$", r.stderr, re.M).group(1).split())
    n = int(re.search(r"timing of \d+ steps, (\d+) particles", r.stderr).group(1))
    walls = float(t["walls"])
    print("%-40s %d spheres x %d steps, walls %.3f s: %.3g wall contacts/s"
          % ("jdem mesh wall", n, a.steps, walls, n * a.steps / walls))


if __name__ == "__main__":
    main()
