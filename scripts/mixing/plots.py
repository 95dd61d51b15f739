"""Pictures of the campaign (PNG, matplotlib): deposits and mixing parameters.

deposit_view: the front (x-z, looking along +y) or side (y-z, looking along -x) view of a
deposit, spheres to scale as circles coloured by cohort (the seed's red = big, blue = small),
the box and the cylinders drawn; `clip` keeps only the spheres cut by the middle plane y = 0.5
(the seed's "middle clip") or x = 0.5 for a side view.
snapshot_sheet: front and side views of several frames in one picture, spheres in the colours
the caller gives (Ch. 5: big spheres, whole blocks, fragments and single spheres apart).
strip_plot: one parameter at the points per model (Figs 4-11, 4-12): the values as dark
symbols on one vertical line per model, the seed's mean as a red square and its standard
deviation as a grey bar (stats.py), and the ideal phi_v as a red dashed line.
break_map: where the bonds of a bonded fill broke (Ch. 5; the seed shows none): the break
positions in the front view (x-z), tension and shear apart, with the box and the cylinders.
mixing_figure: the seed's Fig. 4-11 (pass 1) or 4-12 (pass 2) of one engine from the results of
report_ch4.py (summary.json): its six panels (a)-(f), phi_v, phi_m, e, n, rho_b and Z, each a
strip plot over the models with a finished fill of that pass.
bonded_figure: the seed's Fig. 5-24, 5-25 or 5-26 (Groups 1, 2, 3) of one engine from the fills
of report_ch5.py: (a) phi_v at the 27 points of Table 5-2 in three segments, y = 0.25, 0.5 and
0.75 m, and (b) at the 9 points of the middle clip, each a strip plot over the models.
points_elastic_figure: the seed's Figs 5-28 to 5-30 (Groups 1-3), per model E (left axis) and
νxy, νxz (right axis) against the point of the middle clip, each engine's line.
elastic_figure: the seed's Fig. 5-27, E at the middle clip per group over the six models, the
seed's mean and std beside each engine's; and beneath it the confined modulus M, which the seed
does not give but which a laterally confined cube determines (the E of the fit does not).
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402
from matplotlib.patches import Circle, Rectangle  # noqa: E402

from . import stats  # noqa: E402
from .params import IDEAL_PHI_V, MIDDLE_CLIP, TABLE_5_2_ROWS, big_mask  # noqa: E402

BIG_COLOUR, SMALL_COLOUR = "#d62728", "#1f4fb4"
VIEWS = {"front": (0, 2, 1), "side": (1, 2, 0)}  # (horizontal axis, vertical axis, depth axis)


def draw_deposit(ax, dep, view="front", box=((0, 0, 0), (1, 1, 2)), cylinders=(), clip=None,
                 colours=None, threshold=None, at=None):
    """Draw the view on `ax`; returns the number of spheres drawn.  cylinders: (x, z, radius) of
    horizontal cylinders along y [m]; clip: half-thickness of the slab to keep, around the plane
    at depth `at` [m] (default: the middle plane; clip None: all spheres); colours: one colour
    per particle (default: red big, blue small)."""
    h, v, depth = VIEWS[view]
    keep = np.ones(len(dep.radius), bool)
    if clip is not None:
        mid = 0.5 * (box[0][depth] + box[1][depth]) if at is None else at
        keep = np.abs(dep.position[:, depth] - mid) <= dep.radius + clip
    if colours is None:
        colours = np.where(big_mask(dep.radius, threshold), BIG_COLOUR, SMALL_COLOUR)
    order = np.argsort(-dep.position[keep][:, depth] if view == "front" else dep.position[keep][:, depth])
    xy = dep.position[keep][:, [h, v]][order]
    d = 2.0 * dep.radius[keep][order]
    lo, hi = box
    ax.add_collection(EllipseCollection(d, d, np.zeros(len(d)), units="xy", offsets=xy,
                                        offset_transform=ax.transData,
                                        facecolors=np.asarray(colours)[keep][order], edgecolors="none"))
    ax.add_patch(Rectangle((lo[h], lo[v]), hi[h] - lo[h], hi[v] - lo[v], fill=False, lw=1.5,
                           color="k"))
    for x, z, rc in cylinders:
        if view == "front":
            ax.add_patch(Circle((x, z), rc, color="0.4"))
        else:
            ax.add_patch(Rectangle((lo[1], z - rc), hi[1] - lo[1], 2 * rc, color="0.4", alpha=0.6))
    ax.set_xlim(lo[h] - 0.05, hi[h] + 0.05)
    ax.set_ylim(lo[v] - 0.05, hi[v] + 0.05)
    ax.set_aspect("equal")
    ax.set_xlabel("xyz"[h] + " [m]")
    ax.set_ylabel("z [m]")
    return int(len(d))


def deposit_view(dep, path, view="front", box=((0, 0, 0), (1, 1, 2)), cylinders=(),
                 clip=None, title=None, threshold=None, colours=None):
    """Write the view (draw_deposit) as PNG; returns the number of spheres drawn."""
    fig, ax = plt.subplots(figsize=(4, 7), dpi=100)
    n = draw_deposit(ax, dep, view, box, cylinders, clip, colours, threshold)
    ax.set_title(title or f"{view} view, t = {dep.time:g} s")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return n


def slab_sheet(dep, path, slabs, box=((0, 0, 0), (1, 1, 2)), cylinders=(), colours=None, title=None):
    """Front views of several slabs of one deposit side by side (the seed's Fig. 5-23: the band
    against the front wall beside the middle clip); slabs: [(title, plane depth [m], half
    thickness [m])].  Returns the number of spheres drawn per slab."""
    fig, axes = plt.subplots(1, len(slabs), figsize=(4 * len(slabs), 7), dpi=100, squeeze=False)
    drawn = []
    for ax, (name, at, half) in zip(axes[0], slabs):
        drawn.append(draw_deposit(ax, dep, "front", box, cylinders, clip=half, colours=colours, at=at))
        ax.set_title(name, fontsize=9)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.97 if title else 1))
    fig.savefig(path)
    plt.close(fig)
    return drawn


def snapshot_sheet(frames, path, box=((0, 0, 0), (1, 1, 2)), cylinders=(), legend=(), title=None):
    """The seed's Figs 5-5 to 5-22 as one PNG: the front view (top row) and the side view (bottom
    row) of each of `frames`, a list of (deposit, colours per particle); legend: (label, colour)
    pairs.  Returns the number of spheres drawn per frame."""
    fig, axes = plt.subplots(2, len(frames), figsize=(2.6 * len(frames), 9.5), dpi=100,
                             squeeze=False)
    drawn = []
    for k, (dep, colours) in enumerate(frames):
        for row, view in enumerate(("front", "side")):
            n = draw_deposit(axes[row][k], dep, view, box, cylinders, colours=colours)
            axes[row][k].set_title(f"{view}, t = {dep.time:g} s", fontsize=9)
        drawn.append(n)
    if legend:
        fig.legend(handles=[Rectangle((0, 0), 1, 1, color=c, label=l) for l, c in legend],
                   loc="lower center", ncol=len(legend) if len(frames) > 2 else 2, fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.04 if legend else 0, 1, 0.97 if title else 1))
    fig.savefig(path)
    plt.close(fig)
    return drawn


def break_map(position, mode, path, box=((0, 0, 0), (1, 1, 2)), cylinders=(), title=None):
    """Write the front view of the break positions [K][3] (m) as PNG, mode 1 tension (orange),
    2 shear (purple), with the box and the cylinders (x, z, radius) along y."""
    lo, hi = box
    fig, ax = plt.subplots(figsize=(4, 7), dpi=100)
    for m, name, colour in ((1, "tension", "#ff7f0e"), (2, "shear", "#7b3294")):
        at = position[mode == m]
        ax.scatter(at[:, 0], at[:, 2], s=2, c=colour, alpha=0.4, linewidths=0,
                   label=f"{name} ({len(at)})")
    ax.add_patch(Rectangle((lo[0], lo[2]), hi[0] - lo[0], hi[2] - lo[2], fill=False, lw=1.5,
                           color="k"))
    for x, z, rc in cylinders:
        ax.add_patch(Circle((x, z), rc, color="0.4"))
    ax.set_xlim(lo[0] - 0.05, hi[0] + 0.05)
    ax.set_ylim(lo[2] - 0.05, hi[2] + 0.05)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.legend(loc="lower left", markerscale=4, fontsize=8)
    ax.set_title(title or "bond breaks")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def draw_strip(ax, values_by_model, name, ideal=None):
    """The strip plot on `ax`; returns the number of point markers drawn.  The artists carry
    labels ("points LABEL", "mean LABEL", "std LABEL", "ideal") so that a test can read back
    what was drawn."""
    drawn = 0
    for i, (label, values) in enumerate(values_by_model.items()):
        v = np.asarray(values, dtype=float)
        finite = v[np.isfinite(v)]   # phi_v is infinite at a point without small particles
        ax.plot(np.full(len(finite), i), finite, "o", color="0.15", ms=4, label=f"points {label}")
        drawn += len(finite)
        s = stats.summary(v)
        ax.errorbar(i + 0.15, s["mean"], yerr=s["std"], fmt="none", ecolor="0.6", elinewidth=6,
                    label=f"std {label}")
        ax.plot(i + 0.15, s["mean"], "s", color="red", ms=6, label=f"mean {label}")
    if ideal is not None:
        ax.axhline(ideal, color="red", ls="--", lw=1, label="ideal")
    ax.set_xticks(range(len(values_by_model)), list(values_by_model))
    ax.set_ylabel(name)
    return drawn


def strip_plot(values_by_model, path, name="phi_v", ideal=None, title=None):
    """values_by_model: {model label: the values at the points}.  Writes PNG; returns the number
    of point markers drawn."""
    fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
    drawn = draw_strip(ax, values_by_model, name, ideal)
    ax.set_title(title or name)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return drawn


# What the strip panels of a figure show, in its caption.
STRIP_KEY = "(dots: points; red square: trimmed mean; grey bar: its std; dashed: ideal φv)"


def strip_panel(ax, values_by_model, name, ideal, title):
    """One panel of a figure: the strip plot over the models, titled."""
    draw_strip(ax, values_by_model, name, ideal)
    ax.set_xlabel("model")
    ax.set_title(title)


def save_figure(fig, name, directories):
    """Save an open figure as `name` into each of `directories` and close it; returns name, or
    None for no figure (no data)."""
    if fig is None:
        return None
    for d in directories:
        fig.savefig(os.path.join(d, name))
    plt.close(fig)
    return name


def write_figures(make, name, engines, keys, directories):
    """Save make(engine, key) (an open figure, or None: no data) as name(engine, key) into each
    of `directories`, for every engine and key; returns {(engine, key): file name}."""
    written = {(engine, key): save_figure(make(engine, key), name(engine, key), directories)
               for engine in engines for key in keys}
    return {k: v for k, v in written.items() if v}


# The panels (a)-(f) of Figs 4-11 and 4-12: (summary.json key, axis label); the ideal line on phi_v.
FIGURE_PANELS = (("phi_v", "φv"), ("phi_m", "φm"), ("e", "e"), ("n", "n"),
                 ("rho_b", "ρb [kg/m³]"), ("Z", "Z"))
SEED_FIGURE = {1: "4-11", 2: "4-12"}


def figure_name(engine, p):
    """File name of the figure of one engine and pass, e.g. fig4-11_jdem.png."""
    return "fig%s_%s.png" % (SEED_FIGURE[p], engine)


def mixing_figure(results, engine, p):
    """The open matplotlib figure of Fig. 4-11 (p = 1) or 4-12 (p = 2) for `engine` from
    results[engine][model]["fill%d" % p]["points"] (report_ch4.py), or None when no model has
    that fill.  The caller saves and closes it."""
    by_number = sorted(results.get(engine, {}).items(), key=lambda item: int(item[0][len("model"):]))
    fills = {model[len("model"):]: entry["fill%d" % p] for model, entry in by_number
             if entry.get("fill%d" % p)}
    if not fills:
        return None
    fig, axes = plt.subplots(2, 3, figsize=(12, 7), dpi=100)
    for ax, letter, (key, label) in zip(axes.flat, "abcdef", FIGURE_PANELS):
        values = {m: [q[key] for q in f["points"]] for m, f in fills.items()}
        strip_panel(ax, values, label, IDEAL_PHI_V if key == "phi_v" else None,
                    "(%s) %s" % (letter, label))
    fig.suptitle("Fig. %s: mixing parameters at the 9 points of Table 4-2, %s, pass %d %s"
                 % (SEED_FIGURE[p], engine, p, STRIP_KEY), fontsize=9)
    fig.tight_layout()
    return fig


def write_mixing_figures(results, engines, directory):
    """Write every Fig. 4-11/4-12 that has data into `directory`; returns {(engine, pass): file
    name}."""
    return write_figures(lambda e, p: mixing_figure(results, e, p), figure_name, engines,
                         SEED_FIGURE, [directory])


# Figs 5-24 to 5-26, one per group.
SEED_BONDED_FIGURE = {1: "5-24", 2: "5-25", 3: "5-26"}


def bonded_figure_name(engine, group):
    """File name of the figure of one engine and group, e.g. fig5-24_jdem.png."""
    return "fig%s_%s.png" % (SEED_BONDED_FIGURE[group], engine)


def bonded_figure(found, engine, group):
    """The open matplotlib figure of Fig. 5-24, 5-25 or 5-26 (group 1, 2, 3) for `engine` from
    found["ENGINE/groupG_modelM"]["phi_v"] (the 27 points, report_ch5.py), or None when no model
    of the group has a fill.  The caller saves and closes it."""
    fills = {}
    for m in range(1, 7):
        entry = found.get("%s/group%d_model%d" % (engine, group, m))
        if entry and entry.get("phi_v"):
            fills[str(m)] = list(entry["phi_v"])
    if not fills:
        return None
    fig = plt.figure(figsize=(13, 8), dpi=100)
    grid = fig.add_gridspec(2, 3)
    first = None
    for k, (y, row) in enumerate(TABLE_5_2_ROWS):
        ax = fig.add_subplot(grid[0, k], sharey=first)
        first = first or ax
        strip_panel(ax, {m: v[row] for m, v in fills.items()}, "φv", IDEAL_PHI_V,
                    "(a) y = %.2f m, points %d–%d" % (y, row.start + 1, row.stop))
    strip_panel(fig.add_subplot(grid[1, :]), {m: v[MIDDLE_CLIP] for m, v in fills.items()}, "φv",
                IDEAL_PHI_V, "(b) the middle clip, points %d–%d (Table 5-3)"
                % (MIDDLE_CLIP.start + 1, MIDDLE_CLIP.stop))
    fig.suptitle("Fig. %s: φv at the points of Table 5-2, Group %d, %s %s"
                 % (SEED_BONDED_FIGURE[group], group, engine, STRIP_KEY), fontsize=9)
    fig.tight_layout()
    return fig


def write_bonded_figures(found, engines, directories):
    """Write every Fig. 5-24/25/26 that has data into each of `directories`; returns {(engine,
    group): file name}."""
    return write_figures(lambda e, g: bonded_figure(found, e, g), bonded_figure_name, engines,
                         SEED_BONDED_FIGURE, directories)


# Fig. 5-27 and the M row beneath it: each source's marker and colour, side by side per model
ELASTIC_SOURCES = (("seed", "s", "0.45"), ("jdem", "o", "tab:blue"), ("liggghts-jdem", "^", "tab:orange"))


def elastic_figure(values, groups=(1, 2, 3), models=range(1, 7)):
    """The open figure of Fig. 5-27 (top row, E) and of M (bottom row) per group, or None when no
    source has a value.  values[(quantity, group, model, source)] = (mean, std), quantity "E" or
    "M", source one of ELASTIC_SOURCES; a missing key draws nothing.  The error bars carry the
    label "QUANTITY SOURCE group G" so that a test can read back what was drawn."""
    if not values:
        return None
    fig, axes = plt.subplots(2, len(groups), figsize=(4.2 * len(groups), 7), dpi=100, sharey="row",
                             squeeze=False)
    for row, (quantity, unit) in enumerate((("E", "E [Pa] (orthotropic fit)"), ("M", "M [Pa] (wall strain)"))):
        for ax, g in zip(axes[row], groups):
            for k, (source, marker, colour) in enumerate(ELASTIC_SOURCES):
                pts = [(m, values[(quantity, g, m, source)]) for m in models
                       if (quantity, g, m, source) in values]
                if not pts:
                    continue
                x = np.array([m for m, _ in pts]) + 0.2 * (k - 1)
                ax.errorbar(x, [v[0] for _, v in pts], yerr=[v[1] for _, v in pts], fmt=marker,
                            color=colour, capsize=3, label=f"{quantity} {source} group {g}")
            ax.axhline(0.0, color="0.8", lw=0.8)
            ax.set_xticks(list(models))
            ax.set_xlabel("model")
            ax.set_title("(%s) Group %d" % ("abc"[g - 1], g) if row == 0 else "M, Group %d" % g, fontsize=9)
        axes[row][0].set_ylabel(unit)
    handles = [plt.Line2D([], [], marker=mk, color=c, ls="none", label=src) for src, mk, c in ELASTIC_SOURCES]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8)
    fig.suptitle("Fig. 5-27: E at the middle clip (σzz = 5 kPa), mean ± std over the 9 cubes, the "
                 "highest and lowest dropped; below, M, which the seed does not give", fontsize=9)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    return fig


# Figs 5-28 to 5-30, one per group: E and the Poisson ratios point by point
SEED_POINTS_FIGURE = {1: "5-28", 2: "5-29", 3: "5-30"}
ENGINE_LINES = {"jdem": "-", "liggghts-jdem": "--"}


def points_elastic_figure(cubes, group, points, models=range(1, 7)):
    """The open figure of Fig. 5-28, 5-29 or 5-30 for `group`, or None without data.
    cubes[(model, engine)] = [{"E", "nu_xy", "nu_xz"} per point of `points`]; each model's panel
    draws E on the left axis and νxy, νxz on the right, each engine in its ENGINE_LINES style.
    The lines carry the label "QUANTITY ENGINE model M" so that a test can read them back."""
    if not cubes:
        return None
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5), dpi=100)
    for ax, m in zip(axes.flat, models):
        right = ax.twinx()
        for engine, style in ENGINE_LINES.items():
            rows = cubes.get((m, engine))
            if not rows:
                continue
            ax.plot(points, [r["E"] for r in rows], style, marker="o", color="tab:blue", label=f"E {engine} model {m}")
            for key, colour, name in (("nu_xy", "tab:red", "νxy"), ("nu_xz", "tab:green", "νxz")):
                right.plot(points, [r[key] for r in rows], style, marker="s", ms=3, color=colour,
                           label=f"{name} {engine} model {m}")
        ax.set_title("Model %d" % m, fontsize=9)
        ax.set_xlabel("point (Table 5-2)")
        ax.set_ylabel("E [Pa]", color="tab:blue")
        right.set_ylabel("ν", color="0.3")
    handles = [plt.Line2D([], [], color=c, marker=mk, label=l) for l, c, mk in
               (("E", "tab:blue", "o"), ("νxy", "tab:red", "s"), ("νxz", "tab:green", "s"))] + \
              [plt.Line2D([], [], color="k", ls=st, label=e) for e, st in ENGINE_LINES.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8)
    fig.suptitle("Fig. %s: E and the Poisson ratios of the orthotropic fit at the middle clip, Group %d "
                 "(σzz = 5 kPa; the fit of a confined cube is ill-posed)" % (SEED_POINTS_FIGURE[group], group),
                 fontsize=9)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    return fig
