#!/usr/bin/python3
"""report_ch4.py — the Chapter 4 tables, seed | jdem | liggghts-jdem, from whatever units of
`make mixing` have finished (docs/mixing.md §4).

    /usr/bin/python3 -m scripts.mixing.report_ch4 [--out out/mixing/ch4] [--results DIR]

Reads OUT/ENGINE/modelM/fillP.h5 (the mixing parameters at the 9 points of Table 4-2, from the
last frame) and OUT/ENGINE/modelM/passP_cubeK.h5 (the compression of cube K: E, nu_xy, nu_xz of
the orthotropic fit on the best-fit particle strain, and the unambiguous M and K0), and the
units' wall and CPU seconds from OUT/ENGINE/modelM/.campaign_times.json.  Writes OUT/report.md and
OUT/summary.json; with --results also there (the small results committed under
reference_runs/mixing/ch4/results/), stamped with the commit they came from.  A unit not run is
"—" in the tables and listed under "Not run"; nothing is estimated.
"""
import argparse
import json
import math
import os
import subprocess

import numpy as np

from scripts.mixing import claims_ch4, compression, deposit, params, stats

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

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
    return {"particles": int(len(dep.radius)), "deposit_height": deposit.deposit_height(dep),
            "sides": sides,
            "points": [{k: float(p[k]) for k in PARAMS} for p in points],
            "summary": {k: stats.summary([p[k] for p in points]) for k in PARAMS}}


def cube_result(path):
    r = compression.analyse(path, "top")
    fit = r["best_fit"]
    return {"E": fit.get("E", float("nan")), "nu_xy": fit.get("nu_xy", float("nan")),
            "nu_xz": fit.get("nu_xz", float("nan")), "cond": fit.get("cond", float("nan")),
            "M_wall": r["M_wall"], "M_best_fit": r["M_best_fit"], "K0": r["K0"],
            "particles": r["particles"]}


def jitter_fills(d):
    """The finished realisations fill1_jitterK.h5 of a model's first fill, K = 1, 2, ..."""
    found, k = [], 1
    while os.path.exists(os.path.join(d, "fill1_jitter%d.h5" % k)):
        found.append(os.path.join(d, "fill1_jitter%d.h5" % k))
        k += 1
    return found


def spread_table(found):
    """The run-to-run spread: the first fill and its jittered realisations (generate.py
    --jitter), their trimmed means, and the sample std of those means."""
    lines = ["### Run-to-run spread (the first fill and its realisations with the stream shifted by "
             "K micrometres in y)", "",
             "| engine | model | realisation | height [m] | φv | e | ρb [kg/m³] | Z |",
             "|---|---|---|---|---|---|---|---|"]
    keys = (("phi_v", "%.4f"), ("e", "%.3f"), ("rho_b", "%.0f"), ("Z", "%.2f"))
    any_row = False
    for engine in ENGINES:
        for model in MODELS:
            entry = found[engine][model]
            runs = ([entry["fill1"]] if entry.get("fill1") else []) + entry.get("jitter", [])
            if len(runs) < 2:
                continue
            any_row = True
            for k, r in enumerate(runs):
                lines.append("| %s | %s | %s | %.3f | %s |" % (
                    engine, model, "K = %d" % k, r["deposit_height"],
                    " | ".join(fmt % r["summary"][key]["mean"] for key, fmt in keys)))
            std = lambda vals: float(np.std(vals, ddof=1))
            lines.append("| %s | %s | std of the %d | %.3f | %s |" % (
                engine, model, len(runs), std([r["deposit_height"] for r in runs]),
                " | ".join(fmt % std([r["summary"][key]["mean"] for r in runs]) for key, fmt in keys)))
    return "\n".join(lines) + "\n" if any_row else ""


def collect(out):
    """{engine: {model: {"fillP": ..., "passP_cubes": [...], "times": ...}}} of the finished units."""
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
                    missing.append("%s/%s/fill%d" % (engine, model, p))
                if p == 1:
                    entry["jitter"] = [fill_result(j) for j in jitter_fills(d)]
                cubes = [os.path.join(d, "pass%d_cube%d.h5" % (p, k)) for k in range(1, 10)]
                done = [c for c in cubes if os.path.exists(c)]
                if len(done) == 9:
                    try:
                        entry["pass%d_cubes" % p] = [cube_result(c) for c in cubes]
                    except SystemExit as why:   # compression.py's message: a servo that did not complete
                        missing.append("%s/%s/pass%d_cubes: %s" % (engine, model, p, why))
                else:
                    missing.append("%s/%s/pass%d_cubes (%d of 9)" % (engine, model, p, len(done)))
            found.setdefault(engine, {})[model] = entry
    return found, missing


def cell(mean, std, fmt):
    if mean is None or (isinstance(mean, float) and math.isnan(mean)):
        return "—"
    return (fmt % mean) + " ± " + (fmt % std)


def ours(found, engine, model, p, key):
    cubes = found[engine][model].get("pass%d_cubes" % p)
    if not cubes:
        return None, None
    s = stats.summary([c[key] for c in cubes])
    return s["mean"], s["std"]


def elastic_table(found, key, title, fmt):
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
    return "### %s\n\nmean ± std over the 9 cubes, the highest and lowest dropped (docs/mixing.md §3)\n\n%s%s\n" % (
        title, head, "\n".join(rows))


def constants_table(found):
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
    return "\n".join(lines) + "\n"


def mixing_table(found):
    lines = ["### Mixing parameters at the 9 points of Table 4-2 (the seed gives plots only, Figs 4-11/4-12)",
             "", "trimmed mean ± std (ideal φv = %.4f)" % params.IDEAL_PHI_V, "",
             "| engine | model | pass | particles | height [m] | φv | e | ρb [kg/m³] | Z |",
             "|---|---|---|---|---|---|---|---|---|"]
    for engine in ENGINES:
        for model in MODELS:
            for p in PASSES:
                f = found[engine][model].get("fill%d" % p)
                if not f:
                    continue
                s = f["summary"]
                lines.append("| %s | %s | %d | %d | %.3f | %s | %s | %s | %s |" % (
                    engine, model, p, f["particles"], f["deposit_height"],
                    cell(s["phi_v"]["mean"], s["phi_v"]["std"], "%.4f"), cell(s["e"]["mean"], s["e"]["std"], "%.3f"),
                    cell(s["rho_b"]["mean"], s["rho_b"]["std"], "%.0f"), cell(s["Z"]["mean"], s["Z"]["std"], "%.2f")))
    return "\n".join(lines) + "\n"


def times_table(found):
    lines = ["### Run times of the finished units", "",
             "wall time on the shared machine, and the CPU time of the unit's processes",
             "", "| unit | wall [s] | CPU [s] |", "|---|---|---|"]
    for engine in ENGINES:
        for model in MODELS:
            for name, t in sorted(found[engine][model]["times"].items()):
                cpu = t.get("cpu_seconds")
                lines.append("| %s | %.0f | %s |" % (name, t["seconds"], "%.0f" % cpu if cpu is not None else "not recorded"))
    return "\n".join(lines) + "\n"


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


def report(found, missing, rev):
    parts = ["# Jiang (2021) Chapter 4 mixing campaign: seed | jdem | liggghts-jdem", "",
             "Generated by scripts/mixing/report_ch4.py from the finished units of `make mixing` "
             "(commit %s). Every reconstruction the seed leaves open is a scene parameter "
             "(docs/mixing.md §1).\n" % rev, mixing_table(found)]
    parts += [elastic_table(found, k, t, f) for k, t, f in TABLES]
    parts.append(horizon_section())
    parts += [spread_table(found), constants_table(found), "### The seed's claims\n", claims_ch4.claims(found, ENGINES), times_table(found),
              "### Not run\n", "\n".join("- " + m for m in missing) + "\n" if missing else "nothing\n"]
    return "\n".join(parts)


def write_atomic(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "mixing", "ch4"))
    ap.add_argument("--results", help="also write report.md and summary.json here")
    a = ap.parse_args()
    found, missing = collect(a.out)
    rev = commit()
    text = report(found, missing, rev)
    summary = json.dumps({"commit": rev, "results": found, "not_run": missing}, indent=1, default=float)
    for d in [a.out] + ([a.results] if a.results else []):
        os.makedirs(d, exist_ok=True)
        write_atomic(os.path.join(d, "report.md"), text)
        write_atomic(os.path.join(d, "summary.json"), summary)
        print("report_ch4.py: wrote %s" % os.path.join(d, "report.md"))


if __name__ == "__main__":
    main()
