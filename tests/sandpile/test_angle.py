#!/usr/bin/python3
"""The sandpile's angle of repose (scripts/sandpile/angle.py) on synthetic piles of known angle.

Spheres of the campaign's radii drawn uniformly in a skin under two straight flanks of known
angles (their tops at most on the line): every bin's highest top is then the line at the
bin's far side less a random shortfall that shrinks with the number of spheres, so the fitted
slope is the flank's.  Spheres off the plate (beyond its edges, or below it: what the outlets
let through) must not count.
"""
import math

import numpy as np

from tests.mixing.common import check, close, finish
from scripts.sandpile import angle

HALF = 0.06                                   # the scene's plate: |y| <= 0.06 m
RADII = np.array([0.002574, 0.00286, 0.003146])
TOL = 0.5      # [deg]: the measure on a dense skin, where the bins' maxima lie on the line, is
               # unbiased to this; on a real pile of ~15 spheres per bin the scatter is larger,
               # which the report gives per pile (the fits' errors, the binning's spread)
SKIN = 0.02                                   # [m]: the depth under the surface the spheres fill


def pile(left_deg, right_deg, n=20000, cap=None, seed=1):
    """n spheres under flanks rising from the plate's edges at the given angles (a flat top at
    `cap` [m] if given), plus spheres beside and below the plate."""
    rng = np.random.default_rng(seed)
    r = rng.choice(RADII, n)
    y = rng.uniform(-HALF, HALF, n)
    tl, tr = math.tan(math.radians(left_deg)), math.tan(math.radians(right_deg))
    surface = np.minimum((y + HALF) * tl, (HALF - y) * tr)
    if cap is not None:
        surface = np.minimum(surface, cap)
    top = surface - rng.uniform(0.0, SKIN, n)  # a skin of even density along the surface
    keep = top >= 2 * r                      # a whole sphere above the plate
    pos = np.zeros((keep.sum(), 3))
    pos[:, 1], pos[:, 2] = y[keep], top[keep] - r[keep]
    stray_y = np.concatenate([rng.uniform(-0.11, -HALF - 0.004, 50), rng.uniform(HALF + 0.004, 0.11, 50)])
    stray = np.column_stack([np.zeros(100), stray_y, rng.uniform(0.0, 0.2, 100)])  # beside the plate, high
    fallen = np.column_stack([np.zeros(50), rng.uniform(-HALF, HALF, 50), rng.uniform(-0.04, -0.01, 50)])
    pos = np.vstack([pos, stray, fallen])
    radius = np.concatenate([r[keep], np.full(150, RADII[1])])
    return pos, radius


for deg in (24.0, 36.0, 42.0):
    m = angle.measure(*pile(deg, deg), HALF)
    close(f"symmetric pile at {deg:g} deg: mean of the flanks", m["angle"], deg, TOL)
    close(f"symmetric pile at {deg:g} deg: the flanks agree", m["half_difference"], 0.0, TOL)
    close(f"symmetric pile at {deg:g} deg: peak height", m["peak_height"],
          HALF * math.tan(math.radians(deg)), 2 * RADII[2])

m = angle.measure(*pile(30.0, 40.0), HALF)
close("asymmetric pile: left flank", m["left"], 30.0, TOL)
close("asymmetric pile: right flank", m["right"], 40.0, TOL)
close("asymmetric pile: half-difference", m["half_difference"], 5.0, TOL)

cap = 0.8 * HALF * math.tan(math.radians(36.0))
m = angle.measure(*pile(36.0, 36.0, cap=cap), HALF)
close("flat-topped pile: the crest left out of the flanks", m["angle"], 36.0, TOL)

pos, radius = pile(36.0, 36.0, cap=cap)
perched = np.array([[0.0, 0.004, cap + RADII[1]]])   # one sphere on the flat top
m = angle.measure(np.vstack([pos, perched]), np.append(radius, RADII[1]), HALF)
close("flat-topped pile with a sphere perched on it: the crest found without it", m["angle"], 36.0, TOL)

pos, radius = pile(36.0, 36.0)
on = angle.measure(pos, radius, HALF)["on_plate"]
check("only spheres on the plate count", on == len(pos) - 150, f"{on} of {len(pos)} (150 strays)")

m = angle.measure(np.array([[0.0, 0.0, 0.003]]), np.array([0.003]), HALF)
check("a single sphere is no pile", math.isnan(m["angle"]), f"angle {m['angle']}")

finish()
