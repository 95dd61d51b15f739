"""report.md of the work-precision study (scripts/accuracy.py) from its summary."""
import math

from scripts.accuracy_report import ENGINE_LABEL, TARGET, factor_name

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
        return "not reached (error > 1 % at the smallest swept dt)", None, None, None
    dt = "%s (%s guard)" % (fnum(a["dt"]), ffac(a["factor"]))
    if a["bound"] == "swept maximum":
        dt = "≥ " + dt
    return dt, a["wall_s"], a.get("cpu_s"), a["loop_s"]


def summary_table(s):
    L = ["| item | engine | observed order (slope of log error vs log dt) | dt for 1 % error "
         "| wall time there [s] | CPU time there [s] | loop time there [s] |\n", "|---|---|---|---|---|---|---|\n"]
    for item, it in s["items"].items():
        for engine, res in it["engines"].items():
            if res.get("problem"):
                L.append("| %s | %s | %s | | | | |\n" % (item, engine, res["problem"]))
                continue
            dt, wall, cpu, loop = at_text(res.get("at_1_percent"))
            L.append("| %s | %s | %s | %s | %s | %s | %s |\n" % (item, ENGINE_LABEL[engine], fnum(res["order"], "%.2f"),
                                                               dt, fnum(wall), fnum(cpu), fnum(loop)))
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
        if "ke_history" in fl["seeds"]:
            L.append("The kinetic-energy histories of the other realisations differ from this one's by "
                     "ke_history = %.2e on average: the dt-induced differences above are of the kind two "
                     "realisations of the same bed show.\n" % fl["seeds"]["ke_history"]["mean"])
    return "".join(L)


SETUP = """## Set-up

* **Items.** Chung–Ooi Tests 1, 3 and 4 (cases chosen from `reference_runs/chung_ooi/`; Test 4 once
  in stick and once in gross sliding) and the settling of a small bed
  (`reference_runs/accuracy/bed.yaml`: 343 spheres on a jittered lattice fall into an open box,
  0.15 s). Every run of an item starts from the same physical state and lasts the same physical
  time (the resolved case with dt and the step count changed; Test 1 writes every step, the
  force history being the measurement; Tests 3 and 4 the first and last frame; the bed a frame
  every ~1 ms at the same times for every dt).
* **dt.** Factors of the time-step guard's largest safe dt of each case (stepper/guard.c: the
  smaller of 20 % of the Rayleigh step and 1/50 of the shortest Hertz contact time): impacts
  1/8 … 8, the bed 1/2 … 8 (a finer bed sweep would need a reference beyond the study's 15 min
  budget). Factors above 1 exceed the guard: jdem runs them with `--force`.
* **Engines.** `jdem` (build/jdem); `liggghts-jdem` (build/liggghts-jdem, `pair_style gran/jiang`,
  deck from scripts/scene_to_liggghts.py); LIGGGHTS' own `hertz tangential history` law (deck from
  `scene_to_liggghts.py --builtin`, primitive walls), run by build/liggghts-jdem for its trajectory
  writer. Each engine is compared with its own reference run: the built-in law is a different
  law (other damping and tangential stiffness), so only its convergence and cost are comparable.
  For Test 1 (elastic, equal spheres, no friction) the three laws coincide.
* **Timing.** Every sweep run is timed {repeats} times, serially (median shown): wall time and
  CPU time (user + system, getrusage) of the whole process, and the run loop alone (LIGGGHTS:
  its `Loop time`; jdem: minus a 1-step run of the same case, shown when above the noise).
  The machine ({cpus} cores) was shared with other jobs: the 1-minute load average during
  the runs was {load}, so wall times are noisy; CPU times are steadier. No timing is asserted
  anywhere.
* **Single impacts are start-up dominated**: jdem starts in ~10 ms, LIGGGHTS (MPI
  initialisation, input parsing) in ~0.4–0.6 s, while the impacts themselves take 0.1–1 ms of
  loop time. The wall time a user waits is the whole process; the loop times compare the
  engines' stepping.
"""


def setup_text(s):
    loads = [r["load"] for it in s["items"].values() for res in it["engines"].values()
             for r in (res.get("rows") or []) if r.get("load") is not None]
    load = "%.1f–%.1f (median %.1f)" % (min(loads), max(loads), sorted(loads)[len(loads) // 2]) if loads else "—"
    return SETUP.format(repeats=s["repeats"], cpus=s["machine"]["cpus"], load=load)


def default_dt_text(s):
    d = s.get("default_dt") or {}
    if not d.get("recommended_factor"):
        return ""
    limits = ", ".join("%s %s" % (k, ffac(v)) for k, v in d["jdem_1_percent_factor_by_item"].items())
    L = ["\n## The default time step of jdem\n\n",
         "jdem's dt for 1 %% error, as a multiple of the guard's dt: %s (≥ when beyond the sweep). "
         "Rule: the largest power of two ≤ 1 (the guard is the upper limit) not above any of them "
         "→ **%s × the guard's dt**. " % (limits, ffac(d["recommended_factor"]))]
    if d.get("bed_scene_auto_dt_factor"):
        L.append("The jdem that ran this study resolves `dt: auto` (reference_runs/accuracy/bed.yaml) to "
                 "%.4g × the guard's dt (`JD_DT_AUTO_FACTOR`, stepper/sim.h; the guard's dt is read "
                 "from jdem's message with 6 digits). " % d["bed_scene_auto_dt_factor"])
    L.append("Evidence and reasoning: docs/model.md \"Default time step\".\n")
    return "".join(L)


def bed_text(it):
    res = it["engines"].get("jdem", {})
    ot = res.get("order_against_time")
    if not ot:
        return ""
    L = ["\nThe bed's collisions are chaotic: a difference in dt (or in round-off) grows until two runs "
         "are different realisations of the same bed (figure `bed_divergence.png`). The observed order "
         "of the rms position difference against the time it is measured at (jdem):\n\n",
         "| t [s] | " + " | ".join(ot) + " |\n", "|---" * (len(ot) + 1) + "|\n",
         "| order | " + " | ".join("%.2f" % v["order"] for v in ot.values()) + " |\n",
         "\nUp to ~20 ms the differences grow in proportion to the truncation error (order ≈ 1, "
         "the order of a step with contact onsets inside it): `position_early` at 20 ms is the bed's "
         "error metric. Later the collision cascade mixes them, the order falls towards 0 and the "
         "differences saturate near R for every dt: a pointwise error means nothing there. The settled "
         "state is therefore compared statistically (packing fraction, coordination, kinetic-energy "
         "history; reported, not part of the error), against the limits below.\n"]
    return "".join(L)


def report(s, figures):
    L = ["# Error against run time: the work-precision study\n\n",
         "Generated by `make accuracy` (`scripts/accuracy.py run`; analysed %s); the study took %s s "
         "of wall time. Data: `summary.json` (every run: dt, steps, times of every repeat, load "
         "average, every metric with its reference-run value and error).\n\n"
         % (s["generated"], fnum(s.get("study_wall_seconds"), "%.0f")),
         "Error: relative difference of each metric from the engine's own reference run at a time "
         "step 16 × smaller than the smallest swept one; the largest over the item's metrics is the "
         "item's error. dt for 1 %% error: the largest swept dt at which that error, and the error of "
         "every smaller swept dt, is ≤ %g, refined by log–log interpolation towards the next swept dt "
         "(wall time interpolated the same way).\n\n" % TARGET,
         setup_text(s),
         "\n## dt and time each engine needs for 1 % error\n\n", summary_table(s),
         "\n### jdem's wall time against LIGGGHTS' at 1 % error\n\n", ratio_table(s),
         "\nWhere the 1 % point lies beyond the sweep (≥), the times are those of the largest swept dt.\n",
         default_dt_text(s)]
    for item, it in s["items"].items():
        L.append(item_section(item, it, figures.get(item, [])))
        if it["kind"] == "bed":
            L.append(bed_text(it))
            L.append(bed_floor_section(it))
    return "".join(L)
