"""The measured quantities of the work-precision study (scripts/accuracy.py) and their errors.

Impacts (Chung–Ooi): the benchmark's own metrics (scripts/benchmark/analysis.py), each with the
closed form or limit the benchmark asserts it against (shown beside the errors):
    Test 1  peak_force, peak_overlap, contact_duration     closed-form Hertz
    Test 3  e_n                                             jiang2021 table (spec 13.4)
    Test 4  e_t, w_post, rebound_angle_deg, e_n            rigid-body gross-sliding limit, the
                                                            lever-arm correction included (none
                                                            in stick)
Bed (reference_runs/accuracy/bed.yaml), from the frames (engine-independent: stock LIGGGHTS'
law writes no contact observables).  The collisions of a settling bed are chaotic: any
difference (the truncation error of a dt, or round-off) grows until the runs are different
realisations of the same bed, so a pointwise comparison measures accuracy only early on:
    position_early    rms |x - x_ref| / R at EARLY_TIME: the bottom layers have landed (~30
                      particle and wall contacts) and the differences still grow in proportion
                      to the truncation error (observed order ~1 up to ~20 ms; from ~30 ms the
                      collision cascade mixes them and the order falls towards 0, see the
                      report's table of the order against time): the bed's error metric
and the settled state is compared statistically (reported, not part of the item's error):
    packing_fraction  N V_p / (A 2 z_mean) at the last common frame: the bulk packing fraction
                      of a bed whose centres fill [0, 2 z_mean] uniformly (A the area of the
                      wall named floor)
    coordination      2 x (pairs with overlap > 0) / N at the last common frame
    ke_history        sum_k |KE_k - KE_ref,k| / sum_k KE_ref,k over the common frames (~1 ms
                      apart): the kinetic-energy history of fall, impact and settling
    position_rms      rms |x - x_ref| / R at every common frame (plotted)
The error of a run is the relative difference from the reference run of the same engine
(|v - v_ref| / |v_ref|; position_early and ke_history are already relative); the error of an
item is the largest over its error metrics.
"""
import math

import h5py
import numpy as np
import yaml

from scripts.benchmark.analysis import ANALYSES
from scripts.benchmark.trajectory import Run

IMPACT_METRICS = {1: ("peak_force", "peak_overlap", "contact_duration"), 3: ("e_n",),
                  4: ("e_t", "w_post", "rebound_angle_deg", "e_n")}
BED_ERROR_METRICS = ("position_early",)
BED_STATISTICS = ("packing_fraction", "coordination", "ke_history")
BED_METRICS = BED_ERROR_METRICS + BED_STATISTICS
EARLY_TIME = 0.02  # [s]


def impact_values(path, test, case, engine):
    """{metric: (value, closed form or limit)} of one impact trajectory; the closed form only
    where the benchmark asserts it (not the rigid stick limits, not untabulated e_n)."""
    recs = ANALYSES[test](Run(path), test, case, engine)
    return {r["metric"]: (r["value"], r["reference"] if r["tolerance"] is not None else None)
            for r in recs if r["metric"] in IMPACT_METRICS[test]}


class BedRun:
    """The frames of a bed trajectory at multiples of output.every, keyed by their time in
    units of the frame interval (the same times for every dt of the study)."""

    def __init__(self, path, frame_interval):
        with h5py.File(path, "r") as f:
            p = f["particles/all"]
            step = p["position/step"][()]
            time = p["position/time"][()]
            text = f["parameters/scene"][()]
            scene = yaml.load(text.decode() if isinstance(text, bytes) else text, Loader=yaml.CSafeLoader)
            keep = step % int(scene["output"]["every"]) == 0
            self.keys = np.rint(time[keep] / frame_interval).astype(int)
            self.x = p["position/value"][()][keep]
            self.v = p["velocity/value"][()][keep]
            self.mass = p["mass"][()]
            self.radius = p["radius"][()]
        floor = np.array([w["corners"] for w in scene["walls"] if w["name"] == "floor"][0], dtype=float)
        self.box_area = float(np.ptp(floor[:, 0]) * np.ptp(floor[:, 1]))
        self.frame_interval = frame_interval

    def frame(self, key):
        return int(np.nonzero(self.keys == key)[0][0])

    def kinetic_energy(self, key):
        v = self.v[self.frame(key)]
        return 0.5 * float((self.mass * (v * v).sum(axis=1)).sum())

    def packing_fraction(self, key):
        z_mean = float(self.x[self.frame(key)][:, 2].mean())
        volume = float((4.0 / 3.0 * math.pi * self.radius ** 3).sum())
        return volume / (self.box_area * 2.0 * z_mean)

    def coordination(self, key):
        x = self.x[self.frame(key)]
        d = np.sqrt(((x[:, None, :] - x[None, :, :]) ** 2).sum(axis=2))
        overlap = self.radius[:, None] + self.radius[None, :] - d
        np.fill_diagonal(overlap, -1.0)
        return float((overlap > 0).sum()) / len(x)  # each pair counted twice: 2 x pairs / N


def bed_common_keys(a, b):
    return sorted(set(a.keys.tolist()) & set(b.keys.tolist()))


def bed_values(run, ref):
    """{metric: value} of a bed run, with ke_history and position_rms measured against ref."""
    keys = bed_common_keys(run, ref)
    last = keys[-1]
    ke = np.array([run.kinetic_energy(k) for k in keys])
    ke_ref = np.array([ref.kinetic_energy(k) for k in keys])
    rms = [float(np.sqrt(((run.x[run.frame(k)] - ref.x[ref.frame(k)]) ** 2).sum(axis=1).mean())
                 / run.radius.max()) for k in keys]
    early = int(np.argmin(np.abs(np.array(keys) * run.frame_interval - EARLY_TIME)))
    return {"position_early": rms[early], "packing_fraction": run.packing_fraction(last),
            "coordination": run.coordination(last),
            "ke_history": float(np.abs(ke - ke_ref).sum() / ke_ref.sum()),
            "position_rms": rms, "frame_keys": keys}


def relative_error(value, reference):
    if reference is None or value is None:
        return None
    return abs(value - reference) / abs(reference) if reference != 0 else abs(value)
