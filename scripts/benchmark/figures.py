"""One figure per test: the measured values of both engines against the references."""
import math
import os
import re

import matplotlib
import numpy as np

from .cases import ENGINE_LABEL, TITLES, material_of
from .references import (JIANG2021_RESTITUTION, hertz_closed_form, hertz_effective,
                         hertz_force_history, published_curve, rigid_body_limit)
from .trajectory import (contact_interval, normal_force, oblique_quantities, overlap,
                         pair_coefficient, pre_post)

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

MARKERS = {"jdem": "o", "liggghts": "x"}


def values_of(records, test, metric, engine, case_filter=lambda c: True):
    """{case: record} of one metric."""
    return {r["case"]: r for r in records if r["test"] == test and r["metric"] == metric
            and r["engine"] == engine and case_filter(r["case"])}


def plot_hertz(test, runs, ax_fd, ax_ft):
    for (t, case, engine), run in sorted(runs.items()):
        if t != test:
            continue
        f_n = normal_force(run)
        on = f_n > 0
        label = f"{case} ({ENGINE_LABEL[engine]})"
        ax_fd.plot(overlap(run)[on] * 1e6, f_n[on] / 1e3, MARKERS[engine], ms=2, label=label)
        t_on, _ = contact_interval(run, f_n)
        ax_ft.plot((run.time[on] - t_on) * 1e6, f_n[on] / 1e3, MARKERS[engine], ms=2, label=label)
        if engine == "jdem":
            e_star, r_star, m_star = hertz_effective(run)
            pre, _ = pre_post(run)
            delta, _, _ = hertz_closed_form(e_star, r_star, m_star, pre["V_cn"])
            d = np.linspace(0, delta, 200)
            ax_fd.plot(d * 1e6, 4 / 3 * e_star * math.sqrt(r_star) * d ** 1.5 / 1e3, "k-", lw=1,
                       label=f"Hertz ({case})")
            th, fh = hertz_force_history(e_star, r_star, m_star, pre["V_cn"])
            ax_ft.plot(th * 1e6, fh / 1e3, "k-", lw=1, label=f"Hertz ({case})")
    ax_fd.set(xlabel="overlap δ [µm]", ylabel="normal force F_n [kN]", title="force–overlap")
    ax_ft.set(xlabel="time since first contact [µs]", ylabel="normal force F_n [kN]",
              title="force–time")


def figure_test12(test, records, runs, engines):
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.5))
    plot_hertz(test, runs, a, b)
    return fig, (a, b)


def figure_test3(test, records, runs, engines):
    fig, ax = plt.subplots(figsize=(6.5, 5.5))
    for engine in engines:
        for damping, marker in (("jiang2021", MARKERS[engine]), ("exact", "s" if engine == "jdem" else "+")):
            for mat in ("al_oxide", "cast_iron"):
                sel = values_of(records, test, "e_n", engine,
                                lambda c: c.startswith(mat) and c.endswith(damping))
                e_in = [int(re.search(r"_e(\d{3})_", c).group(1)) / 100 for c in sel]
                ax.plot(e_in, [r["value"] for r in sel.values()], marker, mfc="none",
                        label=f"{mat}, {damping} ({ENGINE_LABEL[engine]})")
    ax.plot([0, 1], [0, 1], "k-", lw=1, label="y = x (exact restitution)")
    tab = sorted(JIANG2021_RESTITUTION.items())
    ax.plot([k for k, _ in tab], [v for _, v in tab], "k^--", mfc="none", lw=0.8,
            label="jiang2021, spec table (F_n = 0 end)")
    ax.set(xlabel="input restitution e [-]", ylabel="output e_n = V'_cn/V_cn [-]")
    return fig, (ax,)


def mean_e_n(records, test):
    """Mean measured e_n of a test (the limit curves of the figures use it)."""
    return float(np.mean([r["value"] for r in records if r["test"] == test and r["metric"] == "e_n"]))


def first_run(runs, test):
    return next(run for (t, _, _), run in sorted(runs.items()) if t == test)


def figure_test4(test, records, runs, engines):
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.5))
    specs = [("e_t", "tangential restitution e_t = V'_ct/V_ct [-]"),
             ("w_post", "rebound spin ω' about n×t [rad/s]"),
             ("rebound_angle_deg", "contact-point rebound angle φ [deg]")]
    e_n = mean_e_n(records, test)
    run = first_run(runs, test)
    mu, v, radius = pair_coefficient(run, "friction"), np.linalg.norm(run.v[0, 0]), run.radius[0]
    theta = np.radians(np.linspace(1, 89, 300))
    for ax, (metric, label) in zip(axs, specs):
        for engine in engines:
            for mat in ("al_oxide", "al_alloy"):
                sel = values_of(records, test, metric, engine, lambda c: material_of(c) == mat)
                ang = [int(c[-2:]) for c in sel]
                ax.plot(ang, [r["value"] for r in sel.values()], MARKERS[engine], mfc="none",
                        label=f"{mat} ({ENGINE_LABEL[engine]})")
        lim = {"sliding": [], "stick": []}
        for th in theta:
            pre = {"V_cn": v * math.cos(th), "V_ct": v * math.sin(th), "w": 0.0,
                   "V_st": v * math.sin(th)}
            for regime in lim:
                q = oblique_quantities(pre, rigid_body_limit(pre, e_n, mu, 1.0, math.inf, radius,
                                                             regime), mu, radius)
                lim[regime].append(q[metric])
        ax.plot(np.degrees(theta), lim["sliding"], "k-", lw=1, label=f"rigid body, sliding (e_n = {e_n:.3f})")
        ax.plot(np.degrees(theta), lim["stick"], "k:", lw=1, label="rigid body, stick")
        ax.axvline(math.degrees(math.atan(3.5 * mu * (1 + e_n))), color="grey", lw=0.5)
        ax.set(xlabel="incident angle θ [deg]", ylabel=label)
    axs[0].set_ylim(0, 1.1)
    return fig, axs


def figure_test5(test, records, runs, engines):
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.5))
    psi = np.linspace(0, 32, 400)
    for ax, metric, label, slide, stick in (
            (axs[0], "psi2", "normalized recoil angle V'_st/(μV'_cn) [-]", psi - 7, 0 * psi),
            (axs[1], "spin_norm", "normalized spin Rω'/(μV_cn) [-]", -5 + 0 * psi, -5 / 7 * psi)):
        for engine in engines:
            for mat in ("steel", "polyethylene"):
                sel = values_of(records, test, metric, engine, lambda c: material_of(c) == mat)
                x = [float(c.split("psi")[1].replace("p", ".")) for c in sel]
                ax.plot(x, [r["value"] for r in sel.values()], MARKERS[engine], mfc="none",
                        label=f"{mat} ({ENGINE_LABEL[engine]})")
        for mat, style in (("steel", "b--"), ("polyethylene", "r--")):
            curve = published_curve(test, "recoil" if metric == "psi2" else "spin", mat)
            if curve is not None:
                ax.plot(*curve, style, lw=0.8, label=f"Chung & Ooi (2011), {mat} (digitized)")
        ax.plot(psi, np.where(psi >= 7, slide, np.nan), "k-", lw=1, label="rigid body, sliding (e_n = 1)")
        ax.plot(psi, np.where(psi < 7, stick, np.nan), "k:", lw=1, label="rigid body, stick")
        ax.set(xlabel="normalized incident angle Ψ1 = V_st/(μV_cn) [-]", ylabel=label)
    return fig, axs


def figure_test68(test, records, runs, engines):
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.5))
    for engine in engines:
        xs = values_of(records, test, "X", engine)
        tans = values_of(records, test, "tan_incident", engine)
        for metric, ax in (("beta", axs[0]), ("tan_recoil", axs[1])):
            sel = values_of(records, test, metric, engine)
            for mat in sorted({material_of(c) for c in sel}):
                cases = [c for c in sel if material_of(c) == mat and c in xs]
                xv = [(xs if metric == "beta" else tans)[c]["value"] for c in cases]
                ax.plot(xv, [sel[c]["value"] for c in cases], MARKERS[engine], mfc="none",
                        label=f"{mat} ({ENGINE_LABEL[engine]})")
    e_n = mean_e_n(records, test)
    k = 3.5 * pair_coefficient(first_run(runs, test), "friction") * (1 + e_n)
    x = np.linspace(0.05, 26, 600)
    axs[0].plot(x, np.where(x < 1, x - 1, 0.0), "k-", lw=1, label=f"rigid body (e_n = {e_n:.3f})")
    axs[0].set(xscale="log", xlabel="3.5μ(1+e_n)V_cn/V_st [-]", ylabel="β = −V'_st/V_st [-]")
    tan_in = np.linspace(0, 12, 400)
    axs[1].plot(tan_in, np.where(tan_in > k, (tan_in - k) / e_n, 0.0), "k-", lw=1,
                label=f"rigid body (e_n = {e_n:.3f})")
    axs[1].set(xlabel="tangent of incident angle V_st/V_cn [-]",
               ylabel="tangent of recoil angle V'_st/V'_cn [-]", xlim=(0, 12))
    return fig, axs


def figure_test7(test, records, runs, engines):
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.5))
    for engine in engines:
        for metric, ax in (("V_ct_post", axs[0]), ("w_post", axs[1])):
            sel = values_of(records, test, metric, engine)
            for mat in sorted({material_of(c) for c in sel}):
                cases = [c for c in sel if material_of(c) == mat]
                w = [float(c.split("omega")[1].replace("p", ".")) for c in cases]
                ax.plot(w, [sel[c]["value"] for c in cases], MARKERS[engine], mfc="none",
                        label=f"{mat} ({ENGINE_LABEL[engine]})")
    w = np.linspace(0, 23, 10)
    axs[0].plot(w, 0 * w, "k-", lw=1, label="reference: V'_ct = 0")
    axs[1].plot(w, w, "k-", lw=1, label="reference: ω' = ω")
    axs[0].set(xlabel="pre-collision spin ω [rad/s]", ylabel="post-collision V'_ct of sphere 1 [m/s]")
    axs[1].set(xlabel="pre-collision spin ω [rad/s]", ylabel="post-collision spin ω' [rad/s]")
    return fig, axs


FIGURES = {1: figure_test12, 2: figure_test12, 3: figure_test3, 4: figure_test4, 5: figure_test5,
           6: figure_test68, 7: figure_test7, 8: figure_test68}


def write_figure(out, test, records, runs, engines):
    fig, axs = FIGURES[test](test, records, runs, engines)
    for ax in axs:
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=6)
    fig.suptitle(TITLES[test])
    fig.tight_layout()
    path = os.path.join(out, f"test{test}.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return os.path.basename(path)
