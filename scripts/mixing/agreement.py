"""agreement.py — two engines' fills against the run-to-run spread, the rule of both chapters'
reports (agreement_ch4.py, agreement_ch5.py).

Past the cross-engine horizon (under a second of a fill) jdem and liggghts-jdem are two
realisations of the same chaotic fill, so their results can differ by what two realisations of
one engine differ by.  Each statistic's difference |jdem - liggghts-jdem| is set against
2 sqrt(2) s: s the sample standard deviation of that statistic over the realisations of one fill
(the fill and its repeats with the stream shifted by K micrometres), sqrt(2) for the difference
of two independent runs, 2 for two standard deviations.  s is the case's own, pooled over both
engines' realisations of it, where that has at least OWN_SPREAD_DOF degrees of freedom (three
realisations in one engine, or two in each), else pooled over the realisations of every case of
its pool (a std from two runs has one degree of freedom, and its 95 % interval spans 0.03 to 2.2
times the true one).  A statistic of the mixing (φv, its std) measures no spread in a case whose
realisations all separate the cohorts (Statistic.segregated: φv under a tenth of the ideal):
their zero std would shrink the pool of the fills that mix.  A value that is not finite (a
packing band without spheres, an outflow of one particle) counts as not measured.
"""
import collections
import math

import numpy as np

ENGINES = ("jdem", "liggghts-jdem")
OWN_SPREAD_DOF = 2    # degrees of freedom from which a case's own std is used rather than the pool


# label: the row's name; get(result) -> float or None (not measured); fmt: its format;
# segregated(result) -> whether the fill separates the cohorts: a case whose realisations all
# do measures no spread of the statistic (None: every realisation counts)
Statistic = collections.namedtuple("Statistic", "label get fmt segregated", defaults=(None,))


def value(st, result):
    """The statistic of one result, None when it is not measured or not finite (a packing
    band without spheres, an outflow of one particle)."""
    v = st.get(result)
    return None if v is None or not math.isfinite(v) else float(v)


def spreads(runs, statistics, pool_of=lambda key: None):
    """{(key, label): (s, source, dof)} for each case key with OWN_SPREAD_DOF degrees of freedom
    of its own, and {(("pool", pool), label): (s, source, dof)} over every case of a pool with at least two
    realisations in one engine.  runs: {key: {engine: [result, ...]}}, each engine's
    realisations of the case; pool_of(key): the pool the case's realisations join."""
    out, pooled = {}, {}
    for key, by_engine in runs.items():
        own = {}
        for engine in ENGINES:
            results = by_engine.get(engine, [])
            if len(results) < 2:
                continue
            for st in statistics:
                vals = [value(st, r) for r in results]
                if None in vals or (st.segregated is not None and all(st.segregated(r) for r in results)):
                    continue
                ss = float(np.var(vals, ddof=1)) * (len(vals) - 1)
                for acc, name in ((own.setdefault(st.label, [0.0, 0, []]), "%s, %d" % (engine, len(results))),
                                  (pooled.setdefault((pool_of(key), st.label), [0.0, 0, []]),
                                   "%s %s" % (engine, key))):
                    acc[0] += ss
                    acc[1] += len(vals) - 1
                    acc[2].append(name)
        for label, (ss, dof, names) in own.items():
            if dof >= OWN_SPREAD_DOF:
                out[(key, label)] = (math.sqrt(ss / dof), "%s, realisations: %s" % (key, "; ".join(names)), dof)
    for (pool, label), (ss, dof, names) in pooled.items():
        out[(("pool", pool), label)] = (math.sqrt(ss / dof), "pooled: " + ", ".join(names), dof)
    return out


def spread_for(s, key, label, pool=None):
    """The case's own spread of the statistic, else its pool's, else None."""
    return s.get((key, label)) or s.get((("pool", pool), label))


def compare(a, b, statistics, spread, missing="not measured", skip_unmeasured=False):
    """Rows (label, jdem, liggghts-jdem, |difference|, bound, spread source, held or None) of one
    case's two fills a and b; spread(label) -> (s, source) or None.  A statistic that a fill does
    not measure gives a row saying `missing`, or none when neither does and skip_unmeasured (a
    statistic the case does not have, such as the breakage of unbonded spheres)."""
    out = []
    for st in statistics:
        va, vb = value(st, a), value(st, b)
        if va is None and vb is None and skip_unmeasured:
            continue
        if va is None or vb is None:
            out.append((st.label, "—" if va is None else st.fmt % va, "—" if vb is None else st.fmt % vb,
                        "—", "—", missing, None))
            continue
        diff = abs(va - vb)
        sp = spread(st.label)
        bound = 2.0 * math.sqrt(2.0) * sp[0] if sp else None
        out.append((st.label, st.fmt % va, st.fmt % vb, st.fmt % diff,
                    st.fmt % bound if sp else "—", sp[1] if sp else "no spread measured",
                    None if bound is None else diff <= bound))
    return out


def verdict(ok):
    return "—" if ok is None else ("held" if ok else "not held")


UNRESOLVED = "not resolved (within the run-to-run spread)"
UNMEASURED = "not resolved (no run-to-run spread measured)"


def ordered(value, spread, pairs, plain_signs=False):
    """Verdict and margin text of "a is above b" for every (a, b) in pairs (a claim such as "a
    mixes better than b", in the value that says it): held when every difference value_a -
    value_b exceeds 2 sqrt(s_a² + s_b²), two standard deviations of the difference of two
    independent fills, not held when one falls below minus it, otherwise UNRESOLVED.  A pair
    without a measured spread leaves the claim UNMEASURED, unless one of the other pairs already
    falls below; plain_signs: the signs alone decide (a published table read against its own
    text, where there is no spread to weigh).  spread(key) -> (s, source) or None."""
    signs, bounds = [], []
    for a, b in pairs:
        sa, sb = spread(a), spread(b)
        if not (sa and sb):
            signs.append((1 if value[a] > value[b] else -1) if plain_signs else None)
            continue
        bound = 2.0 * math.hypot(sa[0], sb[0])
        bounds.append(bound)
        d = value[a] - value[b]
        signs.append(1 if d > bound else (-1 if d < -bound else 0))
    if -1 in signs:
        text = "not held"
    elif None in signs:
        text = UNMEASURED
    else:
        text = "held" if all(x > 0 for x in signs) else UNRESOLVED
    if not bounds:
        return text, "no run-to-run spread measured"
    return text, "a difference counts beyond 2√(s_a² + s_b²) = %.4f" % max(bounds)
