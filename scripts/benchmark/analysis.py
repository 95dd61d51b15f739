"""Metrics: one summary record per trajectory, metric and engine, with its reference and error."""
import math
import os

import numpy as np

from scripts import compare_trajectories
from .cases import ROOT, material_of, selected_cases, trajectory_path
from .references import (JIANG2021_RESTITUTION, hertz_closed_form, hertz_effective, lever_arm,
                         published_curve, rigid_body_limit, sliding_parameter)
from .trajectory import (Run, contact_interval, normal_force, oblique_quantities, overlap,
                         pair_coefficient, pre_post)

TOL_HERTZ = 0.005        # T1/T2 peak force, peak overlap, contact duration vs closed-form Hertz
TOL_RESTITUTION = 0.01   # T3 (and e_n of T6-T8) vs input e / the spec's table
TOL_LIMIT = 0.01         # gross-sliding rigid-body limits (T4, T5, T6, T8)
TOL_ENERGY = 1e-3        # energy balance of every impact
TOL_GAIN = 1e-6          # KE+RE after/before - 1 allowed: the velocity-Verlet energy error of an
                         # elastic impact, O((dt/t_c)^2), is ~1e-8 at the scenes' >= 1000 steps
TOL_SYMMETRY = 1e-9      # T7 mirror symmetry: round-off only
SLIDING_MARGIN = 1.25    # gross sliding asserted for X = 3.5 mu (1+e_n) V_cn/V_st <= 1/1.25,
                         # rigid stick reported for X >= 1.25, transition in between


def regime_of(x):
    if x <= 1.0 / SLIDING_MARGIN:
        return "sliding"
    if x >= SLIDING_MARGIN:
        return "stick"
    return "transition"


def record(test, case, engine, metric, value, reference, tolerance=None, note="", one_sided=False):
    """One summary record.  rel_error is relative to |reference|, absolute when it is 0;
    one_sided: only value > reference counts as error."""
    value = float(value)
    if reference is None:
        err = None
    else:
        diff = max(0.0, value - reference) if one_sided else abs(value - reference)
        err = diff / abs(reference) if reference != 0 else diff
    ok = None if tolerance is None or err is None else bool(err <= tolerance)
    return {"test": test, "case": case, "engine": engine, "metric": metric, "value": value,
            "reference": None if reference is None else float(reference), "rel_error": err,
            "tolerance": tolerance, "pass": ok, "note": note}


def energy_records(run, test, case, engine):
    """Energy balance and no-gain checks of one impact, and that the contact has ended."""
    obs = run.obs
    start = obs["kinetic_energy"][0] + obs["rotational_energy"][0]
    end = obs["kinetic_energy"][-1] + obs["rotational_energy"][-1]
    closed = (end + obs["elastic_energy"][-1] + obs["damping_dissipation"][-1]
              + obs["friction_dissipation"][-1])
    return [
        record(test, case, engine, "energy_balance", closed / start, 1.0, TOL_ENERGY,
               "(KE+RE+elastic at the end + damping + friction dissipation) / initial KE+RE"),
        record(test, case, engine, "energy_gain", end / start, 1.0, TOL_GAIN,
               "final/initial KE+RE; one-sided: must not exceed 1", one_sided=True),
        record(test, case, engine, "force_at_end", np.abs(run.force[-1, 0]).max(), 0.0, 0.0,
               "sphere 1 force at the last frame [N]: post values are post-collision"),
    ]


def analyse_hertz(run, test, case, engine):
    e_star, r_star, m_star = hertz_effective(run)
    pre, _ = pre_post(run)
    delta_ref, force_ref, tc_ref = hertz_closed_form(e_star, r_star, m_star, pre["V_cn"])
    f_n = normal_force(run)
    t_on, t_off = contact_interval(run, f_n)
    note = f"closed-form Hertz, E* = {e_star:.4g} Pa, R* = {r_star:.4g} m, m* = {m_star:.4g} kg"
    return [record(test, case, engine, "peak_force", f_n.max(), force_ref, TOL_HERTZ, note),
            record(test, case, engine, "peak_overlap", overlap(run).max(), delta_ref, TOL_HERTZ, note),
            record(test, case, engine, "contact_duration", t_off - t_on, tc_ref, TOL_HERTZ,
                   note + "; F_n > 0 from onset to end, interpolated")]


def analyse_restitution(run, test, case, engine):
    pre, post = pre_post(run)
    e_in = pair_coefficient(run, "restitution")
    return [e_n_record(test, case, engine, post["V_cn"] / pre["V_cn"], e_in, run)]


def limit_records(test, case, engine, quantities, measured, limits, regime, x, lever):
    """Compare measured quantities with the limit; asserted only in gross sliding.  limits holds
    the limit with the contact's lever arm and the rigid one (lever 1), which is noted."""
    tol = TOL_LIMIT if regime == "sliding" else None
    kind = "sliding" if regime == "transition" else regime
    note = (f"{kind} limit, X = {x:.3f} (regime {regime}), measured e_n, lever arm "
            f"{lever:.5f} R")
    return [record(test, case, engine, q, measured[q], limits[0][q], tol,
                   note + f"; rigid-body limit (lever R): {limits[1][q]:.6g}") for q in quantities]


def analyse_oblique(run, test, case, engine):
    """Tests 4, 5, 6, 8: e_n, and the tangential outcome against the rigid-body limits."""
    pre, post = pre_post(run)
    mu = pair_coefficient(run, "friction")
    e_in = pair_coefficient(run, "restitution")
    e_n = post["V_cn"] / pre["V_cn"]
    m1 = run.mass[0]
    m2 = run.mass[1] if run.two_spheres else math.inf
    r1 = run.radius[0]
    x = sliding_parameter(pre, e_n, mu)
    regime = regime_of(x)
    measured = oblique_quantities(pre, post, mu, r1)
    lever = lever_arm(run, pre["V_cn"])
    kind = "stick" if regime == "stick" else "sliding"
    limits = [oblique_quantities(pre, rigid_body_limit(pre, e_n, mu, m1, m2, r1, kind, arm), mu, r1)
              for arm in (lever, 1.0)]
    quantities = {4: ["e_t", "w_post", "rebound_angle_deg"], 5: ["psi2", "spin_norm"],
                  6: ["beta", "tan_recoil", "w_post", "V_ct_post"],
                  8: ["beta", "tan_recoil", "w_post", "V_ct_post"]}[test]
    recs = limit_records(test, case, engine, quantities, measured, limits, regime, x, lever)
    recs += [record(test, case, engine, "X", x, None, None, "3.5 mu (1+e_n) V_cn/V_st"),
             record(test, case, engine, "tan_incident", pre["V_st"] / pre["V_cn"], None, None,
                    "V_st/V_cn"),
             e_n_record(test, case, engine, e_n, e_in, run)]
    if test == 5:
        recs += published_records(test, case, engine, pre["V_st"] / (mu * pre["V_cn"]), measured)
    return recs


def published_records(test, case, engine, psi1, measured):
    """Test 5: measured Psi2 and spin against the paper's digitized curves (reported only: the
    curves are third-party digitizations)."""
    recs = []
    for quantity, metric in (("recoil", "psi2"), ("spin", "spin_norm")):
        curve = published_curve(test, quantity, material_of(case))
        if curve is None or not curve[0][0] <= psi1 <= curve[0][-1]:
            continue
        recs.append(record(test, case, engine, f"{metric}_vs_paper", measured[metric],
                           np.interp(psi1, *curve), None,
                           "Chung & Ooi (2011) figure, digitized (reference_runs/chung_ooi/published)"))
    return recs


def e_n_record(test, case, engine, e_n, e_in, run):
    """e_n against its reference: e_in for exact_restitution, the spec's table for jiang2021
    when the input e is tabulated; otherwise reported only."""
    damping = run.scene.get("model", {}).get("damping", "jiang2021")
    key = round(e_in, 1)
    if damping == "exact_restitution":
        return record(test, case, engine, "e_n", e_n, e_in, TOL_RESTITUTION,
                      f"input e = {e_in:g}; exact_restitution: e_out = e_in")
    if damping == "jiang2021" and abs(e_in - key) < 1e-12 and key in JIANG2021_RESTITUTION:
        return record(test, case, engine, "e_n", e_n, JIANG2021_RESTITUTION[key], TOL_RESTITUTION,
                      f"input e = {e_in:g}; jiang2021: jiang_model.md 13.4 Test 3 table")
    return record(test, case, engine, "e_n", e_n, None, None, f"input e = {e_in:g} ({damping})")


def analyse_mirror(run, test, case, engine):
    """Test 7: mirror-symmetric spins give zero slip: w' = w, V'_ct = 0."""
    pre, post = pre_post(run)
    e_in = pair_coefficient(run, "restitution")
    return [record(test, case, engine, "w_post/w", post["w"] / pre["w"], 1.0, TOL_SYMMETRY,
                   "mirror symmetry: no tangential force"),
            record(test, case, engine, "V_ct_post/V_cn", post["V_ct"] / pre["V_cn"], 0.0, TOL_SYMMETRY,
                   "mirror symmetry: no tangential force (absolute error)"),
            record(test, case, engine, "w_post", post["w"], pre["w"], None, "pre-collision w"),
            record(test, case, engine, "V_ct_post", post["V_ct"], None, None, ""),
            e_n_record(test, case, engine, post["V_cn"] / pre["V_cn"], e_in, run)]


ANALYSES = {1: analyse_hertz, 2: analyse_hertz, 3: analyse_restitution, 4: analyse_oblique,
            5: analyse_oblique, 6: analyse_oblique, 7: analyse_mirror, 8: analyse_oblique}


def analyse_all(out, tests, engines, quick, timings):
    """Records of every trajectory present, plus run wall times; and the loaded runs for plots."""
    records, runs = [], {}
    for test in tests:
        for case in selected_cases(test, quick):
            for engine in engines:
                path = trajectory_path(out, test, case, engine)
                if not os.path.exists(path):
                    records.append(record(test, case, engine, "trajectory_present", 0, 1, 0.0,
                                          f"missing {os.path.relpath(path, ROOT)}"))
                    continue
                try:
                    run = Run(path)
                    found = ANALYSES[test](run, test, case, engine) + \
                        energy_records(run, test, case, engine)
                except KeyError as missing:
                    records.append(record(test, case, engine, "trajectory_complete", 0, 1, 0.0,
                                          f"{os.path.relpath(path, ROOT)} lacks {missing}"))
                    continue
                runs[(test, case, engine)] = run
                records += found
    records += engine_difference_records(out, tests, engines, quick)
    for t in timings:
        records.append(record(t["test"], t["case"], t["engine"], "run_wall_time_s", t["seconds"],
                              None, None, f"exit status {t['status']}"))
    return records, runs


ENGINE_TOLERANCE = 1e-10  # the two engines run the same kernel in the same order


def engine_difference_records(out, tests, engines, quick):
    """The whole trajectories of the two engines, frame by frame: the largest difference of any
    field or observable, scaled as scripts/compare_trajectories.py documents."""
    if set(engines) != {"jdem", "liggghts"}:
        return []
    recs = []
    for test in tests:
        for case in selected_cases(test, quick):
            a, b = (trajectory_path(out, test, case, e) for e in ("jdem", "liggghts"))
            if not (os.path.exists(a) and os.path.exists(b)):
                continue
            try:
                worst = compare_trajectories.compare(a, b)["worst"]
            except compare_trajectories.Unusable as e:
                worst, note = math.inf, str(e)
            else:
                note = "whole trajectory, every field and observable, scaled"
            recs.append(record(test, case, "jdem-vs-liggghts", "engine_difference", worst, 0.0,
                               ENGINE_TOLERANCE, note))
    return recs
