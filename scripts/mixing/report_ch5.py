#!/usr/bin/python3
"""report_ch5.py — the Chapter 5 results so far, seed | jdem | liggghts-jdem, from the finished
fills of `make mixing-bonded` (docs/mixing.md §11).

    /usr/bin/python3 -m scripts.mixing.report_ch5 [--out out/mixing/ch5] [--results DIR]

Reads OUT/ENGINE/groupG_modelM/fill.h5: phi_v at the 27 points of Table 5-2 from the last frame
(Table 5-3 is the middle clip, points 10-18, y = 0.5 m; the trimmed mean and std of
scripts/mixing/stats.py), and the breakage of the whole fill (scripts/mixing/breakage.py: the
bonds formed and broken per mode, the fragments at the end), and when all 9 compressions of the
middle clip are done (OUT/ENGINE/CASE/cubeK.h5, K = 10..18) Tables 5-4 and 5-5 (E, nu_xy, nu_xz of
the orthotropic fit on the best-fit particle strain) and the unambiguous M and K0
(report_ch4.cube_result, the Ch. 4 analysis); the run times from the campaign's
.campaign_times.json.  Writes OUT/report.md and OUT/summary.json, and with --results (default
reference_runs/mixing/ch5/results for the default OUT) also there; a fill not under OUT is
taken from the committed summary.json, with the commit it came from.  The seed reports no
breakage at all (spec §4.3): those columns have no seed value.
"""
import argparse
import json
import os

import numpy as np

from scripts.mixing import breakage, deposit, outflow, params, plots, stats
from scripts.mixing_views import scene_geometry
from scripts.mixing.report_ch4 import commit, cube_result, write_atomic

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_OUT = os.path.join(ROOT, "out", "mixing", "ch5")
DEFAULT_RESULTS = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "results")
ENGINES = ("jdem", "liggghts-jdem")
GROUPS = (1, 2, 3)
MODELS = tuple(range(1, 7))
# Table 5-2: points 1-27, y = 0.25 (1-9), 0.5 (10-18, the middle clip), 0.75 (19-27)
POINTS_TABLE_5_2 = np.array([[x, y, z] for y in (0.25, 0.5, 0.75) for z in (0.2, 0.3, 0.4)
                             for x in (0.25, 0.5, 0.75)])
MIDDLE_CLIP = slice(9, 18)
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
SNAPSHOTS = (1.0, 3.0, 9.0)   # [s] the seed's snapshot times (Figs 5-5 to 5-22), then the end
# fragment sizes (spheres) counted over time: single spheres, pieces, half blocks, whole blocks
FRAGMENT_BINS = ((1, 1), (2, 7), (8, 15), (16, 31), (32, 32))


def case(g, m):
    return "group%d_model%d" % (g, m)


def fill_result(path):
    dep = deposit.read_frame(path)
    phi = [float(p["phi_v"]) for p in params.at_points(dep, POINTS_TABLE_5_2)]
    out = {"particles": int(len(dep.radius)), "time": dep.time, "phi_v": phi,
           "middle_clip": stats.summary(phi[MIDDLE_CLIP])}
    try:
        rec = breakage.read_bonds(path)
    except breakage.BreakageError:
        return out   # Group 1: no bonds
    end = int(max(rec["formed"].max(initial=0), rec["broken_step"].max(initial=0), dep.step))
    sizes = breakage.fragment_sizes(rec, end)
    out["breakage"] = dict(breakage.broken_fraction(rec, end), fragments=int(len(sizes)),
                           whole_blocks=int(np.count_nonzero(sizes == 32)),
                           singles=int(np.count_nonzero(sizes == 1)))
    steps = [round(t / rec["dt"]) for t in SNAPSHOTS] + [end]
    out["breakage_over_time"] = [dict(b, fragments=fragment_histogram(breakage.fragment_sizes(rec, b["step"])))
                                 for b in breakage.over_time(rec, steps)]
    out["_breaks"] = (rec["broken_at"], rec["mode"])   # for the map; not in summary.json
    return out


def fragment_histogram(sizes):
    """The number of fragments in each FRAGMENT_BINS range of sizes."""
    return [int(np.count_nonzero((sizes >= a) & (sizes <= b))) for a, b in FRAGMENT_BINS]


def write_break_map(entry, name, path, directory):
    """The front view of where the fill's bonds broke, as DIR/ENGINE_CASE_breaks.png."""
    position, mode = entry.pop("_breaks")
    if not len(mode):
        return None
    box, cylinders, _ = scene_geometry(path)
    png = os.path.join(directory, name.replace("/", "_") + "_breaks.png")
    plots.break_map(position, mode, png, box, cylinders, title=f"{name}: bond breaks")
    return os.path.basename(png)


def times(out):
    try:
        with open(os.path.join(out, "jdem", case(1, 1), ".campaign_times.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def collect(out, committed, rev, directory):
    found, spent = {}, times(out)
    for engine in ENGINES:
        for g in GROUPS:
            for m in MODELS:
                name = "%s/%s" % (engine, case(g, m))
                path = os.path.join(out, engine, case(g, m), "fill.h5")
                if os.path.exists(path):
                    entry = dict(fill_result(path), source=rev)
                    entry["outflow"] = outflow.spread(path, scene_geometry(path)[1])
                    if "_breaks" in entry:
                        entry["break_map"] = write_break_map(entry, name, path, directory)
                    cubes = [os.path.join(out, engine, case(g, m), "cube%d.h5" % k) for k in CUBES]
                    if all(os.path.exists(c) for c in cubes):
                        entry["cubes"] = [cube_result(c) for c in cubes]
                        took = [spent.get("%s/cube%d" % (name, k), {}).get("seconds") for k in CUBES]
                        if all(t is not None for t in took):
                            entry["cube_seconds"] = float(sum(took))
                    if name + "/fill" in spent:
                        entry["seconds"] = spent[name + "/fill"].get("seconds")
                    found[name] = entry
                elif name in committed:
                    found[name] = committed[name]
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


def elastic_tables(found):
    """Tables 5-4 and 5-5 (the orthotropic fit) and M, K0 (unambiguous), seed | jdem | liggghts-jdem."""
    lines = ["### Tables 5-4 and 5-5: E and the Poisson ratios at the middle clip (σzz = 5 kPa)", "",
             "mean ± std over the 9 cubes of points 10–18, the highest and lowest dropped; the fit of a "
             "laterally confined cube is ill-posed (spec §2.4, docs/model.md §10): compare M and K0", "",
             "| group | model | E seed [Pa] | E jdem | E liggghts-jdem | νxy seed | νxy jdem | νxy liggghts-jdem "
             "| νxz seed | νxz jdem | νxz liggghts-jdem | M (wall strain) jdem / liggghts-jdem [Pa] | K0 jdem / liggghts-jdem "
             "| 9 cubes' run time jdem / liggghts-jdem [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for g in GROUPS:
        for m in MODELS:
            es = [found.get("%s/%s" % (e, case(g, m))) for e in ENGINES]
            if not any(e and "cubes" in e for e in es):
                continue
            cols = []
            for key, fmt in (("E", "%.0f"), ("nu_xy", "%.3f"), ("nu_xz", "%.3f")):
                cols.append(fmt % SEED_ELASTIC[key][g][m - 1][0] + " ± " + fmt % SEED_ELASTIC[key][g][m - 1][1])
                cols += [elastic_cell(e, key, fmt) for e in es]
            cols.append(" / ".join(elastic_cell(e, "M_wall", "%.0f") for e in es))
            cols.append(" / ".join(elastic_cell(e, "K0", "%.3f") for e in es))
            cols.append(" / ".join("%.0f" % e["cube_seconds"] if e and e.get("cube_seconds") else "—" for e in es))
            lines.append("| %d | %d | %s |" % (g, m, " | ".join(cols)))
    if len(lines) == 6:
        lines.append("(no case has all 9 compressions yet)")
    return lines


def claims(found):
    """The seed's claims (spec §3.8) that the finished fills can decide, per engine: held, not
    held, or what is still missing."""
    lines = ["### The seed's claims (spec §3.8)", ""]
    for engine in ENGINES:
        get = lambda g, m: found.get("%s/%s" % (engine, case(g, m)))
        for m in MODELS:
            g1, g2, g3 = get(1, m), get(2, m), get(3, m)
            if not g1 or not (g2 or g3):
                continue
            d1 = abs(g1["middle_clip"]["mean"] - params.IDEAL_PHI_V)
            for g, e in ((2, g2), (3, g3)):
                if not e:
                    continue
                d = abs(e["middle_clip"]["mean"] - params.IDEAL_PHI_V)
                lines.append("- %s Model %d: Group %d blocks mix better than unbonded ones (|φv − %.4f| at "
                             "the middle clip %.4f against Group 1's %.4f): **%s**" % (
                                 engine, m, g, params.IDEAL_PHI_V, d, d1, "held" if d < d1 else "not held"))
            if m == 3 and g2:
                a, b = g1["middle_clip"]["std"], g2["middle_clip"]["std"]
                lines.append("- %s Model 3: the spread of φv drops by more than 50 %% from Group 1 to Group 2 "
                             "(std %.4f → %.4f, %+.0f %%): **%s**" % (
                                 engine, a, b, 100 * (b - a) / a, "held" if b < 0.5 * a else "not held"))
            for o1, o2 in zip(g1.get("outflow", []), (g2 or {}).get("outflow", [])):
                lines.append("- %s Model %d: weak blocks widen the outflow below the obstacle at (%.2f, %.2f) "
                             "(std of the direction from the vertical %.1f° against Group 1's %.1f°; %d and %d "
                             "particles, scripts/mixing/outflow.py): **%s**" % (
                                 engine, m, o1["x"], o1["z"], o2["std"], o1["std"], o2["n"], o1["n"],
                                 "held" if o2["std"] > o1["std"] else "not held"))
            if all(e and "cubes" in e for e in (g1, g2, g3)):
                ms = [stats.summary([c["M_wall"] for c in e["cubes"]])["mean"] for e in (g1, g2, g3)]
                lines.append("- %s Model %d: stiffness falls as bond strength rises (M %.0f, %.0f, %.0f Pa "
                             "for Groups 1-3): **%s**" % (engine, m, *ms,
                                                         "held" if ms[0] > ms[1] > ms[2] else "not held"))
    if len(lines) == 2:
        lines.append("(none yet: each needs a Group 1 fill and a bonded fill of the same model)")
    return lines


def outflow_rows(found):
    rows = []
    for name, e in sorted(found.items()):
        for o in e.get("outflow", []):
            rows.append("| %s | %s | (%.2f, %.2f) | %d | %.1f | %.1f |" % (
                *name.split("/"), o["x"], o["z"], o["n"], o["mean"], o["std"]))
    return rows


def report(found, rev):
    lines = ["# Jiang (2021) Chapter 5 bonded blocks: seed | jdem | liggghts-jdem", "",
             "Generated by scripts/mixing/report_ch5.py from the finished fills of `make mixing-bonded` "
             "(commit %s); a row from an earlier commit names it. docs/mixing.md §11." % rev, "",
             "### Table 5-3: φv at the middle clip (points 10–18 of Table 5-2, y = 0.5 m)", "",
             "trimmed mean ± std (scripts/mixing/stats.py; the seed does not say how it trims); "
             "ideal φv = 0.0625", "",
             "| group | model | seed | jdem | liggghts-jdem | run time jdem / liggghts-jdem [s] |",
             "|---|---|---|---|---|---|"]
    for g in GROUPS:
        for m in MODELS:
            a, b = (found.get("%s/%s" % (e, case(g, m))) for e in ENGINES)
            t = " / ".join("%.0f" % x["seconds"] if x and x.get("seconds") else "—" for x in (a, b))
            lines.append("| %d | %d | %.4f ± %.4f | %s | %s | %s |" % (g, m, *SEED_PHI_V[g][m - 1], cell(a), cell(b), t))
    lines += ["", "### Breakage over the whole fill (the seed reports none, spec §4.3)", "",
              "| engine | case | bonds formed | broken | tension | shear | fragments at the end | whole blocks | single spheres |",
              "|---|---|---|---|---|---|---|---|---|"]
    for name, e in sorted(found.items()):
        k = e.get("breakage")
        if k:
            lines.append("| %s | %s | %d | %d | %.3f | %.3f | %d | %d | %d |" % (
                *name.split("/"), k["formed"], k["broken"], k["tension"], k["shear"],
                k["fragments"], k["whole_blocks"], k["singles"]))
    lines += ["", "### Breakage over time: broken fraction (tension + shear) and fragments by size", "",
              "at the seed's snapshot times and the end; fragments: connected components of the intact "
              "bonds, counted by size in spheres (%s); the seed reports none" %
              ", ".join("%d" % a if a == b else "%d–%d" % (a, b) for a, b in FRAGMENT_BINS), "",
              "| engine | case | t [s] | broken | tension | shear | fragments by size |",
              "|---|---|---|---|---|---|---|"]
    for name, e in sorted(found.items()):
        for b in e.get("breakage_over_time", []):
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
    lines += [""] + elastic_tables(found) + [""] + claims(found)
    sources = sorted({(n, e["source"]) for n, e in found.items() if e.get("source") != rev})
    lines += ["", "From earlier commits: " + (", ".join("%s (%s)" % s for s in sources) if sources else "none"),
              "", "Not run: %d of %d fills." % (2 * 18 - len(found), 2 * 18), ""]
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
        import shutil
        for e in found.values():
            if e.get("break_map") and os.path.exists(os.path.join(results, e["break_map"])):
                shutil.copy(os.path.join(results, e["break_map"]), os.path.join(a.out, e["break_map"]))
    for d in [a.out] + ([results] if results else []):
        os.makedirs(d, exist_ok=True)
        write_atomic(os.path.join(d, "report.md"), report(found, rev))
        write_atomic(os.path.join(d, "summary.json"),
                     json.dumps({"commit": rev, "results": found}, indent=1, default=float))
        print("report_ch5.py: wrote %s" % os.path.join(d, "report.md"))


if __name__ == "__main__":
    main()
