#!/usr/bin/python3
"""generate.py — the scenes of the second mixing pass and of the compression cubes, cut from a
first- or second-pass deposit, and the first-pass cases as scenes of their own (docs/mixing.md
§1, §2, §4); every scene runs in both engines.

    generate.py fill --case modelM -o FILL1.yaml [--dt DT] [--sections N] [--end-time T]
                     [--jitter K] [--frame-every N]
    generate.py second-pass DEPOSIT.h5 --case modelM -o PASS2.yaml [--gap 0.06] [--dt DT]
    generate.py cubes DEPOSIT.h5 --case modelM -o DIR [--dt DT]  (writes DIR/cubeK.yaml, K = 1..9)

fill: the first-pass case of models.yaml as a scene of its own, optionally with another time
step (a number in s, or auto: the guard's) or a reduced stream (the first N sections, T s).
--jitter K shifts the whole stream by K micrometres in y (the inlet's origin), a realisation of
the same fill for the run-to-run spread: the fill is chaotic, so 1e-6 m grows into another
deposit with the same statistics.  --frame-every N writes a frame every N steps (of the
scene's dt) instead of the seed's snapshots: the dense frames of the cross-engine horizon
(scripts/mixing/horizon_ch4.py).
--dt sets the time step of every scene written (default: the seed's, models.yaml's time.dt); a
number rescales the output cadence so that the frames stay at the same times (auto keeps the
cadence in steps).

second-pass: the bottom 1 m of the deposit's last frame (centres with 0 <= z < 1) is cut into
1 x 2 x 4 cells of 1 (x) x 0.5 (y) x 0.25 (z) m; cell q = 2 layer + half (bottom to top, y < 0.5
first) is queued on the belt, gap m behind the one before, each keeping its orientation, its
bottom at z = 1.8 and centred at y = 0.5; one section inserted once.  Each cell is dilated about
its centre until its closest pair is as far apart as the first pass's lattice neighbours
(1.1 times the sum of their radii) [RECON]: the inlet inserts each sphere as it crosses the
plane, so spheres that touch (or overlap, as a cut from under the deposit's pressure does) are
rammed by their neighbours still on the belt (the undilated fill stops on the watchdog's
overlap limit within 0.1 s, a fill dilated only to touching within 0.3 s).  The cells are `from_deposit`
entries (region + dilation + translation), so the scene names the deposit, not its particles.
cubes: a 0.2 m cube at each Table 4-2 point (scripts/mixing/cube_scene.py: the particles whose
centres lie inside, five fixed walls and a servo top wall at 1000 Pa +- 10 Pa).
Both check every region against the deposit (scripts/mixing/deposit.py) before writing.
"""
import argparse
import os
import sys

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
from scripts.mixing import cube_scene, deposit, params
from scripts.mixing.plan_ch4 import shift_stream
from scripts.stability_scenes import set_path  # the sweep's dotted-path override

MODELS = os.path.join(HERE, "models.yaml")
CELL = (1.0, 0.5, 0.25)   # [RECON] orientation, spec §1.7
DEPTH = 1.0               # [TEXT] L1539
FEED_PITCH = 1.1          # [RECON] the first pass's lattice pitch over the sphere diameter
SERVO_TARGET = 1000.0     # [TEXT] spec §2.4: sigma_zz 1000 Pa, tolerance 10 Pa


def case_scene(case, dt=None):
    """models.yaml with the overrides of one case applied and the sweep removed; dt (a number
    or "auto") replaces the time step."""
    with open(MODELS) as f:
        doc = yaml.load(f, Loader=yaml.CSafeLoader)
    values = doc.pop("sweep")[0]["values"]
    if case not in values:
        sys.exit(f"generate.py: case '{case}' is not in {MODELS}; valid: {', '.join(values)}")
    for path, value in values[case].items():
        set_path(doc, path, value)
    doc["case"] = case
    if dt is not None:
        set_dt(doc, dt)
    return doc


def set_dt(doc, dt):
    """Replace the time step; with a number, the output cadence (in steps) is rescaled so that
    the frames stay at the same times (the seed's snapshots at whole seconds)."""
    old = doc["time"]["dt"]
    doc["time"]["dt"] = dt
    if dt != "auto":
        for key in ("every", "observables_every"):
            if key in doc["output"]:
                doc["output"][key] = max(1, round(doc["output"][key] * old / dt))


def fill(args):
    doc = case_scene(args.case, args.dt)
    if args.sections is not None:
        doc["inlets"][0]["stop"] = {"sections": args.sections}
    if args.end_time is not None:
        doc["time"]["end_time"] = args.end_time
    if args.frame_every is not None:
        doc["output"]["every"] = args.frame_every
    jitter = shift_stream(doc, args.jitter)
    write(args.out, doc, f"first pass, {args.case}, dt {doc['time']['dt']}, "
                         f"{doc['inlets'][0]['stop']['sections']} sections, "
                         f"{doc['time']['end_time']} s{jitter}")


def unloading_dilation(cut):
    """The factor s that spreads the cut until its closest pair is FEED_PITCH times the sum of
    its radii apart, the first pass's pitch (models.yaml: 0.033 m for 0.030 m spheres):
    FEED_PITCH times the largest (R_a + R_b) / d over its pairs, to 9 digits."""
    from scipy.spatial import cKDTree
    pairs = cKDTree(cut.position).query_pairs(2 * cut.radius.max(), output_type="ndarray")
    if len(pairs) == 0:
        return 1.0
    d = np.linalg.norm(cut.position[pairs[:, 0]] - cut.position[pairs[:, 1]], axis=1)
    s = FEED_PITCH * ((cut.radius[pairs[:, 0]] + cut.radius[pairs[:, 1]]) / d).max()
    return max(1.0, round(float(s), 9))


def cells(dep, deposit_path, gap, scene_dir):
    """The from_deposit entries of the second pass, in queue order: each cell dilated
    (unloading_dilation) about its centre, its front gap m behind the previous cell's back."""
    belt = []
    front = 0.05 - 0.005   # the first cell's front, 5 mm behind the inlet plane x = 0.05
    for q in range(8):
        layer, half = divmod(q, 2)
        lo = [0.0, CELL[1] * half, CELL[2] * layer]
        hi = [CELL[0], lo[1] + CELL[1], lo[2] + CELL[2]]
        cut = deposit.keep_box(dep, lo, hi, source=deposit_path)
        if len(cut.id) == 0:
            sys.exit(f"generate.py: {deposit_path}: cell {q} {lo}..{hi} holds no particle")
        s = unloading_dilation(cut)
        centre = [(a + b) / 2 for a, b in zip(lo, hi)]
        half_len = [s * c / 2 for c in CELL]
        shift = [front - half_len[0] - centre[0], 0.5 - centre[1], 1.8 + half_len[2] - centre[2]]
        front -= 2 * half_len[0] + gap
        belt.append({"file": cube_scene.deposit_reference(deposit_path, scene_dir), "frame": -1,
                     "region": {"lo": lo, "hi": hi}, "dilate": s, "translate": shift})
    return belt


def second_pass(args):
    dep = deposit.read_frame(args.deposit)
    if deposit.deposit_height(dep) < DEPTH:
        sys.exit(f"generate.py: {args.deposit}: the deposit is {deposit.deposit_height(dep):.3f} m "
                 f"deep; valid: at least {DEPTH} m for the second pass")
    doc = case_scene(args.case, args.dt)
    doc["name"] = "mixing_ch4_pass2"
    doc["description"] = f"Jiang (2021) Ch. 4 second mixing pass, {args.case} (Fig. 4-9)"
    inlet = doc["inlets"][0]
    inlet["section"] = {"from_deposit": cells(dep, args.deposit, args.gap,
                                             args.scene_dir or os.path.dirname(os.path.abspath(args.out)))}
    inlet["origin"] = [0.0, 0.0, 0.0]  # the translations place the cells
    inlet["stop"] = {"sections": 1}   # inserted once: the period is never used
    write(args.out, doc, f"second pass of {args.deposit} ({args.case}), gap {args.gap} m")


def cubes(args):
    dep = deposit.read_frame(args.deposit)
    os.makedirs(args.out, exist_ok=True)
    for k, c in enumerate(params.POINTS_TABLE_4_2, start=1):
        doc = cube_scene.cube_doc(case_scene(args.case, args.dt), dep, args.deposit, c,
                                  SERVO_TARGET, args.scene_dir or args.out)
        doc["name"] = f"mixing_ch4_cube{k}"
        doc["description"] = f"Jiang (2021) Ch. 4 compression test, cube {k} (Table 4-2)"
        write(os.path.join(args.out, f"cube{k}.yaml"), doc,
              f"compression cube {k} at {c.tolist()} of {args.deposit} ({args.case})")


def write(path, doc, what):
    cube_scene.write(path, doc, "reference_runs/mixing/ch4/generate.py", what)


def time_step(text):
    """--dt: a number > 0 [s] or auto."""
    if text == "auto":
        return text
    try:
        dt = float(text)
    except ValueError:
        dt = -1.0
    if not dt > 0:
        raise argparse.ArgumentTypeError(f"'{text}' is not valid; valid: a number > 0 [s], or auto")
    return dt


def steps(text):
    """--frame-every: a whole number of steps >= 1."""
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"'{text}' is not valid; valid: a whole number of steps >= 1")
    return int(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    for name in ("fill", "second-pass", "cubes"):
        p = sub.add_parser(name)
        if name != "fill":
            p.add_argument("deposit")
        p.add_argument("--case", required=True)
        p.add_argument("-o", "--out", required=True)
        p.add_argument("--dt", type=time_step, help="time step [s] or auto (default: the seed's)")
        if name == "fill":
            p.add_argument("--sections", type=int, help="sections of the stream (default 80)")
            p.add_argument("--end-time", type=float, help="simulated time [s] (default 25)")
            p.add_argument("--jitter", type=int, default=0,
                           help="shift the stream by K micrometres in y (a realisation for the spread)")
            p.add_argument("--frame-every", type=steps,
                           help="a frame every N steps (default: the seed's snapshots, 1 s)")
        if name != "fill":
            p.add_argument("--scene-dir", help="the folder the scene(s) will be read from, against "
                           "which their deposit path is relative (default: --out's)")
        if name == "second-pass":
            p.add_argument("--gap", type=float, default=0.06,
                           help="[RECON] gap between queued cells [m], default 2 R_big")
    args = ap.parse_args()
    try:
        {"fill": fill, "second-pass": second_pass, "cubes": cubes}[args.what](args)
    except deposit.DepositError as e:
        sys.exit(f"generate.py: {e}")


if __name__ == "__main__":
    main()
