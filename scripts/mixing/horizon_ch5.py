#!/usr/bin/python3
"""horizon_ch5.py — how long the two engines' bonded fills of the Chapter 5 campaign agree, and
whether their first bonds break alike (docs/mixing.md §11, "The cross-engine horizon and the
first breaks").

    horizon_ch5.py run --case groupG_modelM -o HORIZON.json [--end-time 2] [--frame-every 200]
                       [--dir DIR]
    horizon_ch5.py realisation --case groupG_modelM --jitter K [--engine liggghts-jdem]
                               -o REALISATION.json [...]
    horizon_ch5.py summary [--out out/mixing/ch5] [--results DIR]

run: the first T seconds of the case's fill (the resolved case of reference_runs/mixing/ch5/
models.yaml, the scene both engines run, with its step count cut to T and a frame every N steps)
in jdem and in liggghts-jdem, each run as the fill units run it (horizon_ch4.run_engines); then
the trajectory horizon of horizon_ch4 (particles matched by id, max |dx| / R_max and
max |dv| / sqrt(g d_max) per frame) and the breaks of the two runs side by side
(break_agreement): whether the bonds formed are the same pairs at the same steps, each engine's
first break (step, pair, mode), how many breaks agree in order (step, pair, mode) before the
first that does not, the breaks up to the horizon, and the totals at T; and the step at which
the first sphere touched a wall or an obstacle (the observables are sampled at every step), for
the seed's claim that weak blocks stay whole in free fall (free_fall_claims).
realisation: one engine (jdem by default) alone on the same scene with the stream shifted by K
micrometres in y (the run-to-run spread, as Ch. 4's realisations): the breaks' totals at T, into
REALISATION.json.
summary: the table of every case's HORIZON.json in OUT/cross/CASE/horizon.json, the totals
against the spread of the realisations OUT/cross/CASE/{jitterK, liggghts-jdem_jitterK}.json,
and the plot of the curves,
into OUT/cross/horizon/{summary.json, horizon.md, horizon.png} and, with --results, also there
(the committed copy, reference_runs/mixing/ch5/results/horizon/); a case or realisation not run
here is taken from the committed summary.json, each result naming the commit it was run at.
"""
import argparse
import collections
import math
import os
import re
import sys

import numpy as np

from scripts import engines
from scripts.mixing import breakage, horizon_ch4, plan_ch4
from scripts.mixing.report_ch4 import commit
from scripts.trajectory_divergence import ROUNDOFF

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
MODELS = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "models.yaml")
ENGINES = plan_ch4.ENGINES
END_TIME = 2.0      # [s] the first sections land at 0.6 s, the horizon is near 0.7 s
FRAME_EVERY = 200   # steps: a frame every 0.02 s at the seed's dt
RESULT = "horizon.json"
REALISATIONS = tuple(range(1, 7))   # K of the jittered jdem runs: the run-to-run spread at T


# ---- the runs -------------------------------------------------------------------------------
def set_key(text, key, value):
    """The resolved scene `text` with its one line `  key: ...` (time.steps, output.every, ...)
    set to value; the rest of the scene, its 100 kB of inlet blocks, is left as jdem wrote it."""
    pattern = re.compile(r"(?m)^  %s: .*$" % re.escape(key))
    if len(pattern.findall(text)) != 1:
        raise SystemExit("horizon_ch5: the resolved scene has not exactly one '  %s:' line" % key)
    return pattern.sub("  %s: %s" % (key, value), text)


def shift_stream(text, origin, jitter):
    """The resolved scene `text` with its inlet's origin (given, [m]) moved by jitter x
    plan_ch4.JITTER in y: a realisation, as Ch. 4's generate.py --jitter."""
    moved = plan_ch4.shifted_origin(origin, jitter)
    return set_key(text, "origin", "[%s]" % ", ".join(repr(x) for x in moved))


def write_scene(case, end_time, frame_every, path, jitter=0, observables_every=None):
    """The case as `jdem resolve --case` gives it, cut to end_time, a frame every frame_every
    steps and an observable sample every observables_every (default: with the frames), the
    stream shifted by jitter steps (shift_stream); returns (path, dt).  The sampling changes no
    bit of the trajectory (suite engine-fastpaths)."""
    import yaml
    text = engines.resolve(MODELS, case, check=True).stdout
    doc = yaml.load(text, Loader=yaml.CSafeLoader)
    dt = float(doc["time"]["dt"])
    if jitter:
        text = shift_stream(text, doc["inlets"][0]["origin"], jitter)
    text = set_key(text, "steps", str(int(round(end_time / dt))))
    text = set_key(text, "every", str(frame_every))
    text = set_key(text, "observables_every", str(observables_every or frame_every))
    with open(path, "w") as f:
        f.write(text)
    return path, dt


# ---- the breaks -----------------------------------------------------------------------------
def breaks_in_order(rec):
    """The broken bonds as (step, lower id, higher id, mode), sorted."""
    pairs = np.sort(rec["broken"], axis=1)
    return sorted(zip(rec["broken_step"].tolist(), pairs[:, 0].tolist(), pairs[:, 1].tolist(),
                      rec["mode"].tolist()))


def same_bonds(a, b):
    """Whether both runs formed the same bonds (pairs, sorted) at the same steps."""
    key = lambda r: sorted(zip(np.sort(r["bonds"], axis=1).tolist(), r["formed"].tolist()))
    return len(a["bonds"]) == len(b["bonds"]) and key(a) == key(b)


def describe(brk, dt):
    """One break as the JSON names it."""
    step, i, j, mode = brk
    return {"step": step, "time": step * dt, "pair": [i, j], "mode": breakage.MODES.get(mode, mode)}


def break_agreement(a, b, horizon_step, end_step):
    """The breaks of two runs' bond records a and b (breakage.read_bonds) side by side: same_bonds,
    each run's first break, the length of the longest common prefix of their ordered breaks and
    the first break after it in each, the breaks each has up to horizon_step, the trajectory
    horizon's (and whether they are the same), and each run's broken fractions at end_step."""
    ka, kb = breaks_in_order(a), breaks_in_order(b)
    n = 0
    while n < min(len(ka), len(kb)) and ka[n] == kb[n]:
        n += 1
    dt = a["dt"]
    first_diff = {e: describe(k[n], dt) if n < len(k) else None for e, k in zip(ENGINES, (ka, kb))}
    upto = [[k for k in ks if k[0] <= horizon_step] for ks in (ka, kb)]
    return {"same_bonds": same_bonds(a, b), "bonds": [len(a["bonds"]), len(b["bonds"])],
            "first": {e: describe(k[0], dt) if k else None for e, k in zip(ENGINES, (ka, kb))},
            "common_prefix": n, "first_difference": first_diff,
            "by_horizon": {"step": horizon_step, "breaks": [len(u) for u in upto], "same": upto[0] == upto[1]},
            "totals": {e: breakage.broken_fraction(r, end_step) for e, r in zip(ENGINES, (a, b))}}


def first_wall_contact(path):
    """The step of the first observable sample at which a sphere touches a wall or an obstacle
    (None when none does), and whether the samples were every step (only then is it the first
    contact itself: one begun and ended between two samples goes unseen)."""
    import h5py
    with h5py.File(path, "r") as f:
        step = f["observables/wall_contacts/step"][()]
        count = f["observables/wall_contacts/value"][()]
    touching = np.nonzero(count > 0)[0]
    every_step = bool(len(step) > 1 and np.all(np.diff(step) == 1))
    return {"step": int(step[touching[0]]) if len(touching) else None, "every_step": every_step}


def realisation(a):
    """One engine alone on the case's first T seconds with the stream shifted by --jitter: its
    breaks' totals at T, one realisation of the run-to-run spread."""
    directory = a.dir or os.path.dirname(os.path.abspath(a.out))
    os.makedirs(directory, exist_ok=True)
    scene, _ = write_scene(a.case, a.end_time, a.frame_every, os.path.join(directory, "fill.yaml"),
                           a.jitter)
    out = os.path.join(directory, "fill.%s.h5" % a.engine)
    cmd = plan_ch4.run_command(a.engine, scene, out, False, skin=None, sort_every=0)  # jdem's lists, order
    r, times = engines.cpu_timed_run(cmd)
    if r.returncode != 0:
        raise engines.failure(cmd, r.returncode, r.stdout, r.stderr)
    rec = breakage.read_bonds(out)
    end_step = int(horizon_ch4.load(out)["step"][-1])
    totals = breakage.broken_fraction(rec, end_step)
    horizon_ch4.write_json(a.out, {"case": a.case, "engine": a.engine, "jitter": a.jitter,
                                   "jitter_m": plan_ch4.JITTER * a.jitter, "totals": totals,
                                   "times": times, "commit": commit()})
    print("horizon_ch5: %s in %s, stream shifted by %d x %g m: %d bonds broken by step %d" % (
        a.case, a.engine, a.jitter, plan_ch4.JITTER, totals["broken"], end_step))
    return 0


# what a spread table counts at T: the bonds broken, or those broken in tension (the rest broke
# in shear), from a run's totals (breakage.broken_fraction)
MODES = {"broken": ("bonds broken by the end", lambda t: t["broken"]),
         "tension": ("bonds broken in tension by the end", lambda t: int(round(t["tension"] * t["formed"])))}


def spread_rows(results, realisations, mode="broken"):
    """Per case with realisations: each engine's bonds broken by T (mode "tension": in tension)
    over its runs (the horizon's, K = 0, and those with the stream shifted by K), their mean and
    std, and whether the engines' means differ by at most 2 s sqrt(1/n_jdem + 1/n_liggghts-jdem)
    (two standard deviations of a difference of means), with s pooled over both engines' runs of
    the case and also over the cases of the same group (whose counts are alike), since a few runs
    give few degrees of freedom.  realisations: {case: {engine: [realisation results]}}."""
    count = MODES[mode][1]
    out = []
    for r in results:
        reals = realisations.get(r["case"], {})
        if not any(reals.values()):
            continue
        t = r["breaks"]["totals"]
        q = {"case": r["case"], "group": r["case"].split("_")[0], "mode": mode, "jitters": {}, "counts": {},
             "mean": {}}
        for e in ENGINES:
            mine = sorted(reals.get(e, []), key=lambda x: x["jitter"])
            q["jitters"][e] = [0] + [x["jitter"] for x in mine]
            q["counts"][e] = [count(t[e])] + [count(x["totals"]) for x in mine]
            q["mean"][e] = float(np.mean(q["counts"][e]))
        q["difference"] = q["mean"]["liggghts-jdem"] - q["mean"]["jdem"]
        out.append(q)

    def pooled(rows):
        ss = sum(float(np.sum((np.array(q["counts"][e]) - q["mean"][e]) ** 2)) for q in rows for e in ENGINES)
        dof = sum(len(q["counts"][e]) - 1 for q in rows for e in ENGINES)
        return math.sqrt(ss / dof), dof

    for q in out:
        scale = math.sqrt(sum(1.0 / len(q["counts"][e]) for e in ENGINES))
        for key, rows in (("", [q]), ("pooled_", [p for p in out if p["group"] == q["group"]])):
            q[key + "std"], q[key + "dof"] = pooled(rows)
            q[key + "bound"] = 2.0 * q[key + "std"] * scale
            q[key + "held"] = abs(q["difference"]) <= q[key + "bound"]
    return out


def spread_table(rows):
    if not rows:
        return ""
    what = MODES[rows[0].get("mode", "broken")][0]
    lines = ["| case | " + what + ", jdem (K µm: count) | liggghts-jdem (K µm: count) | "
             "means jdem / liggghts-jdem | difference | s of the case (dof) | 2 s √(1/n + 1/n'): agree "
             "| s pooled over the group (dof) | 2 s √(1/n + 1/n'): agree |",
             "|---|---|---|---|---|---|---|---|---|"]
    verdict = lambda ok: "held" if ok else "**not held**"
    runs = lambda q, e: ", ".join("%d: %d" % kc for kc in zip(q["jitters"][e], q["counts"][e]))
    for q in rows:
        lines.append("| %s | %s | %s | %.1f / %.1f | %+.1f | %.1f (%d) | %.1f: %s | %.1f (%d) | %.1f: %s |" % (
            q["case"], runs(q, "jdem"), runs(q, "liggghts-jdem"), q["mean"]["jdem"], q["mean"]["liggghts-jdem"],
            q["difference"], q["std"], q["dof"], q["bound"], verdict(q["held"]), q["pooled_std"],
            q["pooled_dof"], q["pooled_bound"], verdict(q["pooled_held"])))
    signed = [q["difference"] for q in rows]
    lines += ["", "%d of %d cases within two standard deviations of the case's own spread, %d of %d of "
              "the group's pooled one; liggghts-jdem's mean minus jdem's averages %+.1f bonds over the "
              "cases (%d above, %d below)." % (
                  sum(q["held"] for q in rows), len(rows), sum(q["pooled_held"] for q in rows), len(rows),
                  float(np.mean(signed)), sum(x > 0 for x in signed), sum(x < 0 for x in signed))]
    if rows[0].get("mode", "broken") == "broken":   # the clustering is the same story for the modes
        lines += ["", repeats(rows)]
    return "\n".join(lines) + "\n"


def repeats(rows):
    """A sentence on how the runs' counts repeat: the pairs of runs of one case and engine with
    equal counts, against the number independent draws from a smooth distribution of each set's
    spread would give (two integer draws of std s coincide with probability 1 / (2 sqrt(pi) s)),
    and the largest ratio of the engines' spreads of one case."""
    equal = expected = 0.0
    sd = {}
    for q in rows:
        for e in ENGINES:
            c = q["counts"][e]
            if len(c) < 2:
                continue
            sd[(q["case"], e)] = s = float(np.std(c, ddof=1))
            equal += sum(m * (m - 1) // 2 for m in collections.Counter(c).values())
            expected += len(c) * (len(c) - 1) / 2.0 / (2.0 * math.sqrt(math.pi) * max(s, 0.5))
    ratios = [(max(sd[(q["case"], e)] for e in ENGINES) / max(min(sd[(q["case"], e)] for e in ENGINES), 0.5),
               q["case"]) for q in rows if all((q["case"], e) in sd for e in ENGINES)]
    text = ("Pairs of runs of one case and engine that end with the same count: %d, where independent "
            "draws from a smooth distribution of each set's spread would give %.1f" % (equal, expected))
    if equal > 2 * expected:
        text += (": the count at 2 s takes few values (whether a given block breaks one way or "
                 "another), so a std over seven runs is a rough measure and the degrees of freedom "
                 "above overstate what the runs tell")
    if ratios:
        text += "; the engines' spreads of one case differ by up to %.1fx (%s)" % max(ratios)
    return text + "."


def run(a):
    directory = a.dir or os.path.dirname(os.path.abspath(a.out))
    os.makedirs(directory, exist_ok=True)
    scene, dt = write_scene(a.case, a.end_time, a.frame_every, os.path.join(directory, "fill.yaml"),
                            observables_every=1)
    runs = horizon_ch4.run_engines(scene, directory, False)
    trajectories = [horizon_ch4.load(runs[e][0]) for e in ENGINES]
    curve = horizon_ch4.difference_by_id(*trajectories)
    result = horizon_ch4.horizon_result(a.case, dt, curve, {e: runs[e][1] for e in runs})
    d = result["divergence"]
    # the horizon is the last frame below round-off: its step, in the frames' own steps
    horizon_step = int(round(d["horizon"] / dt))
    end_step = int(min(t["step"][-1] for t in trajectories))
    result["breaks"] = break_agreement(*[breakage.read_bonds(runs[e][0]) for e in ENGINES],
                                       horizon_step, end_step)
    result["first_wall_contact"] = {e: first_wall_contact(runs[e][0]) for e in ENGINES}
    result["commit"] = commit()
    horizon_ch4.write_json(a.out, result)
    f = result["breaks"]["first"]
    print("horizon_ch5: %s: horizon %s s; first break %s (jdem) / %s (liggghts-jdem); %d breaks "
          "agree in order" % (a.case, d["horizon"], f["jdem"], f["liggghts-jdem"],
                              result["breaks"]["common_prefix"]))
    return 0


# ---- the table and the plot -----------------------------------------------------------------
def first_cell(brk):
    return "none" if brk is None else "%d (%.4f s), %d–%d, %s" % (
        brk["step"], brk["time"], brk["pair"][0], brk["pair"][1], brk["mode"])


def table(results):
    """The report's table: one row per case."""
    fmt = horizon_ch4.fmt
    lines = ["| case | horizon < %.0e [s] | growth rate [1/s] | same bonds formed | first break: "
             "step (t), pair, mode — jdem | liggghts-jdem | breaks up to the horizon (same) | "
             "breaks in the same order, then the first that differs (jdem / liggghts-jdem) | "
             "broken at the end jdem / liggghts-jdem | CPU jdem / liggghts-jdem [s] |" % ROUNDOFF,
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        d, g, b = r["divergence"], r["divergence"]["growth"], r["breaks"]
        h = b["by_horizon"]
        diff = b["first_difference"]
        t = b["totals"]
        lines.append("| %s | %s | %s | %s (%d) | %s | %s | %d / %d (%s) | %d, then %s / %s | %d / %d (%.3f / %.3f) "
                     "| %.0f / %.0f |" % (
                         r["case"], fmt(d["horizon"]), "%.1f" % g["rate"] if g else "—",
                         "yes" if b["same_bonds"] else "**no**", b["bonds"][0],
                         first_cell(b["first"]["jdem"]), first_cell(b["first"]["liggghts-jdem"]),
                         h["breaks"][0], h["breaks"][1], "yes" if h["same"] else "**no**",
                         b["common_prefix"], first_cell(diff["jdem"]), first_cell(diff["liggghts-jdem"]),
                         t["jdem"]["broken"], t["liggghts-jdem"]["broken"], t["jdem"]["total"],
                         t["liggghts-jdem"]["total"], r["times"]["jdem"]["cpu"],
                         r["times"]["liggghts-jdem"]["cpu"]))
    return "\n".join(lines) + "\n"


def free_fall_claims(results):
    """The seed's claim that weak blocks stay whole in free fall (spec §3.8), per Group 2 case
    and engine: held when no bond broke by the step at which the first sphere touched a wall or
    an obstacle (sampled at every step; the sections fall apart from each other, so until then
    only the stream's own contacts load a bond): a bond first feels a wall the step after.  A
    break with no wall contact before it, or none seen at all, is not held; a case without every
    step's sample is undecided."""
    lines = []
    for r in results:
        if not r["case"].startswith("group2_"):
            continue
        for e in ENGINES:
            w, brk = r.get("first_wall_contact", {}).get(e), r["breaks"]["first"][e]
            name = "- %s %s: weak blocks stay whole in free fall" % (e, r["case"])
            if not w or not w["every_step"]:
                lines.append(name + " (the wall contacts were not sampled at every step): **undecided**")
            elif brk is None:
                lines.append(name + " (no bond broke by the end): **held**")
            elif w["step"] is None:
                lines.append(name + " (bond %d–%d broke at step %d, no sphere touched a wall): **not held**"
                             % (brk["pair"][0], brk["pair"][1], brk["step"]))
            else:
                lines.append(name + " (first wall or obstacle contact at step %d, first bond break at step "
                             "%d, %s): **%s**" % (w["step"], brk["step"], brk["mode"],
                                                  "held" if brk["step"] > w["step"] else "not held"))
    return lines


def plot(results, path):
    """horizon_ch4's plot of the difference curves, each case's first break in jdem dashed."""
    first = lambda r: r["breaks"]["first"]["jdem"]["time"] if r["breaks"]["first"]["jdem"] else None
    horizon_ch4.plot(results, path, "Chapter 5 bonded fills", first, "each case's first break in jdem")


def realisation_path(out, case, k, engine):
    """Where a realisation's result goes: jitterK.json for jdem's, ENGINE_jitterK.json else."""
    name = "jitter%d.json" % k if engine == "jdem" else "%s_jitter%d.json" % (engine, k)
    return os.path.join(out, "cross", case, name)


def merged(a, cases):
    """{case: horizon result} and {case: {engine: [realisations]}}: what was run under a.out,
    else what the committed summary in a.results holds (so a machine that ran a few cases keeps
    the others)."""
    results, reals = {}, {}
    committed = os.path.join(a.results or "", "summary.json")
    if a.results and os.path.exists(committed):
        doc = horizon_ch4.read_json(committed)
        results = {r["case"]: r for r in doc.get("cases", [])}
        for c, by_engine in doc.get("realisations", {}).items():
            for e, xs in by_engine.items():
                reals.setdefault(c, {}).setdefault(e, {}).update({x["jitter"]: x for x in xs})
    for c in cases:
        path = os.path.join(a.out, "cross", c, RESULT)
        if os.path.exists(path):
            results[c] = horizon_ch4.read_json(path)
        for e in ENGINES:
            for k in REALISATIONS:
                p = realisation_path(a.out, c, k, e)
                if os.path.exists(p):
                    reals.setdefault(c, {}).setdefault(e, {})[k] = horizon_ch4.read_json(p)
    order = [c for c in cases if c in results]
    return ([results[c] for c in order],
            {c: {e: [x for _, x in sorted(xs.items())] for e, xs in by_engine.items()}
             for c, by_engine in reals.items()})


def summary(a):
    from scripts.mixing import plan_ch5
    results, reals = merged(a, plan_ch5.HORIZON_CASES)
    if not results:   # nothing run yet: the committed results stay as they are
        print("horizon_ch5: no %s under %s/cross/CASE/; nothing written" % (RESULT, a.out))
        return 0
    spread = spread_rows(results, reals)
    tension = spread_rows(results, reals, "tension")
    target = os.path.join(a.out, "cross", "horizon")
    os.makedirs(target, exist_ok=True)
    commits = sorted({x.get("commit", "not recorded") for x in results +
                      [y for by_engine in reals.values() for xs in by_engine.values() for y in xs]})
    horizon_ch4.write_json(os.path.join(target, "summary.json"),
                           {"commits": commits, "cases": results, "realisations": reals, "spread": spread,
                            "spread_tension": tension})
    with open(os.path.join(target, "horizon.md"), "w") as f:
        f.write(table(results) + "\n" + spread_table(spread) + "\n" + spread_table(tension))
    plot(results, os.path.join(target, "horizon.png"))
    horizon_ch4.publish(target, a.results)
    print("horizon_ch5: %d case(s) into %s%s" % (len(results), target,
                                                 " and " + a.results if a.results else ""))
    return 0


def read_summary(directory):
    """(the cases' results, the spread rows of the broken bonds and of those broken in tension,
    the commits they were run at) of a summary directory, or four Nones when it has none."""
    path = os.path.join(directory, "summary.json")
    if not os.path.exists(path):
        return None, None, None, None
    doc = horizon_ch4.read_json(path)
    return doc["cases"], doc.get("spread", []), doc.get("spread_tension", []), doc.get("commits", [])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    r = sub.add_parser("run")
    r.add_argument("--case", required=True, help="groupG_modelM of reference_runs/mixing/ch5/models.yaml")
    r.add_argument("-o", "--out", required=True, help="the result, HORIZON.json")
    r.add_argument("--end-time", type=float, default=END_TIME)
    r.add_argument("--frame-every", type=int, default=FRAME_EVERY)
    r.add_argument("--dir", help="where the scene and the trajectories go (default: beside -o)")
    q = sub.add_parser("realisation")
    q.add_argument("--case", required=True, help="groupG_modelM of reference_runs/mixing/ch5/models.yaml")
    q.add_argument("--engine", choices=ENGINES, default="jdem")
    q.add_argument("--jitter", type=int, required=True,
                   help="the stream's shift in y, in steps of %g m" % plan_ch4.JITTER)
    q.add_argument("-o", "--out", required=True, help="the result, REALISATION.json")
    q.add_argument("--end-time", type=float, default=END_TIME)
    q.add_argument("--frame-every", type=int, default=FRAME_EVERY)
    q.add_argument("--dir", help="where the scene and the trajectory go (default: beside -o)")
    s = sub.add_parser("summary")
    s.add_argument("--out", default=os.path.join(ROOT, "out", "mixing", "ch5"))
    s.add_argument("--results", help="also write the summary, table and plot here")
    a = ap.parse_args(argv)
    return {"run": run, "realisation": realisation, "summary": summary}[a.what](a)


if __name__ == "__main__":
    sys.exit(main())
