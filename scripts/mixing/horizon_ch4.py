#!/usr/bin/python3
"""horizon_ch4.py — how long the two engines' first fills of the Chapter 4 campaign agree
trajectory by trajectory (docs/mixing.md §4, "The cross-engine horizon").

    horizon_ch4.py run --case modelM -o HORIZON.json [--dt DT] [--force] [--end-time 4]
                       [--frame-every 200] [--dir DIR]
    horizon_ch4.py summary [--out out/mixing/ch4] [--results DIR]

run: the first T seconds of the model's first fill (generate.py fill --end-time T --frame-every N,
--force for the seed's dt, which the guard refuses, as the campaign runs it) in jdem and in liggghts-jdem, each run as the
campaign's fill units run it (plan_ch4.run_command), trajectories in DIR (default: beside
HORIZON.json); then per common frame the largest position difference over the particles live
in both (matched by id: the two writers give a growing set different slots) over R_max, and the
largest velocity difference over sqrt(g d_max), d_max = 2 R_max, the pour study's scaling; and
from the larger of the two the first non-zero frame, the round-off horizon and the growth rate
(scripts/trajectory_divergence.py, shared with scripts/pour_study.py).  HORIZON.json holds the
curves, those numbers, each engine's run time and the first frame in which a particle has
touched something (first_touch).
summary: the table of every model's HORIZON.json found in OUT/cross/modelM/horizon.json and the
plot of the curves, into OUT/cross/horizon/{summary.json, horizon.md, horizon.png} and, with
--results, also there (the committed copy, reference_runs/mixing/ch4/results/horizon/).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.mixing import plan_ch4
from scripts.mixing.report_ch4 import commit
from scripts.trajectory_divergence import ROUNDOFF, divergence_summary

END_TIME = 4.0            # [s] the first seconds of the 27 s fill: cheap, and past the horizon
FRAME_EVERY = 200         # steps: a frame every 0.02 s at the seed's dt
G = 9.81                  # [m/s^2] the velocity scale sqrt(g d_max), as the pour study's
RESULT = "horizon.json"
WATCHDOG_STOP = 4         # the exit status of either engine's runner when the watchdog stopped it


# ---- the runs -------------------------------------------------------------------------------
def write_scene(case, dt_arg, end_time, frame_every, path):
    subprocess.run([plan_ch4.PY, plan_ch4.GENERATE, "fill", "--case", case, "--dt", dt_arg,
                    "--end-time", repr(end_time), "--frame-every", str(frame_every), "-o", path],
                   check=True, env=engines.python_env())
    return path


def run_engines(scene, directory, force):
    """Both engines on SCENE as the fill units run them: {engine: (trajectory, times)}.  A run
    the watchdog stopped counts up to its stop (its closed OUT.h5.part; times["stopped"] says
    why): the horizon lies long before that in the other runs."""
    runs = {}
    for engine in plan_ch4.ENGINES:
        out = os.path.join(directory, "fill.%s.h5" % engine)
        cmd = plan_ch4.run_command(engine, scene, out, force, skin=None, sort_every=0)  # jdem's lists, order
        r, times = engines.cpu_timed_run(cmd)
        if r.returncode == WATCHDOG_STOP and os.path.exists(out + ".part"):
            times["stopped"] = next((line.strip() for line in r.stderr.splitlines()
                                     if "watchdog:" in line), "exit status 4")   # its message
            out += ".part"
        elif r.returncode != 0:
            raise engines.failure(cmd, r.returncode, r.stdout, r.stderr)
        runs[engine] = (out, times)
    return runs


# ---- the comparison -------------------------------------------------------------------------
def load(path):
    """A growing-set trajectory: steps, times, ids [F][N] (-1: empty slot), x, v [F][N][3], and
    the largest radius of its particles."""
    with h5py.File(path, "r") as f:
        p = f["particles/all"]
        ids = p["id/value"][()] if isinstance(p["id"], h5py.Group) else \
            np.broadcast_to(p["id"][()], p["position/value"].shape[:2])
        return {"step": p["position/step"][()], "time": p["position/time"][()], "id": ids,
                "x": p["position/value"][()], "v": p["velocity/value"][()],
                "r_max": float(np.nanmax(p["radius"][()]))}


def common_rows(ids_a, ids_b):
    """Slot rows of the ids live in both frames (in id order), and how many are live in one only."""
    live_a, live_b = np.nonzero(ids_a >= 0)[0], np.nonzero(ids_b >= 0)[0]
    common, ka, kb = np.intersect1d(ids_a[live_a], ids_b[live_b], assume_unique=True,
                                    return_indices=True)
    return live_a[ka], live_b[kb], len(live_a) + len(live_b) - 2 * len(common)


def difference_by_id(a, b):
    """Per common frame: time, max|dx|/R_max, max|dv|/sqrt(g d_max) over the particles live in
    both (0 in a frame with none), their number, and the number live in one trajectory only."""
    steps, fa, fb = np.intersect1d(a["step"], b["step"], return_indices=True)
    r_max = max(a["r_max"], b["r_max"])
    v_scale = math.sqrt(G * 2.0 * r_max)
    dx, dv, live, unmatched = (np.zeros(len(steps)) for _ in range(4))
    for k, (i, j) in enumerate(zip(fa, fb)):
        ra, rb, unmatched[k] = common_rows(a["id"][i], b["id"][j])
        live[k] = len(ra)
        if len(ra):
            dx[k] = np.abs(a["x"][i][ra] - b["x"][j][rb]).max() / r_max
            dv[k] = np.abs(a["v"][i][ra] - b["v"][j][rb]).max() / v_scale
    return {"time": a["time"][fa], "dx": dx, "dv": dv, "live": live.astype(int),
            "unmatched": unmatched.astype(int), "r_max": r_max, "v_scale": v_scale}


def first_touch(traj, belt, gravity):
    """Time of the first frame in which a particle has touched something: its velocity across
    gravity is no longer the belt's, which free flight keeps exactly (gravity adds zeros there).
    Contacts last milliseconds, so a contact count sampled with the frames misses most; this
    sees every contact that changed a horizontal velocity, one frame late at most."""
    across = np.asarray(gravity) == 0.0
    for k, t in enumerate(traj["time"]):
        v = traj["v"][k][traj["id"][k] >= 0][:, across]
        if np.any(v != np.asarray(belt)[across]):
            return float(t)
    return None


def horizon_result(case, dt, curve, times, touch=None):
    """The JSON of one model: the numbers, the curves, the run times, the first touch seen."""
    return {"case": case, "dt": dt, "roundoff_level": ROUNDOFF, "first_touch": touch,
            "scaling": {"position": "max |dx| / R_max", "velocity": "max |dv| / sqrt(g d_max)",
                        "r_max": curve["r_max"], "v_scale": curve["v_scale"]},
            "divergence": divergence_summary(curve["time"], curve["dx"], curve["dv"]),
            "frames_with_unmatched_ids": int(np.count_nonzero(curve["unmatched"])),
            "particles_at_end": int(curve["live"][-1]),
            "times": times,
            "curve": {k: [float(x) for x in curve[k]] for k in ("time", "dx", "dv", "live")}}


def run(a):
    directory = a.dir or os.path.dirname(os.path.abspath(a.out))
    os.makedirs(directory, exist_ok=True)
    dt_arg = a.dt or repr(plan_ch4.SEED_DT)
    scene = write_scene(a.case, dt_arg, a.end_time, a.frame_every,
                        os.path.join(directory, "fill.yaml"))
    runs = run_engines(scene, directory, a.force)
    trajectories = [load(runs[e][0]) for e in plan_ch4.ENGINES]
    curve = difference_by_id(*trajectories)
    with open(scene) as f:
        doc = yaml.load(f, Loader=yaml.CSafeLoader)
    touch = first_touch(trajectories[0], doc["inlets"][0]["velocity"], doc["gravity"])
    result = horizon_result(a.case, float(dt_arg), curve, {e: runs[e][1] for e in runs}, touch)
    write_json(a.out, result)
    d = result["divergence"]
    print("horizon_ch4: %s: first non-zero at %s s, horizon %.2f s, growth %s" % (
        a.case, d["first_nonzero"], d["horizon"],
        "%.1f /s" % d["growth"]["rate"] if d["growth"] else "—"))
    return 0


# ---- the table and the plot -----------------------------------------------------------------
def fmt(x, spec="%.2f"):
    return "—" if x is None else spec % x


def table(results):
    """The report's table: one row per model."""
    lines = ["| model | first touch seen at [s] | first non-zero at [s] (value) | horizon < %.0e [s] "
             "| growth rate [1/s] (fit window [s]) | e-folding time [s] | last common frame: "
             "difference (t [s]) | particles then | CPU jdem / liggghts-jdem [s] | run at |" % ROUNDOFF,
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        d, g = r["divergence"], r["divergence"]["growth"]
        lines.append("| %s | %s | %s (%s) | %s%s | %s | %s | %.2e (%s) | %d | %.0f / %.0f | %s |" % (
            r["case"], fmt(r["first_touch"]), fmt(d["first_nonzero"]), fmt(d["first_value"], "%.1e"), fmt(d["horizon"]),
            "" if d["reaches_roundoff_level"] else " (never reached)",
            "%.1f (%.2f–%.2f)" % (g["rate"], g["from"], g["to"]) if g else "—",
            fmt(1.0 / g["rate"], "%.3f") if g and g["rate"] > 0 else "—", d["final"],
            fmt(r["curve"]["time"][-1]), r["particles_at_end"], r["times"]["jdem"]["cpu"],
            r["times"]["liggghts-jdem"]["cpu"], r.get("source", "—")))
    stops = ["- %s, %s: %s" % (r["case"], e, t["stopped"].split("; the trajectory")[0]) for r in results
             for e, t in r["times"].items() if "stopped" in t]
    return "\n".join(lines) + "\n" + ("\nStopped by the watchdog (compared up to the stop):\n\n"
                                      + "\n".join(stops) + "\n" if stops else "")


def plot(results, path, title="Chapter 4 first fills", mark=None, mark_label=""):
    """The cases' difference curves on a log scale, with the round-off level; mark(result), when
    given, is a time [s] (or None) drawn as a dashed line in the case's colour (mark_label says
    what it is)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    for r in results:
        c = r["curve"]
        line, = ax.semilogy(c["time"], np.maximum(np.maximum(c["dx"], c["dv"]), 1e-18), label=r["case"])
        t = mark(r) if mark else None
        if t is not None:
            ax.axvline(t, color=line.get_color(), lw=0.6, ls="--")
    ax.axhline(ROUNDOFF, color="k", lw=0.8, ls=":", label="round-off level %.0e" % ROUNDOFF)
    ax.set_xlabel("time [s]" + ("  (dashed: %s)" % mark_label if mark else ""))
    ax.set_ylabel("max(|Δx| / R_max, |Δv| / sqrt(g d_max))  (1e-18: identical)")
    ax.set_title("%s: jdem vs liggghts-jdem, particles matched by id" % title)
    ax.legend(fontsize=8 if len(results) <= 6 else 7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def merged(a):
    """The models' results, each with the commit it was run at (`source`): what was run under
    a.out, else what the committed summary in a.results holds, so that a machine that ran a few
    models keeps the others' (a summary written before the sources were recorded: its commit)."""
    by_model = {}
    committed = os.path.join(a.results or "", "summary.json")
    if a.results and os.path.exists(committed):
        doc = read_json(committed)
        by_model = {r["case"]: dict(r, source=r.get("source", doc.get("commit", "not recorded")))
                    for r in doc.get("models", [])}
    here = commit()
    ran = [m for m in plan_ch4.MODELS if os.path.exists(os.path.join(a.out, "cross", m, RESULT))]
    for m in ran:
        by_model[m] = dict(read_json(os.path.join(a.out, "cross", m, RESULT)), source=here)
    return [by_model[m] for m in plan_ch4.MODELS if m in by_model], bool(ran)


def summary(a):
    results, ran_here = merged(a)
    if not ran_here:   # nothing run yet: the committed results stay as they are
        print("horizon_ch4: no %s under %s/cross/modelM/; nothing written" % (RESULT, a.out))
        return 0
    target = os.path.join(a.out, "cross", "horizon")
    os.makedirs(target, exist_ok=True)
    write_json(os.path.join(target, "summary.json"),
               {"commits": sorted({r["source"] for r in results}), "models": results})
    with open(os.path.join(target, "horizon.md"), "w") as f:
        f.write(table(results))
    plot(results, os.path.join(target, "horizon.png"))
    publish(target, a.results)
    print("horizon_ch4: %d model(s) into %s%s" % (len(results), target,
                                                  " and " + a.results if a.results else ""))
    return 0


def publish(target, results, names=("summary.json", "horizon.md", "horizon.png")):
    """Copy a summary's files from TARGET into RESULTS (the committed copy), when given."""
    if results:
        os.makedirs(results, exist_ok=True)
        for name in names:
            shutil.copy(os.path.join(target, name), os.path.join(results, name))


def read_summary(directory):
    """The models' results of a summary directory, or None when it has none."""
    path = os.path.join(directory, "summary.json")
    return read_json(path)["models"] if os.path.exists(path) else None


def read_json(path):
    with open(path) as f:
        return json.load(f)


def write_json(path, doc):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=1)
    os.replace(tmp, path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    r = sub.add_parser("run")
    r.add_argument("--case", required=True, choices=plan_ch4.MODELS)
    r.add_argument("-o", "--out", required=True, help="the result, HORIZON.json")
    r.add_argument("--dt", help="time step [s] (default: the seed's)")
    r.add_argument("--force", action="store_true", help="run a time step the guard refuses")
    r.add_argument("--end-time", type=float, default=END_TIME)
    r.add_argument("--frame-every", type=int, default=FRAME_EVERY)
    r.add_argument("--dir", help="where the scene and the trajectories go (default: beside -o)")
    s = sub.add_parser("summary")
    s.add_argument("--out", default=plan_ch4.OUT["seed"])
    s.add_argument("--results", help="also write the summary, table and plot here")
    a = ap.parse_args(argv)
    return run(a) if a.what == "run" else summary(a)


if __name__ == "__main__":
    sys.exit(main())
