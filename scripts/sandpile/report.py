#!/usr/bin/python3
"""report.py — Del Cid's Table 4.3, seed | jdem | liggghts-jdem (`make sandpile-report`).

    python3 -m scripts.sandpile.report [--out out/sandpile] [--results reference_runs/sandpile/results]

For every finished run (out/sandpile/ENGINE/CASE/pile.h5): the angle of repose of its pile
(scripts/sandpile/angle.py) and its measurement uncertainty at the last frame, and the angle
SETTLE_CHECK seconds before; the checks that the pile is at rest (the angle moved less than
REST_ANGLE, no sphere left hanging beside the plate (beyond its edge by more than its radius), at most REST_ENERGY of motion per sphere); the run's
code (its trajectory's creator version) and its CPU time (the campaign's record).
A case not under out/ is taken from the committed summary.json; a local run replaces a committed
one, and says so when its code differs.  Del Cid's qualitative claims (§4.3.4) are weighed
against the piles' uncertainties: the angle grows with mu_r (dry and cohesive), the cohesive pile
stands steeper than the dry one; and each angle's distance from hers against her +-3 deg.
Writes report.md, summary.json, piles.png (the surface profiles) and ParaView's pictures of the
PICTURED cases (pile_CASE_ENGINE.png, with pvbatch) into --out and copies them into --results.
"""
import argparse
import json
import math
import os
import shutil
import sys

import numpy as np

from scripts.campaign import Times, times_path
from scripts.sandpile import angle, plan

SEED = {  # Table 4.3 [deg], +-3 (Del Cid 2015 §4.3.4)
    "dry": {"mur01": 24, "mur02": 29, "mur04": 36, "mur06": 37},
    "kc107": {"mur01": 26, "mur02": 30, "mur04": 39, "mur06": 42},
}
SEED_TOLERANCE = 3.0
MU_R = {"mur01": 0.1, "mur02": 0.2, "mur04": 0.4, "mur06": 0.6}
HERE = os.path.dirname(os.path.abspath(__file__))
PLOT_HALF_WIDTH = 0.06    # [m] the plots' extent: the plate's (plate.stl)
PICTURED = ("dry_mur01", "kc107_mur06")   # ParaView's pictures: the flattest and the steepest pile
SETTLE_CHECK = 0.25       # [s] before the last frame
REST_ANGLE = 1.0          # [deg]: a pile at rest moves less over SETTLE_CHECK
REST_ENERGY = 1.0e-7      # [J] of motion per sphere at the end: 3 cm/s for a 2.86 mm grain


def creator(f):
    """The code that wrote the open trajectory f: its H5MD creator's name and version."""
    c = f["h5md/creator"].attrs
    return " ".join(v.decode() if isinstance(v, bytes) else str(v) for v in (c["name"], c["version"]))


def uncertainty(m):
    """A pile's measurement uncertainty [deg]: the largest of its flanks' half-difference, the
    binning's spread and the flank fits' standard errors (NaN when a flank has no fit)."""
    return max(m["half_difference"], m["offset_spread"], m["left_se"], m["right_se"])


def checks_of(r):
    """What keeps a run from being a pile at rest, or "at rest"."""
    bad = []
    if not abs(r["angle"] - r["angle_earlier"]) <= REST_ANGLE:
        bad.append("angle still moving")
    if r["beside"]:
        bad.append(f"{r['beside']} spheres beside the plate")
    if not r["end_motion_per_sphere"] <= REST_ENERGY:
        bad.append("still moving")
    return "; ".join(bad) or "at rest"


def motion_at(f, time):
    """The kinetic and rotational energy per sphere present [J] in the open trajectory f at its
    last observable sample at or before `time` [s] (the spheres of the frame nearest it)."""
    t = f["observables/kinetic_energy/time"][()]
    k = int(np.flatnonzero(t <= time + 1e-12)[-1])
    e = sum(float(f[f"observables/{n}/value"][k]) for n in ("kinetic_energy", "rotational_energy"))
    frame = int(np.argmin(np.abs(f["particles/all/position/time"][()] - t[k])))
    return e / max(1, len(angle.live_frame(f, frame)[0]))


def opening_time():
    """When the outlets vanish [s]: their until_step in the resolved scene, times dt."""
    doc = plan.resolved()
    return min(w["until_step"] for w in doc["walls"] if "until_step" in w) * doc["time"]["dt"]


def measure_run(out, engine, case, times):
    import h5py
    with h5py.File(os.path.join(out, engine, case, "pile.h5"), "r") as f:
        half_width = angle.plate_half_width(f)
        pos, radius, t_end = angle.live_frame(f)
        t = f["particles/all/position/time"][...]
        p2, r2, t2 = angle.live_frame(f, int(np.argmin(np.abs(t - (t_end - SETTLE_CHECK)))))
        settled, end = motion_at(f, opening_time()), motion_at(f, t_end)
        code = creator(f)
    final, before = angle.measure(pos, radius, half_width), angle.measure(p2, r2, half_width)
    spent = times.get(f"{engine}/{case}/pile")
    r = {"engine": engine, "case": case, "angle": final["angle"], "uncertainty": uncertainty(final),
         "half_difference": final["half_difference"], "offset_spread": final["offset_spread"],
         "left": final["left"], "right": final["right"],
         "fit_se": max(final["left_se"], final["right_se"]),
         "angle_earlier": before["angle"], "earlier_time": t2, "end_time": t_end,
         "peak_height": final["peak_height"], "on_plate": final["on_plate"], "present": len(pos),
         # spheres that cannot touch the plate (beyond its edge by more than their radius) and
         # have not fallen: material hanging beside the pile, not its foot against the edge
         "beside": int(np.sum((np.abs(pos[:, 1]) - radius > half_width) & (pos[:, 2] > 0.0))),
         "settled_motion_per_sphere": settled, "end_motion_per_sphere": end,
         "cpu_seconds": spent["cpu_seconds"] if spent else None,
         "threads": spent.get("threads", 1) if spent else None,
         "code": code,
         "profile": {k: final[k] for k in ("profile_y", "profile_top", "flank_left", "flank_right")}}
    r["checks"] = checks_of(r)
    return r


def split(case):
    cohesion, rolling = case.split("_")
    return cohesion, rolling


def fmt(x, spec=".1f"):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def decided(a, b):
    """+1 when pile a stands steeper than pile b beyond twice their combined uncertainty, -1 when
    less steep, 0 when the difference is within it (or a measure is missing)."""
    values = [r and r[k] for r in (a, b) for k in ("angle", "uncertainty")]
    if None in values:
        return 0
    d, u = a["angle"] - b["angle"], 2.0 * math.hypot(a["uncertainty"], b["uncertainty"])
    if not (math.isfinite(d) and math.isfinite(u)):
        return 0
    return 1 if d > u else -1 if d < -u else 0


def verdict(signs):
    """held when every comparison is decided the claimed way, not held when one is decided the
    other way, else not decided."""
    return "not held" if -1 in signs else "held" if all(s == 1 for s in signs) else "not decided"


def claims(by):
    """Del Cid's qualitative findings per engine, each weighed against the piles' uncertainty."""
    out = []
    for engine in plan.ENGINES:
        for cohesion in SEED:
            runs = [by.get((engine, f"{cohesion}_{r}")) for r in MU_R]
            if None in runs:
                continue
            signs = [decided(b, a) for a, b in zip(runs, runs[1:])]
            out.append((engine, f"the {cohesion} pile steepens with each step of mu_r",
                        verdict(signs), ", ".join(f"mu_r {MU_R[r]:g}: {fmt(x['angle'])} ± {fmt(x['uncertainty'])}"
                                                 for r, x in zip(MU_R, runs))))
        pairs = [(r, by.get((engine, f"dry_{r}")), by.get((engine, f"kc107_{r}"))) for r in MU_R]
        pairs = [(r, d, c) for r, d, c in pairs if d is not None and c is not None]
        if pairs:
            out.append((engine, "the cohesive pile stands steeper than the dry one",
                        verdict([decided(c, d) for _, d, c in pairs]),
                        ", ".join(f"mu_r {MU_R[r]:g}: cohesive {fmt(c['angle'])}, dry {fmt(d['angle'])}"
                                  for r, d, c in pairs)))
    return out


def cpu_text(r):
    if not r.get("cpu_seconds"):
        return "–"
    threads = r.get("threads") or 1
    return "%.1f" % (r["cpu_seconds"] / 60.0) + ("" if threads == 1 else f" ({threads} threads)")


def report(runs, out_dir):
    by = {(r["engine"], r["case"]): r for r in runs}
    lines = ["# Del Cid (2015) Table 4.3: sandpiles of the MEPA material", "",
             "Generated by `scripts/sandpile/report.py` (`make sandpile-report`); docs/sandpile.md.  "
             "Angles of repose [deg] of the pile left on the plate after the outlets opened: the mean "
             "of the two flanks' fitted slopes ± the pile's measurement uncertainty (the largest of "
             "the flanks' half-difference, the binning's spread and the fits' standard errors); the "
             "seed's are ±3°.  Δ: the angle's change over the last %.2f s of the discharge.  CPU: the "
             "whole run, settling and discharge [min]." % SETTLE_CHECK, ""]
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
                row += [f"{fmt(r['angle'])} ± {fmt(r['uncertainty'])}",
                        fmt(r["angle"] - r["angle_earlier"] if None not in (r["angle"], r["angle_earlier"])
                            else None, "+.1f"), cpu_text(r)]
            lines.append("| " + " | ".join(row) + " |")
        lines.append("")
    lines += ["### Against the seed", "",
              "| engine | case | angle − seed [deg] | within ±3° |", "|---|---|---|---|"]
    for r in runs:
        c, rolling = split(r["case"])
        d = r["angle"] - SEED[c][rolling] if r["angle"] is not None else math.nan
        within = "–" if not math.isfinite(d) else "yes" if abs(d) <= SEED_TOLERANCE else "no"
        lines.append(f"| {r['engine']} | {r['case']} | {fmt(d, '+.1f')} | {within} |")
    lines += ["", "### Del Cid's qualitative findings", "",
              "A step is decided when two piles differ by more than twice their combined "
              "uncertainty; a claim is held when every step is decided its way, not held when one "
              "is decided the other way, else not decided.", "",
              "| engine | claim | verdict | numbers |", "|---|---|---|---|"]
    lines += [f"| {e} | {c} | {v} | {n} |" for e, c, v, n in claims(by)]
    lines += ["", "### The runs", "",
              "| engine | case | flanks left / right [deg] | fits' s.e. | binning spread | spheres on the plate "
              "| peak [mm] | motion/sphere at the opening [J] | at the end [J] | checks | code |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        lines.append(f"| {r['engine']} | {r['case']} | {fmt(r['left'])} / {fmt(r['right'])} | "
                     f"{fmt(r['fit_se'])} | {fmt(r['offset_spread'])} | {r['on_plate']} | "
                     f"{1e3 * r['peak_height']:.1f} | {r['settled_motion_per_sphere']:.1e} | "
                     f"{r['end_motion_per_sphere']:.1e} | {r['checks']} | {r['code']} |")
    with open(os.path.join(out_dir, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def seed_line(ax, r, seed_deg):
    """The seed's slope drawn through each fitted flank's centroid (the profile is the spheres'
    tops, about a diameter above a pile's mean surface)."""
    p = r["profile"]
    y = np.array(p["profile_y"])
    top = np.array([np.nan if h is None else h for h in p["profile_top"]])
    slope = math.tan(math.radians(seed_deg))
    for mask, sign in ((p["flank_left"], 1.0), (p["flank_right"], -1.0)):
        m = np.array(mask, dtype=bool)
        if m.sum() < 2:
            continue
        yc, hc = y[m].mean(), top[m].mean()
        ys = np.array([y[m].min() - 0.01, y[m].max() + 0.01])
        ax.plot(1e3 * ys, 1e3 * (hc + sign * slope * (ys - yc)), "k:", lw=0.9)


def plot(runs, path, half_width):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 4, figsize=(14, 5.5), sharex=True, sharey=True)
    for i, cohesion in enumerate(SEED):
        for j, rolling in enumerate(MU_R):
            ax = axes[i][j]
            seed = SEED[cohesion][rolling]
            for engine, style in zip(plan.ENGINES, ("C0-", "C1--")):
                r = next((r for r in runs if r["engine"] == engine and r["case"] == f"{cohesion}_{rolling}"), None)
                if r is None:
                    continue
                y = 1e3 * np.array(r["profile"]["profile_y"])
                top = np.array([np.nan if h is None else 1e3 * h for h in r["profile"]["profile_top"]])
                ax.plot(y, top, style, label=f"{engine} {fmt(r['angle'])}°")
                if engine == "jdem":
                    seed_line(ax, r, seed)
            ax.plot([], [], "k:", label=f"seed {seed}° (through jdem's flanks)")
            ax.set_xlim(-1e3 * half_width, 1e3 * half_width)
            ax.set_ylim(bottom=0.0)
            ax.set_title(f"{cohesion}, μr = {MU_R[rolling]:g}", fontsize=9)
            ax.legend(fontsize=7, loc="lower center")
            if i == 1:
                ax.set_xlabel("y [mm]")
            if j == 0:
                ax.set_ylabel("top of the spheres [mm]")
    fig.suptitle("Del Cid (2015) Table 4.3: the piles' surface profiles on the plate")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def pictures(out_dir, runs):
    """ParaView's picture of the PICTURED cases' piles (scripts/sandpile/pv_pile.py), where
    pvbatch is installed (`make paraview-deps`): pile_CASE_ENGINE.png, the names written."""
    import subprocess
    if not shutil.which("pvbatch"):
        print("report: pvbatch not found, no pictures (make paraview-deps)", file=sys.stderr)
        return []
    names = []
    for r in runs:
        sidecar = os.path.join(out_dir, r["engine"], r["case"], "pile.xdmf")
        if r["case"] not in PICTURED or not os.path.exists(sidecar):
            continue
        png = os.path.join(out_dir, f"pile_{r['case']}_{r['engine']}.png")
        for _ in range(2):   # pvbatch 5.11 under xvfb now and then aborts before it draws
            p = subprocess.run(["xvfb-run", "-a", "pvbatch", os.path.join(HERE, "pv_pile.py"), sidecar, png],
                               capture_output=True, text=True)
            drawn = json.loads(p.stdout.strip().splitlines()[-1]) if p.stdout.strip() else None
            if drawn:
                break
        if drawn and drawn["spheres"] == r["present"]:
            names.append(os.path.basename(png))
        else:
            print(f"report: {png}: ParaView drew {drawn and drawn['spheres']} spheres of the "
                  f"{r['present']} present; picture left out", file=sys.stderr)
    return names


def sanitized(x):
    """x with every NaN as None (strict JSON)."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: sanitized(v) for k, v in x.items()}
    if isinstance(x, list):
        return [sanitized(v) for v in x]
    return x


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=plan.OUT)
    ap.add_argument("--results", default=plan.RESULTS)
    a = ap.parse_args()
    times = Times(times_path(plan.units([]))).seconds
    try:
        with open(os.path.join(a.results, "summary.json")) as f:
            committed = {(r["engine"], r["case"]): r for r in json.load(f)["runs"]}
    except (OSError, ValueError, KeyError):
        committed = {}
    runs = []
    for case in plan.cases():
        for engine in plan.ENGINES:
            if os.path.exists(os.path.join(a.out, engine, case, "pile.h5")):
                r = measure_run(a.out, engine, case, times)
                old = committed.get((engine, case))
                if old and old["code"] != r["code"]:
                    print(f"report: {engine}/{case}: the run here ({r['code']}) replaces the "
                          f"committed one ({old['code']})", file=sys.stderr)
                runs.append(r)
            elif (engine, case) in committed:
                runs.append(committed[(engine, case)])
    if not runs:
        sys.exit("report: no finished pile under %s and none committed: run `make sandpile` first" % a.out)
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump({"runs": sanitized(runs)}, f, indent=1, allow_nan=False)
    report(runs, a.out)
    plot(runs, os.path.join(a.out, "piles.png"), PLOT_HALF_WIDTH)
    names = ["report.md", "summary.json", "piles.png"] + pictures(a.out, runs)
    os.makedirs(a.results, exist_ok=True)
    for name in names:
        shutil.copyfile(os.path.join(a.out, name), os.path.join(a.results, name))
    print(open(os.path.join(a.out, "report.md")).read())


if __name__ == "__main__":
    main()
