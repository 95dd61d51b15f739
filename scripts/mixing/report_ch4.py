#!/usr/bin/python3
"""report_ch4.py — the Chapter 4 tables, seed | jdem | liggghts-jdem, from whatever units of
`make mixing` have finished (docs/mixing.md §4).

    /usr/bin/python3 -m scripts.mixing.report_ch4 [--out out/mixing/ch4] [--results DIR]

Reads OUT/ENGINE/modelM/fillP.h5 (the mixing parameters at the 9 points of Table 4-2, from the
last frame) and OUT/ENGINE/modelM/passP_cubeK.h5 (the compression of cube K: E, nu_xy, nu_xz of
the orthotropic fit on the best-fit particle strain, and the unambiguous M and K0), and the
units' wall and CPU seconds from OUT/ENGINE/modelM/.campaign_times.json.  Writes OUT/report.md,
OUT/summary.json and the seed's Figs 4-11/4-12 (plots.mixing_figure, drawn from the summary);
with --results also there (the small results committed under reference_runs/mixing/ch4/results/,
the default for the default OUT when it exists).

The working outputs under OUT do not travel with the repository, so every result not found
under OUT (a fill, a jitter fill, a set of 9 cubes, a unit's times) is taken from the committed
RESULTS/summary.json; a local result always wins.  Every entry of summary.json says where it
came from ("source": the commit of the report that computed it, kept as it is when an old entry
is written again), and report.md lists under each table the rows taken from an earlier commit.
A unit that is neither local nor committed is "—" in the tables and listed under "Not run";
nothing is estimated.
"""
import argparse
import json
import os
import subprocess

import numpy as np

from scripts.mixing import (agreement_ch4, claims_ch4, compression, deposit, dt_study_ch4, params, plots,
                            stats, structure)
from scripts.mixing.stats import cell
from scripts.mixing_views import scene_geometry

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_OUT = os.path.join(ROOT, "out", "mixing", "ch4")
# The committed results belong to the seed-dt campaign of DEFAULT_OUT only (the DT=guard/half
# variants write elsewhere and must not be mixed with them).
DEFAULT_RESULTS = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "results")

ENGINES = ("jdem", "liggghts-jdem")
MODELS = tuple("model%d" % m for m in range(1, 7))
PASSES = (1, 2)
PARAMS = ("phi_v", "phi_m", "e", "n", "rho_b", "Z")
# spec §3.1-3.3 (Tables 4-3, 4-4, 4-5): (1st mean, 1st std, 2nd mean, 2nd std) per model
SEED = {
    "E": [(1954, 841, 2249, 782), (2230, 992, 1812, 189), (2842, 1255, 1776, 445),
          (3211, 1731, 2564, 577), (1817, 367, 2171, 830), (2105, 1046, 1736, 662)],
    "nu_xy": [(0.631, 0.158, 0.690, 0.075), (0.710, 0.136, 0.633, 0.064), (0.842, 0.224, 0.608, 0.058),
              (0.861, 0.323, 0.767, 0.077), (0.651, 0.099, 0.688, 0.122), (0.666, 0.204, 0.573, 0.124)],
    "nu_xz": [(0.320, 0.134, 0.281, 0.079), (0.269, 0.126, 0.328, 0.046), (0.127, 0.210, 0.340, 0.046),
              (0.095, 0.312, 0.221, 0.077), (0.302, 0.070, 0.272, 0.101), (0.285, 0.182, 0.351, 0.093)],
}
TABLES = (("E", "Table 4-3: effective elastic modulus E [Pa]", "%.0f"),
          ("nu_xy", "Table 4-4: effective Poisson ratio νxy", "%.3f"),
          ("nu_xz", "Table 4-5: effective Poisson ratio νxz (= νyz)", "%.3f"))


def unit_dir(out, engine, model):
    return os.path.join(out, engine, model)


def unit_times(out, engine, model):
    try:
        with open(os.path.join(unit_dir(out, engine, model), ".campaign_times.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def fill_result(path):
    dep = deposit.read_frame(path)
    points = params.at_points(dep)
    big = params.big_mask(dep.radius)
    x = dep.position[:, 0]
    sides = {"big_right": float(np.mean(x[big] > 0.5)), "small_left": float(np.mean(x[~big] < 0.5))}
    box, _, _ = scene_geometry(path)
    return {"particles": int(len(dep.radius)), "deposit_height": deposit.deposit_height(dep),
            "bed_height": structure.free_surface(dep, *box)["mean"], "sides": sides,
            "points": [{k: float(p[k]) for k in PARAMS} for p in points],
            "summary": {k: stats.summary([p[k] for p in points]) for k in PARAMS},
            "built_by": deposit.built_by(path)}


def cube_result(path):
    r = compression.analyse(path, "top")
    fit = r["best_fit"]
    return {"E": fit.get("E", float("nan")), "nu_xy": fit.get("nu_xy", float("nan")),
            "nu_xz": fit.get("nu_xz", float("nan")), "cond": fit.get("cond", float("nan")),
            "M_wall": r["M_wall"], "M_best_fit": r["M_best_fit"], "K0": r["K0"],
            "particles": r["particles"], "built_by": deposit.built_by(path)}


def jitter_fills(d):
    """The finished realisations fill1_jitterK.h5 of a model's first fill, K = 1, 2, ..."""
    found, k = [], 1
    while os.path.exists(os.path.join(d, "fill1_jitter%d.h5" % k)):
        found.append(os.path.join(d, "fill1_jitter%d.h5" % k))
        k += 1
    return found


def spread_table(found, taken):
    """The run-to-run spread: the first fill and its jittered realisations (generate.py
    --jitter), their trimmed means, and the sample std of those means."""
    lines = ["### Run-to-run spread (the first fill and its realisations with the stream shifted by "
             "K micrometres in y)", "",
             "| engine | model | realisation | top [m] | bed [m] | φv | e | ρb [kg/m³] | Z |",
             "|---|---|---|---|---|---|---|---|---|"]
    keys = (("phi_v", "%.4f"), ("e", "%.3f"), ("rho_b", "%.0f"), ("Z", "%.2f"))
    shown = set()   # (engine, model) of the rows
    for engine in ENGINES:
        for model in MODELS:
            entry = found[engine][model]
            runs = ([entry["fill1"]] if entry.get("fill1") else []) + entry.get("jitter", [])
            if len(runs) < 2:
                continue
            shown.add((engine, model))
            for k, r in enumerate(runs):
                lines.append("| %s | %s | %s | %.3f | %s | %s |" % (
                    engine, model, "K = %d" % k, r["deposit_height"], bed_height(r),
                    " | ".join(fmt % r["summary"][key]["mean"] for key, fmt in keys)))
            std = lambda vals: float(np.std(vals, ddof=1))
            beds = [r.get("bed_height") for r in runs]
            lines.append("| %s | %s | std of the %d | %.3f | %s | %s |" % (
                engine, model, len(runs), std([r["deposit_height"] for r in runs]),
                "—" if None in beds else "%.3f" % std(beds),
                " | ".join(fmt % std([r["summary"][key]["mean"] for r in runs]) for key, fmt in keys)))
    if not shown:
        return ""
    jitter = [(k[0], "K = %d" % (k[3] + 1), model_number(k[1]), source)
              for k, source in taken.items() if k[2] == "jitter"]
    first = [r for r in taken_rows(taken, "fill1", "K = 0") if (r[0], "model%d" % r[2]) in shown]
    return "\n".join(lines) + "\n" + earlier_note(first + jitter)


def collect(out):
    """{engine: {model: {"fillP": ..., "passP_cubes": [...], "times": ...}}} of the finished units,
    and the units not finished as (engine, model, key of the entry, message)."""
    found, missing = {}, []
    for engine in ENGINES:
        for model in MODELS:
            d = unit_dir(out, engine, model)
            entry = {"times": unit_times(out, engine, model)}
            for p in PASSES:
                fill = os.path.join(d, "fill%d.h5" % p)
                if os.path.exists(fill):
                    entry["fill%d" % p] = fill_result(fill)
                else:
                    missing.append((engine, model, "fill%d" % p, "%s/%s/fill%d" % (engine, model, p)))
                if p == 1:
                    entry["jitter"] = [fill_result(j) for j in jitter_fills(d)]
                cubes = [os.path.join(d, "pass%d_cube%d.h5" % (p, k)) for k in range(1, 10)]
                done = [c for c in cubes if os.path.exists(c)]
                if len(done) == 9:
                    try:
                        entry["pass%d_cubes" % p] = [cube_result(c) for c in cubes]
                    except SystemExit as why:   # compression.py's message: a servo that did not complete
                        missing.append((engine, model, "pass%d_cubes" % p,
                                        "%s/%s/pass%d_cubes: %s" % (engine, model, p, why)))
                else:
                    missing.append((engine, model, "pass%d_cubes" % p,
                                    "%s/%s/pass%d_cubes (%d of 9)" % (engine, model, p, len(done))))
            found.setdefault(engine, {})[model] = entry
    return found, missing


def committed_summary(results):
    """The summary.json committed in the directory `results` ({} when there is none)."""
    try:
        with open(os.path.join(results, "summary.json")) as f:
            return json.load(f)
    except FileNotFoundError:
        return {}


def stamped(entry, source):
    """A copy of a fill or cube result or a unit's times with its "source"; an entry that has one
    keeps it (an old result written again is not restamped)."""
    return dict(entry, source=entry.get("source", source))


def merge_entry(mine, theirs, rev, theirs_rev, key, taken):
    """The merged value of one entry of found[engine][model] (a fill, the jitter list, a cube
    set, the times); `taken` gets key (+ index or unit) -> source for what came from theirs."""
    name = key[-1]
    if name == "times":
        merged = {u: stamped(t, rev) for u, t in mine.get("times", {}).items()}
        for u, t in theirs.get("times", {}).items():
            if u not in merged:
                merged[u] = stamped(t, theirs_rev)
                taken[key + (u,)] = merged[u]["source"]
        return merged
    if name == "jitter":   # realisation K is the K-th of the list, local ones first (jitter_fills)
        local, old = mine.get("jitter", []), theirs.get("jitter", [])
        merged = [stamped(f, rev) for f in local]
        for k in range(len(local), len(old)):
            merged.append(stamped(old[k], theirs_rev))
            taken[key + (k,)] = merged[-1]["source"]
        return merged
    if mine.get(name):
        local = mine[name]
        return [stamped(c, rev) for c in local] if isinstance(local, list) else stamped(local, rev)
    old = theirs[name]
    merged = [stamped(c, theirs_rev) for c in old] if isinstance(old, list) else stamped(old, theirs_rev)
    taken[key] = (merged[0] if isinstance(merged, list) else merged)["source"]
    return merged


def merge(found, missing, committed, rev):
    """found (local, stamped with rev) completed by the committed summary's entries that found
    lacks; returns (merged, the messages of the units in neither, taken: {(engine, model, key
    [, index or unit]): source} of the committed entries used)."""
    theirs_all, theirs_rev = committed.get("results", {}), committed.get("commit", "unknown")
    merged, taken = {}, {}
    for engine in ENGINES:
        for model in MODELS:
            mine, theirs = found[engine][model], theirs_all.get(engine, {}).get(model, {})
            names = ["times", "jitter"] + [k for k in ["fill%d" % p for p in PASSES] +
                                           ["pass%d_cubes" % p for p in PASSES]
                                           if mine.get(k) or theirs.get(k)]
            merged.setdefault(engine, {})[model] = {
                n: merge_entry(mine, theirs, rev, theirs_rev, (engine, model, n), taken) for n in names}
    not_run = [message for engine, model, key, message in missing if not merged[engine][model].get(key)]
    return merged, not_run, taken


def model_ranges(numbers):
    """[1, 2, 3, 5] -> "model1–3, 5"."""
    numbers, runs = sorted(set(numbers)), []
    for n in numbers:
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    return "model" + ", ".join("%d" % a if a == b else "%d–%d" % (a, b) for a, b in runs)


def earlier_note(rows):
    """The footnote of a table: rows is [(engine, what, model number, source)] of its rows taken
    from the committed summary, e.g. "- jdem model1–6 pass 1: from commit eda0a7e"."""
    groups = {}
    for engine, what, m, source in rows:
        groups.setdefault((engine, what, source), []).append(m)
    if not groups:
        return ""
    lines = ["- %s %s%s: from commit %s" % (engine, model_ranges(ms), what and " " + what, source)
             for (engine, what, source), ms in groups.items()]
    return ("\nFrom an earlier commit (the committed summary.json; no output under --out):\n\n"
            + "\n".join(lines) + "\n")


def model_number(model):
    return int(model[len("model"):])


def taken_rows(taken, name, what):
    """earlier_note rows of the committed entries whose key is `name` (e.g. "fill1")."""
    return [(k[0], what, model_number(k[1]), source) for k, source in taken.items()
            if len(k) == 3 and k[2] == name]


def ours(found, engine, model, p, key):
    cubes = found[engine][model].get("pass%d_cubes" % p)
    if not cubes:
        return None, None
    s = stats.summary([c[key] for c in cubes])
    return s["mean"], s["std"]


def elastic_table(found, taken, key, title, fmt):
    head = ("| Model | seed 1st | jdem 1st | liggghts-jdem 1st | seed 2nd | jdem 2nd | "
            "liggghts-jdem 2nd |\n|---|---|---|---|---|---|---|\n")
    rows = []
    for m, model in enumerate(MODELS):
        s = SEED[key][m]
        cols = []
        for p in PASSES:
            cols.append(cell(s[2 * (p - 1)], s[2 * (p - 1) + 1], fmt))
            cols += [cell(*ours(found, e, model, p, key), fmt) for e in ENGINES]
        rows.append("| %d | %s |" % (m + 1, " | ".join(cols)))
    return "### %s\n\nmean ± std over the 9 cubes, the highest and lowest dropped (docs/mixing.md §3)\n\n%s%s\n%s" % (
        title, head, "\n".join(rows), earlier_note(cube_rows(taken)))


def cube_rows(taken):
    """earlier_note rows of the committed cube sets of every pass."""
    return [r for p in PASSES for r in taken_rows(taken, "pass%d_cubes" % p, "pass %d cubes" % p)]


def constants_table(found, taken):
    """M (wall strain and best-fit strain) and K0 of every finished deposit: the unambiguous
    constants of a laterally confined cube (docs/model.md §10); the seed gives neither."""
    lines = ["### Constrained modulus M = σzz/εzz and K0 = (σxx+σyy)/(2σzz)", "",
             "mean ± std over the 9 cubes, the highest and lowest dropped; the seed reports neither", "",
             "| engine | model | pass | M, wall strain [Pa] | M, best-fit strain [Pa] | K0 | condition number of the fit |",
             "|---|---|---|---|---|---|---|"]
    for engine in ENGINES:
        for model in MODELS:
            for p in PASSES:
                cubes = found[engine][model].get("pass%d_cubes" % p)
                if not cubes:
                    continue
                col = lambda k, fmt: cell(*ours(found, engine, model, p, k), fmt)
                lines.append("| %s | %s | %d | %s | %s | %s | %s |" % (
                    engine, model, p, col("M_wall", "%.0f"), col("M_best_fit", "%.0f"),
                    col("K0", "%.3f"), col("cond", "%.0f")))
    return "\n".join(lines) + "\n" + earlier_note(cube_rows(taken))


def bed_height(fill):
    """The bed's mean surface height [m] (structure.free_surface: spheres held above the bed by
    an obstacle are not its surface) as a cell, "—" for a result computed before it was kept."""
    return "—" if fill.get("bed_height") is None else "%.3f" % fill["bed_height"]


def mixing_table(found, taken):
    lines = ["### Mixing parameters at the 9 points of Table 4-2 (the seed gives plots only, Figs 4-11/4-12)",
             "", "trimmed mean ± std (ideal φv = %.4f)" % params.IDEAL_PHI_V, "",
             "top: the highest sphere's top; bed: the mean height of the bed's free surface "
             "(scripts/mixing/structure.py, spheres resting on an obstacle above the bed left out)", "",
             "| engine | model | pass | particles | top [m] | bed [m] | φv | e | ρb [kg/m³] | Z |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for engine in ENGINES:
        for model in MODELS:
            for p in PASSES:
                f = found[engine][model].get("fill%d" % p)
                if not f:
                    continue
                s = f["summary"]
                lines.append("| %s | %s | %d | %d | %.3f | %s | %s | %s | %s | %s |" % (
                    engine, model, p, f["particles"], f["deposit_height"], bed_height(f),
                    cell(s["phi_v"]["mean"], s["phi_v"]["std"], "%.4f"), cell(s["e"]["mean"], s["e"]["std"], "%.3f"),
                    cell(s["rho_b"]["mean"], s["rho_b"]["std"], "%.0f"), cell(s["Z"]["mean"], s["Z"]["std"], "%.2f")))
    return "\n".join(lines) + "\n" + earlier_note(
        [r for p in PASSES for r in taken_rows(taken, "fill%d" % p, "pass %d" % p)])


def times_table(found, taken):
    lines = ["### Run times of the finished units", "",
             "wall time on the shared machine, the CPU time of the unit's processes, the MPI ranks "
             "it ran on, jdem's threads, and the attempts they add up (a unit resumed after an "
             "interruption; \"not recorded\": timed before the campaign added up the attempts, so "
             "a resumed unit's times are its last attempt's only); the machine, where recorded", "",
             "| unit | wall [s] | CPU [s] | ranks | threads | attempts | machine |",
             "|---|---|---|---|---|---|---|"]
    for engine in ENGINES:
        for model in MODELS:
            for name, t in sorted(found[engine][model]["times"].items()):
                cpu, ranks = t.get("cpu_seconds"), t.get("ranks")
                lines.append("| %s | %.0f | %s | %s | %s | %s | %s |" % (
                    name, t["seconds"], "%.0f" % cpu if cpu is not None else "not recorded",
                    ranks if ranks is not None else 1,    # before ranks were recorded: all ran on one
                    t.get("threads", "not recorded"), t.get("attempts", "not recorded"),
                    t.get("machine", "not recorded")))
    units = [(u.split("/")[0], "units", model_number(u.split("/")[1]), source)
             for k, source in taken.items() if k[2] == "times" for u in [k[3]]]
    return "\n".join(lines) + "\n" + earlier_note(units)


def horizon_section(results=os.path.join(ROOT, "reference_runs", "mixing", "ch4", "results", "horizon")):
    """The cross-engine horizon of the first fills: the table of `horizon_ch4.py summary` (the
    cross/modelM/horizon units), as committed in RESULTS (make mixing-report refreshes it first)."""
    from scripts.mixing import horizon_ch4
    models = horizon_ch4.read_summary(results)
    head = "### Cross-engine horizon of the first fills, jdem vs liggghts-jdem\n\n"
    if not models:
        return head + "not run (make mixing ENGINE=cross)\n"
    return head + ("Particles matched by id; per frame (every 0.02 s) the larger of max |Δx| / R_max "
                   "and max |Δv| / sqrt(g d_max), as in the pour study (docs/mixing.md §4); plot: "
                   "horizon/horizon.png.\n\n") + horizon_ch4.table(models)


def commit():
    r = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    return r.stdout.strip() or "unknown"


def figures_section(figures):
    """Links to the written Figs 4-11/4-12 ({(engine, pass): file name})."""
    lines = ["### Figs 4-11 and 4-12: the mixing parameters at the 9 points", "",
             "drawn from summary.json (the rows of the first table, whatever their source); one "
             "figure per engine and pass, panels (a)–(f) φv, φm, e, n, ρb, Z as in the seed", ""]
    lines += ["![Fig. %s, %s, pass %d](%s)" % (plots.SEED_FIGURE[p], engine, p, name)
              for (engine, p), name in sorted(figures.items())]
    missing = ["Fig. %s (%s pass %d): no finished fill" % (plots.SEED_FIGURE[p], e, p)
               for e in ENGINES for p in PASSES if (e, p) not in figures]
    return "\n".join(lines + [""] + ["- " + m for m in missing]) + "\n"


SPEED_RESULTS = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "results")
# the committed speed measurements the report shows: the first 5 s in all ten configurations
# (`make mixing-speed`), and the first 12 s on one core, where the bed begins to dominate as it
# does over a whole fill (`make mixing-speed SPEED_TIME=12 SPEED_ONLY=jdem/1,liggghts-skin0.5/1`)
SPEEDS = (("speed", "the first seconds of a fill in the three engines", "`make mixing-speed`"),
          ("speed_12s", "the first 12 s of a fill on one core",
           "`make mixing-speed SPEED_TIME=12 SPEED_ROUNDS=1 SPEED_ONLY=jdem/1,liggghts-skin0.5/1`"))


def speed_section(results=SPEED_RESULTS):
    """The fill's speed in jdem, liggghts-jdem and stock LIGGGHTS, as each committed measurement
    of SPEEDS last gave it (its summary.json)."""
    from scripts.mixing import speed_ch4
    parts = []
    for name, what, command in SPEEDS:
        head = f"### Speed: {what}\n\n"
        path = os.path.join(results, name, "summary.json")
        if not os.path.exists(path):
            parts.append(head + f"(not measured yet: {command})\n")
            continue
        with open(path) as f:
            summary = json.load(f)
        parts.append(head + speed_ch4.describe(summary) + f" {command}; docs/mixing.md §10.\n\n"
                     + speed_ch4.table(summary))
    return "\n".join(parts)


def report(found, missing, taken, figures, rev):
    parts = ["# Jiang (2021) Chapter 4 mixing campaign: seed | jdem | liggghts-jdem", "",
             "Generated by scripts/mixing/report_ch4.py from the finished units of `make mixing` "
             "(commit %s) and, for the units without output here, the committed results of earlier "
             "commits (named under each table). Every reconstruction the seed leaves open is a scene "
             "parameter (docs/mixing.md §1).\n" % rev, mixing_table(found, taken), figures_section(figures)]
    parts += [elastic_table(found, taken, k, t, f) for k, t, f in TABLES]
    parts.append(horizon_section())
    parts += [spread_table(found, taken), agreement_ch4.table(found), constants_table(found, taken),
              dt_study_ch4.table(found, ENGINES, MODELS, PASSES), speed_section(), "### The seed's claims\n",
              claims_ch4.claims(found, ENGINES), times_table(found, taken), provenance_section(built_of(found)),
              "### Not run\n", "\n".join("- " + m for m in missing) + "\n" if missing else "nothing\n"]
    return "\n".join(parts)


def provenance_section(built):
    """{result name: [creator versions]} as the code behind each result (deposit.built_by);
    results measured before the trajectories named their commit say "not recorded"."""
    lines = ["### The code behind each result", "",
             "the creator versions of each result's trajectories (release + source commit; a run "
             "resumed by another binary lists both, earliest first)", "",
             "| result | built by |", "|---|---|"]
    def named(v):
        return v if "+" in v else v + " (before the commit was recorded)"
    lines += ["| %s | %s |" % (n, ", ".join(map(named, v)) if v else "not recorded")
              for n, v in sorted(built.items())] or ["| none yet | |"]
    return "\n".join(lines) + "\n"


def built_of(found):
    """{engine/model/fillP or passP_cubes: versions} of the found entries."""
    out = {}
    for engine, models in found.items():
        for model, entry in models.items():
            for key, value in entry.items():
                items = value if isinstance(value, list) else [value]
                if key == "times" or not items or not isinstance(items[0], dict):
                    continue
                out["%s/%s/%s" % (engine, model, key)] = list(dict.fromkeys(
                    v for it in items for v in it.get("built_by", [])))
    return out


def write_atomic(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def results_dir(out, results):
    """--results, or by default the committed results of the default OUT when they exist."""
    if results:
        return results
    same_out = os.path.abspath(out) == os.path.abspath(DEFAULT_OUT)
    return DEFAULT_RESULTS if same_out and os.path.isdir(DEFAULT_RESULTS) else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=DEFAULT_OUT)
    ap.add_argument("--results", help="take the results not under --out from DIR/summary.json, and "
                    "write the report, summary and figures there too (default: %s for the default "
                    "--out, when it exists)" % os.path.relpath(DEFAULT_RESULTS, ROOT))
    a = ap.parse_args()
    results = results_dir(a.out, a.results)
    rev = commit()
    found, missing, taken = merge(*collect(a.out), committed_summary(results) if results else {}, rev)
    summary = json.dumps({"commit": rev, "results": found, "not_run": missing}, indent=1, default=float)
    drawn_from = json.loads(summary)["results"]   # the figures show what summary.json holds
    for d in [a.out] + ([results] if results else []):
        os.makedirs(d, exist_ok=True)
        figures = plots.write_mixing_figures(drawn_from, ENGINES, d)
        write_atomic(os.path.join(d, "report.md"), report(found, missing, taken, figures, rev))
        write_atomic(os.path.join(d, "summary.json"), summary)
        print("report_ch4.py: wrote %s" % os.path.join(d, "report.md"))


if __name__ == "__main__":
    main()
