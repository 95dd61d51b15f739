"""bench_tiling.py — the large bench beds (80k, 320k, 1M) as k x k lateral copies of a settled,
relaxed smaller bed (reference_runs/bench/README.md, "Large beds by tiling").

Settling 1M spheres with build/jdem takes hours, so scripts/bench.py settles and relaxes the 20k
bed once and places k x k copies of it side by side in x and y, in a box whose side walls move
out accordingly.  Each copy is the base bed translated: inside a tile every distance, and so every
contact and its overlap, is the base bed's (to round-off of the translation, ~1e-17 m).  What is
new are the seams, where the particles that touched a side wall of the base bed now face those of
the next tile; seam_gap() spaces the tiles so that no pair across a seam overlaps by more than the
bed's contact overlap.
"""
import numpy as np

# build/jdem refuses a scene whose particles overlap each other or a wall at the start by more
# than this fraction of the (smaller) radius (stepper/scene_particles.c, OVERLAP_TOL)
START_OVERLAP_TOL = 1e-6


def seam_gap(x, r, side, target):
    """Gap [m] between neighbouring tiles of a bed in the box [0, side]^2 (x, y).

    A particle that overlaps the high side wall by a and one of the next tile that overlaps the
    low side wall by b, at the same height and lateral position, overlap by a + b - gap once the
    tiles stand `gap` apart.  The gap makes the worst such pair (largest a and b, along x or y)
    overlap by exactly `target`, the overlap of every contact of the relaxed bed; pairs that are
    not aligned overlap less or not at all.  Never negative: the tiles' boxes do not interpenetrate.
    """
    worst = 0.0
    for axis in (0, 1):
        low = np.max(r - x[:, axis])              # overlap with the wall at 0 (<= 0: no contact)
        high = np.max(r - (side - x[:, axis]))    # overlap with the wall at side
        worst = max(worst, low + high)
    return max(0.0, worst - target)


def tile(x, r, ids, side, k, gap):
    """k x k copies of the bed (positions x [m], radii r [m], ids), tile (i, j) translated by
    (i, j) x (side + gap) in x and y.  Ids of tile t = j k + i are id + t max(ids), so they stay
    unique and positive.  Returns (x, r, ids, side of the tiled box [m])."""
    pitch = side + gap
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="xy")
    shift = np.zeros((k * k, 3))
    shift[:, 0] = i.ravel() * pitch
    shift[:, 1] = j.ravel() * pitch
    xt = (x[None, :, :] + shift[:, None, :]).reshape(-1, 3)
    rt = np.tile(r, k * k)
    idt = (ids[None, :] + np.arange(k * k)[:, None] * ids.max()).ravel()
    return xt, rt, idt, k * side + (k - 1) * gap


def start_overlap_violations(r, I, J, ov, WI, WO):
    """The stepper's refusal rule on a bed's contacts (pairs I, J with overlaps ov; wall contacts
    of particles WI with overlaps WO): the pairs overlapping by more than START_OVERLAP_TOL of
    the smaller radius and the wall contacts by more than START_OVERLAP_TOL of the radius.
    Returns (list of (id index i, j, overlap), list of (index, overlap)), each worst first."""
    bad = np.nonzero(ov > START_OVERLAP_TOL * np.minimum(r[I], r[J]))[0]
    bad = bad[np.argsort(-ov[bad])]
    badw = np.nonzero(WO > START_OVERLAP_TOL * r[WI])[0]
    badw = badw[np.argsort(-WO[badw])]
    return ([(int(I[q]), int(J[q]), float(ov[q])) for q in bad],
            [(int(WI[q]), float(WO[q])) for q in badw])
