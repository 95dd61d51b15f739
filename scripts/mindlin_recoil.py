#!/usr/bin/python3
"""mindlin_recoil.py — Chung–Ooi tests 5 and 8 with both tangential stiffnesses (the seed's
K_t = K_n and Mindlin's K_t = 8 G* sqrt(R* delta)) in both engines, next to the paper's digitised
curves: which stiffness reproduces the micro-slip recoil, and why (docs/model.md §4.5).

    scripts/mindlin_recoil.py [--out out/mindlin] [--report reference_runs/chung_ooi/results]
                              [--analyse-only]

Runs `chung_ooi.py run --tests 5,8 --model tangential_stiffness=V` for V = jiang2021, mindlin:
every case in jdem into OUT/V (Test 8: the primary case B), and, for mindlin, the quick cases
(QUICK_CASES) in both engines into OUT/mindlin_quick, exactly the suite chung-ooi-mindlin
(LIGGGHTS takes ten times as long per case; the engines agree to round-off, engine_difference;
the seed's stiffness in LIGGGHTS is the chung-ooi suite's); reads their summary.json and writes
REPORT/mindlin_recoil.md and REPORT/mindlin_recoil.png.  --analyse-only reuses the trajectories.

The recoil: in Test 5 the contact point of a sphere that sticks rebounds backwards,
Psi2 = V'_st/(mu V'_cn) < 0; in Test 8 its slip reverses, beta = -V'_st/V_st > 0.  Rigid-body
theory gives neither (Psi2 = Psi1 - 3.5(1 + e) in sliding, 0 at the stick threshold; beta = 0 in
stick); their sign and depth come from the tangential compliance, the ratio K_t/K_n.
"""
import argparse
import json
import math
import os
import sys

import matplotlib
import numpy as np
import yaml

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

from scripts.engines import run as run_command, script  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RULES = ("jiang2021", "mindlin")
ENGINES = ("jdem", "liggghts")
PUBLISHED = os.path.join(ROOT, "reference_runs", "chung_ooi", "published")
STYLE = {("jiang2021", "jdem"): "o-", ("jiang2021", "liggghts"): "x",
         ("mindlin", "jdem"): "s-", ("mindlin", "liggghts"): "+"}
LABEL = {"jiang2021": "K_t = K_n (jiang2021)", "mindlin": "Mindlin 8G*√(R*δ)"}


def case_b_scenes(out, rule):
    """OUT/RULE/scenes/test8.yaml with the option and case B only (chung_ooi.py keeps a scene it
    finds there)."""
    path = os.path.join(out, rule, "scenes", "test8.yaml")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(os.path.join(ROOT, "reference_runs", "chung_ooi", "test8", "scene.yaml")) as f:
        scene = yaml.load(f, Loader=yaml.CSafeLoader)
    scene.setdefault("model", {})["tangential_stiffness"] = rule
    values = scene["sweep"][0]["values"]
    scene["sweep"][0]["values"] = {k: v for k, v in values.items() if k.endswith("caseB")}
    with open(path, "w") as f:
        yaml.safe_dump(scene, f)


def run(out, rule):
    case_b_scenes(out, rule)
    runs = [("jdem", [], rule)] + ([(",".join(ENGINES), ["--quick"], rule + "_quick")]
                                   if rule == "mindlin" else [])
    for engines, quick, where in runs:
        cmd = script("chung_ooi", "run", "--tests", "5,8", "--engines", engines,
                     "--model", f"tangential_stiffness={rule}", "--out", os.path.join(out, where), *quick)
        run_command(cmd, check=True, capture=False)


def load(out, rule):
    """jdem's records of every case, and LIGGGHTS' and the engines' difference of the quick ones."""
    with open(os.path.join(out, rule, "summary.json")) as f:
        records = json.load(f)
    records = [r for r in records if r["test"] != 8 or r["case"].rsplit("_", 1)[0].endswith("caseB")]
    quick = os.path.join(out, rule + "_quick", "summary.json")
    if os.path.exists(quick):
        with open(quick) as f:
            records += [r for r in json.load(f) if r["engine"] != "jdem"]
    return records


def series(records, test, material, metric, x_metric, engine):
    """(x, y) of one metric over the cases of one material, sorted by x."""
    by_case = {}
    for r in records:
        if r["test"] == test and r["engine"] == engine and r["case"].rsplit("_", 1)[0] == material:
            by_case.setdefault(r["case"], {})[r["metric"]] = r["value"]
    pts = sorted((v[x_metric], v[metric]) for v in by_case.values() if metric in v and x_metric in v)
    return np.array([p[0] for p in pts]), np.array([p[1] for p in pts])


def psi1_series(records, material, metric, engine, mu=0.3):
    x, y = series(records, 5, material, metric, "tan_incident", engine)
    return x / mu, y


def published(test, quantity, material):
    path = os.path.join(PUBLISHED, f"test{test}_{quantity}_{material}.csv")
    if not os.path.exists(path):
        return None
    d = np.loadtxt(path, delimiter=",", comments="#")
    return d[:, 0], d[:, 1]


def rms_vs(curve, x, y):
    """RMS of y - curve(x) over the x inside the curve's range, and the number of points."""
    inside = (x >= curve[0][0]) & (x <= curve[0][-1])
    if not inside.any():
        return math.nan, 0
    return float(np.sqrt(np.mean((y[inside] - np.interp(x[inside], *curve)) ** 2))), int(inside.sum())


# ------------------------------------------------------------------------------------------
# stiffness ratios, from the scenes' materials (the kernel's formulas, docs/model.md §2, §4.5)

def hertz_prefactor(E, nu, R):
    return 2.0 * E / (2.0 * (1.0 + nu)) * math.sqrt(2.0 * R) / (3.0 * (1.0 - nu))


def shear_share(E, nu):
    return 2.0 * (2.0 - nu) * (1.0 + nu) / E


def ratios(out):
    """{(test, material): (K_t/K_n secant, K_t / dF_n/d(delta))} for Mindlin's K_t; the seed's
    K_t = K_n has 1 and 2/3."""
    found = {}
    for test in (5, 8):
        with open(os.path.join(out, "mindlin", "scenes", f"test{test}.yaml")) as f:
            scene = yaml.load(f, Loader=yaml.CSafeLoader)
        for material, over in scene["sweep"][0]["values"].items():
            if test == 8 and not material.endswith("caseB"):
                continue
            if test == 5:
                E, nu = over["materials.sphere.youngs_modulus"], over["materials.sphere.poisson_ratio"]
                R = scene["particles"][0]["radius"]
                k_n = 4.0 / 3.0 * E / (1.0 - nu * nu) * math.sqrt(R)   # rigid plane, wall_rule hertz
                k_t = 8.0 / shear_share(E, nu) * math.sqrt(R)
            else:
                E1, nu1 = over["materials.small.youngs_modulus"], over["materials.small.poisson_ratio"]
                E2, nu2 = over["materials.big.youngs_modulus"], over["materials.big.poisson_ratio"]
                R1, R2 = (p["radius"] for p in scene["particles"])
                kp1, kp2 = hertz_prefactor(E1, nu1, R1), hertz_prefactor(E2, nu2, R2)
                k_n = 2.0 * kp1 * kp2 / (kp1 + kp2)                    # eq. (5)
                k_t = 8.0 / (shear_share(E1, nu1) + shear_share(E2, nu2)) * math.sqrt(R1 * R2 / (R1 + R2))
            found[(test, material)] = (k_t / k_n, k_t / (1.5 * k_n))
    return found


# ------------------------------------------------------------------------------------------
# the figure

def plot(records, ax, test, material, metric, ylabel, paper):
    for rule in RULES:
        for engine in ENGINES:
            if test == 5:
                x, y = psi1_series(records[rule], material, metric, engine)
            else:
                x, y = series(records[rule], 8, material, metric, "X", engine)
            ax.plot(x, y, STYLE[(rule, engine)], ms=4, lw=1, label=f"{LABEL[rule]}, {engine}")
    if paper is not None:
        ax.plot(*paper, "k--", lw=1.5, label="Chung & Ooi (2011), digitised")
    xlabel = "Ψ1 = V_st/(μ V_cn)" if test == 5 else "X = 3.5μ(1+e)V_cn/V_st"
    ax.set(xlabel=xlabel, ylabel=ylabel, title=f"Test {test}, {material}")
    if test == 5:
        ax.set_xlim(0, 12)
    else:
        ax.set_xscale("log")
    ax.axhline(0.0, color="0.7", lw=0.5)
    ax.grid(alpha=0.3)


def figure(records, path):
    fig, axes = plt.subplots(2, 3, figsize=(16, 9.5))
    panels = [(5, "steel", "psi2", "Ψ2 = V'_st/(μ V'_cn)", published(5, "recoil", "steel")),
              (5, "polyethylene", "psi2", "Ψ2 = V'_st/(μ V'_cn)", published(5, "recoil", "polyethylene")),
              (8, "al_alloy_caseB", "beta", "β = −V'_st/V_st", published(8, "beta", "al_alloy_caseB")),
              (5, "steel", "spin_norm", "R ω'/(μ V_cn)", published(5, "spin", "steel")),
              (5, "polyethylene", "spin_norm", "R ω'/(μ V_cn)", published(5, "spin", "polyethylene")),
              (8, "nylon_caseB", "beta", "β = −V'_st/V_st", None)]
    for ax, (test, material, metric, ylabel, paper) in zip(axes.flat, panels):
        plot(records, ax, test, material, metric, ylabel, paper)
    axes.flat[0].legend(fontsize=7)
    fig.suptitle("Chung & Ooi tests 5 and 8: tangential stiffness K_t = K_n against Mindlin's, "
                 "both engines (lines jdem, every case; markers LIGGGHTS, the quick cases)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------------------------------
# the numbers

def recoil_table(records):
    """Rows: the recoil's extreme in the stick and micro-slip range, per test, material, rule,
    engine, with the paper's extreme and the RMS distance from the paper's curve."""
    rows = []
    for test, material, metric, quantity in [(5, "steel", "psi2", "recoil"),
                                             (5, "polyethylene", "psi2", "recoil"),
                                             (8, "al_alloy_caseB", "beta", "beta"),
                                             (8, "nylon_caseB", "beta", None)]:
        paper = published(test, quantity, material) if quantity else None
        for rule in RULES:
            for engine in ENGINES:
                if test == 5:
                    x, y = psi1_series(records[rule], material, metric, engine)
                    stick = x < 3.5 * 2.0          # below the rigid-body threshold 3.5 (1 + e), e = 1
                else:
                    x, y = series(records[rule], 8, material, metric, "X", engine)
                    stick = x > 1.0                # the rigid-body stick side, beta = 0
                if not stick.any():
                    continue
                k = int(np.argmin(np.where(stick, y, np.inf)) if test == 5 else
                        np.argmax(np.where(stick, y, -np.inf)))
                rms, n = rms_vs(paper, x, y) if paper is not None else (math.nan, 0)
                ref = None
                if paper is not None:
                    px, py = paper
                    ps = px < 7.0 if test == 5 else px > 1.0
                    j = int(np.argmin(np.where(ps, py, np.inf)) if test == 5 else
                            np.argmax(np.where(ps, py, -np.inf)))
                    ref = (px[j], py[j])
                rows.append({"test": test, "material": material, "metric": metric, "rule": rule,
                             "engine": engine, "at": float(x[k]), "extreme": float(y[k]),
                             "paper": ref, "rms": rms, "n": n})
    return rows


def engine_agreement(records):
    """{rule: (largest engine_difference, cases compared, tolerance)}."""
    out = {}
    for rule in RULES:
        d = [r for r in records[rule] if r["metric"] == "engine_difference"]
        if not d:
            continue
        out[rule] = (max(r["value"] for r in d) if d else math.nan, len(d),
                     d[0]["tolerance"] if d else math.nan)
    return out


def failures(records):
    return {rule: sum(1 for r in records[rule] if r["pass"] is False) for rule in RULES}


def write_report(path, png, records, out):
    rows, agree, fails, ratio = recoil_table(records), engine_agreement(records), failures(records), ratios(out)
    L = ["# Chung–Ooi tests 5 and 8: the seed's K_t = K_n against Mindlin's K_t = 8 G* √(R* δ)", "",
         "Generated by `scripts/mindlin_recoil.py` (both values of `model.tangential_stiffness`; every "
         "case of tests 5 and 8 in jdem, the quick cases in LIGGGHTS too); the analysis is "
         "`scripts/chung_ooi.py`'s.", "",
         f"![Tests 5 and 8]({os.path.basename(png)})", "",
         "## Stiffness ratios", "",
         "| test | material | Mindlin K_t/K_n (secant) | Mindlin K_t/(dF_n/dδ) | seed: K_t/K_n, K_t/(dF_n/dδ) |",
         "|---|---|---|---|---|"]
    for (test, material), (sec, tan) in sorted(ratio.items()):
        L.append(f"| {test} | {material} | {sec:.3f} | {tan:.3f} | 1, 0.667 |")
    L += ["", "## The recoil in the stick and micro-slip range", "",
          "Test 5: the most negative Ψ2 below the rigid-body threshold Ψ1 = 7 (and where); Test 8: "
          "the largest β on the stick side X > 1 (and where).  Rigid-body theory gives Ψ2 → 0 at the "
          "threshold and β = 0 in stick.  RMS: distance from the digitised curve over its range "
          "(n points).", "",
          "| test | material | K_t | engine | extreme (at) | paper's extreme (at) | RMS vs paper (n) |",
          "|---|---|---|---|---|---|---|"]
    for r in rows:
        paper = f"{r['paper'][1]:.3f} ({r['paper'][0]:.2f})" if r["paper"] else "–"
        rms = f"{r['rms']:.3f} ({r['n']})" if r["n"] else "–"
        L.append(f"| {r['test']} | {r['material']} | {r['rule']} | {r['engine']} | "
                 f"{r['extreme']:.3f} ({r['at']:.2f}) | {paper} | {rms} |")
    L += ["", "## The engines against each other, and the asserted checks", "",
          "| K_t | largest engine_difference (cases) | tolerance | failed asserted checks |",
          "|---|---|---|---|"]
    for rule in agree:
        worst, n, tol = agree[rule]
        L.append(f"| {rule} | {worst:.3g} ({n}) | {tol:g} | {fails[rule]} |")
    with open(path, "w") as f:
        f.write("\n".join(L) + "\n")
    return rows, agree, fails, ratio


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "mindlin"))
    ap.add_argument("--report", default=os.path.join(ROOT, "reference_runs", "chung_ooi", "results"))
    ap.add_argument("--analyse-only", action="store_true")
    a = ap.parse_args()
    if not a.analyse_only:
        for rule in RULES:
            run(a.out, rule)
    records = {rule: load(a.out, rule) for rule in RULES}
    os.makedirs(a.report, exist_ok=True)
    png = os.path.join(a.report, "mindlin_recoil.png")
    figure(records, png)
    md = os.path.join(a.report, "mindlin_recoil.md")
    write_report(md, png, records, a.out)
    print(f"wrote {os.path.relpath(md, ROOT)} and {os.path.relpath(png, ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
