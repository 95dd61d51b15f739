#!/usr/bin/python3
"""The conveyor inlet in jdem (docs/mixing.md 2.1) against independent references.

One line per check, `PASS name` or `FAIL name: detail`.

* stream: every insertion jdem records (--inlet-record) equals the stream computed here from the
  resolved scene by the closed form of kernel/jdem_inlet.h, in Python: ids, crossing steps,
  positions and velocities bit for bit, in insertion order (step, then id).
* trajectory: the rows are every id the run can hold, sorted; a row's id is -1 before its
  insertion and its id after (H5MD 1.1's time-dependent particle set); a row is finite exactly from its
  insertion step on (NaN before).
* free flight: a particle seen in a frame before anything touched it is at the closed-form
  x_k + v t + g t^2 / 2 (velocity Verlet is exact for constant gravity up to round-off).
* energy: the recorded inlet_energy equals the sum of 1/2 m v^2 - m g.x over the insertions,
  and with it booked as input the energy balance closes (drift well inside the watchdog's 5 %),
  while without it the balance would be off by a large fraction.
"""
import csv
import math
import os
import tempfile

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.engines import JDEM, ROOT
from tests.engine.engine_common import Checks

SCENE = os.path.join(ROOT, "tests", "inlet", "fill_small.yaml")

checks = Checks()
check = checks.check


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]  # left to right, as the kernel


def reference_stream(sc, inlet, steps):
    """(step, id, position, velocity) of every particle of copies that start by `steps`."""
    sec = inlet["section"]["particles"]
    n, v, N = len(sec), inlet["velocity"], inlet["plane"]["normal"]
    P, L, off, dt = inlet["plane"]["point"], inlet["period"], inlet["offset"], sc["time"]["dt"]
    speed = math.sqrt(dot(v, v))
    u = [v[0] / speed, v[1] / speed, v[2] / speed]
    w = dot(N, v) * dt
    out = []
    for c in range(inlet["stop"]["sections"]):
        back = off + c * L
        rows = []
        for p, q in enumerate(sec):
            rel = q["position"]
            a = dot(N, [inlet["origin"][i] + rel[i] - P[i] for i in range(3)]) - back * dot(N, u)
            k = max(0, math.ceil(-a / w))
            while k > 0 and a + (k - 1) * w >= 0.0:
                k -= 1
            while a + k * w < 0.0:
                k += 1
            t = k * dt
            x = [((inlet["origin"][i] + rel[i]) - back * u[i]) + v[i] * t for i in range(3)]
            rows.append((k, inlet["first_id"] + c * n + p, x, list(v)))
        if min(r[0] for r in rows) <= steps:
            out += rows
    return sorted(out, key=lambda r: (r[0], r[1]))


def main():
    with tempfile.TemporaryDirectory() as tmp:
        traj, rec = os.path.join(tmp, "fill.h5"), os.path.join(tmp, "rec.csv")
        run = engines.jdem("run", SCENE, "-o", traj, "--inlet-record", rec, "--quiet", binary=JDEM)
        check("run", run.returncode == 0, run.stderr.strip())
        if run.returncode:
            return
        sc = yaml.load(engines.resolve(SCENE, binary=JDEM, check=True).stdout, Loader=yaml.CSafeLoader)
        inlet = sc["inlets"][0]
        steps = math.ceil(sc["time"]["end_time"] / sc["time"]["dt"] - 1e-9) \
            if "end_time" in sc["time"] else sc["time"]["steps"]
        ref = reference_stream(sc, inlet, steps)
        with open(rec) as f:
            got = [(int(r["id"]), int(r["step"]), [float(r[k]) for k in "xyz"],
                    [float(r[k]) for k in ("vx", "vy", "vz")]) for r in csv.DictReader(f)]
        check("stream-count", len(got) == len(ref) == 27, f"{len(got)} recorded, {len(ref)} expected")
        check("stream-ids", [g[0] for g in got] == [r[1] for r in ref])
        check("stream-steps", [g[1] for g in got] == [r[0] for r in ref])
        check("stream-positions", all(g[2] == r[2] for g, r in zip(got, ref)))
        check("stream-velocities", all(g[3] == r[3] for g, r in zip(got, ref)))
        inserted = {g[0]: g for g in got}

        with h5py.File(traj, "r") as h:
            frame_ids = h["/particles/all/id/value"][:]  # a growing set: -1 in an empty row
            ids = frame_ids.max(axis=0)  # each row's particle, whenever it is there
            mass = dict(zip(ids, h["/particles/all/mass"][:]))
            pos = h["/particles/all/position/value"][:]
            fsteps = h["/particles/all/position/step"][:]
            obs = {k: h[f"/observables/{k}/value"][:] for k in h["/observables"]}
        check("rows-ids", list(ids) == sorted(inserted), f"{list(ids)[:5]}...")
        want = np.array([[inserted[i][1] <= s for i in ids] for s in fsteps])
        have = np.all(np.isfinite(pos), axis=2)
        check("rows-nan-until-inserted", np.array_equal(want, have),
              f"{int(np.sum(want != have))} rows differ")
        check("rows-id-minus-one-until-inserted",
              np.array_equal(frame_ids, np.where(want, ids[None, :], -1)),
              f"{int(np.sum(frame_ids != np.where(want, ids[None, :], -1)))} entries differ")

        g, dt = np.array(sc["gravity"]), sc["time"]["dt"]
        worst, seen = 0.0, 0
        for f, s in enumerate(fsteps):  # the first frame after each particle of the last copy
            for r, i in enumerate(ids):
                k = inserted[i][1]
                if i > ids[-1] - 9 and k <= s and (f == 0 or fsteps[f - 1] < k):
                    t = (s - k) * dt
                    x = np.array(inserted[i][2]) + np.array(inserted[i][3]) * t + 0.5 * g * t * t
                    worst, seen = max(worst, float(np.max(np.abs(pos[f, r] - x)))), seen + 1
        check("free-flight", seen > 0 and worst < 1e-9, f"{seen} seen, largest error {worst:g} m")

        brought = sum(0.5 * mass[i] * dot(r[3], r[3]) - mass[i] * dot(list(g), r[2])
                      for i, r in inserted.items())
        e_in = obs["inlet_energy"][-1]
        check("energy-booked", abs(e_in - brought) <= 1e-12 * abs(brought), f"{e_in} != {brought}")
        terms = ["kinetic_energy", "rotational_energy", "elastic_energy", "gravitational_energy",
                 "damping_dissipation", "friction_dissipation"]
        total = sum(obs[k] for k in terms) - obs["wall_work"]
        scale = max(float(np.max(obs["kinetic_energy"])), 1e-300)
        closed = float(np.max(np.abs(total - obs["inlet_energy"]))) / scale
        unbooked = float(np.max(np.abs(total - total[0]))) / scale
        check("energy-balance", closed < 0.01 and unbooked > 0.5,
              f"drift {closed:g} of the largest kinetic energy with the inflow booked, "
              f"{unbooked:g} without")


# The seed's obstacle models (the figure captions, (x, z) in m; spec jiang_scenes.md §1.6): none
# in Model 1.  The Chapter 4 scene switches them per case with
# `present:`; a wall left out must be absent from the resolved case.
MODEL_CYLINDERS = {"model1": [], "model2": [(0.5, 1.2)], "model3": [(0.3, 1.5)],
                   "model4": [(0.4, 1.2)], "model5": [(0.3, 1.5), (0.7, 1.2)],
                   "model6": [(0.3, 1.5), (0.6, 1.2)]}


def chapter4_models():
    scene = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "models.yaml")
    for case, want in MODEL_CYLINDERS.items():
        r = engines.resolve(scene, case, binary=JDEM)
        if not check(f"ch4-{case}-resolves", r.returncode == 0, r.stderr.strip()):
            continue
        walls = yaml.load(r.stdout, Loader=yaml.CSafeLoader).get("walls") or []
        got = sorted((w["axis"][0][0], w["axis"][0][2]) for w in walls if w["type"] == "cylinder")
        check(f"ch4-{case}-cylinders", got == sorted(want) and len(walls) == 5 + len(want),
              f"cylinders {got}, expected {sorted(want)}; {len(walls)} walls")


if __name__ == "__main__":
    main()
    chapter4_models()
    checks.exit()
