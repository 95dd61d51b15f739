#!/usr/bin/python3
"""angle.py — the angle of repose of a pile on the plate, from its surface profile.

    python3 -m scripts.sandpile.angle TRAJECTORY.h5 [--frame F]   (prints the measurement as JSON)

Zhou et al.'s (2002) measure, which Del Cid (2015) follows: the pile left on the plate after the
outlets opened, its surface profile along the slot (y), a straight line fitted to each flank.
The profile is the top of the spheres, max(z + R), in bins one mean diameter wide across the
plate.  The crest is found on the profile's running median of three bins, so that one sphere
perched on top does not move it.  A flank is the bins between the plate's edge and the crest,
less the edge's bin (spheres there may overhang the edge) and the bins whose median is above
CREST of the crest's height (a rounded or flat top is not the slope).  The angle of a flank is
atan |slope| of the least-squares line through its bins' tops; the pile's is the mean of its two
flanks, with their half-difference, each fit's standard error and the half-range of the mean
over four shifts of the bin grid beside it (a pile's measurement spread: docs/sandpile.md).
"""
import argparse
import json
import math

import numpy as np

CREST = 0.9          # bins above this fraction of the peak height are the crest, not the flank
MIN_BINS = 3         # a flank fitted through fewer bins is no flank (no angle)
OFFSETS = (0.25, 0.5, 0.75)   # shifts of the bin grid beyond the unshifted one, in bin widths,
                              # for the binning's spread


def live_frame(f, frame=-1):
    """Positions [n][3] and radii [n] of the particles present at `frame` of the open H5MD
    trajectory f (a changing set's slots without a particle, id -1, left out), and the frame's
    time [s]."""
    a = f["particles/all"]
    pos = a["position/value"][frame]
    time = float(a["position/time"][frame])
    radius = a["radius"][...]
    ids = a["id/value"][frame] if "value" in a["id"] else a["id"][...]
    live = (ids >= 0) & np.all(np.isfinite(pos), axis=1)
    return pos[live], radius[live], time


def profile(y, top, half_width, width, offset=0.0):
    """The surface profile: per bin of `width` inside [-half_width, half_width] (the grid shifted
    by `offset` in [0, width), the partial bins at the ends left out), its centre and the highest
    top of the spheres centred in it (NaN when none is)."""
    edges = np.arange(-half_width + offset, half_width + 1e-12, width)
    if len(edges) < 2:
        return np.zeros(0), np.zeros(0)
    k = np.searchsorted(edges, y, side="right") - 1
    height = np.full(len(edges) - 1, np.nan)
    for b in range(len(edges) - 1):
        if np.any(k == b):
            height[b] = top[k == b].max()
    return 0.5 * (edges[:-1] + edges[1:]), height


def smoothed(height):
    """The profile's running median of three bins (the ends and gaps as they are): the crest's
    height and place without a single sphere perched on it."""
    out = height.copy()
    for b in range(1, len(height) - 1):
        window = height[b - 1:b + 2]
        if np.all(np.isfinite(window)):
            out[b] = np.median(window)
    return out


def fit_flank(y, h):
    """atan |slope| [deg] of the least-squares line through (y, h), and its standard error [deg]
    (NaN for fewer than MIN_BINS points)."""
    if len(y) < MIN_BINS:
        return math.nan, math.nan
    A = np.vstack([y, np.ones_like(y)]).T
    coef, res, _, _ = np.linalg.lstsq(A, h, rcond=None)
    slope = coef[0]
    dof = len(y) - 2
    sigma2 = (float(res[0]) / dof) if (dof > 0 and len(res)) else 0.0
    se_slope = math.sqrt(sigma2 / np.sum((y - y.mean()) ** 2)) if dof > 0 else math.nan
    return math.degrees(math.atan(abs(slope))), math.degrees(se_slope / (1.0 + slope * slope))


def flanks(y, top, half_width, width, offset=0.0):
    """Both flanks' angles and standard errors [deg], the profile, the flanks' bins and the
    crest's height [m], for the bin grid shifted by `offset`."""
    centre, height = profile(y, top, half_width, width, offset)
    crest = smoothed(height)
    peak = float(np.nanmax(crest)) if np.any(np.isfinite(crest)) else 0.0
    flank = np.isfinite(height) & (crest <= CREST * peak)
    if len(flank):
        flank[[0, -1]] = False      # the edges' bins
    crest_at = centre[np.nanargmax(crest)] if peak > 0 else 0.0
    left, right = flank & (centre < crest_at), flank & (centre > crest_at)
    a_left, se_left = fit_flank(centre[left], height[left])
    a_right, se_right = fit_flank(centre[right], height[right])
    return {"left": a_left, "right": a_right, "left_se": se_left, "right_se": se_right,
            "peak_height": peak, "centre": centre, "height": height, "flank_left": left,
            "flank_right": right}


def measure(pos, radius, half_width, plate_z=0.0):
    """The pile on the plate |y| <= half_width (spheres centred above plate_z): its flanks'
    angles [deg], their mean and half-difference, each fit's standard error, the half-range of
    the mean over the bin grid and its OFFSETS (how much the binning alone moves it), the crest's
    height above the plate [m], the count of spheres on the plate and the profile itself."""
    on = (np.abs(pos[:, 1]) <= half_width) & (pos[:, 2] > plate_z)
    y, top = pos[on, 1], pos[on, 2] + radius[on] - plate_z
    width = 2.0 * float(np.mean(radius)) if len(radius) else half_width
    f = flanks(y, top, half_width, width)
    shifted = [f] + [flanks(y, top, half_width, width, o * width) for o in OFFSETS]
    means = [0.5 * (g["left"] + g["right"]) for g in shifted]
    spread = 0.5 * (max(means) - min(means)) if all(math.isfinite(m) for m in means) else math.nan
    return {"angle": 0.5 * (f["left"] + f["right"]), "half_difference": 0.5 * abs(f["left"] - f["right"]),
            "left": f["left"], "right": f["right"], "left_se": f["left_se"], "right_se": f["right_se"],
            "offset_spread": spread, "peak_height": f["peak_height"], "on_plate": int(on.sum()),
            "bin_width": width, "profile_y": f["centre"].tolist(),
            "profile_top": [None if math.isnan(h) else float(h) for h in f["height"]],
            "flank_left": f["flank_left"].tolist(), "flank_right": f["flank_right"].tolist()}


def plate_half_width(f):
    """Half the plate's extent along y [m] in the open trajectory f: the plate is the scene's
    one mesh wall (type 2 in /jdem/walls, named as the scene does in jdem and by its fix ID in
    LIGGGHTS), its corners those of its quadrilaterals (docs/output.md)."""
    w = f["jdem/walls"]
    meshes = np.flatnonzero(w["type"][...] == 2)
    if len(meshes) != 1:
        raise ValueError(f"{f.filename}: {len(meshes)} mesh walls, not the one plate")
    quads, wall = w["mesh/quads"][...], w["mesh/wall"][...]
    vertices = w["mesh/vertices"][...] if "vertices" in w["mesh"] else w["mesh/vertex_position"][0]
    ys = vertices[quads[wall == meshes[0]].ravel(), 1]
    return 0.5 * float(ys.max() - ys.min())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("trajectory")
    ap.add_argument("--frame", type=int, default=-1)
    a = ap.parse_args()
    import h5py
    with h5py.File(a.trajectory, "r") as f:
        pos, radius, time = live_frame(f, a.frame)
        half_width = plate_half_width(f)
    m = measure(pos, radius, half_width)
    print(json.dumps(dict(m, time=time), indent=1))


if __name__ == "__main__":
    main()
