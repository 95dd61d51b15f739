#!/usr/bin/python3
"""The campaign's pictures (scripts/mixing/plots.py), checked for content: the number of objects
drawn, and the pixel fractions of the cohort colours, the obstacle and the ideal line; the
Figs 4-11/4-12 figure read back from its matplotlib objects against the summary it was drawn
from."""
import math
import os
import tempfile

import matplotlib.image as mpimg
import numpy as np

from tests.mixing.common import check, close, finish
from scripts.mixing import deposit, plots


def colour_fraction(img, hex_colour, tol=0.08):
    rgb = np.array([int(hex_colour[i:i + 2], 16) / 255 for i in (1, 3, 5)])
    return float(np.mean(np.all(np.abs(img[:, :, :3] - rgb) < tol, axis=2)))


def synthetic_deposit():
    """A 0.3 m deep simple-cubic bed of small spheres over the 1 x 1 m floor with a layer of
    big ones on top of its left half."""
    rs, rb = 0.015, 0.03
    g = np.arange(0.015, 1.0, 0.03)
    xs = np.array([[x, y, z] for x in g for y in g for z in np.arange(0.015, 0.3, 0.03)])
    gb = np.arange(0.03, 0.5, 0.06)
    xb = np.array([[x, y, 0.33] for x in gb for y in np.arange(0.03, 1.0, 0.06)])
    x = np.vstack([xs, xb])
    r = np.concatenate([np.full(len(xs), rs), np.full(len(xb), rb)])
    n = len(r)
    return deposit.Deposit(np.arange(1, n + 1), (r > 0.02).astype(np.int32), r,
                           4000 * 4 / 3 * math.pi * r ** 3, x, time=11.0), len(xs), len(xb)


def test_views(tmp):
    dep, n_small, n_big = synthetic_deposit()
    cyl = [(0.5, 1.2, 0.05)]
    front = os.path.join(tmp, "front.png")
    drawn = plots.deposit_view(dep, front, "front", cylinders=cyl)
    check("front_draws_every_sphere", drawn == n_small + n_big, f"{drawn} of {n_small + n_big}")
    img = mpimg.imread(front)
    red, blue = colour_fraction(img, plots.BIG_COLOUR), colour_fraction(img, plots.SMALL_COLOUR)
    # the bed covers 1 x 0.3 m and the big layer 0.5 x 0.06 m of the 1.1 x 2.1 m frame
    check("front_has_both_cohorts", blue > 0.05 and red > 0.003, f"blue {blue:.4f}, red {red:.4f}")
    check("front_small_cover_more", blue > 3 * red, f"blue {blue:.4f}, red {red:.4f}")
    grey = colour_fraction(img, "#666666")
    check("front_draws_the_cylinder", grey > 0.001, f"grey fraction {grey:.5f}")
    clip = os.path.join(tmp, "clip.png")
    drawn = plots.deposit_view(dep, clip, "front", cylinders=cyl, clip=0.0)
    cut = int(np.count_nonzero(np.abs(dep.position[:, 1] - 0.5) <= dep.radius))
    check("middle_clip_draws_the_cut_spheres", drawn == cut and 0 < cut < len(dep.radius),
          f"{drawn} drawn, {cut} cut by y = 0.5")
    side = os.path.join(tmp, "side.png")
    plots.deposit_view(dep, side, "side", cylinders=cyl)
    img = mpimg.imread(side)
    check("side_not_blank", colour_fraction(img, plots.SMALL_COLOUR) > 0.05, "no small spheres")


def test_strip_plot(tmp):
    rng = np.random.default_rng(1)
    values = {f"M{m}": rng.uniform(0, 0.4, 9) for m in range(1, 7)}
    values["M2"][3] = float("nan")  # a point without small spheres is left out
    path = os.path.join(tmp, "phi_v.png")
    drawn = plots.strip_plot(values, path, ideal=0.0625)
    check("strip_plot_markers", drawn == 53, f"{drawn} markers for 53 finite values")
    img = mpimg.imread(path)
    red = float(np.mean((img[:, :, 0] > 0.9) & (img[:, :, 1] < 0.2) & (img[:, :, 2] < 0.2)))
    check("strip_plot_mean_and_ideal_line", red > 0.001, f"red fraction {red:.5f}")
    check("strip_plot_not_blank", float(img[:, :, :3].std()) > 0.05, "uniform image")


def hand_results():
    """summary.json's results for jdem pass 1: Models 1 and 3 (a point of Model 3 without small
    spheres: phi_v infinite), no Model 2, no second pass."""
    rng = np.random.default_rng(2)
    keys = [k for k, _ in plots.FIGURE_PANELS]
    fill = lambda: {"points": [{k: float(v) for k, v in zip(keys, rng.uniform(0, 1, 6))}
                               for _ in range(9)]}
    results = {"jdem": {"model3": {"fill1": fill()}, "model1": {"fill1": fill()},
                        "model2": {"times": {}}}}
    results["jdem"]["model3"]["fill1"]["points"][2]["phi_v"] = float("inf")
    return results


def trimmed(values):
    """The seed's mean of 7 of 9 and the std of the same 7, by hand."""
    kept = sorted(v for v in values if not math.isnan(v))[1:-1]
    mean = sum(kept) / len(kept)
    return mean, math.sqrt(sum((v - mean) ** 2 for v in kept) / (len(kept) - 1))


def artist(ax, label):
    found = [a for a in list(ax.lines) + list(ax.containers) if a.get_label() == label]
    return found[0] if len(found) == 1 else None


def test_mixing_figure():
    results = hand_results()
    fig = plots.mixing_figure(results, "jdem", 1)
    axes = fig.axes
    check("figure_has_six_panels", len(axes) == 6, f"{len(axes)} axes")
    for ax, (key, _) in zip(axes, plots.FIGURE_PANELS):
        ticks = [t.get_text() for t in ax.get_xticklabels()]
        check(f"figure_{key}_models_in_order", ticks == ["1", "3"], f"{ticks}")
        for i, m in enumerate(("1", "3")):
            values = [q[key] for q in results["jdem"]["model" + m]["fill1"]["points"]]
            pts = artist(ax, "points " + m)
            finite = [v for v in values if math.isfinite(v)]
            check(f"figure_{key}_model{m}_points", pts is not None
                  and list(pts.get_ydata()) == finite and set(pts.get_xdata()) == {i},
                  f"{None if pts is None else list(pts.get_ydata())} vs {finite}")
            # phi_v = inf is the highest value: the trimmed mean drops it (stats.py)
            mean, std = trimmed([v if math.isfinite(v) else float("inf") for v in values])
            sq = artist(ax, "mean " + m)
            close(f"figure_{key}_model{m}_mean", float(sq.get_ydata()[0]), mean, 1e-12)
            bar = artist(ax, "std " + m).lines[2][0].get_segments()[0]
            close(f"figure_{key}_model{m}_std_low", float(bar[0][1]), mean - std, 1e-12)
            close(f"figure_{key}_model{m}_std_high", float(bar[1][1]), mean + std, 1e-12)
        ideal = artist(ax, "ideal")
        if key == "phi_v":
            close("figure_ideal_phi_v", float(ideal.get_ydata()[0]), 0.0625, 1e-15)
        else:
            check(f"figure_{key}_no_ideal_line", ideal is None)
    plots.plt.close(fig)
    check("figure_none_without_second_pass", plots.mixing_figure(results, "jdem", 2) is None)
    written = plots.write_mixing_figures(results, ("jdem", "liggghts-jdem"), tmp)
    check("figures_written", written == {("jdem", 1): "fig4-11_jdem.png"}
          and os.path.getsize(os.path.join(tmp, "fig4-11_jdem.png")) > 10000, f"{written}")


def test_bonded_figure(tmp):
    """Fig. 5-25 (Group 2) of jdem from Models 1 and 4 (Model 4's point 14, in the middle clip,
    without small spheres); Group 1 has no fill."""
    rng = np.random.default_rng(5)
    found = {"jdem/group2_model4": {"phi_v": [float(v) for v in rng.uniform(0, 0.2, 27)]},
             "jdem/group2_model1": {"phi_v": [float(v) for v in rng.uniform(0, 0.2, 27)]},
             "liggghts-jdem/group3_model2": {"phi_v": [float(v) for v in rng.uniform(0, 0.2, 27)]}}
    found["jdem/group2_model4"]["phi_v"][13] = float("inf")
    fig = plots.bonded_figure(found, "jdem", 2)
    axes = fig.axes
    check("bonded_figure_has_four_panels", len(axes) == 4, f"{len(axes)} axes")
    # (a) the rows y = 0.25, 0.5, 0.75 (points 1-9, 10-18, 19-27), (b) the middle clip
    for ax, (lo, hi) in zip(axes, ((0, 9), (9, 18), (18, 27), (9, 18))):
        ticks = [t.get_text() for t in ax.get_xticklabels()]
        check(f"bonded_figure_points{lo + 1}_models_in_order", ticks == ["1", "4"], f"{ticks}")
        for i, m in enumerate(("1", "4")):
            values = found["jdem/group2_model" + m]["phi_v"][lo:hi]
            pts = artist(ax, "points " + m)
            finite = [v for v in values if math.isfinite(v)]
            check(f"bonded_figure_points{lo + 1}_model{m}", pts is not None
                  and list(pts.get_ydata()) == finite and set(pts.get_xdata()) == {i},
                  f"{None if pts is None else list(pts.get_ydata())} vs {finite}")
            mean, std = trimmed(values)
            close(f"bonded_figure_points{lo + 1}_model{m}_mean",
                  float(artist(ax, "mean " + m).get_ydata()[0]), mean, 1e-12)
            bar = artist(ax, "std " + m).lines[2][0].get_segments()[0]
            close(f"bonded_figure_points{lo + 1}_model{m}_std", float(bar[1][1]) - float(bar[0][1]),
                  2 * std, 1e-12)
        close(f"bonded_figure_points{lo + 1}_ideal", float(artist(ax, "ideal").get_ydata()[0]),
              0.0625, 1e-15)
    plots.plt.close(fig)
    check("bonded_figure_none_without_fills", plots.bonded_figure(found, "jdem", 1) is None)
    written = plots.write_bonded_figures(found, ("jdem", "liggghts-jdem"), [tmp])
    check("bonded_figures_written", written == {("jdem", 2): "fig5-25_jdem.png",
                                                ("liggghts-jdem", 3): "fig5-26_liggghts-jdem.png"}
          and os.path.getsize(os.path.join(tmp, "fig5-25_jdem.png")) > 10000, f"{written}")


tmp = tempfile.mkdtemp()
test_views(tmp)
test_strip_plot(tmp)
test_mixing_figure()
test_bonded_figure(tmp)
finish()
