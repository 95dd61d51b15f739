"""agreement_ch5.py — the two engines' whole Chapter 5 fills against the run-to-run spread
(report_ch5.py; the issue's "after chaos sets in, the totals agree within the run-to-run
spread"), by agreement.py's rule.

For every case with both engines' fill, each statistic of the deposit and of its breakage is set
against 2 sqrt(2) s, s the std over the realisations of the case's fill (the fill and its repeats
with the stream shifted by K micrometres, plan_ch5.SPREAD_REALISATIONS): the case's own where it
has two degrees of freedom, else pooled over the realisations of its group's cases.  The pool is
the group's, not the campaign's: the bonds set the spread of the breakage (Group 2's all break,
Group 3's about half), and Group 1 has none.  The horizon's spread of the bonds broken by 2 s
(horizon_ch5.py) is the same comparison early in the fill; this one is at its end.
"""
from scripts.mixing import agreement, agreement_ch4
from scripts.mixing.agreement import Statistic


def field(*keys):
    """The entry's value at the nested keys, None where an entry (an older one) lacks them."""
    def get(e):
        for k in keys:
            if not isinstance(e, dict) or k not in e:
                return None
            e = e[k]
        return e
    return get


def bonded(key):
    """A breakage statistic of a fill, None for a fill without bonds (Group 1)."""
    return lambda e: field("breakage", key)(e) if field("breakage", "formed")(e) else None


def outflow_spread(k):
    """The std of the outflow's direction below the fill's obstacle k (outflow.py), None for a
    model with fewer obstacles."""
    return lambda e: e["outflow"][k]["std"] if len(e.get("outflow", [])) > k else None


def voids(e):
    """The solid fraction of the interior less that near the walls."""
    inner, wall = field("packing", "interior")(e), field("packing", "wall")(e)
    return None if inner is None or wall is None else inner - wall


def segregated(e):
    """Whether the fill separates the cohorts at the middle clip (φv under a tenth of the ideal):
    its φv and the spread of it over the points measure no run-to-run spread."""
    phi = field("middle_clip", "mean")(e)
    return phi is not None and phi < agreement_ch4.SEGREGATED


BROKEN = "bonds broken (fraction)"
PHI, PHI_STD, INCLINATION, VOIDS = ("φv at the middle clip", "std of φv at the middle clip",
                                    "free-surface inclination [deg]",
                                    "solid fraction interior − near the walls")
OUTFLOW = ("outflow spread below obstacle 1 [deg]", "outflow spread below obstacle 2 [deg]")
STATISTICS = (
    Statistic(PHI, field("middle_clip", "mean"), "%.4f", segregated),
    Statistic(PHI_STD, field("middle_clip", "std"), "%.4f", segregated),
    Statistic("bed height (mean surface) [m]", field("surface", "mean"), "%.3f"),
    Statistic(INCLINATION, field("surface", "inclination"), "%.1f"),
    Statistic("solid fraction, interior", field("packing", "interior"), "%.4f"),
    Statistic("solid fraction near the walls", field("packing", "wall"), "%.4f"),
    Statistic(VOIDS, voids, "%.4f"),
    Statistic(OUTFLOW[0], outflow_spread(0), "%.1f"),
    Statistic(OUTFLOW[1], outflow_spread(1), "%.1f"),
    Statistic(BROKEN, bonded("total"), "%.3f"),
    Statistic("broken in tension (fraction)", bonded("tension"), "%.3f"),
    Statistic("broken in shear (fraction)", bonded("shear"), "%.3f"),
    Statistic("fragments at the end", bonded("fragments"), "%.0f"),
    Statistic("single spheres at the end", bonded("singles"), "%.0f"))
ENGINES = agreement.ENGINES


def group(case):
    """The pool of a case's realisations: its group (rigid_modelM: the rigid cements)."""
    return case.split("_")[0]


def realisations(entry):
    """The fill and its realisations (report_ch5.py's "realisations") of one engine and case."""
    return ([entry] if entry else []) + (entry or {}).get("realisations", [])


def spread(found, cases):
    """f(case, label) -> (s, source) or None: the run-to-run spread of a statistic of the case's
    fill (agreement.spreads over every case's realisations in both engines, pooled per group);
    found: report_ch5.py's {"ENGINE/CASE": entry}."""
    runs = {c: {e: realisations(found.get("%s/%s" % (e, c))) for e in ENGINES} for c in cases}
    s = agreement.spreads(runs, STATISTICS, group)
    return lambda c, label: agreement.spread_for(s, c, label, group(c))


def rows(found, cases):
    """(case, label, jdem, liggghts-jdem, |difference|, bound, spread source, held or None) for
    each case with both engines' fill."""
    s, out = spread(found, cases), []
    for c in cases:
        a, b = (found.get("%s/%s" % (e, c)) for e in ENGINES)
        if a and b:
            out += [(c,) + r for r in agreement.compare(a, b, STATISTICS, lambda label: s(c, label),
                                                        "measured in one engine only", skip_unmeasured=True)]
    return out


def section(found, cases):
    """The markdown lines of the report's section (a line saying what is missing when no case
    has both engines' fill)."""
    head = ["### Whole fills, jdem against liggghts-jdem, within the run-to-run spread", ""]
    found_rows = rows(found, cases)
    if not found_rows:
        return head + ["(no case has both engines' fill yet)"]
    held = [r[-1] for r in found_rows if r[-1] is not None]
    one_sided = sum(r[6] == "measured in one engine only" for r in found_rows)
    lines = head + [
        "past the horizon the engines are two realisations of one chaotic fill: |jdem − "
        "liggghts-jdem| at the end of the fill against 2√2 s, s the std over the realisations of "
        "one fill (the stream shifted by K µm; the case's own, else pooled over its group); a "
        "pooled s has one degree of freedom for each case it names (a fill and its one shifted "
        "realisation), so an s from one name is a rough one and a verdict near its bound is weak; "
        "scripts/mixing/agreement_ch5.py", "",
        "| case | statistic | jdem | liggghts-jdem | difference | 2√2 s | s from | agree |",
        "|---|---|---|---|---|---|---|---|"]
    for c, label, a, b, d, bound, source, ok in found_rows:
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
            c, label, a, b, d, bound, source, agreement.verdict(ok)))
    lines += ["", "%d of %d statistics with a measured spread agree; %d have no spread measured yet%s." % (
        sum(held), len(held), len(found_rows) - len(held) - one_sided,
        "; %d are measured in one engine only" % one_sided if one_sided else "")]
    return lines
