"""Analysis of the work-precision study (scripts/accuracy.py): errors, observed orders, the dt and
wall time for 1 % error, OUT/summary.json, plots and OUT/report.md."""
import json
import math
import os
import statistics
import time

import numpy as np

from scripts.accuracy_metrics import (BED_METRICS, BED_STATISTICS, IMPACT_METRICS, BedRun, bed_values,
                              impact_values, relative_error)
from scripts.benchmark.cases import ROOT

TARGET = 0.01
ENGINE_LABEL = {"jdem": "jdem", "liggghts-jdem": "liggghts-jdem (gran/jiang)",
                "liggghts": "LIGGGHTS hertz/history"}
ENGINE_STYLE = {"jdem": ("C0", "o", "-"), "liggghts-jdem": ("C1", "s", "--"), "liggghts": ("C2", "^", ":")}


def factor_name(f):
    return "f%g" % f if f >= 1 else "f1_%d" % round(1 / f)


def median(xs):
    return statistics.median(xs) if xs else None


def path_of(rec):
    return os.path.join(ROOT, rec["trajectory"])


# ---------------------------------------------------------------------------------------------
# Errors

def item_rows(info, engine, seeds_floor=None):
    """One row per swept factor: dt, times, every metric's value and error against the engine's
    reference run, the worst error."""
    runs = info["engines"][engine]
    ref = runs.get("reference")
    if not ref or ref["status"] != "ok":
        return None, "reference run failed: %s" % (ref or {}).get("message", "missing")[-300:]
    test = info["test"]
    startup = median(runs["startup"]["wall"]) if runs.get("startup", {}).get("wall") else None
    if info["kind"] == "impact":
        ref_vals = impact_values(path_of(ref), test, info["case"], engine)
    else:
        ref_run = BedRun(path_of(ref), info["frame_interval"])
        ref_vals = bed_values(ref_run, ref_run)
    rows = []
    for f in info["factors"]:
        rec = runs[factor_name(f)]
        row = {"factor": f, "dt": rec["dt"], "steps": rec["steps"], "status": rec["status"],
               "wall_s": median(rec["wall"]), "wall_s_all": rec["wall"], "cpu_s": median(rec["cpu"]),
               "load": median(rec["load"]), "startup_wall_s": startup}
        # jdem prints no loop time: its wall time minus that of a 1-step run, when above the noise
        loop = (median(rec["loop"]) if rec["loop"] else
                row["wall_s"] - startup if row["wall_s"] is not None and startup is not None else None)
        row["loop_s"] = loop if loop is not None and loop > 0 else None
        if rec["status"] != "ok":
            row["message"] = rec.get("message", "")[-300:]
            rows.append(row)
            continue
        metrics = {}
        if info["kind"] == "impact":
            for m, (v, closed) in impact_values(path_of(rec), test, info["case"], engine).items():
                if engine == "liggghts" and test == 3:
                    closed = None  # the table is of jdem's damping, not LIGGGHTS'
                metrics[m] = {"value": v, "reference_run": ref_vals[m][0],
                              "error": relative_error(v, ref_vals[m][0]),
                              "closed_form": closed, "closed_form_error": relative_error(v, closed)}
        else:
            vals = bed_values(BedRun(path_of(rec), info["frame_interval"]), ref_run)
            for m in BED_METRICS:
                err = vals[m] if m in ("ke_history", "position_early") else relative_error(vals[m], ref_vals[m])
                metrics[m] = {"value": vals[m], "reference_run": ref_vals[m], "error": err,
                              "statistic": m in BED_STATISTICS}
            row["position_rms"] = vals["position_rms"]
            row["frame_times"] = [k * info["frame_interval"] for k in vals["frame_keys"]]
        row["metrics"] = metrics
        row["error"] = max(m["error"] for m in metrics.values() if not m.get("statistic"))
        rows.append(row)
    return rows, None


def order_fit(rows, key=None):
    """Least-squares slope of log(error) against log(dt) over the swept runs with error > 0."""
    pts = [(r["dt"], r["error"] if key is None else r["metrics"][key]["error"]) for r in rows
           if r["status"] == "ok"]
    pts = [(d, e) for d, e in pts if e and e > 0]
    if len(pts) < 3:
        return None
    x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(x, y, 1)[0])


def at_target(rows, target=TARGET):
    """The largest dt whose error, and that of every smaller swept dt, is <= target, refined by
    log-log interpolation towards the next swept dt; with the wall and loop time there
    (interpolated the same way).  None when the smallest swept dt misses the target."""
    ok = [r for r in rows if r["status"] == "ok"]
    last = None
    for i, r in enumerate(ok):
        if r["error"] > target:
            break
        last = i
    if last is None:
        return None
    a = ok[last]
    res = {"dt": a["dt"], "factor": a["factor"], "wall_s": a["wall_s"], "cpu_s": a["cpu_s"], "loop_s": a["loop_s"],
           "bound": "swept maximum" if last == len(ok) - 1 else "interpolated"}
    if last + 1 < len(ok) and a["error"] > 0:
        b = ok[last + 1]
        s = (math.log(target) - math.log(a["error"])) / (math.log(b["error"]) - math.log(a["error"]))
        res["dt"] = math.exp(math.log(a["dt"]) + s * (math.log(b["dt"]) - math.log(a["dt"])))
        res["factor"] = a["factor"] * res["dt"] / a["dt"]
        for k in ("wall_s", "cpu_s", "loop_s"):
            if a[k] and b[k] and a[k] > 0 and b[k] > 0:
                res[k] = math.exp(math.log(a[k]) + s * (math.log(b[k]) - math.log(a[k])))
    return res


DIVERGENCE_TIMES = (0.01, 0.02, 0.03, 0.04, 0.06, 0.1, 0.15)  # [s]


def order_against_time(rows):
    """Observed order of the bed's rms position difference at a few times: ~1 while the
    differences grow in proportion to the truncation error, falling towards 0 once the
    collisions have mixed them (chaos)."""
    ok = [r for r in rows if r["status"] == "ok"]
    out = {}
    for t in DIVERGENCE_TIMES:
        k = int(np.argmin(np.abs(np.array(ok[0]["frame_times"]) - t)))
        pts = [(r["dt"], r["position_rms"][k]) for r in ok if r["position_rms"][k] > 0]
        if len(pts) >= 3:
            out["%g" % t] = {"order": float(np.polyfit(np.log([p[0] for p in pts]), np.log([p[1] for p in pts]), 1)[0]),
                             "rms_over_R": [p[1] for p in pts]}
    return out


def recommended_factor(items):
    """The default dt rule: the largest power of two <= 1 (the guard is the upper limit) not
    above the 1 % factor of jdem on any item (dt at the largest swept factor counts as that
    factor; an item that misses 1 % at its smallest swept dt gives that dt / 2)."""
    limits = {}
    for item, it in items.items():
        res = it["engines"].get("jdem", {})
        if not res.get("rows"):
            continue
        a = res.get("at_1_percent")
        limits[item] = a["factor"] if a else min(it["factors"]) / 2
    if not limits:
        return None, limits
    return 2.0 ** min(0, math.floor(math.log2(min(limits.values())))), limits


def bed_floors(info):
    """Two limits on what the bed's errors can show: the round-off floor (liggghts-jdem against
    jdem at the same dt: the same law in another summation order, so their difference is
    round-off amplified by the chaos of the collisions) and the spread of the statistics over
    lattice seeds (other realisations of the same bed)."""
    out = {"roundoff": {}}
    eng = info["engines"]
    if "jdem" in eng and "liggghts-jdem" in eng:
        for f in info["factors"]:
            a, b = eng["jdem"].get(factor_name(f)), eng["liggghts-jdem"].get(factor_name(f))
            if a and b and a["status"] == b["status"] == "ok":
                ra = BedRun(path_of(a), info["frame_interval"])
                va, vb = bed_values(ra, ra), bed_values(BedRun(path_of(b), info["frame_interval"]), ra)
                out["roundoff"][factor_name(f)] = {
                    m: vb[m] if m in ("ke_history", "position_early") else relative_error(vb[m], va[m])
                    for m in BED_METRICS}
                out["roundoff"][factor_name(f)]["position_rms"] = vb["position_rms"]
                out["roundoff"][factor_name(f)]["frame_times"] = [k * info["frame_interval"]
                                                                  for k in vb["frame_keys"]]
    seeds = info.get("seeds")
    if seeds:
        runs = [BedRun(path_of(r), info["frame_interval"]) for r in seeds["runs"].values() if r["status"] == "ok"]
        own = eng.get("jdem", {}).get(factor_name(seeds["factor"]))
        if own and own["status"] == "ok":
            runs.append(BedRun(path_of(own), info["frame_interval"]))
        stats = {}
        for m in ("packing_fraction", "coordination"):
            vals = [bed_values(r, r)[m] for r in runs]
            stats[m] = {"values": vals, "relative_std": float(np.std(vals, ddof=1) / np.mean(vals))}
        if own and own["status"] == "ok":  # KE histories of other realisations against this one
            vals = [bed_values(r, runs[-1])["ke_history"] for r in runs[:-1]]
            stats["ke_history"] = {"values": vals, "mean": float(np.mean(vals))}
        out["seeds"] = stats
    return out


# ---------------------------------------------------------------------------------------------
# Plots

def plot_item(out, item, info, results):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    metrics = BED_METRICS if info["kind"] == "bed" else IMPACT_METRICS[info["test"]]
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    for engine, res in results.items():
        rows = [r for r in (res["rows"] or []) if r["status"] == "ok" and r["error"] > 0]
        if not rows:
            continue
        c, mk, ls = ENGINE_STYLE[engine]
        for ax, key in ((axes[0], "wall_s"), (axes[1], "cpu_s")):
            pts = [(r[key], r["error"], r["factor"]) for r in rows if r[key] and r[key] > 0]
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], ls, marker=mk, color=c, label=ENGINE_LABEL[engine])
            for x, y, f in pts:
                ax.annotate("%g" % f if f >= 1 else "1/%d" % round(1 / f), (x, y), fontsize=6,
                            textcoords="offset points", xytext=(3, 3), color=c)
        for j, m in enumerate(metrics):
            pts = [(r["factor"], r["metrics"][m]["error"]) for r in rows if r["metrics"][m]["error"] > 0]
            axes[2].loglog([p[0] for p in pts], [p[1] for p in pts], ls, marker=mk, color="C%d" % (j + 3),
                           label="%s, %s" % (m, engine), ms=4)
    for ax in axes:
        ax.axhline(TARGET, color="k", lw=0.8, ls=":")
        ax.grid(True, which="both", lw=0.3)
        ax.set_ylabel("relative error vs the 16x finer reference")
    if info["kind"] == "bed" and "floors" in results.get("jdem", {}):
        for m, v in results["jdem"]["floors"].get("seeds", {}).items():
            if "relative_std" in v:
                axes[2].axhline(v["relative_std"], color="grey", lw=0.8, ls="-.")
        axes[2].text(0.02, 0.02, "grey dash-dot: spread over lattice seeds (relative std)", fontsize=7,
                     transform=axes[2].transAxes)
    axes[0].set_xlabel("wall time of the whole process [s] (median of repeats)")
    axes[1].set_xlabel("CPU time (user + system) of the whole process [s] (median)")
    axes[2].set_xlabel("dt / guard dt")
    axes[0].set_title("%s: largest error over the metrics" % item, fontsize=9)
    axes[1].set_title("the same against CPU time (less disturbed by other jobs)", fontsize=9)
    axes[2].set_title("each metric against dt", fontsize=9)
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=6, ncol=2)
    fig.tight_layout()
    name = "%s.png" % item
    fig.savefig(os.path.join(out, name), dpi=110)
    plt.close(fig)
    return name


def plot_bed_divergence(out, info, results):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4.6))
    for i, r in enumerate(r for r in results["jdem"]["rows"] if r["status"] == "ok"):
        ax.semilogy(r["frame_times"], np.maximum(r["position_rms"], 1e-16), color="C%d" % i,
                    label="jdem dt = %g guard vs reference" % r["factor"])
    for name, fl in results["jdem"].get("floors", {}).get("roundoff", {}).items():
        if name == factor_name(min(info["factors"])):
            ax.semilogy(fl["frame_times"], np.maximum(fl["position_rms"], 1e-16), "k--",
                        label="liggghts-jdem vs jdem, same dt (%s): round-off" % name)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("rms position difference / R")
    ax.set_title("bed: how fast runs with different dt part (chaotic collisions)", fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "bed_divergence.png"), dpi=110)
    plt.close(fig)
    return "bed_divergence.png"


# ---------------------------------------------------------------------------------------------

def analyse(out, runs):
    summary = {"generated": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "machine": runs["machine"],
               "repeats": runs["repeats"], "study_wall_seconds": runs.get("study_wall_seconds"),
               "target_error": TARGET, "items": {}}
    figures = {}
    for item, info in runs["items"].items():
        results = {}
        for engine in info["engines"]:
            rows, problem = item_rows(info, engine)
            res = {"rows": rows, "problem": problem}
            if rows:
                res["order"] = order_fit(rows)
                res["order_by_metric"] = {m: order_fit([r for r in rows if r["status"] == "ok"], m)
                                          for m in rows[0]["metrics"]} if rows[0].get("metrics") else {}
                res["at_1_percent"] = at_target(rows)
            results[engine] = res
        if info["kind"] == "bed" and "jdem" in results:
            results["jdem"]["floors"] = bed_floors(info)
        if info["kind"] == "bed":
            for res in results.values():
                if res.get("rows"):
                    res["order_against_time"] = order_against_time(res["rows"])
        figures[item] = [plot_item(out, item, info, results)]
        if info["kind"] == "bed" and results.get("jdem", {}).get("rows"):
            figures[item].append(plot_bed_divergence(out, info, results))
        summary["items"][item] = {k: info[k] for k in ("scene", "case", "kind", "guard_dt", "duration",
                                                       "factors", "reference_factor")}
        summary["items"][item]["engines"] = results
    summary["default_dt"] = dict(zip(("recommended_factor", "jdem_1_percent_factor_by_item"),
                                     recommended_factor(summary["items"])))
    summary["default_dt"]["bed_scene_auto_dt_factor"] = runs["items"].get("bed", {}).get("scene_dt", 0) / \
        runs["items"]["bed"]["guard_dt"] if "bed" in runs["items"] else None
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    from scripts import accuracy_text
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write(accuracy_text.report(summary, figures))
