"""report.md of the work-precision study (scripts/accuracy.py) from its summary."""
import math

from accuracy_report import ENGINE_LABEL, TARGET, factor_name

WHAT = {"test1_glass": "Chung–Ooi Test 1, glass: elastic head-on impact of two spheres at ±10 m/s",
        "test3_al_oxide_e050_jiang2021": "Chung–Ooi Test 3, alumina on a plane at 3.9 m/s, e = 0.5 (jiang2021 damping)",
        "test4_al_oxide_theta20": "Chung–Ooi Test 4, alumina, oblique impact at 20° (stick, X = 1.75)",
        "test4_al_oxide_theta45": "Chung–Ooi Test 4, alumina, oblique impact at 45° (gross sliding, X = 0.64)",
        "bed": "343 spheres (R = 1 mm, E = 10 MPa) fall into a box and settle, 0.15 s"}


def fnum(x, spec="%.3g"):
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else spec % x


def ffac(f):
    if f is None:
        return "—"
    if f >= 1 or abs(1 / f - round(1 / f)) > 1e-9:
        return "%.3g" % f
    return "1/%d" % round(1 / f)


def at_text(a):
    if a is None:
        return "not reached (error > 1 % at the smallest swept dt)", None, None
    dt = "%s (%s guard)" % (fnum(a["dt"]), ffac(a["factor"]))
    if a["bound"] == "swept maximum":
        dt = "≥ " + dt
    return dt, a["wall_s"], a["loop_s"]


def summary_table(s):
    L = ["| item | engine | observed order (slope of log error vs log dt) | dt for 1 % error "
         "| wall time there [s] | loop time there [s] |\n", "|---|---|---|---|---|---|\n"]
    for item, it in s["items"].items():
        for engine, res in it["engines"].items():
            if res.get("problem"):
                L.append("| %s | %s | %s | | | |\n" % (item, engine, res["problem"]))
                continue
            dt, wall, loop = at_text(res.get("at_1_percent"))
            L.append("| %s | %s | %s | %s | %s | %s |\n" % (item, ENGINE_LABEL[engine], fnum(res["order"], "%.2f"),
                                                          dt, fnum(wall), fnum(loop)))
    return "".join(L)


def ratio_table(s):
    L = ["| item | jdem wall [s] | liggghts-jdem wall [s] | LIGGGHTS hertz/history wall [s] "
         "| liggghts-jdem / jdem | LIGGGHTS / jdem | loop-time ratios (liggghts-jdem, LIGGGHTS) / jdem |\n",
         "|---|---|---|---|---|---|---|\n"]
    for item, it in s["items"].items():
        a = {e: (r.get("at_1_percent") or {}) for e, r in it["engines"].items()}
        w = {e: a[e].get("wall_s") for e in a}
        lp = {e: a[e].get("loop_s") for e in a}

        def ratio(d, e):
            return fnum(d.get(e) / d["jdem"], "%.2f") if d.get(e) and d.get("jdem") else "—"
        L.append("| %s | %s | %s | %s | %s | %s | %s, %s |\n" % (
            item, fnum(w.get("jdem")), fnum(w.get("liggghts-jdem")), fnum(w.get("liggghts")),
            ratio(w, "liggghts-jdem"), ratio(w, "liggghts"), ratio(lp, "liggghts-jdem"), ratio(lp, "liggghts")))
    return "".join(L)


def item_section(item, it, figures):
    L = ["\n## %s\n\n%s. Guard dt %s s; swept factors %s; reference at %s of the guard dt; %.3g s "
         "of physical time.\n\n" % (item, WHAT.get(item, item), fnum(it["guard_dt"], "%.4g"),
                                    ", ".join(ffac(f) for f in it["factors"]), ffac(it["reference_factor"]),
                                    it["duration"])]
    L += ["![%s](%s)\n" % (f, f) for f in figures]
    for engine, res in it["engines"].items():
        if not res.get("rows"):
            L.append("\n**%s**: %s\n" % (ENGINE_LABEL[engine], res.get("problem")))
            continue
        rows = res["rows"]
        metrics = list(next((r["metrics"] for r in rows if r.get("metrics")), {}))
        L.append("\n**%s** (order by metric: %s)\n\n" % (ENGINE_LABEL[engine], ", ".join(
            "%s %s" % (m, fnum(res["order_by_metric"].get(m), "%.2f")) for m in metrics)))
        L.append("| dt / guard | dt [s] | steps | wall [s] | CPU [s] | loop [s] | %s | largest |\n"
                 % " | ".join("error %s" % m for m in metrics))
        L.append("|---" * (7 + len(metrics)) + "|\n")
        for r in rows:
            errs = " | ".join(fnum(r["metrics"][m]["error"], "%.2e") for m in metrics) if r.get("metrics") \
                else " | ".join("failed" for _ in metrics)
            L.append("| %s | %.4g | %d | %s | %s | %s | %s | %s |\n" % (
                ffac(r["factor"]), r["dt"], r["steps"], fnum(r["wall_s"]), fnum(r["cpu_s"]), fnum(r["loop_s"]),
                errs, fnum(r.get("error"), "%.2e")))
        closed = [m for m in metrics if any(r.get("metrics", {}).get(m, {}).get("closed_form") is not None
                                            for r in rows)]
        if closed:
            L.append("\nAgainst the closed form / limit of the benchmark (relative error): %s\n\n" % "; ".join(
                "%s = %s: %s" % (m, fnum(next(r["metrics"][m]["closed_form"] for r in rows if r.get("metrics")), "%.6g"),
                                 ", ".join("%s → %s" % (ffac(r["factor"]), fnum(r["metrics"][m]["closed_form_error"], "%.1e"))
                                           for r in rows if r.get("metrics"))) for m in closed))
    return "".join(L)


def bed_floor_section(it):
    fl = it["engines"].get("jdem", {}).get("floors")
    if not fl:
        return ""
    L = ["\n### What the bed's errors can show\n\n",
         "Round-off floor: the same statistics of liggghts-jdem measured against jdem at the same dt "
         "(the same law summed in another order: their difference is round-off amplified by the "
         "collisions):\n\n| dt / guard | packing_fraction | coordination | ke_history |\n|---|---|---|---|\n"]
    for f in it["factors"]:
        r = fl["roundoff"].get(factor_name(f))
        if r:
            L.append("| %s | %.2e | %.2e | %.2e |\n" % (ffac(f), r["packing_fraction"], r["coordination"], r["ke_history"]))
    if fl.get("seeds"):
        L.append("\nSpread over lattice seeds (jdem at %s guard dt, %d realisations): relative standard deviation "
                 "of the packing fraction %.2e, of the coordination %.2e.\n"
                 % (ffac(min(it["factors"])), len(fl["seeds"]["packing_fraction"]["values"]),
                    fl["seeds"]["packing_fraction"]["relative_std"], fl["seeds"]["coordination"]["relative_std"]))
    return "".join(L)


def report(s, figures):
    L = ["# Error against run time: the work-precision study\n\n",
         "Generated by `make accuracy` (`scripts/accuracy.py run`) at %s; %s study wall time %s s. "
         "Every sweep run was timed %d times (median shown); the machine has %s CPUs shared with other "
         "jobs, so wall times are noisy (CPU times and the load average are in summary.json).\n\n"
         % (s["generated"], "", fnum(s.get("study_wall_seconds"), "%.0f"), s["repeats"], s["machine"]["cpus"]),
         "Error: relative difference of each metric from the engine's own reference run at a time "
         "step 16 × smaller than the smallest swept one; the largest over the item's metrics is the "
         "item's error. dt for 1 %% error: the largest swept dt at which that error, and the error of "
         "every smaller swept dt, is ≤ %g, refined by log–log interpolation towards the next swept dt "
         "(wall time interpolated the same way).\n\n" % TARGET,
         "## dt and wall time each engine needs for 1 % error\n\n", summary_table(s),
         "\n### jdem's wall time against LIGGGHTS' at 1 % error\n\n", ratio_table(s)]
    for item, it in s["items"].items():
        L.append(item_section(item, it, figures.get(item, [])))
        if it["kind"] == "bed":
            L.append(bed_floor_section(it))
    return "".join(L)
