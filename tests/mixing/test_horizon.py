#!/usr/bin/python3
"""The cross-engine horizon of the Chapter 4 fills (scripts/mixing/horizon_ch4.py) on a synthetic
pair of growing-set trajectories with a difference injected at a known time.

The inlet stream's identity in the two engines (the same ids, steps, positions and velocities)
is tested by tests/inlet/test_inlet_liggghts.py; this checks what the horizon makes of two
trajectories.  Six particles, ids 10..15, enter at frames out of id order; trajectory A keeps
them in slots sorted by id (jdem's layout), B in order of appearance (liggghts-jdem's growing
dump), with a spare slot never used, and B inserts id 15 one frame late.  Everything is the same
arithmetic in both, except:
* from frame K0 (t0 = 0.4 s) particle 13, at rest near the origin (so that the offset is not
  rounded away), is displaced in B by D0 R_max exp(LAMBDA (t - t0)) along x;
* from frame KV (t = 1.2 s) particle 12, at rest, moves in B at DV sqrt(g d_max) along y.
So the scaled position curve is 0 before t0 and D0 exp(LAMBDA (t - t0)) after; the expected
numbers follow from that closed form:
* first non-zero frame: t0, value D0;
* horizon (the last frame before 1e-10): t0 + ln(1e-10 / D0) / LAMBDA = 0.5956 s lies between
  the frames 0.58 and 0.60, so 0.58 s;
* growth rate: LAMBDA, within the round-off of the offset (its size over the spacing of the
  doubles at particle 13's coordinate, 2e-6 relative, is 1e-5 in the fitted exponent; 1e-3 allowed);
* the velocity curve: DV at every frame from KV on;
* one frame (the one where B lacks id 15) with an unmatched id; 6 particles in the last frame.
first_touch, on trajectories where every particle flies freely at the belt's velocity across
gravity: None, and with particle 14 kicked sideways from frame KT on, the time of frame KT.
"""
import math
import os
import tempfile

import h5py
import numpy as np

from tests.mixing.common import check, close, finish
from scripts.mixing import horizon_ch4
from scripts.trajectory_divergence import ROUNDOFF

FRAMES, EVERY, DT = 100, 200, 1.0e-4          # a frame every 0.02 s, 2 s
IDS = np.arange(10, 16)
ENTERS = {10: 3, 11: 0, 12: 0, 13: 5, 14: 1, 15: 3}   # frame of each id's insertion
LATE_ID = 15                                   # B inserts it one frame later
R = np.array([0.03, 0.015, 0.015, 0.015, 0.03, 0.015])
K0, D0, LAMBDA = 20, 2.0e-12, 20.0             # injected position difference
KV, DV = 60, 1.0e-6                            # injected velocity difference
KT = 30                                        # frame of the sideways kick (first_touch)
BELT, GRAVITY = [1.0, 0.0, 0.0], [0.0, 0.0, -9.81]
R_MAX, V_SCALE = 0.03, math.sqrt(9.81 * 0.06)


def state(i, t):
    """Position and velocity of particle i at time t: ids 12 and 13 at rest near the origin, the
    others in free fall from their insertion."""
    if i in (12, 13):
        return np.array([1e-3 * (i - 11), 1e-3, 1e-3]), np.zeros(3)
    return free_flight(i, t)


def free_flight(i, t):
    t0 = ENTERS[i] * EVERY * DT
    x0, v0, g = np.array([0.05, 0.5, 1.8 + 0.01 * (i - 10)]), np.array(BELT), np.array(GRAVITY)
    return x0 + v0 * (t - t0) + 0.5 * g * (t - t0) ** 2, v0 + g * (t - t0)


def kicked(i, k, x, v):
    """Particle 14 pushed sideways from frame KT on."""
    return (x, v + np.array([0.0, 1e-3, 0.0])) if i == 14 and k >= KT else (x, v)


def perturbed(i, k, x, v):
    """B's state: A's with the injected differences."""
    t = k * EVERY * DT
    if i == 13 and k >= K0:
        x = x + np.array([D0 * R_MAX * math.exp(LAMBDA * (t - K0 * EVERY * DT)), 0.0, 0.0])
    if i == 12 and k >= KV:
        v = v + np.array([0.0, DV * V_SCALE, 0.0])
    return x, v


def write(path, slots, enters, perturb=None, motion=state):
    """A growing-set trajectory in the H5MD layout the engines write (slots: the id of each slot
    row, -1 for a spare one; enters: id -> first frame; perturb(i, k, x, v): the state written)."""
    n = len(slots)
    ids = np.full((FRAMES, n), -1, dtype=np.int64)
    x, v = np.full((FRAMES, n, 3), np.nan), np.full((FRAMES, n, 3), np.nan)
    radius = np.full(n, np.nan)
    for s, i in enumerate(slots):
        if i < 0:
            continue
        radius[s] = R[i - IDS[0]]
        for k in range(enters[i], FRAMES):
            xi, vi = motion(i, k * EVERY * DT)
            x[k, s], v[k, s] = perturb(i, k, xi, vi) if perturb else (xi, vi)
            ids[k, s] = i
    steps = np.arange(FRAMES) * EVERY
    with h5py.File(path, "w") as f:
        p = f.create_group("particles/all")
        for name, value in (("id", ids), ("position", x), ("velocity", v)):
            g = p.create_group(name)
            g["step"], g["time"], g["value"] = steps, steps * DT, value
        p["radius"] = radius


def main():
    with tempfile.TemporaryDirectory() as tmp:
        a, b = os.path.join(tmp, "a.h5"), os.path.join(tmp, "b.h5")
        write(a, list(IDS), ENTERS, False)
        late = {**ENTERS, LATE_ID: ENTERS[LATE_ID] + 1}
        appearance = sorted(IDS, key=lambda i: (late[i], i))
        write(b, appearance + [-1], late, perturbed)
        check("synthetic-slot-orders-differ", appearance != list(IDS), "the test needs two layouts")
        curve = horizon_ch4.difference_by_id(horizon_ch4.load(a), horizon_ch4.load(b))
        free, kick = os.path.join(tmp, "free.h5"), os.path.join(tmp, "kick.h5")
        write(free, list(IDS), ENTERS, motion=free_flight)
        write(kick, list(IDS), ENTERS, kicked, motion=free_flight)
        touch_free = horizon_ch4.first_touch(horizon_ch4.load(free), BELT, GRAVITY)
        touch_kick = horizon_ch4.first_touch(horizon_ch4.load(kick), BELT, GRAVITY)
    t = curve["time"]
    result = horizon_ch4.horizon_result("synthetic", DT, curve, {})
    d = result["divergence"]
    before = curve["dx"][:K0].max()
    check("horizon-identical-before-t0", before == 0.0 and curve["dv"][:KV].max() == 0.0,
          "largest scaled difference before t0 %.3g (0 expected: matched by id)" % before)
    close("horizon-first-nonzero", d["first_nonzero"], K0 * EVERY * DT, 1e-12)
    close("horizon-first-value", d["first_value"] / D0, 1.0, 1e-3)
    crossing = K0 * EVERY * DT + math.log(ROUNDOFF / D0) / LAMBDA
    want = max(s for s in t if s < crossing)
    check("horizon-reached", d["reaches_roundoff_level"], "never reached %g" % ROUNDOFF)
    close("horizon-time", d["horizon"], want, 1e-12)
    check("horizon-growth", d["growth"] is not None and abs(d["growth"]["rate"] / LAMBDA - 1) < 1e-3,
          "growth %r, expected rate %g" % (d["growth"], LAMBDA))
    close("horizon-velocity-scale", curve["v_scale"], V_SCALE, 1e-15)
    dv = curve["dv"][KV:]
    check("horizon-velocity-difference", np.all(np.abs(dv / DV - 1) < 1e-9),
          "velocity curve from t = %.2f s: %s, expected %g" % (t[KV], dv[:3], DV))
    unmatched = np.nonzero(curve["unmatched"])[0]
    check("horizon-unmatched-ids", list(unmatched) == [ENTERS[LATE_ID]]
          and result["frames_with_unmatched_ids"] == 1,
          "frames with an id live in one trajectory only: %s" % list(unmatched))
    check("horizon-particles-at-end", result["particles_at_end"] == len(IDS),
          "%d at the end" % result["particles_at_end"])
    check("touch-free-flight", touch_free is None, "first touch at %r in free flight" % touch_free)
    check("touch-kicked", touch_kick is not None and abs(touch_kick - KT * EVERY * DT) < 1e-12,
          "first touch at %r, the kick at %g" % (touch_kick, KT * EVERY * DT))
    check_summary_merge()
    finish()


def check_summary_merge():
    """A machine that ran one model's horizon again keeps the committed summary's others, each
    with the commit it was run at; the model run here replaces its committed result."""
    import argparse
    with tempfile.TemporaryDirectory() as d:
        results, out = os.path.join(d, "results"), os.path.join(d, "out")
        os.makedirs(results)
        os.makedirs(os.path.join(out, "cross", "model2"))
        horizon_ch4.write_json(os.path.join(results, "summary.json"), {"commit": "abc1234", "models": [
            {"case": "model1", "mark": "committed"}, {"case": "model2", "mark": "committed"}]})
        horizon_ch4.write_json(os.path.join(out, "cross", "model2", horizon_ch4.RESULT),
                               {"case": "model2", "mark": "here"})
        models, ran = horizon_ch4.merged(argparse.Namespace(out=out, results=results))
    got = [(m["case"], m["mark"], m["source"]) for m in models]
    check("horizon-summary-merge", ran and got == [("model1", "committed", "abc1234"),
                                                   ("model2", "here", horizon_ch4.commit())], repr(got))


if __name__ == "__main__":
    main()
