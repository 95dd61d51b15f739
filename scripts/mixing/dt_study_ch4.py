"""dt_study_ch4.py — error against run time for the Chapter 4 campaign (report_ch4.py; docs/mixing.md
§6): every model and pass that has fills at more than one dt (the seed's, the guard's, half of it:
`make mixing DT=seed|guard|half`), its deposit statistics and constants side by side with the CPU
time of its fill.

The seed's dt is the report's own results; the other variants are their committed summaries
(reference_runs/mixing/ch4_dt_guard/results/summary.json and ch4_dt_half/...), which
`report_ch4.py --out out/mixing/ch4_dt_X --results reference_runs/mixing/ch4_dt_X/results`
writes.  A fill's dt is read back from its unit's cost (plan_ch4: particles x time / dt).  How far a
variant moves is measured in standard deviations over the points (or the cubes): for each
statistic |mean - mean at the seed's dt| / the larger of the two stds, and the largest of these.
"""
import json
import math
import os

from scripts.mixing import plan_ch4, stats

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VARIANTS = ("seed", "guard", "half")
RESULTS = {v: os.path.join(ROOT, "reference_runs", "mixing", "ch4" if v == "seed" else "ch4_dt_" + v, "results")
           for v in VARIANTS}
# (label, value of a fill or cube set -> (mean, std), format); scale 1e-3 for M in kPa
FILL_STATS = (("φv", "phi_v", "%.4f"), ("e", "e", "%.3f"), ("ρb [kg/m³]", "rho_b", "%.0f"), ("Z", "Z", "%.2f"))
CUBE_STATS = (("M, wall [kPa]", "M_wall", "%.1f", 1e-3), ("K0", "K0", "%.2f", 1.0))


def committed(variant):
    """The committed results of a variant ({} when it has none)."""
    try:
        with open(os.path.join(RESULTS[variant], "summary.json")) as f:
            return json.load(f)["results"]
    except (OSError, ValueError, KeyError):
        return {}


def fill_dt(times, engine, model, p):
    t = times.get("%s/%s/fill%d" % (engine, model, p))
    return plan_ch4.FILL_PARTICLES * plan_ch4.FILL_TIME / t["cost"] if t and t.get("cost") else None


def measures(entry, p):
    """{key: (mean, std)} of a pass of one model: the fill's statistics and its cubes' constants."""
    fill = entry.get("fill%d" % p)
    if not fill:
        return None
    m = {key: (fill["summary"][key]["mean"], fill["summary"][key]["std"]) for _, key, _ in FILL_STATS}
    cubes = entry.get("pass%d_cubes" % p)
    for _, key, _, scale in CUBE_STATS:
        s = stats.summary([c[key] for c in cubes]) if cubes else None
        m[key] = (s["mean"] * scale, s["std"] * scale) if s else (None, None)
    return m


def largest_move(m, ref):
    """max over the statistics of |mean - ref mean| / max(std, ref std), and which."""
    moves = []
    for key in m:
        (a, sa), (b, sb) = m[key], ref[key]
        if None in (a, b, sa, sb) or any(math.isnan(x) for x in (a, b, sa, sb)):
            continue
        scale = max(sa, sb)
        if scale > 0:
            moves.append((abs(a - b) / scale, key))
        elif a != b:
            moves.append((math.inf, key))
    return max(moves) if moves else None


def move_text(move):
    if not move:
        return "—"
    size, key = move
    return "∞ (%s: both std 0, means differ)" % key if size == math.inf else "%.2f (%s)" % (size, key)


def cpu_text(t):
    """A fill's CPU seconds over all its attempts; timed before the campaign added them up, a
    resumed fill's figure is its last attempt's only, which the table cannot tell apart.  The
    threads (their CPU seconds add up) and the machine where the campaign recorded them: the
    variants ran in different sessions, on different machines."""
    if t.get("cpu_seconds") is None:
        return "not recorded"
    notes = ([] if "attempts" in t else ["last attempt, if resumed"]) + \
        (["%d threads" % t["threads"]] if t.get("threads", 1) > 1 else []) + \
        ([t["machine"]] if t.get("machine") else [])
    return "%.0f" % t["cpu_seconds"] + (" (%s)" % ", ".join(notes) if notes else "")


def table(found, engines, models, passes):
    """The markdown section: found is the report's own (seed-dt) results."""
    results = {"seed": found, **{v: committed(v) for v in VARIANTS[1:]}}
    head = ["### Error against run time: the same fills at the seed's dt, the guard's and half of it", "",
            "trimmed mean ± std over the 9 points (the cubes for M and K0); the largest move of any of "
            "these statistics from the seed's dt, in units of the larger std; the fill's CPU time "
            "(`make mixing DT=guard|half`; each variant's own report is under "
            "reference_runs/mixing/ch4_dt_X/results/)", "",
            "| engine | model | pass | dt [s] | " + " | ".join(s[0] for s in FILL_STATS + CUBE_STATS) +
            " | largest move [std] | fill CPU [s] |",
            "|---|---|---|---|" + "---|" * (len(FILL_STATS) + len(CUBE_STATS)) + "---|---|"]
    rows = []
    for engine in engines:
        for model in models:
            for p in passes:
                runs = [(v, results[v].get(engine, {}).get(model, {})) for v in VARIANTS]
                runs = [(v, e, m) for v, e in runs for m in [measures(e, p)] if m]
                if len(runs) < 2 or runs[0][0] != "seed":
                    continue
                ref = runs[0][2]
                for v, e, m in runs:
                    times = e.get("times", {})
                    dt = fill_dt(times, engine, model, p)
                    t = times.get("%s/%s/fill%d" % (engine, model, p)) or {}
                    rows.append("| %s | %s | %d | %s (%s) | %s | %s | %s | %s |" % (
                        engine, model, p, "%.3g" % dt if dt else "—", v,
                        " | ".join(stats.cell(*m[key], fmt) for _, key, fmt in FILL_STATS),
                        " | ".join(stats.cell(*m[key], fmt) for _, key, fmt, _ in CUBE_STATS),
                        move_text(largest_move(m, ref)) if v != "seed" else "(reference)",
                        cpu_text(t)))
    if not rows:
        return "\n".join(head[:1] + ["", "no model and pass has fills at two dt yet (`make mixing DT=guard`)", ""])
    return "\n".join(head + rows) + "\n"
