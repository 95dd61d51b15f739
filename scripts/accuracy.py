#!/usr/bin/python3
"""accuracy.py — error against run time (work-precision study): `make accuracy`.

    scripts/accuracy.py run     [--out out/accuracy] [--items a,b] [--engines jdem,...] [--repeats 3]
    scripts/accuracy.py analyse [--out out/accuracy]
    scripts/accuracy.py check   [--out out/accuracy]   PASS/FAIL: orders and engine agreement

For each item (Chung–Ooi Tests 1, 3 and 4, chosen cases, and the settling of a small bed,
reference_runs/accuracy/bed.yaml) and each engine, the time step is swept over factors of the
guard's safe dt of that case (stepper/guard.c: min(20 % Rayleigh, t_c/50)):

    impacts: 1/8, 1/4, 1/2, 1, 2, 4, 8   reference run at 1/128 (16 x smaller than the smallest)
    bed:     1/2, 1, 2, 4, 8             reference run at 1/32  (idem; a finer bed sweep would cost
                                         more than the study's 15 min budget on 2 cores)

Every run of an item starts from the same physical state and lasts the same physical time; only
dt (and the output interval in steps) changes.  Engines:
    jdem            build/jdem run ... --force (factors above 1 exceed the guard)
    liggghts-jdem   build/liggghts-jdem, pair_style gran/jiang (deck: scene_to_liggghts.py --force:
                    its fix jdem/guard lets the factors above 1 run)
    liggghts        LIGGGHTS' own hertz/history law (deck: scene_to_liggghts.py --builtin), run by
                    build/liggghts-jdem for its trajectory writer; against its own reference
Each sweep run is timed --repeats times (median wall and CPU time of the whole process; runs are
serial); a 1-step run of each item and engine, timed the same way, gives the start-up time.
The reference runs are not timed (they run two at a time first).

`run` writes OUT/ITEM/ENGINE/fFACTOR/{scene.yaml,traj.h5[,deck/]} and OUT/runs.json, then
`analyse`: OUT/summary.json and OUT/report.md with plots (scripts/accuracy_report.py).  Metrics
and their errors: see accuracy_metrics.py.
"""
import argparse
import concurrent.futures
import copy
import json
import math
import os
import shutil
import statistics
import sys
import time

import yaml

from scripts import engines
from scripts.benchmark.cases import LIGGGHTS, ROOT
from scripts.benchmark.cases import scene_path as chung_ooi_scene
from scripts.engines import JDEM, guard_dt

IMPACT_FACTORS = (1 / 8, 1 / 4, 1 / 2, 1, 2, 4, 8)
BED_FACTORS = (1 / 2, 1, 2, 4, 8)
REFERENCE_DIVISOR = 16     # reference dt = smallest swept dt / 16
BED_SEEDS = (2, 3, 4, 5)   # jdem re-runs of the bed with other lattice seeds: the chaotic spread
BED_FRAME_STEPS = 32       # bed frames every 32 steps of the largest swept dt (~1 ms)
ENGINES = ("jdem", "liggghts-jdem", "liggghts")
BED_SCENE = os.path.join(ROOT, "reference_runs", "accuracy", "bed.yaml")

# item -> (Chung–Ooi test or None, case, kind).  Test 4: one case in stick (20 deg, X = 1.75)
# and one in gross sliding (45 deg, X = 0.64), where different parts of the tangential law
# decide the outcome.
ITEMS = {
    "test1_glass": (1, "glass", "impact"),
    "test3_al_oxide_e050_jiang2021": (3, "al_oxide_e050_jiang2021", "impact"),
    "test4_al_oxide_theta20": (4, "al_oxide_theta20", "impact"),
    "test4_al_oxide_theta45": (4, "al_oxide_theta45", "impact"),
    "bed": (None, None, "bed"),
}
FORCE_HISTORY_TESTS = {1}  # their metrics read the force history: a frame every step


def scene_of(item):
    test = ITEMS[item][0]
    return chung_ooi_scene(test) if test else BED_SCENE


def log(msg):
    sys.stderr.write("[accuracy %s] %s\n" % (time.strftime("%H:%M:%S"), msg))
    sys.stderr.flush()


def factors(item):
    return BED_FACTORS if ITEMS[item][2] == "bed" else IMPACT_FACTORS


def reference_factor(item):
    return min(factors(item)) / REFERENCE_DIVISOR


def factor_name(f):
    return "f%g" % f if f >= 1 else "f1_%d" % round(1 / f)


# ---------------------------------------------------------------------------------------------
# Scenes

def resolved(item):
    case = ITEMS[item][1]
    return yaml.load(engines.resolve(scene_of(item), case, check=True).stdout, Loader=yaml.CSafeLoader)


def write_yaml(doc, path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        yaml.safe_dump(doc, f, sort_keys=False)
    return path


def base_of(item, out):
    """The resolved case, its physical duration [s] and the guard's safe dt [s]."""
    doc = resolved(item)
    duration = float(doc["time"]["steps"]) * float(doc["time"]["dt"])
    probe = copy.deepcopy(doc)
    probe["time"]["dt"] = 1.0
    guard = guard_dt(write_yaml(probe, os.path.join(out, item, "guard_probe.yaml")))
    return doc, duration, guard


def scene_at(item, base, factor, steps=None):
    """The case with dt = factor x guard dt over the same physical time (or `steps` steps).
    Output: impacts of Test 1 every step (the force history is the measurement), other impacts
    the first and last frame; the bed every BED_FRAME_STEPS steps of the largest swept dt, so
    frames fall at the same times for every dt."""
    doc, duration, guard = base
    s = copy.deepcopy(doc)
    dt = factor * guard
    n = steps or int(math.ceil(duration / dt - 1e-9))
    s["time"]["dt"] = dt
    s["time"]["steps"] = n
    if ITEMS[item][2] == "bed":
        every = int(round(BED_FRAME_STEPS * max(BED_FACTORS) / factor))
        obs = max(1, every // 4)
    else:
        every = obs = 1 if ITEMS[item][0] in FORCE_HISTORY_TESTS else n
    s["output"]["every"] = min(every, n)
    s["output"]["observables_every"] = min(obs, n)
    return s


def seed_scene(out, base, factor, seed):
    """The bed with another lattice seed, at dt = factor x the guard dt of the original bed."""
    src = yaml.load(open(BED_SCENE), Loader=yaml.CSafeLoader)
    src["generate"][0]["lattice"]["seed"] = seed
    tmp = write_yaml(src, os.path.join(out, "bed", "seeds", "seed%d.source.yaml" % seed))
    doc = yaml.load(engines.resolve(tmp, check=True).stdout, Loader=yaml.CSafeLoader)
    return scene_at("bed", (doc,) + tuple(base[1:]), factor)


# ---------------------------------------------------------------------------------------------
# Running

def engine_command(engine, scene_file, traj):
    """(command, cwd) running scene_file in engine, writing traj."""
    if engine == "jdem":
        return [JDEM, "run", scene_file, "-o", traj, "--quiet", "--force"], None
    deck_dir = os.path.join(os.path.dirname(traj), "deck")
    engines.write_deck(scene_file, os.path.join(deck_dir, "in.jdem"), "--trajectory", traj, "--force",
                       *(["--builtin"] if engine == "liggghts" else []), check=True)
    return engines.liggghts_command("in.jdem", binary=LIGGGHTS), deck_dir


def run(engine, scene, directory, repeats):
    """Write scene, run it `repeats` times; returns the record (times of every repeat)."""
    scene_file = write_yaml(scene, os.path.join(directory, "scene.yaml"))
    traj = os.path.join(directory, "traj.h5")
    rec = {"dt": scene["time"]["dt"], "steps": scene["time"]["steps"], "trajectory":
           os.path.relpath(traj, ROOT), "wall": [], "cpu": [], "load": [], "loop": []}
    try:
        cmd, cwd = engine_command(engine, scene_file, traj)
        for _ in range(repeats):
            for stale in (traj, traj + ".part"):
                if os.path.exists(stale):
                    os.remove(stale)
            t = engines.cpu_timed(cmd, cwd)
            for k in ("wall", "cpu", "load"):
                rec[k].append(t[k])
            if cwd:  # LIGGGHTS: its own time of the run loop
                rec["loop"].append(engines.liggghts_loop_seconds(os.path.join(cwd, "log.lammps")))
        rec["status"] = "ok"
    except RuntimeError as e:
        rec["status"] = "failed"
        rec["message"] = str(e)[-1500:]
        log("%s failed: %s" % (os.path.relpath(directory, ROOT), str(e).splitlines()[-1][:300]))
    return rec


def run_all(out, items, engines, repeats):
    bases = {item: base_of(item, out) for item in items}
    runs = {"machine": {"cpus": os.cpu_count(), "shared": "2 cores shared with other jobs"},
            "repeats": repeats, "items": {}}
    for item in items:
        test, case, kind = ITEMS[item]
        runs["items"][item] = {"scene": os.path.relpath(scene_of(item), ROOT), "test": test, "case": case,
                               "kind": kind,
                               "guard_dt": bases[item][2], "duration": bases[item][1],
                               "scene_dt": bases[item][0]["time"]["dt"],
                               "frame_interval": BED_FRAME_STEPS * max(BED_FACTORS) * bases[item][2],
                               "factors": list(factors(item)), "reference_factor": reference_factor(item),
                               "engines": {e: {} for e in engines}}

    def directory(item, engine, name):
        return os.path.join(out, item, engine, name)

    # references first, two at a time (not timed: their wall time is not a point of the study)
    jobs = [(item, engine) for item in items for engine in engines]
    t0 = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        futures = {pool.submit(run, engine, scene_at(item, bases[item], reference_factor(item)),
                               directory(item, engine, "reference"), 1): (item, engine)
                   for item, engine in jobs}
        for fut in concurrent.futures.as_completed(futures):
            item, engine = futures[fut]
            runs["items"][item]["engines"][engine]["reference"] = fut.result()
            log("reference %s %s done" % (item, engine))
    log("references: %.0f s" % (time.monotonic() - t0))
    # the sweep, serially, each run timed `repeats` times; the start-up time (1 step) likewise
    for item in items:
        for engine in engines:
            rows = runs["items"][item]["engines"][engine]
            for f in factors(item):
                rows[factor_name(f)] = run(engine, scene_at(item, bases[item], f),
                                           directory(item, engine, factor_name(f)), repeats)
            rows["startup"] = run(engine, scene_at(item, bases[item], max(factors(item)), steps=1),
                                  directory(item, engine, "startup"), repeats)
            log("%s %s: %s" % (item, engine, ", ".join(
                "%s %.3g s" % (k, statistics.median(r["wall"])) for k, r in rows.items() if r["wall"])))
    if "bed" in items and "jdem" in engines:
        seeds = {}
        for seed in BED_SEEDS:
            seeds["seed%d" % seed] = run("jdem", seed_scene(out, bases["bed"], min(BED_FACTORS), seed),
                                         os.path.join(out, "bed", "seeds", "seed%d" % seed), 1)
        runs["items"]["bed"]["seeds"] = {"factor": min(BED_FACTORS), "runs": seeds}
    return runs


# Checks of `check` (the reduced study of `make test`): the observed order of Test 1 in each
# engine against the theory of velocity Verlet, second order for a force that is smooth
# enough (elastic Hertz: F ~ delta^1.5, continuously differentiable at the onset), and the two
# engines of the Jiang kernel against each other (the same kernel in the same order).
EXPECTED_ORDER = {"test1_glass": (2.0, 0.3)}
ENGINE_AGREEMENT = 1e-9


def check_summary(out):
    """PASS/FAIL lines from OUT/summary.json; returns the number of failures."""
    with open(os.path.join(out, "summary.json")) as f:
        items = json.load(f)["items"]
    failures, checked = 0, 0

    def report(ok, name, detail):
        nonlocal failures, checked
        checked += 1
        failures += not ok
        print("%s accuracy/%s: %s" % ("PASS" if ok else "FAIL", name, detail))

    for item, (order, tol) in EXPECTED_ORDER.items():
        for engine, res in items.get(item, {}).get("engines", {}).items():
            for metric, got in (res.get("order_by_metric") or {}).items():
                report(got is not None and abs(got - order) <= tol, "%s/%s/%s/order" % (item, engine, metric),
                       "observed order %s, expected %g +- %g" % (got, order, tol))
    for item, it in items.items():
        eng = it["engines"]
        if "jdem" not in eng or "liggghts-jdem" not in eng:
            continue
        for a, b in zip(eng["jdem"]["rows"] or [], eng["liggghts-jdem"]["rows"] or []):
            worst = max(abs(a["metrics"][m]["value"] - b["metrics"][m]["value"]) / abs(a["metrics"][m]["value"])
                        for m in a["metrics"]) if a.get("metrics") and b.get("metrics") else math.inf
            report(worst <= ENGINE_AGREEMENT, "%s/f%g/jdem-vs-liggghts-jdem" % (item, a["factor"]),
                   "largest relative difference of the metrics %.3g (limit %g)" % (worst, ENGINE_AGREEMENT))
    if not checked:
        report(False, "summary", "nothing to check in %s" % out)
    return failures


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("command", choices=("run", "analyse", "check"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "accuracy"))
    ap.add_argument("--items", default=",".join(ITEMS))
    ap.add_argument("--engines", default=",".join(ENGINES))
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args(argv[1:])
    out = os.path.abspath(a.out)
    items = a.items.split(",")
    engines = a.engines.split(",")
    bad = [i for i in items if i not in ITEMS] + [e for e in engines if e not in ENGINES]
    if bad:
        ap.error("unknown item(s)/engine(s) %s; valid items: %s; engines: %s"
                 % (bad, ", ".join(ITEMS), ", ".join(ENGINES)))
    if a.repeats < 1:
        ap.error("--repeats must be >= 1")
    runs_path = os.path.join(out, "runs.json")
    if a.command == "check":
        return 1 if check_summary(out) else 0
    if a.command == "run":
        if os.path.isdir(out) and os.listdir(out) and not os.path.exists(runs_path):
            ap.error("%s exists and holds no runs.json: not a study to replace" % out)
        if os.path.isdir(out):
            shutil.rmtree(out)  # a fresh study: no trajectory of an earlier one may be analysed
        os.makedirs(out)
        t0 = time.monotonic()
        runs = run_all(out, items, engines, a.repeats)
        runs["study_wall_seconds"] = time.monotonic() - t0
        with open(runs_path, "w") as f:
            json.dump(runs, f, indent=1)
    from scripts import accuracy_report
    accuracy_report.analyse(out, json.load(open(runs_path)))
    log("wrote %s and %s" % (os.path.join(out, "summary.json"), os.path.join(out, "report.md")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
