#!/usr/bin/python3
"""section_ch5.py — the seed's Fig. 5-4, the repeated section of the Chapter 5 stream (front,
side and 3D views, the big spheres red, the 2 x 2 x 8 blocks blue with their bonds white), in
both engines, rendered by ParaView from each trajectory's XDMF sidecar (docs/mixing.md §11).

    /usr/bin/python3 -m scripts.mixing.section_ch5 [--case group3_model1] [--out DIR] [--results DIR]

Each engine runs the case's first END_TIME s (horizon_ch5.write_scene: the resolved case, the
scene both engines run, a frame every FRAME_EVERY steps) into OUT/ENGINE.h5 and its sidecar.
The frame drawn is the first that holds the first section whole and nothing else (its ids, the
inlet's first_id onward, all inserted; no other particle yet).  `xvfb-run -a pvbatch
scripts/mixing/pv_section.py` draws it, and what ParaView drew is checked against the section:
its big and small spheres, and 60 bonds a block (a 2 x 2 x 8 block has 4 x 7 bonds along its
axis and 4 x 8 across), all intact in free flight.  Writes OUT/fig5-4.png and, with --results
(default reference_runs/mixing/ch5/results for the default OUT), also there.  Needs ParaView
(`make paraview-deps`).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.mixing import horizon_ch5, plan_ch4

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DEFAULT_OUT = os.path.join(ROOT, "out", "mixing", "ch5", "section")
DEFAULT_RESULTS = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "results")
FIGURE = "fig5-4.png"
END_TIME = 0.3       # [s] the first section crosses the inlet plane by 0.25 s, the next at 0.264 s
FRAME_EVERY = 100    # steps: a frame every 0.01 s at the seed's dt
BIG_RADIUS = 0.0225  # [m] between the small (0.015) and the big (0.03) spheres, as pv_section.py
BLOCK = 32           # spheres in a 2 x 2 x 8 block; every small sphere of a bonded section is in one
BONDS_PER_BLOCK = 4 * 7 + 4 * 8
VIEWS = ("front", "side", "3d")


class SectionError(Exception):
    pass


def section_of(scene):
    """(first id, big spheres, small spheres, blocks) of the resolved scene's inlet section (no
    blocks in an unbonded one)."""
    with open(scene) as f:
        inlet = yaml.load(f, Loader=yaml.CSafeLoader)["inlets"][0]
    radius = np.array([p["radius"] for p in inlet["section"]["particles"]])
    small = int(np.sum(radius < BIG_RADIUS))
    return (int(inlet.get("first_id", 0)), int(np.sum(radius > BIG_RADIUS)), small,
            small // BLOCK if inlet["section"].get("bonds") else 0)


def whole_section_frame(path, first_id, count):
    """The time of the first frame whose particles are exactly the first section's ids."""
    want = np.arange(first_id, first_id + count)
    with h5py.File(path, "r") as f:
        ids, times = f["particles/all/id/value"], f["particles/all/position/time"][()]
        for k in range(len(times)):
            live = np.sort(ids[k][ids[k] >= 0])
            if np.array_equal(live, want):
                return float(times[k])
    raise SectionError("%s: no frame holds the first section alone (ids %d..%d)" % (
        path, first_id, first_id + count - 1))


def render(sidecar, when, prefix, attempts=2):
    """pv_section.py on the sidecar at time `when`: what it drew (its JSON line).  pvbatch 5.11
    under xvfb now and then aborts before it draws (tests/paraview/pv_probe.py): one more try."""
    cmd = ["xvfb-run", "-a", "pvbatch", os.path.join(HERE, "pv_section.py"), sidecar, repr(when), prefix]
    for _ in range(attempts):
        r = subprocess.run(cmd, capture_output=True, text=True)
        lines = [x for x in r.stdout.splitlines() if x.startswith("{")]
        if lines:
            return json.loads(lines[-1])
    raise engines.failure(cmd, r.returncode, r.stdout, r.stderr)


def compose(panels, path, case, caption):
    """The engines' rows of front, side and 3D views as one PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(panels), len(VIEWS), figsize=(4 * len(VIEWS), 4.6 * len(panels)),
                             dpi=100, squeeze=False)
    for k, (row, (engine, prefix)) in enumerate(zip(axes, panels)):
        for ax, view, letter in zip(row, VIEWS, "abc"):
            ax.imshow(mpimg.imread("%s_%s.png" % (prefix, view)))
            ax.set_xticks([])
            ax.set_yticks([])
            if k == 0:
                ax.set_title("(%s) %s view" % (letter, view.replace("3d", "3D")), fontsize=9)
        row[0].set_ylabel(engine, fontsize=10)
    fig.suptitle("\n".join(textwrap.wrap("Fig. 5-4: the repeated section of %s (ParaView, spheres at "
                                          "0.6 of their radius): %s" % (case, caption), 120)), fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", default="group3_model1")
    ap.add_argument("--out", default=DEFAULT_OUT)
    ap.add_argument("--results", default=None)
    a = ap.parse_args()
    results = a.results or (DEFAULT_RESULTS if os.path.abspath(a.out) == DEFAULT_OUT else None)
    if not shutil.which("pvbatch"):
        sys.exit("section_ch5.py: pvbatch not found: install ParaView with `make paraview-deps`")
    os.makedirs(a.out, exist_ok=True)
    scene, _ = horizon_ch5.write_scene(a.case, END_TIME, FRAME_EVERY, os.path.join(a.out, "section.yaml"))
    first_id, big, small, blocks = section_of(scene)
    panels, drawn = [], {}
    pictures = tempfile.mkdtemp(prefix="section_ch5.")
    try:
        for engine in plan_ch4.ENGINES:
            out = os.path.join(a.out, "%s.h5" % engine)
            cmd = plan_ch4.run_command(engine, scene, out, False, skin=None, sort_every=0)
            r = engines.run(cmd)
            if r.returncode != 0:
                raise engines.failure(cmd, r.returncode, r.stdout, r.stderr)
            when = whole_section_frame(out, first_id, big + small)
            prefix = os.path.join(pictures, engine)
            drawn[engine] = render(os.path.splitext(out)[0] + ".xdmf", when, prefix)
            panels.append((engine, prefix))
        want = {"big": big, "small": small, "bonds": BONDS_PER_BLOCK * blocks}
        for engine, d in drawn.items():
            got = {k: d[k] for k in want}
            if got != want:
                raise SectionError("%s: ParaView drew %s of the first section at t = %g s, expected %s"
                                   % (engine, got, d["time"], want))
        caption = ("the first section alone, at t = %g s (its columns of blocks leave the belt one after "
                   "another): %d big and %d small spheres, %d blocks of 2 x 2 x 8 and %d bonds, as drawn "
                   "in each engine" % (drawn["jdem"]["time"], big, small, blocks, want["bonds"]))
        for d in [a.out] + ([results] if results else []):
            os.makedirs(d, exist_ok=True)
            compose(panels, os.path.join(d, FIGURE), a.case, caption)
            print("section_ch5.py: wrote %s (%s)" % (os.path.join(d, FIGURE), caption))
    finally:
        shutil.rmtree(pictures, ignore_errors=True)


if __name__ == "__main__":
    try:
        main()
    except (SectionError, engines.EngineError) as e:
        sys.exit("section_ch5.py: %s" % e)
