"""claims_ch4.py — the seed's qualitative Chapter 4 conclusions, checked on the finished units
(report_ch4.py; docs/mixing.md §3).  Each check states its measure and says "held" or "not
held" with the numbers; a check whose units are not all finished is left out.

A claim that orders the models by their trimmed mean φv is weighed against the run-to-run
spread (agreement_ch4.spreads: the std s of one fill's realisations, the model's own or
pooled): a difference of two models' means counts only beyond 2 sqrt(s_a² + s_b²), two standard
deviations of the difference of two independent fills.  Within it the claim is "not resolved":
one fill per model cannot order them (docs/mixing.md §3).

found[engine][model] holds "fillP" (fill_result: per-point parameters, their trimmed summary and
the cohorts' sides) and "passP_cubes" (cube_result per cube) of report_ch4.py.
"""

import numpy as np

from scripts.mixing import agreement, agreement_ch4, params, stats
from scripts.mixing.agreement import UNMEASURED, UNRESOLVED, ordered

MODELS = tuple("model%d" % m for m in range(1, 7))
PASSES = (1, 2)


def verdict(ok):
    return "held" if ok else "not held"


def phi_spread(found):
    """model -> (s, source) of the trimmed mean phi_v over a fill's realisations, or None
    (agreement_ch4.spreads): the model's own, pooled over both engines' realisations of it, once
    it has two degrees of freedom, else the pool over every model; past the horizon the engines
    are realisations of one chaotic fill, so their spreads measure the same thing."""
    s = agreement_ch4.spreads(found)
    return lambda model: agreement.spread_for(s, model, "φv")


def phi_means(found, engine, p):
    """{model: trimmed mean of phi_v} of the finished fills of pass p."""
    return {m: found[engine][m]["fill%d" % p]["summary"]["phi_v"]["mean"]
            for m in MODELS if found[engine][m].get("fill%d" % p)}


def zero_phi(found, engine):
    """Models 1 and 2: "many zero or very small phi_v values" (below a tenth of the ideal)."""
    out = []
    for m in ("model1", "model2"):
        for p in PASSES:
            f = found[engine][m].get("fill%d" % p)
            if not f:
                continue
            small = sum(q["phi_v"] < agreement_ch4.SEGREGATED for q in f["points"])
            out.append("%s %s pass %d: \"many zero or very small φv values\" (below a tenth of the "
                       "ideal %.4f) at %d of the 9 points: %s"
                       % (engine, m, p, params.IDEAL_PHI_V, small, verdict(small >= 5)))
    return out


def model2_split(found, engine):
    """Model 2 splits the cohorts: most big spheres right of the cylinder (x > 0.5 m), most small
    ones left of it, in the first-pass deposit; and it mixes worst of the six."""
    f = found[engine]["model2"].get("fill1")
    if not f:
        return []
    side = f["sides"]
    out = ["%s model2 pass 1: big spheres to the right, small to the left: %.0f %% of the big "
           "spheres at x > 0.5 m, %.0f %% of the small at x < 0.5 m: %s"
           % (engine, 100 * side["big_right"], 100 * side["small_left"],
              verdict(side["big_right"] > 0.5 and side["small_left"] > 0.5))]
    phi = phi_means(found, engine, 1)
    if len(phi) == len(MODELS):
        text, margin = ordered(phi, phi_spread(found), [(m, "model2") for m in MODELS
                                                         if m != "model2"])
        out.append("%s pass 1: Model 2 mixes worst (trimmed mean φv per model: %s; %s): %s"
                   % (engine, ", ".join("%s %.4f" % (m[5:], phi[m]) for m in MODELS), margin,
                      text))
    return out


def obstacles_left(found, engine):
    """Obstacles shifted left (Models 3, 4) mix better than Models 1, 2; Model 5 slightly better
    than Model 3 (first pass, trimmed mean phi_v)."""
    phi, spread = phi_means(found, engine, 1), phi_spread(found)
    out = []
    if all(m in phi for m in ("model1", "model2", "model3", "model4")):
        text, margin = ordered(phi, spread, [(a, b) for a in ("model3", "model4")
                                             for b in ("model1", "model2")])
        out.append("%s pass 1: Models 3 and 4 mix better than 1 and 2 (φv %.4f, %.4f against "
                   "%.4f, %.4f; %s): %s" % (engine, phi["model3"], phi["model4"], phi["model1"],
                                            phi["model2"], margin, text))
    if "model3" in phi and "model5" in phi:
        text, margin = ordered(phi, spread, [("model5", "model3")])
        out.append("%s pass 1: Model 5 mixes slightly better than Model 3 (φv %.4f against %.4f; "
                   "%s): %s" % (engine, phi["model5"], phi["model3"], margin, text))
    return out


def second_pass(found, engine):
    """After the second pass the means agree across models (their spread across models shrinks)
    and the spread over the points shrinks in every model."""
    out = []
    one, two = phi_means(found, engine, 1), phi_means(found, engine, 2)
    both = [m for m in MODELS if m in one and m in two]
    if len(both) >= 2:
        a, b = np.std([one[m] for m in both], ddof=1), np.std([two[m] for m in both], ddof=1)
        # Noise alone scatters the models' means by about the run-to-run s of one mean, so a
        # change of their std within 2 s is not told from it (pass 1's s: pass 2 has no repeats).
        s = phi_spread(found)(None)
        text = UNMEASURED if not s else verdict(b < a) if abs(a - b) > 2.0 * s[0] else UNRESOLVED
        margin = "a change counts beyond 2 s = %.4f, s of pass 1" % (2.0 * s[0]) if s else \
            "no run-to-run spread measured"
        out.append("%s: after the second pass the models' means agree better (std of the %d "
                   "models' φv means %.4f → %.4f; %s): %s" % (engine, len(both), a, b, margin, text))
    pairs = [(found[engine][m]["fill1"]["summary"]["phi_v"]["std"],
              found[engine][m]["fill2"]["summary"]["phi_v"]["std"]) for m in both]
    if pairs:
        out.append("%s: the second pass reduces the spread of φv over the points: std %s: %s"
                   % (engine, "; ".join("%.4f → %.4f" % ab for ab in pairs),
                      verdict(all(b < a for a, b in pairs))))
    return out


def discrimination(found, engine, key, p):
    """Range of the models' trimmed means over the mean within-model std: above 1 the models
    are told apart by the parameter."""
    fills = [found[engine][m]["fill%d" % p]["summary"][key] for m in MODELS
             if found[engine][m].get("fill%d" % p)]
    if len(fills) < 2:
        return None
    means = [s["mean"] for s in fills]
    within = float(np.mean([s["std"] for s in fills]))
    return (max(means) - min(means)) / within if within > 0 else float("inf")


def phi_discriminates(found, engine):
    """phi_v tells the models apart, rho_b and Z do not (index of discrimination())."""
    d = {k: discrimination(found, engine, k, 1) for k in ("phi_v", "rho_b", "Z")}
    if d["phi_v"] is None:
        return []
    ok = d["phi_v"] > 1 and d["rho_b"] < 1 and d["Z"] < 1
    n = sum(1 for m in MODELS if found[engine][m].get("fill1"))
    return ["%s pass 1, %d of 6 models: φv discriminates, ρb and Z do not (range of the model means "
            "over the mean std within a model: φv %.2f, ρb %.2f, Z %.2f; above 1 discriminates): %s"
            % (engine, n, d["phi_v"], d["rho_b"], d["Z"], verdict(ok))]


def poisson_anisotropy(found, engine):
    """nu_xy is more than twice nu_xz (trimmed means of the cubes of one deposit)."""
    out = []
    for m in MODELS:
        for p in PASSES:
            cubes = found[engine][m].get("pass%d_cubes" % p)
            if not cubes:
                continue
            xy = stats.summary([c["nu_xy"] for c in cubes])["mean"]
            xz = stats.summary([c["nu_xz"] for c in cubes])["mean"]
            out.append("%s %s pass %d: νxy > 2 νxz (%.3f against %.3f; the orthotropic fit of a "
                       "laterally confined cube, docs/model.md §10): %s"
                       % (engine, m, p, xy, xz, verdict(xy > 2 * xz)))
    return out


CHECKS = (zero_phi, model2_split, obstacles_left, second_pass, phi_discriminates,
          poisson_anisotropy)


def claims(found, engines):
    lines = ["- " + line for e in engines for check in CHECKS for line in check(found, e)]
    return ("\n".join(lines) + "\n") if lines else \
        "No claim can be checked with the units finished so far.\n"
