#!/usr/bin/python3
"""compression.py — the effective elastic constants of one servo-controlled compression run
(spec §2.4, docs/model.md §10) from its trajectory, in either engine.

    scripts/mixing/compression.py TRAJ.h5 [--wall top] [--json OUT.json]

Reads the servo's observables (servo_stress/WALL, servo_position/WALL, the diagonal of
stress_tensor/*) and the positions: the compression starts at the first frame at or after the
wall's first contact (servo_stress > 0) and ends at the first frame at or after the test's
completion (the first sample from which servo_position no longer changes); x1, x2 are the
positions there.  H0 is the wall's height above the floor at the start of the compression (the
resolved scene in /parameters/scene, less the servo's travel until then), H = H0 less the
travel since; the stresses are those at the completion.
Prints E, nu_xy, nu_xz and the condition number of the 3 x 3 fit for the best-fit particle
strain and for the wall strain (which is singular: docs/model.md §10), M = sigma_zz/eps_zz for
both strains and K0 (scripts/mixing/elastic.py), as JSON.
"""
import argparse
import json
import sys

import h5py
import numpy as np

from scripts.mixing import elastic
from scripts.mixing.deposit import scene_of


def series(obs, name):
    if name not in obs:
        sys.exit("compression.py: the trajectory has no observable %s (not a servo scene?)" % name)
    return obs[name]["step"][()], obs[name]["value"][()]


def completion_step(steps, position):
    """The first sample from which the wall no longer moves, or None if it still moved last."""
    moved = np.nonzero(np.diff(position))[0]
    first_still = moved[-1] + 1 if len(moved) else 0
    return int(steps[first_still]) if first_still < len(steps) - 1 else None


def wall_height(scene, wall):
    """The servo wall's height above the box bottom at the start [m], from the resolved scene."""
    walls = {w["name"]: w for w in scene["walls"]}
    top = np.asarray(walls[wall]["corners"], dtype=float)
    floors = [np.asarray(w["corners"], dtype=float) for w in scene["walls"] if w["name"] != wall]
    bottom = min(float(c[:, 2].max()) for c in floors if np.ptp(c[:, 2]) == 0.0)
    return float(top[:, 2].mean()) - bottom


def analyse(path, wall):
    with h5py.File(path, "r") as f:
        obs = f["observables"]
        steps, position = series(obs, "servo_position/" + wall)
        done = completion_step(steps, position)
        if done is None:
            sys.exit("compression.py: %s: the servo did not complete (the wall still moved at the "
                     "last sample); valid: a longer run" % path)
        k = int(np.searchsorted(steps, done))
        sig = [float(series(obs, "stress_tensor/" + c)[1][k]) for c in ("xx", "yy", "zz")]
        _, stress = series(obs, "servo_stress/" + wall)
        frame_steps = f["particles/all/position/step"][()]
        touched = int(steps[np.argmax(stress > 0.0)])
        i, j = (int(np.searchsorted(frame_steps, s)) for s in (touched, done))
        if j >= len(frame_steps):
            sys.exit("compression.py: %s: no frame at or after the completion (step %d)" % (path, done))
        x = f["particles/all/position/value"]
        x1, x2 = x[i], x[j]
        start = float(position[int(np.searchsorted(steps, frame_steps[i]))])
        scene = scene_of(f)
    h0 = wall_height(scene, wall) - start
    result = elastic.compression_result(sig, x1, x2, h0, h0 - (float(position[k]) - start))
    result.update({"trajectory": path, "completed_at_step": done, "first_contact_step": touched,
                   "frames": [int(frame_steps[i]), int(frame_steps[j])],
                   "sigma": sig, "H0": h0, "servo_position": float(position[k]),
                   "particles": int(x1.shape[0])})
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("trajectory")
    ap.add_argument("--wall", default="top", help="the servo wall's name (default top)")
    ap.add_argument("--json", help="also write the result here")
    a = ap.parse_args()
    text = json.dumps(analyse(a.trajectory, a.wall), indent=2, sort_keys=True)
    print(text)
    if a.json:
        with open(a.json, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
