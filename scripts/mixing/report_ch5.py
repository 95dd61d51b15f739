#!/usr/bin/python3
"""report_ch5.py — the Chapter 5 results so far, seed | jdem | liggghts-jdem, from the finished
fills of `make mixing-bonded` (docs/mixing.md §11).

    /usr/bin/python3 -m scripts.mixing.report_ch5 [--out out/mixing/ch5] [--results DIR]

Reads OUT/ENGINE/groupG_modelM/fill.h5 and measures it with scripts/mixing/fill_ch5.py: Table
5-3 (phi_v at the middle clip, points 10-18 of Table 5-2, y = 0.5 m; the trimmed mean and std of
scripts/mixing/stats.py), the breakage over time, the free surface and packing, the energy
balance and the bond-steps, its pictures (the break map and the snapshot sheet); the outflow
below each obstacle (outflow.py); and when all 9 compressions of the middle clip are done
(OUT/ENGINE/CASE/cubeK.h5, K = 10..18) Tables 5-4 and 5-5 (E, nu_xy, nu_xz of the orthotropic
fit on the best-fit particle strain) and the unambiguous M and K0 (report_ch4.cube_result, the
Ch. 4 analysis); the run times (CPU, else wall) from the campaign's .campaign_times.json; the
seed's Figs 5-24 to 5-26 (plots.bonded_figure); the realisations of a fill with the stream
shifted (OUT/ENGINE/CASE/fill_jitterK.h5: its deposit and breakage, "realisations"), against whose
spread the two engines' fills are weighed (agreement_ch5.py).  Then the seed's claims that the
finished fills decide.  Writes OUT/report.md and OUT/summary.json, and with --results (default
reference_runs/mixing/ch5/results for the default OUT) also there; a fill not under OUT
is taken from the committed summary.json, with the commit it came from.  The seed reports no
breakage at all (spec §4.3): those columns have no seed value.
"""
import argparse
import functools
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np

from scripts.mixing import agreement_ch5, fill_ch5, outflow, params, plan_ch4, plots, section_ch5, stats, structure
from scripts.mixing.agreement import ordered
from scripts.mixing.fill_ch5 import FRAGMENT_BINS
from scripts.mixing.plan_ch5 import CASES, ENERGY_MODELS, RIGID_CASES, SPREAD_REALISATIONS
from scripts.mixing_views import scene_geometry
from scripts.mixing.report_ch4 import commit, cube_result, provenance_section, write_atomic

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_OUT = os.path.join(ROOT, "out", "mixing", "ch5")
DEFAULT_RESULTS = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "results")
ENGINES = ("jdem", "liggghts-jdem")
GROUPS = (1, 2, 3)
MODELS = tuple(range(1, 7))
# spec §3.5, Table 5-3: (mean, std) of phi_v at the middle clip, per group and model
SEED_PHI_V = {1: [(0.0575, 0.0933), (0.0186, 0.0319), (0.4658, 0.2712), (0.4507, 0.2039),
                  (0.3197, 0.1548), (0.3214, 0.3750)],
              2: [(0.1210, 0.1876), (0.1203, 0.0469), (0.3643, 0.1180), (0.4724, 0.1695),
                  (0.3771, 0.1441), (0.3225, 0.3449)],
              3: [(0.0434, 0.0663), (0.0501, 0.0671), (0.2417, 0.1927), (0.2846, 0.1744),
                  (0.1331, 0.0540), (0.3163, 0.4352)]}


# spec §3.6-3.7, Tables 5-4 and 5-5: (mean, std) per group, Models 1-6
SEED_ELASTIC = {
    "E": {1: [(4483, 2860), (5702, 3050), (4753, 1317), (8195, 3396), (5970, 2801), (5427, 2893)],
          2: [(6522, 1781), (4189, 742), (3157, 697), (3072, 1081), (6759, 2122), (4618, 857)],
          3: [(5838, 1350), (4764, 1317), (4880, 1415), (5136, 1959), (4803, 820), (4827, 1394)]},
    "nu_xy": {1: [(0.513, 0.074), (0.549, 0.076), (0.519, 0.122), (0.661, 0.117), (0.554, 0.080), (0.559, 0.118)],
              2: [(0.578, 0.085), (0.470, 0.061), (0.451, 0.079), (0.495, 0.061), (0.554, 0.081), (0.509, 0.056)],
              3: [(0.515, 0.066), (0.484, 0.055), (0.505, 0.091), (0.582, 0.071), (0.485, 0.049), (0.523, 0.084)]},
    "nu_xz": {1: [(0.441, 0.068), (0.412, 0.067), (0.411, 0.071), (0.298, 0.113), (0.386, 0.068), (0.387, 0.088)],
              2: [(0.371, 0.063), (0.460, 0.034), (0.465, 0.045), (0.454, 0.029), (0.374, 0.060), (0.418, 0.029)],
              3: [(0.426, 0.043), (0.452, 0.041), (0.428, 0.058), (0.386, 0.058), (0.442, 0.032), (0.419, 0.058)]},
}
CUBES = range(10, 19)


def case(g, m):
    return "group%d_model%d" % (g, m)


def times(out):
    try:
        with open(os.path.join(out, "jdem", case(1, 1), ".campaign_times.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


# a unit's times (.campaign_times.json) that its summary entry keeps
TIMING = ("seconds", "cpu_seconds", "ranks", "threads", "machine", "attempts")


def timing(took):
    """The TIMING keys of a unit's recorded times that it has."""
    return {key: took[key] for key in TIMING if took.get(key) is not None}


def measured(path, rev):
    """A fill's measures (fill_ch5.result) with its outflow and the commit that measured it."""
    return dict(fill_ch5.result(path), source=rev, outflow=outflow.spread(path, scene_geometry(path)[1]))


def measure(path, name, out, spent, directory, rev):
    """The summary entry of the finished fill at path, with its cubes when all 9 are done."""
    entry = measured(path, rev)
    fill_ch5.write_pictures(entry, name, path, directory)
    cubes = [os.path.join(out, name, "cube%d.h5" % k) for k in CUBES]
    if all(os.path.exists(c) for c in cubes):
        entry["cubes"] = [cube_result(c) for c in cubes]
        for key in ("seconds", "cpu_seconds"):
            took = [spent.get("%s/cube%d" % (name, k), {}).get(key) for k in CUBES]
            if all(t is not None for t in took):
                entry["cube_" + key] = float(sum(took))
    entry.update(timing(spent.get(name + "/fill", {})))
    return entry


RUN_TIME_NOTE = ("run times are the CPU time of the unit's processes (all ranks and threads), "
                 "since the wall clock of a shared machine also counts the pauses of the runs beside "
                 "it; \"w\" marks a wall time alone, of a unit timed before its CPU time was recorded (which "
                 "may then be its last attempt only, if it was resumed) or whose CPU time was lost")


def cpu_or_wall(e, prefix=""):
    """The entry's CPU seconds (prefix "cube_": its 9 compressions'), else its wall seconds, else
    None; and whether it is the CPU time."""
    if not e:
        return None, False
    if e.get(prefix + "cpu_seconds"):
        return e[prefix + "cpu_seconds"], True
    return e.get(prefix + "seconds") or None, False


def run_time(e, prefix=""):
    """A run-time cell: CPU seconds, "N w" for a wall time only, "—" when not timed."""
    t, cpu = cpu_or_wall(e, prefix)
    if t is None:
        return "—"
    ranks = e.get("ranks", 1) if not prefix else 1
    threads = e.get("threads", 1) if not prefix else 1
    return "%.0f" % t + ("" if cpu else " w") + (" (%d ranks)" % ranks if ranks > 1 else "") + \
        (" (%d threads)" % threads if threads > 1 else "")


REALISATION_KEYS = ("particles", "time", "middle_clip", "surface", "packing", "breakage", "built_by")


def realisation(path, name, k, spent, rev):
    """The summary entry of the fill's realisation K (fill_jitterK.h5): what agreement_ch5.py
    compares, its run time and commit."""
    r = measured(path, rev)
    return dict({key: r[key] for key in REALISATION_KEYS if key in r}, jitter=k, source=rev,
                outflow=r["outflow"], **timing(spent.get("%s/fill_jitter%d" % (name, k), {})))


def realisations_here(out, name):
    """[(K, path)] of the fill's realisations under out."""
    engine, c = name.split("/")
    return [(k, p) for k in range(1, SPREAD_REALISATIONS[engine].get(c, 0) + 1)
            for p in [os.path.join(out, name, "fill_jitter%d.h5" % k)] if os.path.exists(p)]


def realisations(out, name, spent, rev, committed):
    """The fill's realisations measured here, and the committed ones of the other K."""
    here = [realisation(p, name, k, spent, rev) for k, p in realisations_here(out, name)]
    ks = {r["jitter"] for r in here}
    return sorted(here + [r for r in committed if r["jitter"] not in ks], key=lambda r: r["jitter"])


def collect(out, committed, rev, directory):
    found, spent = {}, times(out)
    for engine in ENGINES:
        for c in CASES + RIGID_CASES:
            name = "%s/%s" % (engine, c)
            path = os.path.join(out, name, "fill.h5")
            if os.path.exists(path):
                found[name] = measure(path, name, out, spent, directory, rev)
            elif name in committed:
                found[name] = dict(committed[name])
            else:
                if realisations_here(out, name):
                    print("report_ch5.py: %s: its realisations wait for the fill itself "
                          "(`make mixing-bonded UNIT=%s/fill`)" % (name, name), file=sys.stderr)
                continue
            reals = realisations(out, name, spent, rev, committed.get(name, {}).get("realisations", []))
            if reals:
                found[name]["realisations"] = reals
    return found


def cell(entry, fmt="%.4f"):
    if not entry:
        return "—"
    s = entry["middle_clip"]
    return (fmt + " ± " + fmt) % (s["mean"], s["std"])


def elastic_cell(entry, key, fmt):
    if not entry or "cubes" not in entry:
        return "—"
    s = stats.summary([c[key] for c in entry["cubes"]])
    return (fmt + " ± " + fmt) % (s["mean"], s["std"])


ELASTIC_FIGURE = "fig5-27.png"


def elastic_values(found):
    """plots.elastic_figure's values: E of the seed and of each engine's cubes, M of each
    engine's, per group and model (mean and std as in elastic_tables)."""
    values = {}
    for g in GROUPS:
        for m in MODELS:
            for e in ENGINES:
                entry = found.get("%s/%s" % (e, case(g, m)))
                if not entry or "cubes" not in entry:
                    continue
                values[("E", g, m, "seed")] = SEED_ELASTIC["E"][g][m - 1]
                for quantity, key in (("E", "E"), ("M", "M_wall")):
                    s = stats.summary([c[key] for c in entry["cubes"]])
                    values[(quantity, g, m, e)] = (s["mean"], s["std"])
    return values


def write_elastic_figures(found, directories):
    """Fig. 5-27 (and M beneath it) and Figs 5-28 to 5-30 (point by point) into each of
    directories; their file names (None: no data)."""
    names = [plots.save_figure(plots.elastic_figure(elastic_values(found)), ELASTIC_FIGURE, directories)]
    for g in GROUPS:
        cubes = {(m, e): found["%s/%s" % (e, case(g, m))]["cubes"] for m in MODELS for e in ENGINES
                 if "cubes" in found.get("%s/%s" % (e, case(g, m)), {})}
        names.append(plots.save_figure(plots.points_elastic_figure(cubes, g, list(CUBES)),
                                       "fig%s.png" % plots.SEED_POINTS_FIGURE[g], directories))
    return [n for n in names if n]


def elastic_tables(found):
    """Tables 5-4 and 5-5 (the orthotropic fit) and M, K0 (unambiguous), seed | jdem | liggghts-jdem."""
    lines = ["### Tables 5-4 and 5-5: E and the Poisson ratios at the middle clip (σzz = 5 kPa)", "",
             "mean ± std over the 9 cubes of points 10–18, the highest and lowest dropped; E, νxy and "
             "νxz from the orthotropic fit of the best-fit particle strain (the seed's measure, Ch. 2 "
             "eqs 46–50) with the wall stresses, which for a laterally confined cube is ill-posed (spec "
             "§2.4, docs/model.md §10): compare M = σzz/εzz with εzz the wall's strain, and K0 = "
             "(σxx + σyy)/(2σzz), which the test determines; every seed row is shown, ours \"—\" until "
             "its 9 compressions are done", "",
             "| group | model | E seed [Pa] | E jdem | E liggghts-jdem | νxy seed | νxy jdem | νxy liggghts-jdem "
             "| νxz seed | νxz jdem | νxz liggghts-jdem | M (wall strain) jdem / liggghts-jdem [Pa] | K0 jdem / liggghts-jdem "
             "| 9 cubes' run time jdem / liggghts-jdem [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for g in GROUPS:
        for m in MODELS:
            es = [found.get("%s/%s" % (e, case(g, m))) for e in ENGINES]
            cols = []
            for key, fmt in (("E", "%.0f"), ("nu_xy", "%.3f"), ("nu_xz", "%.3f")):
                cols.append(fmt % SEED_ELASTIC[key][g][m - 1][0] + " ± " + fmt % SEED_ELASTIC[key][g][m - 1][1])
                cols += [elastic_cell(e, key, fmt) for e in es]
            cols.append(" / ".join(elastic_cell(e, "M_wall", "%.0f") for e in es))
            cols.append(" / ".join(elastic_cell(e, "K0", "%.3f") for e in es))
            cols.append(" / ".join(run_time(e, "cube_") for e in es))
            lines.append("| %d | %d | %s |" % (g, m, " | ".join(cols)))
    return lines + ["", fit_note(found)]


def fit_note(found):
    """The best fit's M against the wall's, and the fit's condition numbers, over every cube."""
    cubes = [c for e in found.values() for c in e.get("cubes", [])]
    if not cubes:
        return "(no case has all 9 compressions yet)"
    ratio = [c["M_best_fit"] / c["M_wall"] for c in cubes]
    cond = [c["cond"] for c in cubes]
    return ("Over the %d cubes compressed so far the best fit's M (its εzz from the particles' "
            "translations) is %.2f to %.2f times the wall's, above 1 in %d of them (there the "
            "translations give the smaller strain), and the orthotropic fit's condition number "
            "runs from %.3g to %.3g (median %.3g): a value of E or ν from a condition number of "
            "1e4 or more carries little." % (
                len(cubes), min(ratio), max(ratio), sum(r > 1 for r in ratio), min(cond), max(cond),
                float(np.median(cond))))


def halved(sp):
    """The spread of half a statistic."""
    return (0.5 * sp[0],) + tuple(sp[1:]) if sp else None


def weighed(value, spread, pairs, plain_signs=False):
    """agreement.ordered, its margin saying how many degrees of freedom the roughest spread it
    used has (a std from one or two is a rough one: its 95 % upper bound is 32 or 6 times it)."""
    text, margin = ordered(value, spread, pairs, plain_signs)
    dof = [sp[2] for a, b in pairs for sp in (spread(a), spread(b)) if sp and len(sp) > 2]
    if dof and margin.startswith("a difference counts"):
        margin += ", its s from %d degree%s of freedom" % (min(dof), "" if min(dof) == 1 else "s")
    return text, margin


def claims(found):
    """The seed's claims (spec §3.8) that the finished fills can decide, per engine: held, not
    held, or not resolved, weighed as Chapter 4's against the run-to-run spread of each group's
    fill (agreement_ch5.spread: a difference of two groups' fills counts beyond
    2 sqrt(s_a² + s_b²); not resolved where no spread is measured).  The stiffness and anisotropy
    claims have no such spread (the realisations are not compressed): cube_claims."""
    spread = agreement_ch5.spread(found, CASES)
    head = ["### The seed's claims (spec §3.8)", "",
             "each weighed against the run-to-run spread of the groups' fills (the realisations with "
             "the stream shifted, scripts/mixing/agreement_ch5.py): a difference counts beyond "
             "2√(s_a² + s_b²), else the claim is not resolved, as it is while a group compared has no "
             "spread measured yet (the stiffness claim alone is weighed against the cubes' spread "
             "within each deposit); the seed's own table is read by its signs; \"mixes "
             "better\" is read as φv nearer the ideal 0.0625 at the middle clip, a reading the seed's "
             "own Table 5-3 does not bear out (its lines \"seed\" below, without a spread: its \"best\" "
             "models have φv of 0.32-0.47, far above the ideal, spec §3.8); in our fills φv stays under "
             "the ideal (%s), where \"nearer the ideal\" and \"more big spheres in the clip\" are one "
             "reading" % above_ideal(found), ""]
    lines = []
    for engine in ENGINES:
        get = lambda g, m: found.get("%s/%s" % (engine, case(g, m)))
        for m in MODELS:
            g1, g2, g3 = get(1, m), get(2, m), get(3, m)
            if sum(e is not None for e in (g1, g2, g3)) < 2:
                continue
            within = lambda label: (lambda g: spread(case(g, m), label))
            near = {g: -abs(e["middle_clip"]["mean"] - params.IDEAL_PHI_V)
                    for g, e in ((1, g1), (2, g2), (3, g3)) if e}
            for g in (2, 3):
                if g in near and 1 in near:
                    text, margin = weighed(near, within(agreement_ch5.PHI), [(g, 1)])
                    lines.append("- %s Model %d: Group %d blocks mix better than unbonded ones (|φv − %.4f| "
                                 "at the middle clip %.4f against Group 1's %.4f; %s): **%s**" % (
                                     engine, m, g, params.IDEAL_PHI_V, -near[g], -near[1], margin, text))
            if 2 in near and 3 in near:
                text, margin = weighed(near, within(agreement_ch5.PHI), [(2, 3)])
                lines.append("- %s Model %d: strong blocks mix worse than weak ones (|φv − %.4f| at the "
                             "middle clip %.4f against Group 2's %.4f; %s): **%s**" % (
                                 engine, m, params.IDEAL_PHI_V, -near[3], -near[2], margin, text))
            if m == 3 and g1 and g2:
                a, b = g1["middle_clip"]["std"], g2["middle_clip"]["std"]
                sp = within(agreement_ch5.PHI_STD)
                text, margin = weighed({"half": 0.5 * a, 2: b},
                                       lambda k: halved(sp(1)) if k == "half" else sp(2), [("half", 2)])
                lines.append("- %s Model 3: the spread of φv drops by more than 50 %% from Group 1 to Group 2 "
                             "(std %.4f → %.4f, %s; %s): **%s**" % (
                                 engine, a, b, "%+.0f %%" % (100 * (b - a) / a) if a else "from zero",
                                 margin, text))
            for k, (o1, o2) in enumerate(zip((g1 or {}).get("outflow", []), (g2 or {}).get("outflow", []))):
                text, margin = weighed({2: o2["std"], 1: o1["std"]}, within(agreement_ch5.OUTFLOW[k]), [(2, 1)])
                lines.append("- %s Model %d: weak blocks widen the outflow below the obstacle at (%.2f, %.2f) "
                             "(std of the direction from the vertical %.1f° against Group 1's %.1f°; %d and %d "
                             "particles, scripts/mixing/outflow.py; %s): **%s**" % (
                                 engine, m, o1["x"], o1["z"], o2["std"], o1["std"], o2["n"], o1["n"], margin, text))
            if all(e and "cubes" in e for e in (g1, g2, g3)):
                lines += cube_claims(engine, m, (g1, g2, g3))
            lines += surface_claim(engine, m, g1, g3, within)
        lines += model_claims(engine, found, spread) + crushing_claim(engine, found, spread)
    if not lines:
        lines.append("(none yet: each needs a Group 1 fill and a bonded fill of the same model)")
    seed = {"seed/%s" % case(g, m): {"middle_clip": {"mean": SEED_PHI_V[g][m - 1][0]}} for g in GROUPS for m in MODELS}
    return head + seed_table_claims() + model_claims("seed", seed, lambda c, label: None, plain_signs=True) + [
        "- not decided: Group 2's \"fewer extreme values\" and \"φv rises near the boundaries\", and "
        "\"the earlier in the flow path that the obstacles are added, the better\": the seed defines "
        "no extreme value, does not say which of its 27 points are near the boundaries, and orders "
        "no models by how early their obstacles are met", ""] + lines


def cube_claims(engine, m, fills):
    """Stiffness falls and the anisotropy νxy/νxz falls as bond strength rises (Groups 1-3 of
    Model m).  M is weighed against the standard error of each fill's mean over its cubes (the
    realisations are not compressed, so there is no run-to-run spread of M); the Poisson ratios
    are not weighed at all: the fit that gives them is ill-posed (docs/model.md §10)."""
    m_of = [[c["M_wall"] for c in e["cubes"]] for e in fills]
    n_of = [len(e["cubes"]) for e in fills]
    mean = {g: stats.trimmed_mean(v) for g, v in zip(GROUPS, m_of)}
    error = {g: (stats.trimmed_mean_error(v), "cubes") for g, v in zip(GROUPS, m_of)}
    text, _ = ordered(mean, error.get, [(1, 2), (2, 3)])
    bound = max(2.0 * math.hypot(error[a][0], error[b][0]) for a, b in ((1, 2), (2, 3)))
    ratio = [stats.summary([c["nu_xy"] for c in e["cubes"]])["mean"] /
             stats.summary([c["nu_xz"] for c in e["cubes"]])["mean"] for e in fills]
    return ["- %s Model %d: stiffness falls as bond strength rises (M %.0f, %.0f, %.0f Pa for Groups "
            "1-3; a difference counts beyond 2√(e_a² + e_b²) = %.0f Pa, e the standard error of a "
            "fill's trimmed mean of M over its %s cubes (Tukey–McLaughlin), there being no run-to-run "
            "spread of M): **%s**" % (
                engine, m, *mean.values(), bound, "/".join(str(n) for n in sorted(set(n_of))),
                text.replace("run-to-run spread", "cubes' spread")),
            "- %s Model %d: the anisotropy νxy/νxz falls with bond strength (%.3f, %.3f, %.3f for "
            "Groups 1-3): **not resolved (the fit that gives the Poisson ratios is ill-posed, "
            "docs/model.md §10)**" % (engine, m, *ratio)]


def above_ideal(found):
    """Which fills have φv above the ideal at the middle clip, as words."""
    above = ["%s %.4f" % (n, e["middle_clip"]["mean"]) for n, e in sorted(found.items())
             if e["middle_clip"]["mean"] > params.IDEAL_PHI_V]
    return "every fill" if not above else "all but " + ", ".join(above)


def crushing_claim(engine, found, spread):
    """Strong bonds: "little crushing without obstacles" (Group 3's Model 1 breaks fewer bonds
    than each model with obstacles, by its broken fraction, weighed as claims())."""
    broken = {m: e["breakage"]["total"] for m in MODELS
              for e in [found.get("%s/%s" % (engine, case(3, m)))] if e and e.get("breakage", {}).get("formed")}
    if 1 not in broken or len(broken) < 2:
        return []
    fewer = {m: -f for m, f in broken.items()}
    text, margin = weighed(fewer, lambda m: spread(case(3, m), agreement_ch5.BROKEN),
                           [(1, m) for m in broken if m != 1])
    return ["- %s Group 3: little crushing without obstacles (the broken fraction of Model 1 under "
            "each model's with obstacles: %s; %s): **%s**" % (
                engine, ", ".join("%d: %.3f" % mf for mf in sorted(broken.items())), margin, text)]


def model_claims(engine, found, spread, plain_signs=False):
    """The seed's claims that order the models of one group by their mixing (|φv − ideal| at the
    middle clip, weighed as claims()): obstacles improve mixing (Models 2-6 against Model 1),
    Model 5 mixes best in Group 1, Models 3 and 5 in Group 2.  plain_signs: the seed's own table,
    read by its signs (agreement.ordered)."""
    lines = []
    for g in GROUPS:
        near = {m: -abs(e["middle_clip"]["mean"] - params.IDEAL_PHI_V) for m in MODELS
                for e in [found.get("%s/%s" % (engine, case(g, m)))] if e}
        within = lambda m: spread(case(g, m), agreement_ch5.PHI)
        listed = ", ".join("%d: %.4f" % (m, -v) for m, v in sorted(near.items()))
        checks = []
        if 1 in near and len(near) > 1:
            checks.append(("obstacles improve mixing (Models %s against Model 1)" %
                           ", ".join(str(m) for m in near if m != 1), [(m, 1) for m in near if m != 1]))
        if g == 1 and len(near) == len(MODELS):
            checks.append(("Model 5 mixes best", [(5, m) for m in MODELS if m != 5]))
        if g == 1 and 3 in near and 4 in near:
            checks.append(("Model 3 mixes better than Model 4", [(3, 4)]))
        if g == 2 and len(near) == len(MODELS):
            checks.append(("Models 3 and 5 mix best", [(a, m) for a in (3, 5) for m in MODELS if m not in (3, 5)]))
        for claim, pairs in checks:
            text, margin = weighed(near, within, pairs, plain_signs)
            lines.append("- %s Group %d: %s (|φv − %.4f| at the middle clip per model %s; %s): **%s**" % (
                engine, g, claim, params.IDEAL_PHI_V, listed, margin, text))
    return lines


def differences_section(found):
    """Why our Tables 5-3 to 5-5 differ from the seed's, with the numbers of the finished fills
    (docs/mixing.md §11 has the evidence)."""
    lines = ["### Why ours differ from the seed", ""]
    for engine in ENGINES:
        fills = {(g, m): found["%s/%s" % (engine, case(g, m))] for g in GROUPS for m in MODELS
                 if "%s/%s" % (engine, case(g, m)) in found}
        if not fills:
            continue
        ours = {g: [e["middle_clip"]["mean"] for (gg, _), e in fills.items() if gg == g] for g in GROUPS}
        seed = {g: [SEED_PHI_V[g][m - 1][0] for (gg, m) in fills if gg == g] for g in GROUPS}
        weak = [e["breakage"] for (g, _), e in fills.items() if g == 2 and e.get("breakage", {}).get("formed")]
        cubes = [c for e in fills.values() for c in e.get("cubes", [])]
        unbonded = ours[1] and np.mean(ours[1]) < 0.5 * np.mean(seed[1])
        lines.append("- %s, Table 5-3: φv at the middle clip averages %s against the seed's %s over the same "
                     "cases (Groups 1-3).%s The stream's width and the sampling spheres are reconstructions "
                     "(docs/mixing.md §1, §11 \"Why φv is low\")." % (
                         engine, " / ".join("%.4f" % np.mean(ours[g]) if ours[g] else "—" for g in GROUPS),
                         " / ".join("%.4f" % np.mean(seed[g]) if seed[g] else "—" for g in GROUPS),
                         " The gap is there without bonds (Group 1, %.0f %% of the seed's), as in Chapter 4: "
                         "our deposits put the big spheres against the walls and out of the middle clip, "
                         "whatever the bonds do." % (100 * np.mean(ours[1]) / np.mean(seed[1]))
                         if unbonded else ""))
        if weak:
            broken, formed = sum(k["broken"] for k in weak), sum(k["formed"] for k in weak)
            lines.append("- %s, Group 2: %d of %d weak bonds broke over its %d fill%s%s" % (
                engine, broken, formed, len(weak), "" if len(weak) == 1 else "s",
                ": a 5 kPa bond of the reconstructed stiffness (k̄n = 1e6 Pa/m, spec §4.2) breaks in any "
                "impact faster than 0.56 m/s and the blocks meet the first obstacle or the bed at 2.2 m/s "
                "or faster, so they break on impact (in Model 1 on the bed: the first breaks, in the horizon section) and lie "
                "in the deposit as single spheres; whether they mix otherwise than Group 1's is the claims' question below "
                "(docs/mixing.md §11)." if broken >= 0.99 * formed else "."))
        if cubes:
            nu = [c["nu_xy"] for c in cubes]
            lines.append("- %s, Tables 5-4 and 5-5: the orthotropic fit of a laterally confined cube is "
                         "ill-posed (docs/model.md §10): over %d cubes νxy spans %.2f to %.2f (%d of them "
                         "negative) and E %.0f to %.0f Pa; M and K0 are what the cubes determine." % (
                             engine, len(cubes), min(nu), max(nu), sum(v < 0 for v in nu),
                             min(c["E"] for c in cubes), max(c["E"] for c in cubes)))
    if len(lines) == 2:
        lines.append("(no fill yet)")
    return lines


def seed_table_claims():
    """The seed's own Tables 5-4 and 5-5 against its text (spec §3.8): E falls "in the range of
    25 percent" with bond strength, and νxy falls and νxz rises "about ten percent"; "the range of
    values decreases" with bond strength (read both as the range of the models' means and as the
    cubes' std); νxy > νxz."""
    means = {k: [float(np.mean([v[0] for v in SEED_ELASTIC[k][g]])) for g in GROUPS] for k in SEED_ELASTIC}
    e = means["E"]
    change = lambda v: ", ".join("%+.0f %%" % (100 * (x - v[0]) / v[0]) for x in v[1:])
    lines = ["- the seed's Table 5-4: E falls \"in the range of 25 percent\" as bond strength rises: "
            "its group means over the six models %.0f, %.0f, %.0f Pa (%s against Group 1): **%s** "
            "(the seed's own table does not show it, spec §3.8)" % (
                *e, change(e), "held" if e[0] > e[1] > e[2] and e[2] <= 0.8 * e[0] else "not held"),
            "- the seed's Table 5-5: νxy falls and νxz rises \"about ten percent\" as bond strength "
            "rises: group means νxy %.3f, %.3f, %.3f (%s), νxz %.3f, %.3f, %.3f (%s): **%s** (by about "
            "ten percent from Group 1, but νxy not monotonically)" % (
                *means["nu_xy"], change(means["nu_xy"]), *means["nu_xz"], change(means["nu_xz"]),
                "held" if means["nu_xy"][0] > means["nu_xy"][1] > means["nu_xy"][2]
                and means["nu_xz"][0] < means["nu_xz"][1] < means["nu_xz"][2] else "not held")]
    stds = [float(np.mean([v[1] for v in SEED_ELASTIC["E"][g]])) for g in GROUPS]
    ranges = [float(np.ptp([v[0] for v in SEED_ELASTIC["E"][g]])) for g in GROUPS]
    falls = lambda v: v[0] > v[1] > v[2]
    pairs = [(xy[0], xz[0]) for g in GROUPS for xy, xz in zip(SEED_ELASTIC["nu_xy"][g], SEED_ELASTIC["nu_xz"][g])]
    return lines + [
        "- the seed's Table 5-4: the range of E falls as bond strength rises: the range of the six "
        "models' means %.0f, %.0f, %.0f Pa; the cubes' std, averaged over the models, %.0f, %.0f, "
        "%.0f Pa: **%s**" % (*ranges, *stds, "held" if falls(ranges) and falls(stds) else
                              "held on the models' range, not on the cubes' std" if falls(ranges) else
                              "held on the cubes' std, not on the models' range" if falls(stds) else "not held"),
        "- the seed's Table 5-5: νxy > νxz (anisotropy): in %d of its %d model means: **%s**" % (
            sum(a > b for a, b in pairs), len(pairs), "held" if all(a > b for a, b in pairs) else "not held"),
        ""]


def structure_table(found):
    lines = ["### Free surface and packing of the deposit (scripts/mixing/structure.py; the seed shows "
             "pictures only)", "",
             "the plane fitted to the height map (0.05 m columns, %.2f m from the walls out): its "
             "inclination and slope along x; the solid fraction within %.2f m of the side walls and "
             "farther than %.2f m from them, %.2f m over the floor to %.2f m under the lowest column" % (
                 structure.WALL_BAND, structure.WALL_BAND, structure.INTERIOR, structure.FLOOR_BAND,
                 structure.SURFACE_BAND), "",
             "| engine | case | inclination [deg] | slope along x [deg] | surface lowest–highest [m] "
             "| solid fraction near the walls | in the interior | wall − interior |",
             "|---|---|---|---|---|---|---|---|"]
    for name, e in sorted(found.items()):
        s, p = e.get("surface"), e.get("packing")
        if not (s and p):
            continue
        surface = "| %s | %s | %.1f | %+.1f | %.3f–%.3f |" % (
            *name.split("/"), s["inclination"], s["slope_x"], s["lowest"], s["highest"])
        if p["samples"]:
            lines.append(surface + " %.4f | %.4f | %+.4f |" % (p["wall"], p["interior"], p["wall"] - p["interior"]))
        else:   # a column whose bed ends near the floor: no layer under the surface
            lines.append(surface + " no layer: the lowest column's bed, wall columns included (a gap over "
                         "%.2f m ends a bed), tops out at %.3f m, so nothing lies between %.2f m over the "
                         "floor and %.2f m under it | — | — |" % (
                             structure.BED_GAP, p["top"] + structure.SURFACE_BAND, structure.FLOOR_BAND,
                             structure.SURFACE_BAND))
    if len(lines) == 5:
        lines.append("(no fill measured since these measures were added)")
    return lines


# The bookkeeping that closes the balance to second order in dt: the previous step's contact
# force (8c7b0d5) and bond load (ENERGY_FIX, after it) booked through the lever arms they were
# applied with (docs/model.md §7).  A fill run, even in part, by an older binary carries the
# first-order bookkeeping in its energy observables (its trajectory is the same).
ENERGY_FIX = "9756717"


def current_bookkeeping(built_by):
    """Whether every binary that wrote a fill (deposit.built_by: "release+commit") contains
    ENERGY_FIX; a version without its commit predates the recording, and the fix."""
    return bool(built_by) and all(version_has_fix(v) for v in built_by)


def version_has_fix(version):
    """Whether the binary "release+commit" contains ENERGY_FIX."""
    return has_commit(version.partition("+")[2], ENERGY_FIX)


# The commit from which an unbonded fill (its empty bond table) is drawn blue, not as single
# spheres in orange.
UNBONDED_BLUE = "34e98d4"


def orange_group1(found):
    """"; ..." naming the Group 1 pictures drawn before UNBONDED_BLUE (their small spheres orange,
    single spheres by the bonded rule), or ""."""
    older = [n for n, e in sorted(found.items()) if e.get("views") and n.split("/")[1].startswith("group1_")
             and not has_commit(e.get("source", ""), UNBONDED_BLUE)]
    return "; the pictures of %s, drawn before %s, show their small spheres orange" % (
        ", ".join(older), UNBONDED_BLUE) if older else ""


@functools.lru_cache(maxsize=None)
def has_commit(rev, commit):
    """Whether rev contains commit (git merge-base --is-ancestor; one git call per pair: the fills
    share a few binaries and commits)."""
    return bool(rev) and subprocess.run(["git", "-C", ROOT, "merge-base", "--is-ancestor", commit, rev],
                                        capture_output=True).returncode == 0


def energy_table(found):
    """The energy balance of each fill that keeps the accounts, and every fill's bond-steps per
    second; the worst balance over the fills whose binaries all book the previous load through
    its lever arms (current_bookkeeping)."""
    lines = ["### Energy balance and speed of the fills (scripts/mixing/energy.py)", "",
             "largest residual of KE + RE + elastic + gravitational + dissipated (the bonds' stored, "
             "damped and breakage energy included) − wall work − inflow, over the energy in play and "
             "over the inflow; the stability suite holds 1e-3 of the energy in play; bond-steps per "
             "second of the CPU time, none from a wall time (" + RUN_TIME_NOTE + "); \"old\" marks a fill run, at least in "
             "part, before " + ENERGY_FIX + " (the previous load booked through the current lever "
             "arms: first order in dt, docs/mixing.md §11), left out of the worst fill", "",
             "| engine | case | residual / in play | residual / inflow | breakage [J] | inflow [J] "
             "| bond-steps | run time [s] | bond-steps per second |",
             "|---|---|---|---|---|---|---|---|---|"]
    worst, old, worst_old = None, [], 0.0
    for name, e in sorted(found.items()):
        b = e.get("energy")
        took, cpu = cpu_or_wall(e)
        rate = e["bond_steps"] / took if cpu and e.get("bond_steps") else None   # not from "w" times
        current = bool(b) and current_bookkeeping(e.get("built_by", []))
        balance = ("%.2e%s | %.2e | %.3g | %.4g" % (
            b["residual_in_play"], "" if current else " old", b["residual_inflow"], b["breakage"],
            b["inflow"]) if b else "no accounts | — | — | —")   # without the accounts: speed alone
        lines.append("| %s | %s | %s | %.3g | %s | %s |" % (
            *name.split("/"), balance, e.get("bond_steps", 0.0), run_time(e),
            "%.3g" % rate if rate else "—"))
        if b and not current:
            old.append(name)
            worst_old = max(worst_old, b["residual_in_play"])
        elif current and (worst is None or b["residual_in_play"] > worst[1]):
            worst = (name, b["residual_in_play"])
    if worst:
        lines += ["", "Worst fill on the current bookkeeping: %s, %.2e of the energy in play (%s the "
                  "stability suite's 1e-3)." % (worst[0], worst[1],
                                               "within" if worst[1] <= 1e-3 else "**beyond**")]
    else:
        lines += ["", "(no fill on the current bookkeeping yet)"]
    if old:
        lines += ["", "On the old bookkeeping: %s; the worst of them %.2e of the energy in play (%s the "
                  "stability suite's 1e-3)." % (", ".join(old), worst_old,
                                               "within" if worst_old <= 1e-3 else "beyond")]
    lines += ["", "Only jdem's fills of %s keep the energy accounts (scripts/mixing/plan_ch5.py, "
              "keeps_energy); every other fill, liggghts-jdem's included, runs without them: the "
              "same trajectory bit for bit, 1.57x faster in liggghts-jdem and 1.9x in jdem "
              "(docs/mixing.md §11). The fills above from other models ran before that rule." % (
                  " and ".join("Model " + m[len("model"):] for m in ENERGY_MODELS))]
    return lines


def hours(seconds):
    """The sum of a list of seconds in hours, or "—" for none."""
    return "%.2f" % (sum(seconds) / 3600.0) if seconds else "—"


def speed_table(found):
    """The same fill in both engines: their CPU times and jdem's speed-up over liggghts-jdem, for
    each case both ran on one thread or rank and alike without (or with) the energy accounts."""
    lines = ["### Speed: the same fill in both engines", "",
             "CPU time of each engine's fill of the case on one core (jdem one thread, liggghts-jdem "
             "one rank) of the same machine, both without the energy accounts or both with them "
             "(a fill resumed after an interruption counts all its attempts)", "",
             "| case | jdem [CPU s] | liggghts-jdem [CPU s] | liggghts-jdem / jdem |", "|---|---|---|---|"]
    rows = []
    for label, a, b in same_scenes(found):
        if not (a.get("cpu_seconds") and b.get("cpu_seconds")):
            continue
        if a.get("threads", 1) != 1 or b.get("ranks", 1) != 1 or bool(a.get("energy")) != bool(b.get("energy")) \
                or not a.get("machine") or a.get("machine") != b.get("machine"):
            continue
        rows.append("| %s | %.0f%s | %.0f%s | %.2f |" % (
            label, a["cpu_seconds"], attempts_note(a), b["cpu_seconds"], attempts_note(b),
            b["cpu_seconds"] / a["cpu_seconds"]))
    return lines + (rows or ["| (no case yet with both engines' fill timed alike) | | | |"])


def same_scenes(found):
    """[(label, jdem's entry, liggghts-jdem's)] of every scene both engines ran: a case's fill,
    and each realisation K both ran (the same stream shift)."""
    pairs = []
    for c in CASES + RIGID_CASES:
        a, b = (found.get("%s/%s" % (e, c)) for e in ENGINES)
        if not (a and b):
            continue
        pairs.append((c, a, b))
        theirs = {r["jitter"]: r for r in b.get("realisations", [])}
        pairs += [("%s, stream shifted %d µm" % (c, r["jitter"]), r, theirs[r["jitter"]])
                  for r in a.get("realisations", []) if r["jitter"] in theirs]
    return pairs


def attempts_note(e):
    """" (N attempts)" for a fill that ran in more than one."""
    return " (%d attempts)" % e["attempts"] if e.get("attempts", 1) > 1 else ""


def campaign_time_table(found):
    """The time of the campaign so far per engine: its finished fills' (with their realisations)
    and compressions' wall and CPU times summed, and the campaign's fills projected from the mean
    fill."""
    planned = {e: len(CASES + RIGID_CASES) + sum(SPREAD_REALISATIONS[e].values()) for e in ENGINES}
    lines = ["### Time of the campaign per engine", "",
             "the units' wall and CPU times summed over the finished fills, their realisations with "
             "the stream shifted and their 9 compressions each (the units run one after another on "
             "a lane, so the sums are the campaign's time on one lane; wall times include any "
             "pause, and units timed before the CPU time was recorded have a wall time only); the "
             "whole campaign's fills (%s: the %d cases, the %d rigid ones and the realisations) "
             "projected from the mean CPU time per fill" %
             (", ".join("%s %d" % (e, n) for e, n in planned.items()), len(CASES), len(RIGID_CASES)), "",
             "| engine | fills timed | fills' wall [h] | fills' CPU [h] | cube sets timed "
             "| cubes' wall [h] | cubes' CPU [h] | all fills projected [CPU h] |",
             "|---|---|---|---|---|---|---|---|"]
    for engine in ENGINES:
        es = [e for n, e in sorted(found.items()) if n.split("/")[0] == engine]
        fills = [f for e in es for f in [e] + e.get("realisations", []) if f.get("seconds")]
        cubes = [e for e in es if e.get("cube_seconds")]
        if not fills and not cubes:
            lines.append("| %s | 0 | — | — | 0 | — | — | — |" % engine)
            continue
        cpu = [e["cpu_seconds"] for e in fills if e.get("cpu_seconds")]
        cube_cpu = [e["cube_cpu_seconds"] for e in cubes if e.get("cube_cpu_seconds")]
        lines.append("| %s | %d (%d with CPU) | %s | %s | %d (%d with CPU) | %s | %s | %s |" % (
            engine, len(fills), len(cpu), hours([e["seconds"] for e in fills]), hours(cpu),
            len(cubes), len(cube_cpu), hours([e["cube_seconds"] for e in cubes]), hours(cube_cpu),
            "%.1f" % (planned[engine] * sum(cpu) / len(cpu) / 3600.0) if cpu else "—"))
    return lines


def surface_claim(engine, m, g1, g3, within):
    """Strong bonds leave an inclined free surface and more voids near the walls (Group 3 against
    Group 1 of the same model); within(label)(group) -> its run-to-run spread or None."""
    if not (g1 and g3 and g1.get("surface") and g3.get("surface")):
        return []
    who = "- %s Model %d" % (engine, m)
    s1, s3 = g1["surface"]["inclination"], g3["surface"]["inclination"]
    v1, v3 = ((e["packing"]["interior"] - e["packing"]["wall"]) for e in (g1, g3))
    slope, slope_margin = weighed({3: s3, 1: s1}, within(agreement_ch5.INCLINATION), [(3, 1)])
    voids, voids_margin = weighed({3: v3, 1: v1}, within(agreement_ch5.VOIDS), [(3, 1)])
    return ["%s: strong bonds leave a more inclined free surface (%.1f° against Group 1's %.1f°; %s): "
            "**%s**" % (who, s3, s1, slope_margin, slope),
            "%s: strong bonds leave more voids near the walls (solid fraction interior − wall %.4f "
            "against Group 1's %.4f; %s): **%s**" % (who, v3, v1, voids_margin, voids)]


def rigid_section(found):
    """Chapter 6's rigid cements (Figs 6-1, 6-2; the seed shows pictures only)."""
    lines = ["### Chapter 6: rigid cements (Figs 6-1 and 6-2, unbreakable bonds)", "",
             "| engine | case | φv at the middle clip | bonds formed | broken | fragments at the end "
             "| whole blocks | run time [s] |", "|---|---|---|---|---|---|---|---|"]
    rigid = [(n, e) for n, e in sorted(found.items()) if n.split("/")[1] in RIGID_CASES]
    for name, e in rigid:
        k = e.get("breakage", {})
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
            *name.split("/"), cell(e), k.get("formed", "—"), k.get("broken", "—"),
            k.get("fragments", "—"), k.get("whole_blocks", "—"),
            run_time(e)))
    if not rigid:
        lines.append("(not run yet: `make mixing-bonded MODEL=rigid_model1`, `MODEL=rigid_model3`)")
    lines += [x for x in (skipped_blocks(n, e) for n, e in rigid) if x]
    clips = ["![%s](%s)" % (n, e["clip"]) for n, e in rigid if e.get("clip")]
    return lines + (["", "Their final middle clips (the spheres cut by y = 0.5 m):", ""] + clips if clips else [])


# the stream's blocks: 80 sections of 4 big and 512 small spheres, the small ones in 16 blocks
SECTION_BIG, SECTION_SMALL = 4, 512
STREAM_BLOCKS = plan_ch4.FILL_PARTICLES // (SECTION_BIG + SECTION_SMALL) * SECTION_SMALL // section_ch5.BLOCK


def skipped_blocks(name, e):
    """"" or, for a fill whose inlet skipped blocks (fewer bonds formed than the stream holds: a
    block is inserted whole or not at all, and not where its place is still occupied), a line
    with how many entered and the ideal φv of what entered."""
    formed = e.get("breakage", {}).get("formed", 0)
    entered, part = divmod(formed, section_ch5.BONDS_PER_BLOCK)
    if not entered or part or entered >= STREAM_BLOCKS:   # not the campaign's stream of blocks
        return ""
    small = entered * section_ch5.BLOCK
    big = e["particles"] - small
    volume_ratio = params.IDEAL_PHI_V * SECTION_SMALL / SECTION_BIG   # of a big sphere to a small one
    return ("\n%s: the inlet skipped %d of the %d blocks (a block is inserted whole or not at all, "
            "and not while its place is occupied: docs/mixing.md §2.1), so %d blocks and %d big "
            "spheres entered, whose own ideal φv is %.4f, not %.4f." % (
                name, STREAM_BLOCKS - entered, STREAM_BLOCKS, entered, big,
                volume_ratio * big / small, params.IDEAL_PHI_V))


def clips_section(found):
    """Every fill's final middle clip (the spheres cut by y = 0.5 m)."""
    clips = ["![%s](%s)" % (n, e["clip"]) for n, e in sorted(found.items())
             if e.get("clip") and n.split("/")[1] not in RIGID_CASES]
    return ["### Final middle clips (the spheres cut by y = 0.5 m)", ""] + clips if clips else []


def outflow_rows(found):
    rows = []
    for name, e in sorted(found.items()):
        for o in e.get("outflow", []):
            rows.append("| %s | %s | (%.2f, %.2f) | %d | %.1f | %.1f |" % (
                *name.split("/"), o["x"], o["z"], o["n"], o["mean"], o["std"]))
    return rows


def horizon_section(results=os.path.join(ROOT, "reference_runs", "mixing", "ch5", "results", "horizon")):
    """The cross-engine horizon of the bonded fills and their first breaks: the table of
    `horizon_ch5.py summary` (the cross/CASE/horizon and cross/CASE/jitterK units), as committed
    in RESULTS (make mixing-bonded-report refreshes it first)."""
    from scripts.mixing import horizon_ch5
    cases, spread, tension, commits = horizon_ch5.read_summary(results)
    head = ["### Cross-engine horizon and first breaks of the bonded fills, jdem vs liggghts-jdem", ""]
    if not cases:
        return head + ["(not run yet: `make mixing-bonded ENGINE=cross`)"]
    lines = head + [
        "the first %g s of each fill in both engines (run at commit %s); particles matched by id, "
        "per frame (every 0.02 s) the larger of max |Δx| / R_max and max |Δv| / sqrt(g d_max), as in "
        "Ch. 4; breaks as (step, pair, mode), in order; scripts/mixing/horizon_ch5.py, plot: "
        "horizon/horizon.png" % (cases[0]["curve"]["time"][-1], ", ".join(commits)), "",
        horizon_ch5.table(cases)]
    if spread:
        lines += ["Past the horizon the engines are two realisations of one chaotic fill: the bonds "
                  "broken by the end of each engine's runs, the horizon's (K = 0) and those with the "
                  "stream shifted by K µm in y (`horizon_ch5.py realisation`); the engines' means "
                  "within two standard deviations of a difference of means (2 s √(1/n + 1/n'), n and "
                  "n' the runs of each engine):", "", horizon_ch5.spread_table(spread)]
    if tension:
        lines += ["The same for the failure mode: the bonds broken in tension by the end (the rest broke "
                  "in shear):", "", horizon_ch5.spread_table(tension)]
    claims = horizon_ch5.free_fall_claims(cases)
    if claims:
        lines += ["The seed's claim that weak blocks stay whole in free fall, from the same runs:", ""] + claims
    return lines


def bonded_figures_section(figures):
    """The seed's Figs 5-24 to 5-26 (plots.bonded_figure), as written by main()."""
    lines = ["### Figs 5-24 to 5-26: φv at the 27 points of Table 5-2, per group", ""]
    if not figures:
        return lines + ["(no fill yet)"]
    return lines + ["![Fig. %s, %s](%s)" % (plots.SEED_BONDED_FIGURE[g], e, name)
                    for (e, g), name in sorted(figures.items())]


def section_figure_section(section):
    """The seed's Fig. 5-4 (scripts/mixing/section_ch5.py, ParaView), when it has been drawn."""
    if not section:
        return ["(Fig. 5-4, the repeated section in 3D: `make mixing-bonded-section`, which needs ParaView)"]
    return ["Fig. 5-4, the repeated section in both engines (scripts/mixing/section_ch5.py: ParaView "
            "draws each trajectory's sidecar; the spheres and bonds drawn are checked against the "
            "section):", "", "![Fig. 5-4](%s)" % section]


def report(found, rev, figures=None, elastic=None, section=None):
    lines = ["# Jiang (2021) Chapter 5 bonded blocks: seed | jdem | liggghts-jdem", "",
             "Generated by scripts/mixing/report_ch5.py from the finished fills of `make mixing-bonded` "
             "(commit %s); a row from an earlier commit names it. docs/mixing.md §11." % rev, "",
             "### Table 5-3: φv at the middle clip (points 10–18 of Table 5-2, y = 0.5 m)", "",
             "φv = V_big / V_small, the volumes of the big and the small spheres within a sampling "
             "sphere of r = 0.1 m at each point (the parts of spheres that cross its surface counted, "
             "scripts/mixing/lens.py); ideal φv = 0.0625 (4 big spheres to 512 small per section); "
             "trimmed mean ± std of the points the trim keeps, of 9 (scripts/mixing/stats.py; the seed does not say how "
             "it trims); " + RUN_TIME_NOTE + "; \"e\" marks a fill that kept the energy "
             "accounts (about 1.9x the time in jdem, 1.57x in liggghts-jdem; plan_ch5.keeps_energy)", "",
             "| group | model | seed | jdem | liggghts-jdem | run time jdem / liggghts-jdem [s] |",
             "|---|---|---|---|---|---|"]
    for g in GROUPS:
        for m in MODELS:
            a, b = (found.get("%s/%s" % (e, case(g, m))) for e in ENGINES)
            t = " / ".join(run_time(x) + (" e" if x and x.get("energy") else "") for x in (a, b))
            lines.append("| %d | %d | %.4f ± %.4f | %s | %s | %s |" % (g, m, *SEED_PHI_V[g][m - 1], cell(a), cell(b), t))
    lines += [""] + section_figure_section(section)
    lines += [""] + bonded_figures_section(figures)
    lines += ["", "### Breakage over the whole fill (the seed reports none, spec §4.3)", "",
              "tension and shear: the fractions of the bonds formed that broke in each mode (a bond "
              "breaks in tension when σmax = −Fn/A + |Mt| R̄/I reaches its tensile strength, in shear "
              "when τmax = |Ft|/A + |Mn| R̄/J reaches its shear strength; when both do on one step, by "
              "the larger ratio of stress to strength, tension on a tie: docs/model.md, kernel/jdem_bond.h); "
              "fragments at the end: the connected components of the intact bonds, whole blocks (the "
              "32 spheres of a block) and single spheres included", "",
              "| engine | case | bonds formed | broken | tension | shear | fragments at the end | whole blocks | single spheres |",
              "|---|---|---|---|---|---|---|---|---|"]
    for name, e in sorted(found.items()):
        k = e.get("breakage")
        if k and (k.get("formed") or not name.split("/")[1].startswith("group1_")):   # older Group 1 entries keep an empty one
            lines.append("| %s | %s | %d | %d | %.3f | %.3f | %d | %d | %d |" % (
                *name.split("/"), k["formed"], k["broken"], k["tension"], k["shear"],
                k["fragments"], k["whole_blocks"], k["singles"]))
    lines += ["", "### Breakage over time: broken fraction (tension + shear) and fragments by size", "",
              "at the seed's snapshot times and the end; broken, tension, shear: fractions of the bonds "
              "formed by then (a block still entering adds bonds, so the fraction can fall); fragments: "
              "connected components of the intact bonds, counted by size in spheres (%s); the seed "
              "reports none" %
              ", ".join("%d" % a if a == b else "%d–%d" % (a, b) for a, b in FRAGMENT_BINS), "",
              "| engine | case | t [s] | broken | tension | shear | fragments by size |",
              "|---|---|---|---|---|---|---|"]
    for name, e in sorted(found.items()):
        for b in e.get("breakage_over_time", []) if e.get("breakage", {}).get("formed") else []:
            lines.append("| %s | %s | %.1f | %.3f | %.3f | %.3f | %s |" % (
                *name.split("/"), b["time"], b["total"], b["tension"], b["shear"],
                " / ".join(str(n) for n in b["fragments"])))
    rows = outflow_rows(found)
    if rows:
        lines += ["", "### The outflow below each obstacle (scripts/mixing/outflow.py; the seed measures none)", "",
                  "particles falling faster than 0.5 m/s within 0.3 m of the axis in x and 2–7 radii below it, "
                  "over all frames; the direction from the vertical, positive towards +x", "",
                  "| engine | case | obstacle (x, z) [m] | particles | mean [deg] | std [deg] |",
                  "|---|---|---|---|---|---|"] + rows
    maps = [(n, e["break_map"]) for n, e in sorted(found.items()) if e.get("break_map")]
    if maps:
        lines += ["", "Where the bonds broke (front view, the obstacles grey):", ""]
        lines += ["![%s](%s)" % m for m in maps]
    lines += [""] + horizon_section()
    lines += [""] + agreement_ch5.section(found, CASES + RIGID_CASES)
    lines += [""] + structure_table(found) + [""] + energy_table(found) + [""] + campaign_time_table(found)
    lines += [""] + speed_table(found)
    lines += [""] + elastic_tables(found)
    if elastic:
        lines += ["", "Fig. 5-27 beside the seed's (E per group over the models), and M beneath it; "
                  "Figs 5-28 to 5-30, E and the Poisson ratios point by point (the seed's per-point "
                  "values are not in the text):", ""] + ["![%s](%s)" % (n[:-4], n) for n in elastic]
    walls = [(n, e["wall"]) for n, e in sorted(found.items()) if e.get("wall")]
    lines += ["", "### Fig. 5-23: the voids near the walls (Model 1, Groups 1 and 3)", "",
              "the final deposit's layer against the front wall (the spheres cut by the plane a small "
              "radius off it) beside the middle clip; the solid fractions are in the structure table "
              "above", ""]
    lines += ["![%s](%s)" % w for w in walls] if walls else \
        ["(not drawn yet: a Model 1 fill of Group 1 or 3 measured on this machine)"]
    lines += [""] + differences_section(found)
    lines += [""] + claims(found)
    lines += [""] + rigid_section(found)
    views = [(n, e["views"]) for n, e in sorted(found.items()) if e.get("views")]
    if views:
        lines += ["", "### Snapshots (Figs 5-5 to 5-22): front and side views at t = 1, 3, 9 s and the end", "",
                  "big spheres red, the small ones in whole blocks blue, in fragments of 2–31 green, "
                  "alone orange (Group 1: all small blue)%s" % orange_group1(found), ""]
        lines += ["![%s](%s)" % v for v in views]
    clips = clips_section(found)
    lines += [""] + clips if clips else []
    built = {n: list(dict.fromkeys(e.get("built_by", []) + [v for part in e.get("cubes", []) + e.get("realisations", [])
                                                             for v in part.get("built_by", [])]))
             for n, e in found.items()}
    lines += ["", provenance_section(built)]
    sources = sorted({(n, e["source"]) for n, e in found.items() if e.get("source") != rev} |
                     {("%s, realisation %d" % (n, r["jitter"]), r["source"]) for n, e in found.items()
                      for r in e.get("realisations", []) if r.get("source") != rev})
    lines += ["", "From earlier commits: " + (", ".join("%s (%s)" % s for s in sources) if sources else "none"),
              "", "Not run: %d of %d fills." % (2 * len(CASES + RIGID_CASES) - len(found),
                                                2 * len(CASES + RIGID_CASES)), ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=DEFAULT_OUT)
    ap.add_argument("--results", default=None)
    a = ap.parse_args()
    results = a.results or (DEFAULT_RESULTS if os.path.abspath(a.out) == DEFAULT_OUT else None)
    committed = {}
    if results and os.path.exists(os.path.join(results, "summary.json")):
        with open(os.path.join(results, "summary.json")) as f:
            committed = json.load(f).get("results", {})
    rev = commit()
    os.makedirs(a.out, exist_ok=True)
    found = collect(a.out, committed, rev, results or a.out)
    if results and results != a.out:   # the maps beside both reports
        for e in found.values():
            for png in (e.get("break_map"), e.get("views"), e.get("clip"), e.get("wall")):
                if png and os.path.exists(os.path.join(results, png)):
                    shutil.copy(os.path.join(results, png), os.path.join(a.out, png))
    directories = [a.out] + ([results] if results else [])
    for d in directories:
        os.makedirs(d, exist_ok=True)
    figures = plots.write_bonded_figures(found, ENGINES, directories)
    elastic = write_elastic_figures(found, directories)
    section = None
    if results and os.path.exists(os.path.join(results, section_ch5.FIGURE)):   # drawn by section_ch5.py
        section = section_ch5.FIGURE
        if results != a.out:
            shutil.copy(os.path.join(results, section), os.path.join(a.out, section))
    for d in directories:
        write_atomic(os.path.join(d, "report.md"), report(found, rev, figures, elastic, section))
        write_atomic(os.path.join(d, "summary.json"),
                     json.dumps({"commit": rev, "results": found}, indent=1, default=float))
        print("report_ch5.py: wrote %s" % os.path.join(d, "report.md"))


if __name__ == "__main__":
    main()
