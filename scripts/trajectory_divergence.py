"""trajectory_divergence.py — how two runs of the same scene drift apart: the round-off horizon
and the exponential growth rate of a scaled difference curve, shared by the pour study
(scripts/pour_study.py) and the Chapter 4 fills (scripts/mixing/horizon_ch4.py).

A curve is one number per common frame: the largest difference between the runs, scaled so that
1 means "a particle radius apart" (each study says how it scales).
"""
import numpy as np

ROUNDOFF = 1e-10          # scaled difference counted as round-off


def horizon(t, diff, level=ROUNDOFF):
    """Last time before the scaled difference first reaches LEVEL (the whole run if never)."""
    above = np.nonzero(diff >= level)[0]
    if len(above) == 0:
        return float(t[-1]), False
    return float(t[above[0] - 1]) if above[0] > 0 else 0.0, True


def growth_rate(t, diff, lo=1e-12, hi=1e-3):
    """Exponential rate [1/s]: least-squares slope of ln(diff) where LO < diff < HI, from the first
    frame above LO to the first frame above HI (before saturation)."""
    start = np.nonzero(diff > lo)[0]
    if len(start) == 0:
        return None
    stop = np.nonzero(diff > hi)[0]
    end = stop[0] if len(stop) else len(diff)
    sel = np.arange(start[0], end)
    sel = sel[diff[sel] > 0]
    if len(sel) < 3:
        return None
    slope = np.polyfit(t[sel], np.log(diff[sel]), 1)[0]
    return {"rate": float(slope), "from": float(t[sel[0]]), "to": float(t[sel[-1]])}


def divergence_summary(t, dx, dv):
    """First non-zero difference, round-off horizon and growth of the larger of the position and
    velocity curves (dx, dv: scaled differences per frame at times t)."""
    both = np.maximum(dx, dv)
    nonzero = np.nonzero(both > 0)[0]
    h, reached = horizon(t, both)
    return {"first_nonzero": float(t[nonzero[0]]) if len(nonzero) else None,
            "first_value": float(both[nonzero[0]]) if len(nonzero) else 0.0,
            "horizon": h, "reaches_roundoff_level": reached, "growth": growth_rate(t, both),
            "final": float(both[-1])}
