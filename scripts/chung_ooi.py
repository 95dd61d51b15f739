#!/usr/bin/python3
"""Chung & Ooi (2011) benchmark: run the eight tests, analyse them, write the report, check them.

    chung_ooi.py run     --out out/chung_ooi [--tests 1,2,...] [--engines jdem[,liggghts]]
                         [--jobs 2] [--quick]
    chung_ooi.py analyse --out out/chung_ooi [--tests ...] [--engines ...] [--quick]
    chung_ooi.py check   --out out/chung_ooi

`--model OPTION=VALUE` (run, analyse; repeatable) runs every test with that `model:` option set
(the scenes are written to OUT/scenes/), e.g. `--model tangential_stiffness=mindlin`.

`run` runs every case of reference_runs/chung_ooi/testN/scene.yaml (`build/jdem cases SCENE`)
into OUT/testN/CASE.ENGINE.h5, then does what `analyse` does: it reads the trajectories, writes
OUT/summary.json (one record per metric, with its reference and error), one figure per test
(OUT/testN.png) and OUT/report.md; `analyse` alone re-analyses existing trajectories.  `check`
reads summary.json, prints one PASS/FAIL line per asserted metric and exits non-zero on any
failure.  `--quick` selects the subset QUICK_CASES.  Run wall times go to OUT/run_times.json.

Every reference is independent of the engine: closed-form Hertz computed from E, nu, rho, R and v;
the spec's tabulated restitution (jiang_model.md 13.4, Test 3); rigid-body impulse theory
(anchors.md 1.3), for a sphere on a plane with the lever arm R - delta of its contact (closed-form
Hertz mean).  The only run values they use are the measured e_n and the pre-impact state.

This file is the command line; the work is done by the package scripts/benchmark/:
    cases.py       the tests, their cases (QUICK_CASES) and the paths of scenes, tools, trajectories
    runner.py      running the cases in the engines
    trajectory.py  reading a trajectory; the impact kinematics and the sign conventions
    references.py  closed-form Hertz, rigid-body limits, lever-arm correction, tabulated references
    analysis.py    tolerances and the summary records of every metric
    figures.py     one figure per test
    report.py      report.md
"""
import argparse
import json
import os
import sys

from scripts.benchmark.analysis import analyse_all
from scripts.benchmark import cases
from scripts.benchmark.cases import ENGINE_LABEL, LIGGGHTS, ROOT, TESTS
from scripts.benchmark.figures import write_figure
from scripts.benchmark.report import write_report
from scripts.benchmark.runner import run_all


def analyse_and_report(out, tests, engines, quick, timings):
    records, runs = analyse_all(out, tests, engines, quick, timings)
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(records, f, indent=1)
    figures = {t: write_figure(out, t, records, runs, engines) for t in tests}
    write_report(out, records, engines, figures)
    print(f"wrote {os.path.relpath(out, ROOT)}/summary.json and report.md", file=sys.stderr)


def parse_engines(text):
    engines = text.split(",")
    unknown = set(engines) - set(ENGINE_LABEL)
    if unknown:
        raise SystemExit(f"unknown engine(s) {sorted(unknown)}; valid: jdem, liggghts")
    if "liggghts" in engines and not os.path.exists(LIGGGHTS):
        print("liggghts requested but build/liggghts-jdem is missing: "
              "running jdem only", file=sys.stderr)
        engines.remove("liggghts")
    return engines


def cmd_run(args):
    timings = run_all(args.out, args.tests, args.engines, args.jobs, args.quick)
    with open(os.path.join(args.out, "run_times.json"), "w") as f:
        json.dump(timings, f, indent=1)
    analyse_and_report(args.out, args.tests, args.engines, args.quick, timings)
    return 0


def cmd_analyse(args):
    """Re-analyse existing trajectories, with the wall times of the last `run` if recorded."""
    path = os.path.join(args.out, "run_times.json")
    timings = []
    if os.path.exists(path):
        with open(path) as f:
            timings = [t for t in json.load(f) if t["test"] in args.tests and t["engine"] in args.engines]
    analyse_and_report(args.out, args.tests, args.engines, args.quick, timings)
    return 0


def cmd_check(args):
    with open(os.path.join(args.out, "summary.json")) as f:
        records = json.load(f)
    failures = 0
    for r in records:
        if r["pass"] is None:
            continue
        line = (f"chung_ooi/test{r['test']}/{r['case']}/{r['engine']}/{r['metric']}: "
                f"{r['value']:.6g} vs {r['reference']:.6g}, error {r['rel_error']:.3g} "
                f"(tolerance {r['tolerance']:g})")
        print(("PASS " if r["pass"] else "FAIL ") + line)
        failures += not r["pass"]
    if not any(r["pass"] is not None for r in records):
        print("FAIL chung_ooi: summary.json holds no asserted metric")
        return 1
    return 1 if failures else 0


def model_option(text):
    option, sep, value = text.partition("=")
    if not sep or not option or not value:
        raise argparse.ArgumentTypeError(f"'{text}': expected OPTION=VALUE")
    return option, value


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name in ("run", "analyse"):
        p = sub.add_parser(name)
        p.add_argument("--out", default=os.path.join(ROOT, "out", "chung_ooi"))
        p.add_argument("--tests", default="1,2,3,4,5,6,7,8",
                       type=lambda s: [int(t) for t in s.split(",")])
        p.add_argument("--engines", default="jdem", type=parse_engines)
        p.add_argument("--quick", action="store_true", help="the representative subset QUICK_CASES")
        p.add_argument("--model", action="append", default=[], type=model_option,
                       help="OPTION=VALUE: a model option set in every scene")
        if name == "run":
            p.add_argument("--jobs", type=int, default=2)
    p = sub.add_parser("check")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "chung_ooi"))
    args = parser.parse_args(argv[1:])
    args.out = os.path.abspath(args.out)
    if args.command != "check":
        bad = set(args.tests) - set(TESTS)
        if bad:
            parser.error(f"unknown test(s) {sorted(bad)}; valid: 1..8")
        os.makedirs(args.out, exist_ok=True)
        if args.model:
            cases.use_model_options(dict(args.model), args.out)
    return {"run": cmd_run, "analyse": cmd_analyse, "check": cmd_check}[args.command](args)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
