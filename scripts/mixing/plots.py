"""Pictures of the campaign (PNG, matplotlib): deposits and mixing parameters.

deposit_view: the front (x-z, looking along +y) or side (y-z, looking along -x) view of a
deposit, spheres to scale as circles coloured by cohort (the seed's red = big, blue = small),
the box and the cylinders drawn; `clip` keeps only the spheres cut by the middle plane y = 0.5
(the seed's "middle clip") or x = 0.5 for a side view.
strip_plot: one parameter at the points per model (Figs 4-11, 4-12): the values as dark
symbols on one vertical line per model, the seed's mean as a red square and its standard
deviation as a grey bar (stats.py), and the ideal phi_v as a red dashed line.
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402
from matplotlib.patches import Circle, Rectangle  # noqa: E402

from . import stats  # noqa: E402
from .params import big_mask  # noqa: E402

BIG_COLOUR, SMALL_COLOUR = "#d62728", "#1f4fb4"
VIEWS = {"front": (0, 2, 1), "side": (1, 2, 0)}  # (horizontal axis, vertical axis, depth axis)


def deposit_view(dep, path, view="front", box=((0, 0, 0), (1, 1, 2)), cylinders=(),
                 clip=None, title=None, threshold=None):
    """Write the view as PNG; returns the number of spheres drawn.  cylinders: (x, z, radius)
    of horizontal cylinders along y [m]; clip: half-thickness of the slab around the middle
    plane to keep (None: all spheres)."""
    h, v, depth = VIEWS[view]
    keep = np.ones(len(dep.radius), bool)
    if clip is not None:
        mid = 0.5 * (box[0][depth] + box[1][depth])
        keep = np.abs(dep.position[:, depth] - mid) <= dep.radius + clip
    big = big_mask(dep.radius, threshold)
    order = np.argsort(-dep.position[keep][:, depth] if view == "front" else dep.position[keep][:, depth])
    xy = dep.position[keep][:, [h, v]][order]
    d = 2.0 * dep.radius[keep][order]
    colours = np.where(big[keep][order], BIG_COLOUR, SMALL_COLOUR)
    lo, hi = box
    fig, ax = plt.subplots(figsize=(4, 7), dpi=100)
    ax.add_collection(EllipseCollection(d, d, np.zeros(len(d)), units="xy", offsets=xy,
                                        offset_transform=ax.transData, facecolors=colours,
                                        edgecolors="none"))
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
    ax.set_title(title or f"{view} view, t = {dep.time:g} s")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return int(len(d))


def strip_plot(values_by_model, path, name="phi_v", ideal=None, title=None):
    """values_by_model: {model label: the values at the points}.  Writes PNG; returns the number
    of point markers drawn."""
    fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
    drawn = 0
    for i, (label, values) in enumerate(values_by_model.items()):
        v = np.asarray(values, dtype=float)
        finite = v[np.isfinite(v)]
        ax.plot(np.full(len(finite), i), finite, "o", color="0.15", ms=4)
        drawn += len(finite)
        s = stats.summary(v)
        ax.errorbar(i + 0.15, s["mean"], yerr=s["std"], fmt="none", ecolor="0.6", elinewidth=6)
        ax.plot(i + 0.15, s["mean"], "s", color="red", ms=6)
    if ideal is not None:
        ax.axhline(ideal, color="red", ls="--", lw=1)
    ax.set_xticks(range(len(values_by_model)), list(values_by_model))
    ax.set_ylabel(name)
    ax.set_title(title or name)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return drawn
