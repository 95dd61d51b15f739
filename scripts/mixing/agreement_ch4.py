"""agreement_ch4.py — the two engines' deposits against the run-to-run spread (report_ch4.py;
the deposit statistics must agree within the measured run-to-run spread), by agreement.py's rule.

For every model and pass with both engines' fill, each statistic's difference is set against
2 sqrt(2) s, s the std over the realisations of the model's first fill (the first fill and its
jittered repeats, generate.py --jitter): the model's own where it has two degrees of freedom,
else pooled over every model's realisations (one jittered fill of each model, two of Model 3 in
each engine).  φv is floored at a tenth of the ideal: Model 1's realisations all separate the
cohorts and measure no φv spread.  The height is the bed's mean surface height
(structure.free_surface), which the same 41280 spheres set through their packing in every model,
so it pools like the intensive statistics (phi_v, packing fraction, rho_b, Z); the highest
sphere's top is not compared: a sphere resting on an obstacle sets it (Model 3's first two
realisations: 1.580 and 1.110 m).  A fill computed before the bed height was kept has none: its
row says so.
"""
from scripts.mixing import agreement, params
from scripts.mixing.agreement import Statistic

MODELS = tuple("model%d" % m for m in range(1, 7))
SEGREGATED = 0.1 * params.IDEAL_PHI_V   # φv of a realisation that separates the cohorts (claims_ch4)
PASSES = (1, 2)
# packing fraction = 1 - n (porosity)
STATISTICS = (Statistic("bed height [m]", lambda r: r.get("bed_height"), "%.3f"),
              Statistic("φv", lambda r: r["summary"]["phi_v"]["mean"], "%.4f",
                        lambda r: r["summary"]["phi_v"]["mean"] < SEGREGATED),
              Statistic("packing fraction", lambda r: 1.0 - r["summary"]["n"]["mean"], "%.4f"),
              Statistic("ρb [kg/m³]", lambda r: r["summary"]["rho_b"]["mean"], "%.0f"),
              Statistic("Z", lambda r: r["summary"]["Z"]["mean"], "%.3f"))


def realisations(entry):
    """The first fill and its jittered realisations of one engine and model."""
    return ([entry["fill1"]] if entry.get("fill1") else []) + entry.get("jitter", [])


def spreads(found):
    """agreement.spreads over each model's realisations in both engines, one pool for all."""
    return agreement.spreads({m: {e: realisations(found.get(e, {}).get(m, {})) for e in agreement.ENGINES}
                              for m in MODELS}, STATISTICS)


def rows(found):
    """One row per model, pass and statistic with both engines' fill: (model, pass, label,
    jdem, liggghts-jdem, |difference|, bound or None, spread source, held or None)."""
    s, out = spreads(found), []
    for model in MODELS:
        for p in PASSES:
            a = found.get("jdem", {}).get(model, {}).get("fill%d" % p)
            b = found.get("liggghts-jdem", {}).get(model, {}).get("fill%d" % p)
            if a and b:
                out += [(model, p) + r for r in agreement.compare(
                    a, b, STATISTICS, lambda label: agreement.spread_for(s, model, label),
                    "computed before the bed height was kept")]
    return out


def table(found):
    """The markdown section, "" when no model has both engines' fill."""
    found_rows = rows(found)
    if not found_rows:
        return ""
    lines = ["### Cross-engine deposits against the run-to-run spread", "",
             "past the horizon the engines are two realisations of one chaotic fill: |jdem − "
             "liggghts-jdem| against 2√2 s, s the std over one fill's realisations (the model's "
             "own, else pooled); the bed height is the mean of the free surface, not the highest "
             "sphere's top; scripts/mixing/agreement_ch4.py", "",
             "| model | pass | statistic | jdem | liggghts-jdem | difference | 2√2 s | s from | agree |",
             "|---|---|---|---|---|---|---|---|---|"]
    for model, p, label, a, b, d, bound, source, ok in found_rows:
        lines.append("| %s | %d | %s | %s | %s | %s | %s | %s | %s |" % (
            model, p, label, a, b, d, bound, source, agreement.verdict(ok)))
    return "\n".join(lines) + "\n"
