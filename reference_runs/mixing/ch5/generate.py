#!/usr/bin/python3
"""generate.py — the Chapter 5 fills without energy accounts, and the compression cubes cut from a
bonded fill's deposit (docs/mixing.md §11); every scene runs in both engines.

    generate.py fill --case groupG_modelM --no-energy [--jitter K] -o FILL.yaml
    generate.py cubes DEPOSIT.h5 --case groupG_modelM -o DIR   (writes DIR/cubeK.yaml, K = 10..18)

`fill --no-energy` writes the resolved case with output.energy: false, the scene of every fill
that keeps no energy accounts (all but jdem's Models 2 and 4, plan_ch5.keeps_energy): the same
trajectory bit for bit as with the accounts (suite cross-engine, the energy-off checks), at a
contact history of 7 doubles instead of 23 (docs/mixing.md §11).  --jitter K shifts the stream
by K x plan_ch4.JITTER in y, as Ch. 4's generate.py: one more realisation of the fill, for the
run-to-run spread the two engines' fills are weighed against (scripts/mixing/agreement_ch5.py).

A 0.2 m cube at each middle-clip point (points 10-18 of Table 5-2, y = 0.5 m) under a servo top
wall at sigma_zz = 5 kPa [TEXT] +- 1 % [RECON] (the seed states no tolerance), with Table 5-1's
wall friction 0.2 (models.yaml's wall material) and scripts/mixing/cube_scene.py's walls.  The
cubes overlap in z (0.1-0.3, 0.2-0.4, 0.3-0.5 m), so each is its own scene with its own copy of
the deposit's particles and of the bonds intact between them (particles_from keeps them,
formed afresh with zero force: docs/scenes.md).  The case's materials and bonds are
`jdem resolve` of models.yaml's case, the scene both engines run.
"""
import argparse
import os
import subprocess
import sys

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
from scripts.mixing import cube_scene, deposit, params
from scripts.mixing.plan_ch4 import JITTER, shift_stream   # [m] one step of --jitter

MODELS = os.path.join(HERE, "models.yaml")
SERVO_TARGET = 5000.0     # [TEXT] spec §2.4: sigma_zz = 5 kPa
# Table 5-2's middle clip, points 10-18 (scripts/mixing/params.py)
MIDDLE_CLIP = params.POINTS_TABLE_5_2[params.MIDDLE_CLIP]
FIRST_POINT = params.MIDDLE_CLIP.start + 1


def case_scene(case):
    """The resolved case (jdem resolve --case): the one scene both engines run."""
    jdem = os.environ.get("JDEM", os.path.join(ROOT, "build", "jdem"))
    r = subprocess.run([jdem, "resolve", MODELS, "--case", case], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"generate.py: case '{case}': {r.stderr.strip()}")
    return yaml.load(r.stdout, Loader=yaml.CSafeLoader)


def fill(args):
    doc = case_scene(args.case)
    doc["output"]["energy"] = False
    jitter = shift_stream(doc, args.jitter)
    cube_scene.write(args.out, doc, "reference_runs/mixing/ch5/generate.py",
                     f"the fill of {args.case} without energy accounts{jitter}")


def cubes(args):
    dep = deposit.read_frame(args.deposit)
    base = case_scene(args.case)
    os.makedirs(args.out, exist_ok=True)
    for k, c in enumerate(MIDDLE_CLIP, start=FIRST_POINT):
        doc = cube_scene.cube_doc(base, dep, args.deposit, c, SERVO_TARGET,
                                    args.scene_dir or args.out)
        doc["name"] = f"mixing_ch5_cube{k}"
        doc["description"] = f"Jiang (2021) Ch. 5 compression test at point {k} (Table 5-2)"
        for key in ("case", "bonds"):   # the resolved case's; the cube's come from the deposit
            doc.pop(key, None)
        cube_scene.write(os.path.join(args.out, f"cube{k}.yaml"), doc,
                         "reference_runs/mixing/ch5/generate.py",
                         f"compression cube {k} at {c.tolist()} of {args.deposit} ({args.case})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    f = sub.add_parser("fill")
    f.add_argument("--case", required=True)
    f.add_argument("--no-energy", action="store_true", required=True,
                   help="output.energy: false (the only variant: with the accounts, jdem resolve "
                   "writes the case)")
    f.add_argument("--jitter", type=int, default=0,
                   help="shift the stream by K x %g m in y: a realisation of the fill (default 0)" % JITTER)
    f.add_argument("-o", "--out", required=True)
    p = sub.add_parser("cubes")
    p.add_argument("deposit")
    p.add_argument("--case", required=True)
    p.add_argument("-o", "--out", required=True)
    p.add_argument("--scene-dir", help="the folder the scenes will be read from, against which "
                   "their deposit path is relative (default: --out)")
    args = ap.parse_args()
    if args.what == "fill":
        return fill(args)
    try:
        cubes(args)
    except deposit.DepositError as e:
        sys.exit(f"generate.py: {e}")


if __name__ == "__main__":
    main()
