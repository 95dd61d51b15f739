#!/usr/bin/python3
"""pour_study.py — the pour scene in both engines: round-off divergence and settled statistics.

    scripts/pour_study.py run     [--out out/pour] [--every 100] [--engines jdem,lig1,...]
                                  [--seeds 8,9,10,11,12,13,14,15]
    scripts/pour_study.py analyze [--out out/pour]
    scripts/pour_study.py all     (run, then analyze)

`run` writes a copy of reference_runs/pour/scene.yaml with denser output (output.every, the
physics untouched) and runs it in
    jdem      build/jdem
    lig1      build/liggghts-jdem, 1 rank          (pair_style gran/jiang, fix wall/jiang)
    lig2      build/liggghts-jdem, 2 MPI ranks (LIGGGHTS' default grid 1 x 1 x 2: the cut is at
              z = 0.075 m, above the pile once the particles have fallen)
    lig2x     build/liggghts-jdem, 2 MPI ranks cut at x = 0.027 m (`processors 2 1 1`), through
              the pile and the bar for the whole run
    builtin   build/liggghts-jdem, 1 rank, LIGGGHTS' own hertz/history/epsd2 law and primitive
              walls (scene_to_liggghts.py --builtin)
plus jdem runs of the same scene with other lattice seeds, output every 2000 steps (the
run-to-run spread of the settled statistics).  Run times go to OUT/runs.json (merged, so
`run --engines ... --seeds ...` can add runs).  `analyze` writes OUT/summary.json, OUT/report.md
and the plots.

Decks: the generator's, except that lig2x adds a `processors` line (set_processors()).  2-rank runs
use Open MPI's mpi_yield_when_idle (the results do not depend on it).  The environment variables
JDEM and LIGGGHTS_JDEM select the engines (default build/jdem, build/liggghts-jdem).
"""
import argparse
import json
import math
import os
import sys

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.engines import ROOT
from scripts.trajectory_divergence import ROUNDOFF, divergence_summary

JDEM, LIG = engines.JDEM, engines.LIGGGHTS_JDEM   # $JDEM and $LIGGGHTS_JDEM when set
SCENE = os.path.join(ROOT, "reference_runs", "pour", "scene.yaml")
ENGINES = ("jdem", "lig1", "lig2", "lig2x", "builtin")
PAIRS = (("jdem", "lig1"), ("lig1", "lig2"), ("lig1", "lig2x"), ("jdem", "builtin"))
SEED_EVERY = 2000         # output.every of the seed runs (statistics only)


# ---------------------------------------------------------------------------------------------
# Running

def write_scene(src, dst, overrides):
    """Copy a scene with dotted-path overrides, e.g. {"output.every": 100}."""
    scene = yaml.load(open(src), Loader=yaml.CSafeLoader)
    for path, value in overrides.items():
        node = scene
        keys = path.split(".")
        for k in keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        node[keys[-1]] = value
    with open(dst, "w") as f:
        yaml.safe_dump(scene, f, sort_keys=False)
    return dst


def run_jdem(scene, out):
    """Run build/jdem; returns its times (timed).  --no-sort: the engines are compared in the
    particle order closest to LIGGGHTS' summation order (jdem's default renumbering in cell
    order changes only the order of the force sums, which brings the chaotic divergence from
    LIGGGHTS forward by ~0.02 s; tests/engine/test_fastpaths.py checks the sorted path against
    this one)."""
    return engines.cpu_timed([JDEM, "run", scene, "-o", out, "--quiet", "--no-sort"])


def set_processors(deck_dir, grid):
    """Insert `processors GRID` before read_data in DECK_DIR/in.jdem."""
    path = os.path.join(deck_dir, "in.jdem")
    text = open(path).read()
    with open(path, "w") as f:
        f.write(text.replace("read_data", "processors      %s\nread_data" % grid, 1))


def run_liggghts(scene, out, np_=1, builtin=False, grid=None):
    """Resolve, write the deck (OUT minus .h5 plus .deck/), run build/liggghts-jdem; its times."""
    out = os.path.abspath(out)
    deck_dir = out[:-3] + ".deck"
    os.makedirs(deck_dir, exist_ok=True)
    for stale in (out, out + ".part"):
        if os.path.exists(stale):
            os.remove(stale)
    resolved = os.path.join(deck_dir, "resolved.yaml")
    with open(resolved, "w") as f:
        f.write(engines.resolve(scene, binary=JDEM, check=True).stdout)
    engines.write_deck(resolved, os.path.join(deck_dir, "in.jdem"), "--trajectory", out,
                       *(["--builtin"] if builtin else []), check=True)
    if grid:
        set_processors(deck_dir, grid)
    # idle ranks yield instead of spinning: 2.5x faster on 2 busy cores, same results
    cmd = engines.liggghts_command("in.jdem", np_, binary=LIG, mpi_flags=("--mca", "mpi_yield_when_idle", "1"))
    times = engines.cpu_timed(cmd, cwd=deck_dir)
    if not os.path.exists(out):
        raise RuntimeError("%s wrote no trajectory (see %s/log.lammps)" % (" ".join(cmd), deck_dir))
    return times


def run_all(scene, out_dir, which=ENGINES):
    """Run the engines on SCENE into OUT_DIR/NAME.h5; returns {name: times}."""
    runners = {"jdem": lambda o: run_jdem(scene, o),
               "lig1": lambda o: run_liggghts(scene, o, 1),
               "lig2": lambda o: run_liggghts(scene, o, 2),
               "lig2x": lambda o: run_liggghts(scene, o, 2, grid="2 1 1"),
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


def settled_stats(path, scene, at=None):
    """Statistics of the frame at time AT (default: the last; definitions in the report)."""
    t = load(path)
    n = len(t["time"]) - 1 if at is None else int(np.argmin(np.abs(t["time"] - at)))
    x, v, w, r, m = t["x"][n], t["v"][n], t["w"][n], t["radius"], t["mass"]
    L, bar = box_geometry(scene)
    dmax = 2.0 * float(r.max())
    h_s, on_bar, h_max = pile_top(x, r, L, bar)
    core_lo, core_hi = [dmax, dmax, dmax / 2], [L - dmax, L - dmax, h_s - dmax]
    pp, pw = contacts(x, r, L, bar)
    below = x[:, 2] < bar[1] - bar[2]
    solid = float((4.0 / 3.0 * math.pi * r[below] ** 3).sum())
    return {"time": float(t["time"][n]),
            "phi_core": packing_fraction(x, r, core_lo, core_hi, dmax / 40),
            "phi_bulk": solid / (L * L * h_s),
            "z_pp": 2.0 * pp / len(r), "z_all": (2.0 * pp + pw) / len(r), "pp_contacts": pp, "wall_contacts": pw,
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


STAT_KEYS = ("phi_core", "phi_bulk", "z_pp", "z_all", "surface", "height_pile")
EARLY_TIME = 0.4          # a second look at the statistics while contacts still form [s]


def spread(stats, names):
    """Per statistic: range (max - min) and sample standard deviation over the runs NAMES."""
    out = {}
    for k in STAT_KEYS:
        vals = np.array([stats[n][k] for n in names])
        out[k] = {"range": float(np.ptp(vals)), "std": float(vals.std(ddof=1)) if len(vals) > 1 else None}
    return out


def divergence(a, b):
    """Round-off horizon and growth of the scaled difference between two loaded trajectories."""
    t, dx, dv = scaled_difference(a, b)
    return (t, dx, dv), divergence_summary(t, dx, dv)


def analyze(out_dir):
    meta = json.load(open(os.path.join(out_dir, "runs.json")))
    scene = yaml.load(engines.resolve(meta["scene"], binary=JDEM, check=True).stdout, Loader=yaml.CSafeLoader)
    traj = {n: os.path.join(out_dir, n + ".h5") for n in meta["times"]}
    loaded = {n: load(traj[n]) for n in ENGINES}
    curves, div = {}, {}
    for a, b in PAIRS:
        curves["%s vs %s" % (a, b)], div["%s vs %s" % (a, b)] = divergence(loaded[a], loaded[b])
    plot_differences(curves, os.path.join(out_dir, "divergence.png"))
    stats = {n: settled_stats(p, scene) for n, p in traj.items()}
    plot_stats(stats, os.path.join(out_dir, "settled.png"))
    seeds = ["jdem"] + sorted((n for n in stats if n.startswith("seed")), key=lambda n: int(n[4:]))
    at_early = {n: settled_stats(p, scene, EARLY_TIME) for n, p in traj.items() if n != "builtin"}
    summary = {"scene": meta["scene"], "every": meta["every"], "roundoff_level": ROUNDOFF,
               "times": meta["times"], "load_average": meta.get("load_average"),
               "divergence": div, "settled": stats,
               "spread_engines": spread(stats, ("jdem", "lig1", "lig2", "lig2x")),
               "spread_seeds": spread(stats, seeds), "seed_runs": seeds,
               "builtin_minus_jdem": {k: stats["builtin"][k] - stats["jdem"][k] for k in STAT_KEYS},
               "early_time": EARLY_TIME, "at_early_time": at_early,
               "spread_engines_at_early_time": spread(at_early, ("jdem", "lig1", "lig2", "lig2x")),
               "spread_seeds_at_early_time": spread(at_early, seeds)}
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    with open(os.path.join(out_dir, "report.md"), "w") as f:
        f.write(report(summary, meta, scene))


def fmt(x, spec="%.4g"):
    return "—" if x is None else spec % x


def report(s, meta, scene):
    L = ["# Pour: jdem, liggghts-jdem on 1 and 2 ranks, and LIGGGHTS' built-in law\n",
         "Generated by `scripts/pour_study.py all` (%s, output every %d steps = %.1e s).\n"
         % (os.path.relpath(meta["scene"], ROOT), meta["every"], meta["every"] * meta["dt"]),
         RUNS_TEXT,
         "\n## Divergence between runs\n",
         "Per frame, the largest |Δx| over all particles and components / R_max, and the largest "
         "|Δv| / sqrt(g d_max) (d_max = 2 R_max); the curve used below is the larger of the two. "
         "Horizon: the last frame before it reaches %.0e. Growth rate: least-squares slope of "
         "ln(difference) from 1e-12 to 1e-3 (before saturation). Plot: `divergence.png`.\n\n" % ROUNDOFF,
         "| runs | first non-zero at [s] (value) | horizon < 1e-10 [s] | growth rate [1/s] (fit window [s]) "
         "| e-folding time [s] | final |\n",
         "|---|---|---|---|---|---|\n"]
    for k, d in s["divergence"].items():
        g = d["growth"]
        L.append("| %s | %s (%s) | %s%s | %s | %s | %.2e |\n" % (
            k, fmt(d["first_nonzero"]), fmt(d["first_value"], "%.1e"), fmt(d["horizon"]),
            "" if d["reaches_roundoff_level"] else " (never reached)",
            "%.1f (%.3f–%.3f)" % (g["rate"], g["from"], g["to"]) if g else "—",
            fmt(1.0 / g["rate"], "%.4f") if g and g["rate"] > 0 else "—", d["final"]))
    L.append("\n## Settled statistics at t = %.2f s\n\n" % s["settled"]["jdem"]["time"])
    L.append(STAT_DEFINITIONS)
    L.append("| run | wall / CPU time [s] (load) | φ core | φ bulk | Z pairs | Z with walls | pair / wall contacts "
             "| KE trans [J] | KE rot [J] | H_s [m] | max z+R below bar [m] | max z+R [m] | on bar |\n")
    L.append("|---|" + "---|" * 12 + "\n")
    for n, st in s["settled"].items():
        L.append("| %s | %s | %.4f | %.4f | %.3f | %.3f | %d / %d | %.2e | %.2e | %.4f | %.4f | %.4f | %d |\n" % (
            n, "%.1f / %.1f (%.1f)" % (s["times"][n]["wall"], s["times"][n]["cpu"], s["times"][n]["load"]), st["phi_core"], st["phi_bulk"],
            st["z_pp"], st["z_all"],
            st["pp_contacts"], st["wall_contacts"], st["ke_trans"], st["ke_rot"], st["surface"],
            st["height_pile"], st["height_max"], st["on_bar"]))
    L.append(spread_table("at t = %.2f s" % s["settled"]["jdem"]["time"], s["spread_engines"],
                          s["spread_seeds"], s["seed_runs"], s["builtin_minus_jdem"]))
    L.append(spread_table("at t = %.2f s (settling: contacts still forming)" % s["early_time"],
                          s["spread_engines_at_early_time"], s["spread_seeds_at_early_time"], s["seed_runs"]))
    L.append(EXPLANATION)
    L.append(model_section(scene))
    return "".join(L)


def model_ratios(nu, ra, rb):
    """LIGGGHTS' hertz/history (wall material = grain, as in the deck) over jdem's law, same overlap.
    Pair stiffness rules: jdem k_n = harmonic mean of k_p = E sqrt(2R)/(3(1-nu^2)); LIGGGHTS
    (4/3) Y* sqrt(R* delta), Y* = E/(2(1-nu^2)) (docs/model.md, normal_model_hertz.h)."""
    def harmonic(a, b):
        return 2.0 * math.sqrt(2 * a) * math.sqrt(2 * b) / (math.sqrt(2 * a) + math.sqrt(2 * b)) / 3.0
    return {"K_n pair, unequal radii": (2.0 / 3.0) * math.sqrt(ra * rb / (ra + rb)) / harmonic(ra, rb),
            "K_n wall (grain E as wall E vs rigid wall)": 0.5,
            "K_t pair (8 G* sqrt(R* delta) vs K_t = K_n)": 3.0 * (1.0 - nu) / (2.0 - nu),
            "K_t wall": 1.5 * (1.0 - nu) / (2.0 - nu),
            "C_n at equal K_n (2 sqrt(5/6) beta sqrt(S_n m*), S_n = 1.5 K_n)": math.sqrt(1.25)}


def model_section(scene):
    grain = scene["materials"]["grain"]
    radii = sorted({float(p["radius"]) for p in scene["particles"]})
    L = ["\nStiffness and damping of LIGGGHTS' built-in law relative to ours for this scene (ν = %g, "
         "R = %s mm):\n\n| quantity | LIGGGHTS / jdem |\n|---|---|\n"
         % (float(grain["poisson_ratio"]), " and ".join("%g" % (1e3 * r) for r in radii))]
    for k, v in model_ratios(float(grain["poisson_ratio"]), radii[0], radii[-1]).items():
        L.append("| %s | %.3f |\n" % (k, v))
    return "".join(L) + MODEL_TEXT


def spread_table(when, engines, seeds, seed_runs, builtin=None):
    L = ["\nSpread %s: range (max − min) over jdem, lig1, lig2, lig2x; range and standard deviation "
         "over %d jdem runs with lattice seeds (%s)%s:\n\n" % (
             when, len(seed_runs), ", ".join(seed_runs), "; builtin − jdem" if builtin else ""),
         "| quantity | engines range | seeds range | seeds std |%s\n" % (" builtin − jdem |" if builtin else ""),
         "|---|---|---|---|%s\n" % ("---|" if builtin else "")]
    for k in STAT_KEYS:
        L.append("| %s | %.4g | %.4g | %.4g |%s\n" % (k, engines[k]["range"], seeds[k]["range"], seeds[k]["std"],
                                                   " %+.4g |" % builtin[k] if builtin else ""))
    return "".join(L)


RUNS_TEXT = """
## Runs

* jdem: build/jdem. lig1: build/liggghts-jdem on 1 rank (pair_style gran/jiang, fix wall/jiang).
  lig2: 2 MPI ranks, LIGGGHTS' default grid 1 × 1 × 2, cut at z = 0.075 m: every particle is below
  it by t = 0.15 s, so afterwards rank 1 is empty. lig2x: 2 ranks cut at x = 0.027 m
  (`processors 2 1 1`), through the pile and the bar for the whole run. builtin: 1 rank,
  LIGGGHTS' own `gran model hertz tangential history rolling_friction epsd2` and primitive walls
  (scene_to_liggghts.py --builtin). seedN: jdem with lattice seed N instead of 7.
* Decks: the generator's, except lig2x's `processors` line.
* Times: wall and CPU (user + system of all processes, both ranks for lig2/lig2x), with the
  1-minute load average when the run started: the machine was shared (load 3–6 on 2 cores), so
  wall times are upper bounds; CPU times compare better. 2-rank runs use
  `--mca mpi_yield_when_idle 1` (2.5× faster under load than spinning, identical results).
* Every run is deterministic: repeating them gave bit-identical trajectories (all five engines).
"""

EXPLANATION = """
## Where the differences come from

* Until the first particles reach the bar (t ≈ 0.09 s) nothing touches (the jittered lattice has
  no overlaps), and every run is bit-identical.
* jdem vs liggghts-jdem (1 rank): the same kernel evaluates every contact with the same
  arithmetic; only the order in which a particle's contact forces and torques are summed differs.
  LIGGGHTS adds them in its neighbour-list order (bins, i < j of the half list), walls after pairs;
  jdem in sorted (i, j) order. With two contacts the sum is exact in either order; from three
  on, (a + b) + c ≠ (a + c) + b in the last bit. The first difference is one ulp-sized step
  (2.8e-16 of R_max).
* 1 vs 2 ranks: with `newton off`, a pair that straddles the cut is evaluated on both ranks,
  each from its own side (i and j swapped: normal, relative velocity and history increment
  computed in the opposite orientation, not bitwise the negative), and the owned and ghost
  atoms sit in a different order in the lists. Hence it starts earlier than jdem vs 1 rank.
* Growth: a dense granular flow is chaotic: collisions of round particles amplify a small change
  of the impact geometry (like a billiard), so round-off grows exponentially, here by e every 3–4 ms (a contact lasts about 0.3 ms), and
  saturates at O(1) (particles in different places) near t = 0.2 s.
* No sign of a migration or history bug: the 1- vs 2-rank difference is exactly zero while the
  particles migrate across the cut during the fall, it appears at round-off size (1e-16 to
  1e-15) at the first multi-contact collisions, and grows smoothly at the same rate as the
  jdem vs 1-rank difference. A lost or misoriented wall or contact history on migration would
  change a force by a whole spring increment at once, far above round-off.
* After saturation the runs are different realisations of the same pour: their settled
  statistics differ like those of runs with different lattice seeds (compare the columns of the
  spread tables), which is what tests/liggghts/check_pour.py checks.
"""

MODEL_TEXT = """
How LIGGGHTS' `gran model hertz tangential history rolling_friction epsd2` differs from ours
(read in /usr/include/liggghts: normal_model_hertz.h, tangential_model_history.h,
rolling_model_epsd2.h, pair_gran_base.h, primitive_wall_definitions.h):
* Normal: F_n = (4/3) Y* sqrt(R* δ) δ − γ_n v_n, exact Hertz for any radii (ours: the harmonic
  mean of per-particle prefactors, exact only for equal radii). No end-of-collision rule: with
  the default `limitForce off` the damped force may pull at the end of unloading (ours: Luding's
  rule, never tension).
* Walls: LIGGGHTS treats the wall as a body of its atom type; the deck gives the wall type the
  grain's E and ν (a placeholder for our styles), so the built-in wall is as soft as a grain:
  half our stiffness (ours: rigid wall, exact Hertz). Primitive walls are infinite and
  two-sided; the bar is `ycylinder R z_c x_c` (the centre in the coordinates (d+1)%3, (d+2)%3).
* Damping: γ_n = 2 sqrt(5/6) β sqrt(S_n m*), S_n = 2 Y* sqrt(R* δ) the tangent stiffness
  (1.5 K_n); β from e (libliggghts' createBetaEff, not in the headers: β = ln e/sqrt(ln² e + π²),
  our γ of eq. 30 up to sign), so at equal K_n the built-in damping is sqrt(1.25) = 1.118× ours.
* Tangential: K_t = 8 G* sqrt(R* δ) (Mindlin's tangent stiffness) vs our K_t = K_n; damping
  γ_t = 2 sqrt(5/6) β sqrt(S_t m*) only while sticking (ours: C_t = C_n while sticking too);
  sliding rescales the spring to μ|F_n|, F_n including the damping force (as our `coulomb`
  limit resets ξ).
* History: the shear spring is zeroed by `surfacesClose`, which pair_gran_base.h reaches only
  for rsq < contactDistanceFactor² (R_i + R_j)², i.e. never with the default factor 1: the
  spring of a separated pair survives until the next neighbour rebuild and is picked up again
  if the pair re-touches before it. Ours resets at separation.
* Rolling (epsd2): k_r = k_t R*² acting on the tangential part of the relative rotation (torsion
  removed), capped at μ_r |F_n| R*, no rolling damping. Ours: K_r = K_t R_r² on the full relative
  rotation, C_r = 2 γ sqrt(I* K_r), cap η R_r F_n. Same dimensionless coefficient 0.1, different
  springs (K_t differs) and no dissipation in the built-in spring. (The final kinetic energies
  in the table are set by single particles still rocking, e.g. on the bar, in ours too: seed 8;
  they do not separate the models.)
* Despite all this the built-in run's packing fraction and coordination number fall inside the
  seed spread of ours: for this pour (μ = 0.5, rolling resistance 0.1, e = 0.5) the settled
  structure is set by friction, rolling resistance and gravity, not by the stiffness and damping
  details. Trajectories differ from the first bar contact on (difference O(1) at t = 0.0875 s).
"""


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
    ap.add_argument("--engines", default=",".join(ENGINES), help="engine runs to do (default: all)")
    ap.add_argument("--seeds", default="8,9,10,11,12,13,14,15", help="extra lattice seeds run in jdem")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    runs = os.path.join(a.out, "runs.json")
    if a.command in ("run", "all"):
        meta = json.load(open(runs)) if os.path.exists(runs) else {"times": {}}
        over = {"output.every": a.every, "output.observables_every": a.every}
        scene = write_scene(SCENE, os.path.join(a.out, "scene.yaml"), over)
        meta["times"].update(run_all(scene, a.out, [e for e in a.engines.split(",") if e]))
        for seed in [int(x) for x in a.seeds.split(",") if x]:
            seeded = write_scene(SCENE, os.path.join(a.out, "scene_seed%d.yaml" % seed),
                                 {"output.every": SEED_EVERY, "generate.0.lattice.seed": seed})
            meta["times"]["seed%d" % seed] = run_jdem(seeded, os.path.join(a.out, "seed%d.h5" % seed))
        meta.update(load_average=os.getloadavg(), scene=scene, every=a.every,
                    dt=float(yaml.load(open(SCENE), Loader=yaml.CSafeLoader)["time"]["dt"]))
        with open(runs, "w") as f:
            json.dump(meta, f, indent=1)
    if a.command in ("analyze", "all"):
        analyze(a.out)
        sys.stdout.write(open(os.path.join(a.out, "report.md")).read())
    return 0


if __name__ == "__main__":
    sys.exit(main())
