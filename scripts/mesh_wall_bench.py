#!/usr/bin/python3
"""mesh_wall_bench.py — mesh-wall contacts per second in liggghts-jdem: fix wall/jiang mesh
against stock fix wall/gran on the same STL floor.

    scripts/mesh_wall_bench.py [--steps N] [--out DIR]

A 64 x 64 grid floor (8192 triangles, 2^-7 m cells) carries 32 x 32 spheres of radius 5 mm on
a 12.5 mm lattice (no sphere touches another, so the pair style has no contacts); one rank.
Each run's "Other" time (LIGGGHTS 3.8's timing breakdown: the fixes, where the wall is) gives
wall contacts x steps / time.  Prints one line per wall style; a timing, not a test.
"""
import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
from tests.liggghts.liggghts_common import granular_deck_head
from tests.mesh.test_mesh_liggghts import floor_triangles, write_stl

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
    write_stl(os.path.join(a.out, "floor.stl"), floor_triangles(64, -0.25))
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


if __name__ == "__main__":
    main()
