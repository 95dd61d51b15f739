#!/usr/bin/python3
"""mepa_drop.py — Del Cid's (2015) MEPA drop test (her §4.3.2, Table 4.1, Figs 4.5 and 4.6) in
both engines, its force–overlap traces checked against the law's closed-form branches.

    scripts/mepa_drop.py [--out DIR] [--engines jdem,liggghts-jdem] [--quick]

Runs the cases of reference_runs/mepa/drop.yaml (linear: n = 1; hertzian: n = 3/2; and
hertzian_past_end, thrown down so that it passes the virgin branch's end) in each
engine and writes DIR/report.md, DIR/summary.json and DIR/drop_CASE.png (default DIR out/mepa),
stamped with the commit they came from; --results R copies them into R as well (make mepa:
reference_runs/mepa/results, committed).
--quick (make test): the first impact only, the sphere starting just above the floor with the
speed of its fall (the same energy), for QUICK_TIME seconds.
The checks, one PASS/FAIL line each (exit status 1 if any fails):
  - the first impact loads along the virgin branch k1 delta^n (past its end
    d_end = (k2/(k2 - k1))^(1/n) dp_max along k2 (delta^n - dp_max^n)), and unloads along
    k2 (delta^n - dp^n), dp = min(((k2 - k1)/k2)^(1/n) delta_peak, dp_max), until the adhesive
    bound -kc delta^n, which it follows to separation: every frame within BRANCH_TOL of the
    largest force;
  - every contact frame of the run, the second impact included, lies between the adhesive bound
    and the upper one (the virgin branch, continued past its end along k2 from dp_max);
  - the peak overlap is the energy balance's, the work of the upper bound to d equal to
    m g (h + d) + m v0^2/2 for a drop from gap h at speed v0, to PEAK_TOL;
  - the engines' trajectories agree (scripts/compare_trajectories.py, the scene's tolerance).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

import h5py
import matplotlib
import numpy as np
import yaml

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from scripts import engines  # noqa: E402

SCENE = os.path.join(engines.ROOT, "reference_runs", "mepa", "drop.yaml")
BRANCH_TOL = 1e-9   # of the largest force: the same law on the same overlaps, round-off apart
PEAK_TOL = 1e-4     # relative: the frame nearest the peak misses it by O((v dt)^2)
QUICK_TIME = 0.04   # [s]: both cases' first impacts end within it
QUICK_GAP = 1e-4    # of the radius: where the quick run's sphere starts above the floor
ENGINE_LABELS = {"jdem": "jdem", "liggghts-jdem": "liggghts-jdem"}


def resolved(case):
    return yaml.load(engines.resolve(SCENE, case, check=True).stdout, Loader=yaml.CSafeLoader)


def quick_scene(doc, case, out_dir):
    """CASE's first impact alone, from its resolved scene DOC (changed in place): the sphere
    QUICK_GAP radii above the floor with the speed of its fall from the scene's gap, for
    QUICK_TIME seconds (a resolved scene in OUT_DIR)."""
    p = doc["particles"][0]
    R, g = float(p["radius"]), -float(doc["gravity"][2])
    fall = float(p["position"][2]) - R - QUICK_GAP * R
    v0 = float((p.get("velocity") or [0.0, 0.0, 0.0])[2])
    p["position"][2] = R * (1.0 + QUICK_GAP)
    p["velocity"] = [0.0, 0.0, -(v0 * v0 + 2.0 * g * fall) ** 0.5]
    doc["time"] = {"dt": doc["time"]["dt"], "end_time": QUICK_TIME}
    doc.pop("sweep", None)
    path = os.path.join(out_dir, "quick_%s.yaml" % case)
    with open(path, "w") as f:
        yaml.safe_dump(doc, f)
    return path


def law_of(doc):
    """The contact's MEPA constants of a case's resolved scene DOC: the sphere against the floor
    (series pairs), its mass, radius, drop gap and initial speed."""
    mats, model = doc["materials"], doc["model"]
    sphere, floor = mats["sphere"], mats["floor"]

    def series(key):
        a, b = float(sphere.get(key, 0.0)), float(floor.get(key, 0.0))
        return a * b / (a + b) if a + b > 0 else 0.0
    p = doc["particles"][0]
    R = float(p["radius"])
    return {"k1": series("loading_stiffness"), "k2": series("unloading_stiffness"),
            "kc": series("cohesive_stiffness"), "n": float(model["mepa_exponent"]),
            "dp_max": float(model["mepa_plastic_depth"]) * R, "R": R,
            "m": 4.0 / 3.0 * np.pi * R ** 3 * float(sphere["density"]),
            "g": -float(doc["gravity"][2]), "gap": float(p["position"][2]) - R,
            "v0": float((p.get("velocity") or [0.0, 0.0, 0.0])[2])}


def virgin_end(law):
    """Where the virgin branch ends [m]."""
    return (law["k2"] / (law["k2"] - law["k1"])) ** (1.0 / law["n"]) * law["dp_max"]


def upper_bound(d, law):
    """The virgin branch, continued past its end along k2 from dp_max [N]."""
    n = law["n"]
    return np.maximum(law["k1"] * d ** n, law["k2"] * (d ** n - law["dp_max"] ** n))


def run(engine, scene, case, out_dir):
    """Run CASE of SCENE (case None: its only one) in ENGINE, every step written: (trajectory
    path, wall seconds)."""
    out = os.path.join(out_dir, "%s_%s.h5" % (case, engine))
    which = engines.case_args(None if scene != SCENE else case)
    if engine == "jdem":
        cmd = [engines.JDEM, "run", scene, *which, "-o", out, "--force", "--quiet"]
    else:
        cmd = engines.script("liggghts_run", scene, *which, "-o", out)
    r, seconds = engines.timed(cmd, check=True)
    return out, seconds


def trace(path, law):
    """Overlap [m] and the floor's normal force on the sphere [N] at every frame."""
    with h5py.File(path, "r") as f:
        z = f["particles/all/position/value"][:, 0, 2]
        fz = f["particles/all/force/value"][:, 0, 2]
    return law["R"] - z, fz + law["m"] * law["g"]


def first_impact(delta):
    """Frames [start, end) of the first contact and the frame of its peak overlap."""
    touching = delta > 0
    start = int(np.argmax(touching))
    end = start + int(np.argmin(touching[start:]))
    return start, end, start + int(np.argmax(delta[start:end]))


def branch_residual(delta, force, law, impact):
    """Largest |F - branch| of the first impact (its frames and peak, first_impact), relative to
    the largest force, and the plastic overlap it leaves."""
    k1, k2, kc, n = law["k1"], law["k2"], law["kc"], law["n"]
    s, e, peak = impact
    d = delta[s:e]
    dp = min(((k2 - k1) / k2) ** (1.0 / n) * delta[peak], law["dp_max"])
    ref = np.where(np.arange(s, e) <= peak, upper_bound(d, law),
                   np.maximum(k2 * (d ** n - dp ** n), -kc * d ** n))
    return float(np.max(np.abs(force[s:e] - ref)) / np.max(np.abs(force))), dp


def within_bounds(delta, force, law):
    """Worst excursion of any contact frame beyond the bounds, relative to the largest force."""
    c = delta > 0
    d, f = delta[c], force[c]
    above = f - upper_bound(d, law)
    below = -law["kc"] * d ** law["n"] - f
    return float(max(above.max(), below.max(), 0.0) / np.max(np.abs(force)))


def upper_work(d, law):
    """The work of the upper bound from 0 to d [J] (closed form)."""
    k1, k2, n, dp = law["k1"], law["k2"], law["n"], law["dp_max"]
    e = virgin_end(law)
    if d <= e:
        return k1 * d ** (n + 1) / (n + 1)
    return k1 * e ** (n + 1) / (n + 1) + k2 * ((d ** (n + 1) - e ** (n + 1)) / (n + 1) - dp ** n * (d - e))


def peak_by_energy(law):
    """The peak overlap of the first impact from the energy balance (bisection)."""
    m, g, h = law["m"], law["g"], law["gap"]
    lo, hi = 0.0, law["R"]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if upper_work(mid, law) - m * g * (h + mid) - 0.5 * m * law["v0"] ** 2 < 0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def measure(delta, force, law, seconds):
    """The checks' figures of one run's trace."""
    s, e, peak = impact = first_impact(delta)
    residual, dp = branch_residual(delta, force, law, impact)
    x_end = virgin_end(law)
    expected = peak_by_energy(law)
    return {"branch_residual": residual, "bounds_excursion": within_bounds(delta, force, law),
            "peak_overlap": float(delta[peak]), "peak_overlap_energy": expected,
            "peak_error": abs(float(delta[peak]) - expected) / expected,
            "largest_overlap": float(delta.max()), "virgin_branch_end": x_end,
            "plastic_overlap": dp, "peak_force": float(force[s:e].max()),
            "largest_tension": float(force[s:e].min()),
            "contacts": int(np.sum(np.diff((delta > 0).astype(int)) == 1) + (delta[0] > 0)),
            "seconds": seconds}


def figure(case, law, traces, path):
    """F against delta for each engine, with the bounds and the first unloading branch."""
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    dmax = max(float(d.max()) for d, _ in traces.values())
    d = np.linspace(0.0, 1.05 * dmax, 400)
    n = law["n"]
    ax.plot(d * 1e3, upper_bound(d, law), "k--", lw=0.8, label="virgin bound $k_1\\delta^n$ (then $k_2$)")
    ax.plot(d * 1e3, -law["kc"] * d ** n, "k:", lw=0.8, label="adhesive bound $-k_c\\delta^n$")
    styles = {"jdem": dict(color="tab:blue", lw=0.8, zorder=3),
              "liggghts-jdem": dict(color="tab:orange", lw=0, marker=".", ms=3, zorder=2)}
    for engine, (delta, force) in sorted(traces.items(), reverse=True):
        c = delta > 0
        ax.plot(delta[c] * 1e3, force[c], label=ENGINE_LABELS[engine], **styles[engine])
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.set_xlabel("overlap $\\delta$ [mm]")
    ax.set_ylabel("normal force on the sphere [N]")
    ax.set_title("MEPA drop test past the virgin branch's end, n = %g (not in the seed)" % n
                 if case.endswith("past_end") else
                 "MEPA drop test, n = %g (Del Cid 2015, Fig. %s)" % (n, "4.5" if n == 1 else "4.6"))
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def commit():
    """The repository's commit (with '+' when the tree has changes), or 'unknown'."""
    def git(*args):
        r = subprocess.run(["git", "-C", engines.ROOT, *args], capture_output=True, text=True)
        return r.stdout.strip() if r.returncode == 0 else ""
    head = git("rev-parse", "--short", "HEAD")
    return (head + ("+" if git("status", "--porcelain", "--untracked-files=no") else "")) or "unknown"


def report(results, agreement, out_dir, checks, stamp):
    engines_run = sorted({e for r in results.values() for e in r["engines"]})
    lines = ["# MEPA drop test (Del Cid 2015, §4.3.2, Table 4.1, Figs 4.5 and 4.6)", "",
             ("Generated by `scripts/mepa_drop.py` (`make mepa`) at commit %s.  A sphere of R = 50 mm "
              "dropped from a gap of one radius onto a floor, MEPA's law alone (no dashpot, no "
              "friction); the table's stiffnesses are the contact's (per-type inputs twice them, "
              "combined in series).  The seed shows the traces as figures only and prints no "
              "number: its column says what the figures show." % stamp), ""]
    for case, r in results.items():
        law = r["law"]
        lines += ["## %s (n = %g)" % (case, law["n"]), "",
                  "k1 = %.4g, k2 = %.4g, kc = %.4g N/m^%g; dp_max = %.4g mm." % (
                      law["k1"], law["k2"], law["kc"], law["n"], law["dp_max"] * 1e3), "",
                  "| | seed | " + " | ".join(engines_run) + " |",
                  "|---|---|" + "---|" * len(engines_run)]
        rows = [("virgin loading along k1, unloading along k2, then the adhesive bound "
                 "(first impact; largest deviation / largest force)", "follows the three branches",
                 lambda m: "%.1e" % m["branch_residual"]),
                ("every contact frame within the bounds (worst excursion / largest force)",
                 "the branches bound the trace", lambda m: "%.1e" % m["bounds_excursion"]),
                ("peak overlap [mm] (energy balance: %.6g)" % (
                    list(r["engines"].values())[0]["peak_overlap_energy"] * 1e3), "not given",
                 lambda m: "%.6g (%.1e off)" % (m["peak_overlap"] * 1e3, m["peak_error"])),
                ("plastic overlap after the first impact [mm]", "not given",
                 lambda m: "%.4g" % (m["plastic_overlap"] * 1e3)),
                ("peak force, largest tension [N]", "not given",
                 lambda m: "%.4g, %.4g" % (m["peak_force"], m["largest_tension"])),
                ("impacts in the run", "one shown", lambda m: "%d" % m["contacts"]),
                ("run time [s] (wall, one core)", "not given", lambda m: "%.2f" % m["seconds"])]
        ours_only = case.endswith("past_end")  # thrown down: not the seed's test
        for label, seed, fmt in rows:
            lines.append("| %s | %s | %s |" % (label, "—" if ours_only else seed, " | ".join(
                fmt(r["engines"][e]) if e in r["engines"] else "—" for e in engines_run)))
        if case in agreement:
            lines += ["", "Engines' trajectories: %s." % agreement[case]]
        lines += ["", "![](drop_%s.png)" % case, ""]
    lines += ["## Checks", ""] + ["- %s" % c for c in checks]
    with open(os.path.join(out_dir, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(engines.ROOT, "out", "mepa"))
    ap.add_argument("--engines", default="jdem,liggghts-jdem")
    ap.add_argument("--quick", action="store_true", help="the first impacts only (make test)")
    ap.add_argument("--results", help="a directory to copy the report, summary and figures into")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    names = a.engines.split(",")
    results, agreement, checks, failed = {}, {}, [], 0

    def check(name, ok, detail):
        nonlocal failed
        failed += not ok
        line = "%s %s: %s" % ("PASS" if ok else "FAIL", name, detail)
        print(line, flush=True)
        checks.append(line)

    for case in engines.cases(SCENE):
        doc = resolved(case)
        law = law_of(doc)
        scene = quick_scene(doc, case, a.out) if a.quick else SCENE
        runs = {e: run(e, scene, case, a.out) for e in names}
        traces = {e: trace(p, law) for e, (p, _) in runs.items()}
        measured = {e: measure(*traces[e], law, s) for e, (_, s) in runs.items()}
        for e, m in measured.items():
            check("%s %s branches" % (case, e), m["branch_residual"] <= BRANCH_TOL,
                  "largest deviation %.2e of the largest force (<= %g)" % (m["branch_residual"], BRANCH_TOL))
            past = m["largest_overlap"] > m["virgin_branch_end"]
            check("%s %s bounds" % (case, e),
                  m["bounds_excursion"] <= BRANCH_TOL and past == case.endswith("past_end"),
                  "worst excursion %.2e; largest overlap %.4g mm %s the virgin branch's end %.4g mm" % (
                      m["bounds_excursion"], m["largest_overlap"] * 1e3, "past" if past else "short of",
                      m["virgin_branch_end"] * 1e3))
            check("%s %s peak" % (case, e), m["peak_error"] <= PEAK_TOL,
                  "peak overlap %.6g mm against the energy balance's %.6g mm" % (
                      m["peak_overlap"] * 1e3, m["peak_overlap_energy"] * 1e3))
        if "jdem" in runs and "liggghts-jdem" in runs:
            r = engines.run(engines.script("compare_trajectories", runs["jdem"][0], runs["liggghts-jdem"][0]))
            agreement[case] = r.stdout.strip().splitlines()[-1] if r.stdout.strip() else "no output"
            check("%s engines agree" % case, r.returncode == 0, agreement[case])
        figure(case, law, traces, os.path.join(a.out, "drop_%s.png" % case))
        results[case] = {"law": law, "engines": measured}
    stamp = commit()
    report(results, agreement, a.out, checks, stamp)
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump({"commit": stamp, "results": results, "agreement": agreement, "checks": checks}, f,
                  indent=1)
    print("report: %s" % os.path.join(a.out, "report.md"))
    if a.results:
        os.makedirs(a.results, exist_ok=True)
        for name in ["report.md", "summary.json"] + ["drop_%s.png" % c for c in results]:
            shutil.copy(os.path.join(a.out, name), os.path.join(a.results, name))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
