#!/usr/bin/python3
"""mixing_views.py — front and side views of a mixing-campaign trajectory as PNG.

    scripts/mixing_views.py TRAJ.h5 -o DIR [--times 1,2,3,6,11,final] [--views front,side]
                            [--clip HALF_THICKNESS]

For each requested time (s, or `final`: the last frame) the frame nearest to it is drawn by
scripts/mixing/plots.py (spheres to scale, red big, blue small) with the box and the cylinders
of the run's own resolved scene (/parameters/scene), as DIR/VIEW_tTIME.png.  The default times
are the seed's snapshots (Figs 4-3 to 4-8).  --clip keeps the spheres within that distance of
the middle plane (the seed's "middle clip").  Prints each file it writes.
"""
import argparse
import os
import sys

import h5py
import numpy as np

from scripts.mixing import deposit, plots


def scene_geometry(path):
    """(box lo, box hi, [(x, z, radius)] of the cylinders along y) from the resolved scene."""
    with h5py.File(path, "r") as f:
        scene = deposit.scene_of(f)
    walls = scene.get("walls") or []
    corners = np.array([c for w in walls if w["type"] == "plane" for c in w["corners"]], float)
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    cylinders = [(w["axis"][0][0], w["axis"][0][2], w["radius"]) for w in walls
                 if w["type"] == "cylinder"]
    return (tuple(lo), tuple(hi)), cylinders, scene.get("case") or scene.get("name")


def frame_index(path, when):
    """The frame nearest to time `when` (s), or the last for 'final'."""
    if when == "final":
        return -1
    with h5py.File(path, "r") as f:
        times = f["particles/all/position/time"][()]
    return int(np.argmin(np.abs(times - float(when))))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("trajectory")
    ap.add_argument("-o", "--out", required=True, help="directory for the PNGs")
    ap.add_argument("--times", default="1,2,3,6,11,final")
    ap.add_argument("--views", default="front,side")
    ap.add_argument("--clip", type=float, default=None)
    a = ap.parse_args(argv)
    try:
        box, cylinders, label = scene_geometry(a.trajectory)
    except (OSError, KeyError) as e:
        sys.exit(f"mixing_views.py: {a.trajectory}: not a trajectory with a resolved scene ({e}); "
                 f"valid: an H5MD file written by jdem or liggghts-jdem")
    os.makedirs(a.out, exist_ok=True)
    done = set()
    for when in a.times.split(","):
        index = frame_index(a.trajectory, when)
        dep = deposit.read_frame(a.trajectory, index)
        for view in a.views.split(","):
            path = os.path.join(a.out, f"{view}_t{dep.time:g}.png")
            if path in done:
                continue
            n = plots.deposit_view(dep, path, view, box=box, cylinders=cylinders, clip=a.clip,
                                   title=f"{label}: {view} view, t = {dep.time:g} s, "
                                         f"{len(dep.id)} spheres")
            done.add(path)
            print(f"{path}: {n} spheres")


if __name__ == "__main__":
    main(sys.argv[1:])
