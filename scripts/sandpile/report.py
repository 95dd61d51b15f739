#!/usr/bin/python3
"""report.py — Del Cid's Table 4.3, seed | jdem | liggghts-jdem (`make sandpile-report`).

    python3 -m scripts.sandpile.report [--out out/sandpile] [--results reference_runs/sandpile/results]

For every finished discharge (out/sandpile/ENGINE/CASE/discharge.h5) the pile's angle of repose
(scripts/sandpile/angle.py) at the last frame and SETTLE_CHECK seconds before it (the pile has come
to rest when the two agree), the spheres left on the plate, the kinetic energy per sphere at the
end of the settling and of the discharge, the run's code (the trajectory's creator version) and
its CPU time (the campaign's record of its two runs).  A case not under out/ is taken from the
committed summary.json.  The qualitative claims of Del Cid's §4.3.4 are checked with numbers:
the angle grows with mu_r (dry and cohesive), the cohesive pile stands at least as steep as the
dry one at each mu_r, and each angle's distance from her value against her +-3 deg.  Writes
report.md, summary.json and piles.png into --out and copies them into --results.
"""
import argparse
import json
import math
import os
import shutil

import numpy as np
import yaml

from scripts.campaign import Times, times_path
from scripts.sandpile import angle, plan
from scripts.sandpile.discharge import SCENE

SEED = {  # Table 4.3 [deg], +-3 (Del Cid 2015 §4.3.4)
    "dry": {"mur01": 24, "mur02": 29, "mur04": 36, "mur06": 37},
    "kc107": {"mur01": 26, "mur02": 30, "mur04": 39, "mur06": 42},
}
SEED_TOLERANCE = 3.0
MU_R = {"mur01": 0.1, "mur02": 0.2, "mur04": 0.4, "mur06": 0.6}
SETTLE_CHECK = 0.25       # [s] before the last frame


def creator(path):
    import h5py
    with h5py.File(path, "r") as f:
        c = f["h5md/creator"].attrs
        return "%s %s" % (c["name"].decode() if isinstance(c["name"], bytes) else c["name"],
                          c["version"].decode() if isinstance(c["version"], bytes) else c["version"])


def kinetic_per_sphere(path):
    """The last sample of kinetic_energy over the spheres present then [J]."""
    import h5py
    with h5py.File(path, "r") as f:
        ke = float(f["observables/kinetic_energy/value"][-1])
    pos, _, _ = angle.live_frame(path)
    return ke / max(1, len(pos))


def measure_run(out, engine, case, half_width, times):
    base = os.path.join(out, engine, case)
    discharge, fill = os.path.join(base, "discharge.h5"), os.path.join(base, "fill.h5")
    pos, radius, t_end = angle.live_frame(discharge)
    final = angle.measure(pos, radius, half_width)
    import h5py
    with h5py.File(discharge, "r") as f:
        t = f["particles/all/position/time"][...]
    earlier = int(np.argmin(np.abs(t - (t_end - SETTLE_CHECK))))
    p2, r2, t2 = angle.live_frame(discharge, earlier)
    before = angle.measure(p2, r2, half_width)
    cpu = [times.get(f"{engine}/{case}/{u}", {}).get("cpu_seconds") for u in ("fill", "discharge")]
    return {"engine": engine, "case": case, "angle": final["angle"],
            "half_difference": final["half_difference"], "left": final["left"],
            "right": final["right"], "fit_se": max(final["left_se"], final["right_se"]),
            "angle_earlier": before["angle"], "earlier_time": t2, "end_time": t_end,
            "peak_height": final["peak_height"], "on_plate": final["on_plate"],
            "fill_ke_per_sphere": kinetic_per_sphere(fill),
            "discharge_ke_per_sphere": kinetic_per_sphere(discharge),
            "cpu_seconds": sum(cpu) if all(c is not None for c in cpu) else None,
            "code": creator(discharge),
            "profile": {k: final[k] for k in ("profile_y", "profile_top", "flank_left", "flank_right")}}


def split(case):
    cohesion, rolling = case.split("_")
    return cohesion, rolling


def fmt(x, spec=".1f"):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def claims(by):
    """Del Cid's qualitative findings, each held, not held or not decided, per engine."""
    out = []
    for engine in plan.ENGINES:
        for cohesion in SEED:
            a = [by.get((engine, f"{cohesion}_{r}"), {}).get("angle") for r in MU_R]
            if None in a:
                continue
            rising = all(y > x for x, y in zip(a, a[1:]))
            out.append((engine, f"the {cohesion} angle grows with mu_r",
                        "held" if rising else "not held", " < ".join(fmt(x) for x in a)))
        pairs = [(by.get((engine, f"dry_{r}"), {}).get("angle"),
                  by.get((engine, f"kc107_{r}"), {}).get("angle")) for r in MU_R]
        pairs = [(d, c) for d, c in pairs if d is not None and c is not None]
        if pairs:
            ok = all(c >= d for d, c in pairs)
            out.append((engine, "the cohesive pile is at least as steep as the dry one",
                        "held" if ok else "not held",
                        ", ".join("%s vs %s" % (fmt(c), fmt(d)) for d, c in pairs)))
    return out


def report(runs, out_dir):
    by = {(r["engine"], r["case"]): r for r in runs}
    lines = ["# Del Cid (2015) Table 4.3: sandpiles of the MEPA material", "",
             "Generated by `scripts/sandpile/report.py` (`make sandpile-report`).  Angles of repose "
             "[deg] of the pile left on the plate after the outlets opened (docs/sandpile.md): the "
             "mean of the two flanks' fitted slopes, ± their half-difference; the seed's are ±3°.  "
             "Δ: the angle's change over the last %.2f s of the discharge (the pile at rest: "
             "small).  CPU: the settling and the discharge together [min], one core each." % SETTLE_CHECK, ""]
    head = "| μr | seed | jdem | Δ | CPU | liggghts-jdem | Δ | CPU |"
    for cohesion, title in (("dry", "Dry material"), ("kc107", "kadh = 1.07e7 N/m^1.5")):
        lines += [f"### {title}", "", head, "|---|---|---|---|---|---|---|---|"]
        for rolling, mu in MU_R.items():
            row = [f"{mu:g}", f"{SEED[cohesion][rolling]} ± 3"]
            for engine in plan.ENGINES:
                r = by.get((engine, f"{cohesion}_{rolling}"))
                if r is None:
                    row += ["not run yet", "", ""]
                    continue
                row += [f"{fmt(r['angle'])} ± {fmt(r['half_difference'])}",
                        fmt(r["angle"] - r["angle_earlier"], "+.1f"),
                        fmt(r["cpu_seconds"] / 60.0 if r["cpu_seconds"] else None)]
            lines.append("| " + " | ".join(row) + " |")
        lines.append("")
    lines += ["### Against the seed", "",
              "| engine | case | angle − seed [deg] | within ±3° |", "|---|---|---|---|"]
    for r in runs:
        c, rolling = split(r["case"])
        d = r["angle"] - SEED[c][rolling]
        lines.append(f"| {r['engine']} | {r['case']} | {d:+.1f} | {'yes' if abs(d) <= SEED_TOLERANCE else 'no'} |")
    lines += ["", "### Del Cid's qualitative findings", "", "| engine | claim | verdict | numbers |",
              "|---|---|---|---|"]
    lines += [f"| {e} | {c} | {v} | {n} |" for e, c, v, n in claims(by)]
    lines += ["", "### The runs", "",
              "| engine | case | spheres on the plate | peak height [mm] | KE/sphere after settling [J] "
              "| KE/sphere at the end [J] | code |", "|---|---|---|---|---|---|---|"]
    for r in runs:
        lines.append(f"| {r['engine']} | {r['case']} | {r['on_plate']} | {1e3 * r['peak_height']:.1f} | "
                     f"{r['fill_ke_per_sphere']:.2e} | {r['discharge_ke_per_sphere']:.2e} | {r['code']} |")
    with open(os.path.join(out_dir, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def plot(runs, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 4, figsize=(14, 5.5), sharex=True, sharey=True)
    for i, cohesion in enumerate(SEED):
        for j, rolling in enumerate(MU_R):
            ax = axes[i][j]
            for engine, style in zip(plan.ENGINES, ("C0-", "C1--")):
                r = next((r for r in runs if r["engine"] == engine and r["case"] == f"{cohesion}_{rolling}"), None)
                if r is None:
                    continue
                y = 1e3 * np.array(r["profile"]["profile_y"])
                top = np.array([np.nan if h is None else 1e3 * h for h in r["profile"]["profile_top"]])
                ax.plot(y, top, style, label=f"{engine} {r['angle']:.1f}°")
            seed = math.radians(SEED[cohesion][rolling])
            ax.plot([-60, 0, 60], [0, 60 * math.tan(seed), 0], "k:", lw=0.8,
                    label=f"seed {SEED[cohesion][rolling]}°")
            ax.set_title(f"{cohesion}, μr = {MU_R[rolling]:g}", fontsize=9)
            ax.legend(fontsize=7, loc="lower center")
            if i == 1:
                ax.set_xlabel("y [mm]")
            if j == 0:
                ax.set_ylabel("surface height [mm]")
    fig.suptitle("Del Cid (2015) Table 4.3: pile profiles on the plate (dotted: a pile at the seed's angle)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=plan.OUT)
    ap.add_argument("--results", default=plan.RESULTS)
    a = ap.parse_args()
    with open(SCENE) as f:
        half = angle.plate_half_width(yaml.load(f, Loader=yaml.CSafeLoader))
    times = Times(times_path(plan.units([]))).seconds
    try:
        with open(os.path.join(a.results, "summary.json")) as f:
            committed = {(r["engine"], r["case"]): r for r in json.load(f)["runs"]}
    except (OSError, ValueError, KeyError):
        committed = {}
    runs = []
    for case in plan.cases():
        for engine in plan.ENGINES:
            if os.path.exists(os.path.join(a.out, engine, case, "discharge.h5")):
                runs.append(measure_run(a.out, engine, case, half, times))
            elif (engine, case) in committed:
                runs.append(committed[(engine, case)])
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump({"runs": runs}, f, indent=1)
    report(runs, a.out)
    plot(runs, os.path.join(a.out, "piles.png"))
    os.makedirs(a.results, exist_ok=True)
    for name in ("report.md", "summary.json", "piles.png"):
        shutil.copyfile(os.path.join(a.out, name), os.path.join(a.results, name))
    print(open(os.path.join(a.out, "report.md")).read())


if __name__ == "__main__":
    main()
