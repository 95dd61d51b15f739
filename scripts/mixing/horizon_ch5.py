#!/usr/bin/python3
"""horizon_ch5.py — how long the two engines' bonded fills of the Chapter 5 campaign agree, and
whether their first bonds break alike (docs/mixing.md §11, "The cross-engine horizon of the
bonded fills").

    horizon_ch5.py run --case groupG_modelM -o HORIZON.json [--end-time 2] [--frame-every 200]
                       [--dir DIR]
    horizon_ch5.py summary [--out out/mixing/ch5] [--results DIR]

run: the first T seconds of the case's fill (the resolved case of reference_runs/mixing/ch5/
models.yaml, the scene both engines run, with its step count cut to T and a frame every N steps)
in jdem and in liggghts-jdem, each run as the fill units run it (horizon_ch4.run_engines); then
the trajectory horizon of horizon_ch4 (particles matched by id, max |dx| / R_max and
max |dv| / sqrt(g d_max) per frame) and the breaks of the two runs side by side
(break_agreement): whether the bonds formed are the same pairs at the same steps, each engine's
first break (step, pair, mode), how many breaks agree in order (step, pair, mode) before the
first that does not, the breaks up to the horizon, and the totals at T; and between which
observable samples the first sphere touched a wall or an obstacle (first_wall_contact), for the
seed's claim that weak blocks stay whole in free fall (free_fall_claims).
summary: the table of every case's HORIZON.json in OUT/cross/CASE/horizon.json and the plot of
the curves, into OUT/cross/horizon/{summary.json, horizon.md, horizon.png} and, with --results,
also there (the committed copy, reference_runs/mixing/ch5/results/horizon/).
"""
import argparse
import os
import re
import shutil
import sys

import numpy as np

from scripts import engines
from scripts.mixing import breakage, horizon_ch4
from scripts.mixing.report_ch4 import commit
from scripts.trajectory_divergence import ROUNDOFF, divergence_summary

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
MODELS = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "models.yaml")
ENGINES = ("jdem", "liggghts-jdem")
END_TIME = 2.0      # [s] the first sections land at 0.6 s, the horizon is near 0.7 s
FRAME_EVERY = 200   # steps: a frame every 0.02 s at the seed's dt
RESULT = "horizon.json"


# ---- the runs -------------------------------------------------------------------------------
def set_key(text, key, value):
    """The resolved scene `text` with its one line `  key: ...` (time.steps, output.every, ...)
    set to value; the rest of the scene, its 100 kB of inlet blocks, is left as jdem wrote it."""
    pattern = re.compile(r"(?m)^  %s: .*$" % re.escape(key))
    if len(pattern.findall(text)) != 1:
        raise SystemExit("horizon_ch5: the resolved scene has not exactly one '  %s:' line" % key)
    return pattern.sub("  %s: %s" % (key, value), text)


def write_scene(case, end_time, frame_every, path):
    """The case as `jdem resolve --case` gives it, cut to end_time, a frame every frame_every
    steps; returns (path, dt)."""
    import yaml
    text = engines.resolve(MODELS, case, check=True).stdout
    dt = float(yaml.safe_load(text)["time"]["dt"])
    text = set_key(text, "steps", str(int(round(end_time / dt))))
    for key in ("every", "observables_every"):
        text = set_key(text, key, str(frame_every))
    with open(path, "w") as f:
        f.write(text)
    return path, dt


# ---- the breaks -----------------------------------------------------------------------------
def breaks_in_order(rec):
    """The broken bonds as (step, lower id, higher id, mode), sorted."""
    pairs = np.sort(rec["broken"], axis=1)
    return sorted(zip(rec["broken_step"].tolist(), pairs[:, 0].tolist(), pairs[:, 1].tolist(),
                      rec["mode"].tolist()))


def same_bonds(a, b):
    """Whether both runs formed the same bonds (pairs, sorted) at the same steps."""
    key = lambda r: sorted(zip(np.sort(r["bonds"], axis=1).tolist(), r["formed"].tolist()))
    return len(a["bonds"]) == len(b["bonds"]) and key(a) == key(b)


def describe(brk, dt):
    """One break as the JSON names it."""
    step, i, j, mode = brk
    return {"step": step, "time": step * dt, "pair": [i, j], "mode": breakage.MODES.get(mode, mode)}


def break_agreement(a, b, horizon_step, end_step):
    """The breaks of two runs' bond records a and b (breakage.read_bonds) side by side: same_bonds,
    each run's first break, the length of the longest common prefix of their ordered breaks and
    the first break after it in each, the breaks each has up to horizon_step (and whether they are
    the same), and each run's broken fractions at end_step."""
    ka, kb = breaks_in_order(a), breaks_in_order(b)
    n = 0
    while n < min(len(ka), len(kb)) and ka[n] == kb[n]:
        n += 1
    dt = a["dt"]
    first_diff = {e: describe(k[n], dt) if n < len(k) else None for e, k in zip(ENGINES, (ka, kb))}
    upto = [[k for k in ks if k[0] <= horizon_step] for ks in (ka, kb)] if horizon_step is not None else None
    return {"same_bonds": same_bonds(a, b), "bonds": [len(a["bonds"]), len(b["bonds"])],
            "first": {e: describe(k[0], dt) if k else None for e, k in zip(ENGINES, (ka, kb))},
            "common_prefix": n, "first_difference": first_diff,
            "by_horizon": None if upto is None else
            {"step": horizon_step, "breaks": [len(u) for u in upto], "same": upto[0] == upto[1]},
            "totals": {e: breakage.broken_fraction(r, end_step) for e, r in zip(ENGINES, (a, b))}}


def first_wall_contact(path):
    """{"last_free": the last observable sample's step before any sphere touched a wall or an
    obstacle, "seen": the first sample's step with a wall contact} of a trajectory (None when
    no sphere touched one): the first wall contact lies in between."""
    import h5py
    with h5py.File(path, "r") as f:
        step = f["observables/wall_contacts/step"][()]
        count = f["observables/wall_contacts/value"][()]
    touching = np.nonzero(count > 0)[0]
    if len(touching) == 0:
        return None
    k = int(touching[0])
    return {"last_free": int(step[k - 1]) if k > 0 else None, "seen": int(step[k])}


def run(a):
    directory = a.dir or os.path.dirname(os.path.abspath(a.out))
    os.makedirs(directory, exist_ok=True)
    scene, dt = write_scene(a.case, a.end_time, a.frame_every, os.path.join(directory, "fill.yaml"))
    runs = horizon_ch4.run_engines(scene, directory, False)
    trajectories = [horizon_ch4.load(runs[e][0]) for e in ENGINES]
    curve = horizon_ch4.difference_by_id(*trajectories)
    result = horizon_ch4.horizon_result(a.case, dt, curve, {e: runs[e][1] for e in runs})
    d = result["divergence"]
    # the horizon is the last frame below round-off: its step, in the frames' own steps
    horizon_step = None if d["horizon"] is None else int(round(d["horizon"] / dt))
    end_step = int(min(t["step"][-1] for t in trajectories))
    result["breaks"] = break_agreement(*[breakage.read_bonds(runs[e][0]) for e in ENGINES],
                                       horizon_step, end_step)
    result["first_wall_contact"] = {e: first_wall_contact(runs[e][0]) for e in ENGINES}
    horizon_ch4.write_json(a.out, result)
    f = result["breaks"]["first"]
    print("horizon_ch5: %s: horizon %s s; first break %s (jdem) / %s (liggghts-jdem); %d breaks "
          "agree in order" % (a.case, d["horizon"], f["jdem"], f["liggghts-jdem"],
                              result["breaks"]["common_prefix"]))
    return 0


# ---- the table and the plot -----------------------------------------------------------------
def first_cell(brk):
    return "none" if brk is None else "%d (%.4f s), %d–%d, %s" % (
        brk["step"], brk["time"], brk["pair"][0], brk["pair"][1], brk["mode"])


def table(results):
    """The report's table: one row per case."""
    fmt = horizon_ch4.fmt
    lines = ["| case | horizon < %.0e [s] | growth rate [1/s] | same bonds formed | first break: "
             "step (t), pair, mode — jdem | liggghts-jdem | breaks up to the horizon (same) | "
             "breaks in the same order, then the first that differs (jdem / liggghts-jdem) | "
             "broken at the end jdem / liggghts-jdem | CPU jdem / liggghts-jdem [s] |" % ROUNDOFF,
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        d, g, b = r["divergence"], r["divergence"]["growth"], r["breaks"]
        h = b["by_horizon"]
        diff = b["first_difference"]
        t = b["totals"]
        lines.append("| %s | %s | %s | %s (%d) | %s | %s | %s | %d, then %s / %s | %d / %d (%.3f / %.3f) "
                     "| %.0f / %.0f |" % (
                         r["case"], fmt(d["horizon"]), "%.1f" % g["rate"] if g else "—",
                         "yes" if b["same_bonds"] else "**no**", b["bonds"][0],
                         first_cell(b["first"]["jdem"]), first_cell(b["first"]["liggghts-jdem"]),
                         "—" if h is None else "%d / %d (%s)" % (h["breaks"][0], h["breaks"][1],
                                                                "yes" if h["same"] else "**no**"),
                         b["common_prefix"], first_cell(diff["jdem"]), first_cell(diff["liggghts-jdem"]),
                         t["jdem"]["broken"], t["liggghts-jdem"]["broken"], t["jdem"]["total"],
                         t["liggghts-jdem"]["total"], r["times"]["jdem"]["cpu"],
                         r["times"]["liggghts-jdem"]["cpu"]))
    return "\n".join(lines) + "\n"


def free_fall_claims(results):
    """The seed's claim that weak blocks stay whole in free fall (spec §3.8), per Group 2 case
    and engine: held when the first bond broke after the last observable sample at which no
    sphere touched a wall or an obstacle (the sections fall apart from each other, so a bond can
    only be loaded by a wall, an obstacle or the spheres that already landed)."""
    lines = []
    for r in results:
        if not r["case"].startswith("group2_") or "first_wall_contact" not in r:
            continue
        for e in ENGINES:
            w, brk = r["first_wall_contact"][e], r["breaks"]["first"][e]
            if w is None or brk is None or w["last_free"] is None:
                continue
            lines.append("- %s %s: weak blocks stay whole in free fall (first wall or obstacle contact "
                         "between steps %d and %d, first bond break at step %d, %s): **%s**" % (
                             e, r["case"], w["last_free"], w["seen"], brk["step"], brk["mode"],
                             "held" if brk["step"] > w["last_free"] else "not held"))
    return lines


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    for r in results:
        c = r["curve"]
        line, = ax.semilogy(c["time"], np.maximum(np.maximum(c["dx"], c["dv"]), 1e-18), label=r["case"])
        first = r["breaks"]["first"]["jdem"]
        if first:
            ax.axvline(first["time"], color=line.get_color(), lw=0.6, ls="--")
    ax.axhline(ROUNDOFF, color="k", lw=0.8, ls=":", label="round-off level %.0e" % ROUNDOFF)
    ax.set_xlabel("time [s]  (dashed: each case's first break in jdem)")
    ax.set_ylabel("max(|Δx| / R_max, |Δv| / sqrt(g d_max))  (1e-18: identical)")
    ax.set_title("Chapter 5 bonded fills: jdem vs liggghts-jdem, particles matched by id")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def summary(a):
    from scripts.mixing import plan_ch5
    found = [os.path.join(a.out, "cross", c, RESULT) for c in plan_ch5.HORIZON_CASES]
    results = [horizon_ch4.read_json(p) for p in found if os.path.exists(p)]
    if not results:   # nothing run yet: the committed results stay as they are
        print("horizon_ch5: no %s under %s/cross/CASE/; nothing written" % (RESULT, a.out))
        return 0
    target = os.path.join(a.out, "cross", "horizon")
    os.makedirs(target, exist_ok=True)
    horizon_ch4.write_json(os.path.join(target, "summary.json"), {"commit": commit(), "cases": results})
    with open(os.path.join(target, "horizon.md"), "w") as f:
        f.write(table(results))
    plot(results, os.path.join(target, "horizon.png"))
    if a.results:
        os.makedirs(a.results, exist_ok=True)
        for name in ("summary.json", "horizon.md", "horizon.png"):
            shutil.copy(os.path.join(target, name), os.path.join(a.results, name))
    print("horizon_ch5: %d case(s) into %s%s" % (len(results), target,
                                                 " and " + a.results if a.results else ""))
    return 0


def read_summary(directory):
    """The cases' results of a summary directory, or None when it has none."""
    path = os.path.join(directory, "summary.json")
    return horizon_ch4.read_json(path)["cases"] if os.path.exists(path) else None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    r = sub.add_parser("run")
    r.add_argument("--case", required=True, help="groupG_modelM of reference_runs/mixing/ch5/models.yaml")
    r.add_argument("-o", "--out", required=True, help="the result, HORIZON.json")
    r.add_argument("--end-time", type=float, default=END_TIME)
    r.add_argument("--frame-every", type=int, default=FRAME_EVERY)
    r.add_argument("--dir", help="where the scene and the trajectories go (default: beside -o)")
    s = sub.add_parser("summary")
    s.add_argument("--out", default=os.path.join(ROOT, "out", "mixing", "ch5"))
    s.add_argument("--results", help="also write the summary, table and plot here")
    a = ap.parse_args(argv)
    return run(a) if a.what == "run" else summary(a)


if __name__ == "__main__":
    sys.exit(main())
