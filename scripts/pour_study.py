#!/usr/bin/python3
"""pour_study.py — the pour scene in both engines: round-off divergence and settled statistics.

    scripts/pour_study.py run     [--out out/pour] [--every 100] [--seeds 8,9]
    scripts/pour_study.py analyze [--out out/pour]
    scripts/pour_study.py all     (run, then analyze)

`run` writes a copy of reference_runs/pour/scene.yaml with denser output (output.every, the
physics untouched) and runs it in
    jdem      build/jdem
    lig1      build/liggghts-jdem, 1 rank          (pair_style gran/jiang, fix wall/jiang)
    lig2      build/liggghts-jdem, 2 MPI ranks
    builtin   build/liggghts-jdem, 1 rank, LIGGGHTS' own hertz/history/epsd2 law and primitive
              walls (scene_to_liggghts.py --builtin)
plus jdem runs of the same scene with other lattice seeds (the run-to-run spread of the settled
statistics).  Wall times go to OUT/runs.json.  `analyze` writes OUT/summary.json, OUT/report.md
and the plots.

Deck box: scene_to_liggghts.py sizes the LIGGGHTS box for free fall over the whole run (1.8 m
for 0.6 s), which makes LIGGGHTS stop with "Too many neighbor bins".  The particles are
enclosed by the walls here, so the deck's box is replaced by the box the generator writes for a
run of zero duration (the walls' extent plus 4 radii).  See tight_box().
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

import h5py
import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import scene_to_liggghts  # noqa: E402  (bounding_box: the deck's box rule)

JDEM = os.path.join(ROOT, "build", "jdem")
LIG = os.path.join(ROOT, "build", "liggghts-jdem")
SCENE = os.path.join(ROOT, "reference_runs", "pour", "scene.yaml")
ROUNDOFF = 1e-10          # scaled difference counted as round-off
ENGINES = ("jdem", "lig1", "lig2", "builtin")
PAIRS = (("jdem", "lig1"), ("lig1", "lig2"), ("jdem", "lig2"))


# ---------------------------------------------------------------------------------------------
# Running

def write_scene(src, dst, overrides):
    """Copy a scene with dotted-path overrides, e.g. {"output.every": 100}."""
    scene = yaml.safe_load(open(src))
    for path, value in overrides.items():
        node = scene
        keys = path.split(".")
        for k in keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        node[keys[-1]] = value
    with open(dst, "w") as f:
        yaml.safe_dump(scene, f, sort_keys=False)
    return dst


def check(cmd, cwd=None):
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("%s failed (exit %d):\n%s%s" % (" ".join(cmd), r.returncode,
                                                        r.stdout[-2000:], r.stderr[-2000:]))
    return r.stdout


def run_jdem(scene, out):
    """Run build/jdem; returns the wall time [s]."""
    start = time.monotonic()
    check([JDEM, "run", scene, "-o", out, "--quiet"])
    return time.monotonic() - start


def tight_box(deck_dir):
    """Replace the box of DECK_DIR/particles.data by the generator's box for a zero-length run."""
    scene = yaml.safe_load(open(os.path.join(deck_dir, "resolved.yaml")))
    scene["time"]["steps"] = 0
    rmax = max(float(p["radius"]) for p in scene["particles"])
    lo, hi = scene_to_liggghts.bounding_box(scene, rmax)
    path = os.path.join(deck_dir, "particles.data")
    lines = open(path).read().split("\n")
    for n, line in enumerate(lines[:12]):
        for d, ax in enumerate("xyz"):
            if line.endswith(" %slo %shi" % (ax, ax)):
                lines[n] = "%s %s %slo %shi" % (repr(lo[d]), repr(hi[d]), ax, ax)
    with open(path, "w") as f:
        f.write("\n".join(lines))


def run_liggghts(scene, out, np_=1, builtin=False):
    """Resolve, write the deck (OUT minus .h5 plus .deck/), run build/liggghts-jdem; wall time [s]."""
    out = os.path.abspath(out)
    deck_dir = out[:-3] + ".deck"
    os.makedirs(deck_dir, exist_ok=True)
    for stale in (out, out + ".part"):
        if os.path.exists(stale):
            os.remove(stale)
    resolved = os.path.join(deck_dir, "resolved.yaml")
    with open(resolved, "w") as f:
        f.write(check([JDEM, "resolve", scene]))
    check([sys.executable, os.path.join(HERE, "scene_to_liggghts.py"), resolved, "-o",
           os.path.join(deck_dir, "in.jdem"), "--trajectory", out] + (["--builtin"] if builtin else []))
    tight_box(deck_dir)
    cmd = [LIG, "-in", "in.jdem", "-log", "log.lammps", "-screen", "none"]
    if np_ > 1:
        root = ["--allow-run-as-root", "--oversubscribe"] if os.geteuid() == 0 else []
        cmd = [shutil.which("mpirun") or "mpirun"] + root + ["-np", str(np_)] + cmd
    start = time.monotonic()
    check(cmd, cwd=deck_dir)
    if not os.path.exists(out):
        raise RuntimeError("%s wrote no trajectory (see %s/log.lammps)" % (" ".join(cmd), deck_dir))
    return time.monotonic() - start


def run_all(scene, out_dir, which=ENGINES):
    """Run the engines on SCENE into OUT_DIR/NAME.h5; returns {name: wall time}."""
    runners = {"jdem": lambda o: run_jdem(scene, o),
               "lig1": lambda o: run_liggghts(scene, o, 1),
               "lig2": lambda o: run_liggghts(scene, o, 2),
               "builtin": lambda o: run_liggghts(scene, o, 1, builtin=True)}
    return {name: runners[name](os.path.join(out_dir, name + ".h5")) for name in which}


# ---------------------------------------------------------------------------------------------
# Trajectory differences

def load(path):
    """Per-particle data of a trajectory, sorted by id: steps, times, x, v, radius, mass, w."""
    with h5py.File(path, "r") as f:
        p = f["particles/all"]
        order = np.argsort(p["id"][()])
        return {"step": p["position/step"][()], "time": p["position/time"][()],
                "x": p["position/value"][()][:, order], "v": p["velocity/value"][()][:, order],
                "w": p["angular_velocity/value"][()][:, order], "radius": p["radius"][()][order],
                "mass": p["mass"][()][order], "dt": float(f["parameters"].attrs["dt"])}


def scaled_difference(a, b, g=9.81):
    """Per common frame: (time, max|dx|/R_max, max|dv|/sqrt(g d_max)), d_max = 2 R_max."""
    common, ia, ib = np.intersect1d(a["step"], b["step"], return_indices=True)
    rmax = float(a["radius"].max())
    dx = np.abs(a["x"][ia] - b["x"][ib]).max(axis=(1, 2)) / rmax
    dv = np.abs(a["v"][ia] - b["v"][ib]).max(axis=(1, 2)) / math.sqrt(g * 2.0 * rmax)
    return a["time"][ia], dx, dv


def horizon(t, diff, level=ROUNDOFF):
    """Last time before the scaled difference first reaches LEVEL (the whole run if never)."""
    above = np.nonzero(diff >= level)[0]
    if len(above) == 0:
        return float(t[-1]), False
    return float(t[above[0] - 1]) if above[0] > 0 else 0.0, True


def growth_rate(t, diff, lo=1e-12, hi=1e-3):
    """Exponential rate [1/s]: least-squares slope of ln(diff) where LO < diff < HI, from the first
    frame above LO to the first frame above HI (before saturation)."""
    start = np.nonzero(diff > lo)[0]
    if len(start) == 0:
        return None
    stop = np.nonzero(diff > hi)[0]
    end = stop[0] if len(stop) else len(diff)
    sel = np.arange(start[0], end)
    sel = sel[diff[sel] > 0]
    if len(sel) < 3:
        return None
    slope = np.polyfit(t[sel], np.log(diff[sel]), 1)[0]
    return {"rate": float(slope), "from": float(t[sel[0]]), "to": float(t[sel[-1]])}


# ---------------------------------------------------------------------------------------------
# Settled statistics

def box_geometry(scene):
    """Inner box [0, L]^2 (floor at z = 0) and the bar (x_c, z_c, R_c) of the pour scene."""
    walls = {w["name"]: w for w in scene["walls"]}
    L = float(walls["x_high"]["corners"][0][0])
    bar = walls["bar"]
    return L, (float(bar["axis"][0][0]), float(bar["axis"][0][2]), float(bar["radius"]))


def pile_top(x, r, L, bar, cells=6):
    """Free surface height H_s: median over cells x cells columns of the highest z + R, counting
    only particles below the bar; also the particles resting on the bar."""
    below = x[:, 2] < bar[1] - bar[2]
    ix = np.clip((x[below, 0] / L * cells).astype(int), 0, cells - 1)
    iy = np.clip((x[below, 1] / L * cells).astype(int), 0, cells - 1)
    top = np.zeros((cells, cells))
    np.maximum.at(top, (ix, iy), x[below, 2] + r[below])
    return float(np.median(top)), int((~below).sum()), float((x[below, 2] + r[below]).max())


def packing_fraction(x, r, lo, hi, h):
    """Solid volume fraction of the box [lo, hi] sampled on a grid of spacing h."""
    axes = [np.arange(lo[d] + h / 2, hi[d], h) for d in range(3)]
    solid = np.zeros([len(a) for a in axes], dtype=bool)
    for c, rad in zip(x, r):
        sl = [slice(np.searchsorted(axes[d], c[d] - rad), np.searchsorted(axes[d], c[d] + rad))
              for d in range(3)]
        gx, gy, gz = np.meshgrid(axes[0][sl[0]], axes[1][sl[1]], axes[2][sl[2]], indexing="ij")
        solid[tuple(sl)] |= (gx - c[0]) ** 2 + (gy - c[1]) ** 2 + (gz - c[2]) ** 2 < rad * rad
    return float(solid.mean())


def contacts(x, r, L, bar):
    """Geometric contacts (overlap > 0): particle pairs, and particles against walls and bar."""
    d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
    iu = np.triu_indices(len(r), 1)
    pairs = int(((d - (r[:, None] + r[None, :]))[iu] < 0).sum())
    gaps = [x[:, 2], x[:, 0], L - x[:, 0], x[:, 1], L - x[:, 1],
            np.hypot(x[:, 0] - bar[0], x[:, 2] - bar[1]) - bar[2]]
    walls = int(sum((g < r).sum() for g in gaps))
    return pairs, walls


def settled_stats(path, scene):
    """Statistics of the last frame (definitions in the report)."""
    t = load(path)
    x, v, w, r, m = t["x"][-1], t["v"][-1], t["w"][-1], t["radius"], t["mass"]
    L, bar = box_geometry(scene)
    dmax = 2.0 * float(r.max())
    h_s, on_bar, h_max = pile_top(x, r, L, bar)
    core_lo, core_hi = [dmax, dmax, dmax / 2], [L - dmax, L - dmax, h_s - dmax]
    pp, pw = contacts(x, r, L, bar)
    n = len(r)
    below = x[:, 2] < bar[1] - bar[2]
    solid = float((4.0 / 3.0 * math.pi * r[below] ** 3).sum())
    return {"time": float(t["time"][-1]),
            "phi_core": packing_fraction(x, r, core_lo, core_hi, dmax / 40),
            "phi_bulk": solid / (L * L * h_s),
            "z_pp": 2.0 * pp / n, "z_all": (2.0 * pp + pw) / n, "pp_contacts": pp, "wall_contacts": pw,
            "ke_trans": float(0.5 * (m * (v ** 2).sum(axis=1)).sum()),
            "ke_rot": float(0.5 * (0.4 * m * r ** 2 * (w ** 2).sum(axis=1)).sum()),
            "height_max": float((x[:, 2] + r).max()), "height_pile": h_max, "surface": h_s,
            "on_bar": on_bar, "core": [core_lo, core_hi]}


# ---------------------------------------------------------------------------------------------
# Report

def plot_differences(curves, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    for label, (t, dx, dv) in curves.items():
        line, = ax.semilogy(t, np.maximum(dx, 1e-18), label=label + ": position / R_max")
        ax.semilogy(t, np.maximum(dv, 1e-18), "--", color=line.get_color(),
                    label=label + ": velocity / sqrt(g d_max)")
    ax.axhline(ROUNDOFF, color="k", lw=0.8, ls=":")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("max scaled difference (1e-18 = identical)")
    ax.set_title("pour: divergence between runs")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_stats(stats, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(stats)
    keys = (("phi_core", "packing fraction (core)"), ("z_pp", "coordination (pairs)"),
            ("z_all", "coordination (+walls)"), ("surface", "free surface H_s [m]"))
    fig, axes = plt.subplots(1, len(keys), figsize=(14, 3.5))
    for ax, (k, title) in zip(axes, keys):
        ax.bar(range(len(names)), [stats[n][k] for n in names], color="C0")
        ax.set_xticks(range(len(names)))
        ax.set_xticklabels(names, rotation=45, fontsize=7)
        lo = min(stats[n][k] for n in names)
        hi = max(stats[n][k] for n in names)
        ax.set_ylim(lo - 0.5 * (hi - lo + 1e-12) - 0.02 * abs(lo), hi + 0.5 * (hi - lo + 1e-12) + 0.02 * abs(hi))
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def spread(stats, names, key):
    vals = [stats[n][key] for n in names if n in stats]
    return max(vals) - min(vals) if vals else None


def analyze(out_dir):
    meta = json.load(open(os.path.join(out_dir, "runs.json")))
    scene = yaml.safe_load(check([JDEM, "resolve", meta["scene"]]))
    traj = {n: os.path.join(out_dir, n + ".h5") for n in meta["wall_time"]}
    loaded = {n: load(p) for n, p in traj.items() if n in ENGINES}
    curves, divergence = {}, {}
    for a, b in PAIRS:
        t, dx, dv = scaled_difference(loaded[a], loaded[b])
        both = np.maximum(dx, dv)
        h, reached = horizon(t, both)
        curves["%s vs %s" % (a, b)] = (t, dx, dv)
        divergence["%s_vs_%s" % (a, b)] = {
            "first_nonzero": float(t[np.nonzero(both > 0)[0][0]]) if (both > 0).any() else None,
            "first_value": float(both[np.nonzero(both > 0)[0][0]]) if (both > 0).any() else 0.0,
            "horizon": h, "reaches_roundoff_level": reached, "growth": growth_rate(t, both),
            "final": float(both[-1])}
    plot_differences(curves, os.path.join(out_dir, "divergence.png"))
    stats = {n: settled_stats(p, scene) for n, p in traj.items()}
    plot_stats(stats, os.path.join(out_dir, "settled.png"))
    seeds = [n for n in stats if n.startswith("seed")]
    keys = ("phi_core", "phi_bulk", "z_pp", "z_all", "surface", "height_pile")
    summary = {"scene": meta["scene"], "every": meta["every"], "roundoff_level": ROUNDOFF,
               "wall_time": meta["wall_time"], "divergence": divergence, "settled": stats,
               "spread": {k: {"engines_jdem_lig1_lig2": spread(stats, ("jdem", "lig1", "lig2"), k),
                              "seeds_jdem": spread(stats, ["jdem"] + seeds, k),
                              "builtin_minus_jdem": stats["builtin"][k] - stats["jdem"][k]}
                          for k in keys}}
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    with open(os.path.join(out_dir, "report.md"), "w") as f:
        f.write(report(summary, meta))
    return summary


def fmt(x, spec="%.4g"):
    return "—" if x is None else spec % x


def report(s, meta):
    L = ["# Pour: jdem, liggghts-jdem on 1 and 2 ranks, and LIGGGHTS' built-in law\n",
         "Generated by `scripts/pour_study.py all` (%s, output every %d steps = %.1e s).\n"
         % (os.path.relpath(meta["scene"], ROOT), meta["every"], meta["every"] * meta["dt"]),
         "\n## Divergence between runs\n",
         "Per frame, the largest |Δx| over all particles and components / R_max, and the largest "
         "|Δv| / sqrt(g d_max) (d_max = 2 R_max); the curve used below is the larger of the two. "
         "Horizon: the last frame before it reaches %.0e. Growth rate: least-squares slope of "
         "ln(difference) from 1e-12 to 1e-3 (before saturation). Plot: `divergence.png`.\n\n" % ROUNDOFF,
         "| runs | first non-zero at [s] (value) | horizon < 1e-10 [s] | growth rate [1/s] (fit window [s]) | e-folding time [s] | final |\n",
         "|---|---|---|---|---|---|\n"]
    for k, d in s["divergence"].items():
        g = d["growth"]
        L.append("| %s | %s (%s) | %s%s | %s | %s | %.2e |\n" % (
            k.replace("_", " "), fmt(d["first_nonzero"]), fmt(d["first_value"], "%.1e"), fmt(d["horizon"]),
            "" if d["reaches_roundoff_level"] else " (never reached)",
            "%.1f (%.3f–%.3f)" % (g["rate"], g["from"], g["to"]) if g else "—",
            fmt(1.0 / g["rate"], "%.4f") if g and g["rate"] > 0 else "—", d["final"]))
    L.append("\n## Settled statistics at t = %.2f s\n\n" % s["settled"]["jdem"]["time"])
    L.append(STAT_DEFINITIONS)
    L.append("| run | wall time [s] | φ core | φ bulk | Z pairs | Z with walls | pair / wall contacts "
             "| KE trans [J] | KE rot [J] | H_s [m] | max z+R below bar [m] | max z+R [m] | on bar |\n")
    L.append("|---|" + "---|" * 12 + "\n")
    for n, st in s["settled"].items():
        L.append("| %s | %s | %.4f | %.4f | %.3f | %.3f | %d / %d | %.2e | %.2e | %.4f | %.4f | %.4f | %d |\n" % (
            n, fmt(s["wall_time"].get(n), "%.1f"), st["phi_core"], st["phi_bulk"], st["z_pp"], st["z_all"],
            st["pp_contacts"], st["wall_contacts"], st["ke_trans"], st["ke_rot"], st["surface"],
            st["height_pile"], st["height_max"], st["on_bar"]))
    L.append("\nSpread (max − min) of jdem, lig1, lig2; of jdem over lattice seeds; builtin − jdem:\n\n")
    L.append("| quantity | engines | seeds | builtin − jdem |\n|---|---|---|---|\n")
    for k, d in s["spread"].items():
        L.append("| %s | %s | %s | %s |\n" % (k, fmt(d["engines_jdem_lig1_lig2"]), fmt(d["seeds_jdem"]),
                                            fmt(d["builtin_minus_jdem"], "%+.4g")))
    return "".join(L)


STAT_DEFINITIONS = """Definitions (last frame; d_max = 4 mm the largest diameter, L = 0.054 m the box):
* H_s, the free surface: the box is cut into 6 × 6 columns; in each the highest z + R of the
  particles below the bar (centre below its lowest point, z < 0.024 m); H_s is the median of
  these 36 maxima. Particles above that are counted as "on bar".
* φ core: solid volume fraction of the core box x, y ∈ [d_max, L − d_max], z ∈ [d_max/2, H_s − d_max]
  (the pile is only about 3 diameters deep, so the inset is one diameter, half of one at the
  floor), sampled on a grid of spacing d_max/40 (spheres cut by the box count only inside).
* φ bulk: volume of the particles below the bar / (L² H_s).
* Z pairs = 2 × (particle pairs with overlap > 0) / N; Z with walls adds the particle–wall and
  particle–bar overlaps. Geometric, so the same definition serves every engine.
* KE: ½ Σ m v², ½ Σ (2/5) m R² ω².

"""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=("run", "analyze", "all"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "pour"))
    ap.add_argument("--every", type=int, default=100, help="output.every of the study's scene copy")
    ap.add_argument("--seeds", default="8,9", help="extra lattice seeds run in jdem (spread)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.command in ("run", "all"):
        over = {"output.every": a.every, "output.observables_every": a.every}
        scene = write_scene(SCENE, os.path.join(a.out, "scene.yaml"), over)
        walls = run_all(scene, a.out)
        for seed in [int(s) for s in a.seeds.split(",") if s]:
            seeded = write_scene(SCENE, os.path.join(a.out, "scene_seed%d.yaml" % seed),
                                 dict(over, **{"generate.0.lattice.seed": seed}))
            walls["seed%d" % seed] = run_jdem(seeded, os.path.join(a.out, "seed%d.h5" % seed))
        dt = float(yaml.safe_load(open(SCENE))["time"]["dt"])
        with open(os.path.join(a.out, "runs.json"), "w") as f:
            json.dump({"scene": scene, "every": a.every, "dt": dt, "wall_time": walls}, f, indent=1)
    if a.command in ("analyze", "all"):
        s = analyze(a.out)
        sys.stdout.write(report(s, json.load(open(os.path.join(a.out, "runs.json")))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
