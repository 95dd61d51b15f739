"""agreement_ch4.py — the two engines' deposits against the run-to-run spread (report_ch4.py;
the deposit statistics must agree within the measured run-to-run spread).

Past the cross-engine horizon (under a second of the fill) jdem and liggghts-jdem are two
realisations of the same chaotic fill, so their deposits can differ by what two realisations of
one engine differ by.  For every model and pass with both engines' fill, each statistic's
difference |jdem - liggghts-jdem| is set against 2 sqrt(2) s: s the sample standard deviation of
that statistic over the realisations of one fill (the first fill and its jittered repeats,
generate.py --jitter), sqrt(2) for the difference of two independent runs, 2 for two standard
deviations.  s is the model's own, pooled over both engines' realisations of it, where that has
at least OWN_SPREAD_DOF degrees of freedom (three realisations in one engine, or two in each),
else pooled over every model's realisations (one jittered fill of each model, two of Model 3 in
each engine: a std from two runs has one degree of freedom, and its 95 % interval spans 0.03 to
2.2 times the true one).  φv is floored at zero: a model whose realisations all separate the
cohorts (φv below a tenth of the ideal in every one, as Model 1's) has no φv spread to measure,
so its zero std neither stands as its own nor joins the pool, which would otherwise shrink the
spread of the models that mix (SEGREGATED).  The height is the bed's mean surface height (structure.free_surface),
which the same 41280 spheres set through their packing in every model, so it pools like the
intensive statistics (phi_v, packing fraction, rho_b, Z); the highest sphere's top is not
compared: a sphere resting on an obstacle sets it (Model 3's first two realisations: 1.580 and
1.110 m).  A fill
computed before the bed height was kept has none: its row says so.
"""
import math

import numpy as np

from scripts.mixing import params

ENGINES = ("jdem", "liggghts-jdem")
MODELS = tuple("model%d" % m for m in range(1, 7))
OWN_SPREAD_DOF = 2    # degrees of freedom from which a model's own std is used rather than the pool
SEGREGATED = 0.1 * params.IDEAL_PHI_V   # φv of a realisation that separates the cohorts (claims_ch4)
PASSES = (1, 2)
# (label, how to read it from a fill_result, format); packing fraction = 1 - n (porosity)
STATISTICS = (("bed height [m]", lambda r: r.get("bed_height"), "%.3f"),
              ("φv", lambda r: r["summary"]["phi_v"]["mean"], "%.4f"),
              ("packing fraction", lambda r: 1.0 - r["summary"]["n"]["mean"], "%.4f"),
              ("ρb [kg/m³]", lambda r: r["summary"]["rho_b"]["mean"], "%.0f"),
              ("Z", lambda r: r["summary"]["Z"]["mean"], "%.3f"))


def realisations(entry):
    """The first fill and its jittered realisations of one engine and model."""
    return ([entry["fill1"]] if entry.get("fill1") else []) + entry.get("jitter", [])


def spreads(found):
    """{(model or None for the pool, label): (s, source)}: each model's sample std pooled over
    both engines' realisations where it has OWN_SPREAD_DOF degrees of freedom, and the pooled one
    over every engine and model with at least two realisations."""
    out, pooled = {}, {}
    for model in MODELS:
        own = {}
        for engine in ENGINES:
            runs = realisations(found.get(engine, {}).get(model, {}))
            if len(runs) < 2:
                continue
            for label, get, _ in STATISTICS:
                vals = [get(r) for r in runs]
                if None in vals or (label == "φv" and max(vals) < SEGREGATED):
                    continue
                ss = float(np.var(vals, ddof=1)) * (len(vals) - 1)
                for acc, name in ((own.setdefault(label, [0.0, 0, []]), "%s, %d" % (engine, len(runs))),
                                  (pooled.setdefault(label, [0.0, 0, []]), "%s %s" % (engine, model))):
                    acc[0] += ss
                    acc[1] += len(vals) - 1
                    acc[2].append(name)
        for label, (ss, dof, names) in own.items():
            if dof >= OWN_SPREAD_DOF:
                out[(model, label)] = (math.sqrt(ss / dof), "%s, realisations: %s" % (model, "; ".join(names)))
    for label, (ss, dof, names) in pooled.items():
        out[(None, label)] = (math.sqrt(ss / dof), "pooled: " + ", ".join(names))
    return out


def spread_for(s, model, label):
    return s.get((model, label)) or s.get((None, label))


def rows(found):
    """One row per model, pass and statistic with both engines' fill: (model, pass, label,
    jdem, liggghts-jdem, |difference|, bound or None, spread source, held or None)."""
    s, out = spreads(found), []
    for model in MODELS:
        for p in PASSES:
            a = found.get("jdem", {}).get(model, {}).get("fill%d" % p)
            b = found.get("liggghts-jdem", {}).get(model, {}).get("fill%d" % p)
            if not (a and b):
                continue
            for label, get, fmt in STATISTICS:
                va, vb = get(a), get(b)
                if va is None or vb is None:
                    out.append((model, p, label, "—" if va is None else fmt % va,
                                "—" if vb is None else fmt % vb, "—", "—",
                                "computed before the bed height was kept", None))
                    continue
                diff = abs(va - vb)
                sp = spread_for(s, model, label)
                bound = 2.0 * math.sqrt(2.0) * sp[0] if sp else None
                out.append((model, p, label, fmt % va, fmt % vb, fmt % diff,
                            fmt % bound if sp else "—", sp[1] if sp else "no spread measured",
                            None if bound is None else diff <= bound))
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
            model, p, label, a, b, d, bound, source,
            "—" if ok is None else ("held" if ok else "not held")))
    return "\n".join(lines) + "\n"
