#!/usr/bin/python3
"""bench.py — the performance benchmark (`make bench`).

    scripts/bench.py [--sizes 5k,20k] [--variants all] [--engines jdem,liggghts-jdem,liggghts]
                     [--repeats 3] [--ranks-size 20k] [--out out/bench] [--fresh] [--report-only]
                     [--prepare-only] [--timeout 3600] [--keep-files]

Its parts, by job: bench_config.py (sizes, variants, materials), bench_beds.py (1. below),
bench_scenes.py (2.), bench_runs.py (3. and the feature check), bench_summary.py and
bench_report.py (5.); this module runs them in order.

Dense beds of spheres settled under gravity in an open box (reference_runs/bench/README.md):
monodisperse R = 1 mm or bidisperse 1 mm / 2 mm (half and half by number), soft (E = 1e7 Pa) or
stiff (E = 7e10 Pa), with or without rolling resistance; nu = 0.3, rho = 2500, e = 0.5, mu = 0.5.

1. Beds (once per size and dispersity, reused by every variant, engine and repeat; kept in
   OUT/beds/, regenerated only when missing): build/jdem settles a jittered lattice of soft
   spheres (reference_runs/bench/settle.yaml.in).  build/jdem refuses scenes whose spheres
   overlap by more than 1e-6 R at the start, so the settled bed is then relaxed until every
   contact overlaps by exactly 5e-10 m (damped Gauss-Newton least squares, CGLS, numpy only):
   the settled contact network with nearly zero forces, which gravity loads again in the timed
   run.  Soft and stiff variants start from the same bed (settling at the stiff time step would
   take ~1e6 steps).  80k, 320k and 1M are 2 x 2, 4 x 4 and 7 x 7 copies of the 20k bed side by
   side (bench_tiling.py; settling 1M spheres would take ~1.5 h), checked against the
   stepper's start-overlap rule.
   The bonded variants (*_bonded) are the same beds with a parallel bond between every touching
   pair, formed at step 0 by a bond rule; stock LIGGGHTS has no parallel bonds (n/a).
2. Scenes: reference_runs/bench/bench.yaml.in + the bed as explicit particles at rest; dt is the
   stepper's largest safe dt (its guard at max_impact_speed 1 m/s), rounded down; frames only
   at step 0 and the last step.
3. Timings, each repeated --repeats times (median reported):
   * jdem: its timer of the time loop (`--timing`, loop=: the S steps, their two frames and the
     per-step checks), the counterpart of LIGGGHTS' "Loop time";
   * liggghts-jdem and stock liggghts: LIGGGHTS' "Loop time of ..." (the run loop only).  The
     decks come from scene_to_liggghts.py (stock: --builtin, dump removed).
   The throughput tables, ratios and flatness use that loop time less its output (jdem: the
   `output=` part, frames and observables; LIGGGHTS: its "Outpt" share), because the engines
   write different output: jdem and liggghts-jdem write two full frames, stock LIGGGHTS (which
   has no dump h5md/jdem) only thermo lines.  At 1M the frames are 12 % of jdem's loop, at 20k
   1 %.  The loop with its output is kept as well (loop_seconds_with_output).
   Until 2026-11-22 jdem's wall time was a run of S steps minus a run of 1 step, which should
   cancel the set-up but does not reliably: the set-up (scene parsing, ~1 s at 80k, ~15 s at
   1M) varies by more than the loop takes, and the difference was off by up to 30 % at 80k and
   50 % at 1M (in the bench of that day, in both directions across repeats).  It is still
   recorded (diff_wall_s), and the CPU time below is taken that way for every engine.
   Also the CPU time of the loop (GNU time's user+sys of the S-step run minus that of a 1-step
   run, for every engine on 1 rank): steadier than wall time when other jobs share the machine.
   The LIGGGHTS decks get `processors * * 1` (the box is twice the bed's height: a z split
   would leave one rank empty); 2 MPI ranks are timed at --ranks-size.
   Peak resident memory is GNU time's maximum RSS (for MPI runs: of the largest process).
   Average contacts per particle = 2 x particle-particle contacts / N at the last step (jdem and
   liggghts-jdem: the trajectory's /observables/contacts; stock: compute contact/atom).
4. A callgrind profile of a 200-step jdem run (if valgrind is installed; OUT/profile.json).
5. OUT/summary.json, OUT/runs.jsonl (every single timing), OUT/report.md with plots; with the
   flatness of jdem's cost per particle-step over N (max/min, target 1.25), its engine memory
   against 300 B/particle + 100 B/contact, and ns per bond-step of the bonded variants.

Timing results are appended to OUT/runs.jsonl and reused (a run already measured is not run
again) unless --fresh; so an interrupted bench continues where it stopped.
"""
import argparse
import json
import os
import shutil
import sys
import time

import numpy as np

from scripts import bench_report
from scripts.bench_beds import bed_infos, make_bed
from scripts.bench_config import (ENGINES, PROFILE_MAX_SIZE, RUN_TIMEOUT_S, SIZES, STEPS, TILES, VARIANT_NAMES, log,
                                  variant_dispersity)
from scripts.bench_runs import ENGINE_BINARY, calibrate_liggghts, feature_check, run_jdem, run_liggghts
from scripts.bench_scenes import deck_dir, make_decks, make_scene, scene_path
from scripts.bench_summary import flatness, load_runs, machine_info, summarise
from scripts.engines import ROOT


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default=os.environ.get("BENCH_SIZES", "5k,20k"))
    ap.add_argument("--variants", default=os.environ.get("BENCH_VARIANTS", "all"))
    ap.add_argument("--engines", default=os.environ.get("BENCH_ENGINES", ",".join(ENGINES)))
    ap.add_argument("--repeats", type=int, default=int(os.environ.get("BENCH_REPEATS", "3")))
    ap.add_argument("--ranks-size", default=os.environ.get("BENCH_RANKS_SIZE", "20k"),
                    help="size at which the LIGGGHTS engines also run on 2 MPI ranks ('' for none)")
    ap.add_argument("--steps", default=os.environ.get("BENCH_STEPS", ""),
                    help="override steps per size, e.g. 5k=1000,20k=300")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench"))
    ap.add_argument("--fresh", action="store_true", help="forget earlier timings (beds are kept)")
    ap.add_argument("--threads", default=os.environ.get("BENCH_THREADS", "1,2"),
                    help="OpenMP thread counts of the jdem runs (default 1,2)")
    ap.add_argument("--threads-variants", default=os.environ.get("BENCH_THREADS_VARIANTS", "soft_mono"),
                    help="variants whose jdem runs use every --threads count ('all' for every variant); "
                         "the others run on 1 thread (default soft_mono: the beds the "
                         "thread target is set on; keeps make bench short)")
    ap.add_argument("--timeout", type=float, default=RUN_TIMEOUT_S,
                    help="seconds after which one engine run is killed and recorded as failed")
    ap.add_argument("--keep-files", action="store_true",
                    help="keep the LIGGGHTS decks of the tiled sizes after their timings (~0.5 GB per variant at 1M)")
    ap.add_argument("--report-only", action="store_true")
    ap.add_argument("--prepare-only", action="store_true",
                    help="generate the beds, scenes and decks only (no timings, no report)")
    ap.add_argument("--no-profile", action="store_true", help="skip the callgrind profile of jdem")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    runs_path = os.path.join(out, "runs.jsonl")
    if a.fresh and os.path.exists(runs_path):
        os.remove(runs_path)
    steps_of = dict(STEPS)
    for item in filter(None, a.steps.split(",")):
        k, v = item.split("=")
        steps_of[k] = int(v)
    sizes = [s for s in a.sizes.split(",") if s]
    for s in sizes:
        if s not in SIZES:
            ap.error("unknown size %s (valid: %s)" % (s, ", ".join(SIZES)))
    variants = VARIANT_NAMES if a.variants == "all" else a.variants.split(",")
    for v in variants:
        if v not in VARIANT_NAMES:
            ap.error("unknown variant %s (valid: all, %s)" % (v, ", ".join(VARIANT_NAMES)))
    engines = a.engines.split(",")
    threads = [int(t) for t in a.threads.split(",") if t]

    if not a.report_only:
        done = {}
        for r in load_runs(runs_path):
            if r.get("failed"):
                continue  # a failed run is tried again
            key = (r["size"], r["variant"], r["engine"], r["ranks"], r.get("threads", 1), r["steps"])
            done[key] = done.get(key, 0) + 1
        for size in sizes:
            beds = {disp: make_bed(out, size, disp) for disp in ("mono", "bi")
                    if any(variant_dispersity(v) == disp for v in variants)}
            steps = steps_of[size]
            for variant in variants:
                disp = variant_dispersity(variant)
                t0 = time.time()
                scene, dt = make_scene(out, size, variant, beds[disp], steps)
                t_scene = time.time() - t0
                n = int(np.load(beds[disp])["id"].shape[0])
                t0 = time.time()
                decks = make_decks(out, size, variant, scene, beds[disp], steps, engines)
                log("%s %s: scene and decks ready (%.0f s)" % (size, variant, time.time() - t0 + t_scene))
                if a.prepare_only:
                    continue
                jobs = []
                for engine in engines:
                    if engine == "jdem":
                        many = a.threads_variants == "all" or variant in a.threads_variants.split(",")
                        jobs += [(engine, 1, t) for t in (threads if many else [1])]
                        continue
                    if engine not in decks:
                        continue  # bonded variant: stock LIGGGHTS has no parallel bonds (n/a)
                    jobs.append((engine, 1, 1))
                    if size == a.ranks_size:
                        jobs.append((engine, 2, 1))
                for rep in range(a.repeats):
                    for engine, ranks, nt in jobs:
                        key = (size, variant, engine, ranks, nt, steps)
                        if done.get(key, 0) > rep:
                            continue
                        try:
                            if engine == "jdem":
                                res = run_jdem(out, size, variant, scene, steps, n, threads=nt, timeout=a.timeout)
                            else:
                                res = run_liggghts(out, size, variant, decks[engine], engine, ranks, steps, n,
                                                   timeout=a.timeout)
                        except RuntimeError as e:  # timeouts, crashes: recorded, the bench goes on
                            log("%s %s %s np=%d threads=%d rep %d FAILED: %s"
                                % (size, variant, engine, ranks, nt, rep, str(e)[-2000:]))
                            with open(runs_path, "a") as f:
                                f.write(json.dumps(dict(size=size, variant=variant, engine=engine, ranks=ranks,
                                                        threads=nt, n=n, steps=steps, repeat=rep,
                                                        failed=str(e)[-2000:])) + "\n")
                            continue
                        res.update(size=size, variant=variant, engine=engine, ranks=ranks, threads=nt,
                                   n=n, steps=steps, dt=dt, repeat=rep, when=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                                   load_average=os.getloadavg()[0],
                                   binary_mtime=time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(os.path.getmtime(
                                       ENGINE_BINARY[engine]))))
                        log("%s %s %s np=%d threads=%d rep %d: %.3f s, %.3g particle-steps/s, %.2f contacts/particle"
                            % (size, variant, engine, ranks, nt, rep, res["wall_s"], n * steps / res["wall_s"],
                               res["contacts_per_particle"]))
                        with open(runs_path, "a") as f:
                            f.write(json.dumps(res) + "\n")
                for rep in range(a.repeats):  # CPU-time calibration of the LIGGGHTS engines (1 rank)
                    for engine in engines:
                        key = (size, variant, engine + "/calib", 1, 1, steps)
                        if engine == "jdem" or engine not in decks or done.get(key, 0) > rep:
                            continue
                        try:
                            res = calibrate_liggghts(decks[engine], engine, timeout=a.timeout)
                        except RuntimeError as e:
                            log("%s %s %s 1-step calibration FAILED: %s" % (size, variant, engine, str(e)[-2000:]))
                            continue
                        res.update(size=size, variant=variant, engine=engine + "/calib", ranks=1, n=n,
                                   steps=steps, dt=dt, repeat=rep, load_average=os.getloadavg()[0])
                        with open(runs_path, "a") as f:
                            f.write(json.dumps(res) + "\n")
                if size in TILES and not a.keep_files and os.path.isdir(deck_dir(out, size, variant)):
                    shutil.rmtree(deck_dir(out, size, variant))  # ~0.5 GB per variant at 1M
    if a.prepare_only:
        return 0
    # the feature check and the profile on the smallest size run (callgrind is ~50x slower than
    # the run itself: never above PROFILE_MAX_SIZE)
    small = min(sizes, key=SIZES.get)
    if not a.report_only and "jdem" in engines and "soft_mono" in variants:
        feature_check(out, small, steps_of[small], a.repeats, timeout=a.timeout)
    if not a.report_only and not a.no_profile and not os.path.exists(os.path.join(out, "profile.json")):
        sc = scene_path(out, small, "soft_mono")
        if SIZES[small] > SIZES[PROFILE_MAX_SIZE]:
            log("no callgrind profile: the smallest size run (%s) is above %s" % (small, PROFILE_MAX_SIZE))
        elif os.path.exists(sc):
            log("profiling jdem (callgrind) on %s" % sc)
            bench_report.profile_jdem(out, sc, int(np.load(make_bed(out, small, "mono"))["id"].shape[0]))
    all_runs = load_runs(runs_path)
    rows = summarise([r for r in all_runs if not r.get("failed")])
    failures = [r for r in all_runs if r.get("failed")]
    fc_path = os.path.join(out, "feature_check.json")
    fc = json.load(open(fc_path)) if os.path.exists(fc_path) else None
    beds = bed_infos(out)
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(dict(generated=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                       machine=machine_info(), runs=rows, flatness=flatness(rows), beds=beds,
                       failures=failures, feature_check=fc), f, indent=1)
    bench_report.write_report(out, rows, machine_info(), fc, flatness(rows), beds, failures)
    log("wrote %s and %s" % (os.path.join(out, "summary.json"), os.path.join(out, "report.md")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
