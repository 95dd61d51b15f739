#!/usr/bin/python3
"""Evidence for a model option: run Chung–Ooi tests with each value of one `model:` option and
print, per test and metric, the RMS and largest deviation from the references that
scripts/chung_ooi.py uses (closed forms, rigid-body limits, the digitized Test 5 curves).

    scripts/model_option_evidence.py tangential_limit coulomb unconstrained [--tests 4,5,6,8]

Writes the scenes and trajectories under out/evidence/OPTION/VALUE/.  The result of this command
is quoted in docs/model.md (choice of the tangential limit).
"""
import argparse
import collections
import os

import numpy as np
from scripts import chung_ooi  # the benchmark's runner and analysis, reused as they are
from scripts.benchmark import cases  # its scene_path is replaced per option value

SKIPPED_METRICS = {"run_wall_time_s", "force_at_end"}


def deviations(records):
    """{(test, metric): array of |value - reference|} over the records with a reference."""
    dev = collections.defaultdict(list)
    for r in records:
        if r["metric"] in SKIPPED_METRICS or r.get("reference") is None or r.get("value") is None:
            continue
        dev[(r["test"], r["metric"])].append(abs(r["value"] - r["reference"]))
    return {k: np.array(v) for k, v in dev.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("option")
    parser.add_argument("values", nargs="+")
    parser.add_argument("--tests", default="4,5,6,8")
    args = parser.parse_args()
    tests = [int(t) for t in args.tests.split(",")]
    results = {}
    for value in args.values:
        work = os.path.join(chung_ooi.ROOT, "out", "evidence", args.option, value)
        cases.use_model_options({args.option: value}, work)
        chung_ooi.run_all(os.path.join(work, "out"), tests, ["jdem"], 2, False)
        records, _ = chung_ooi.analyse_all(os.path.join(work, "out"), tests, ["jdem"], False, [])
        results[value] = deviations(records)
    print("| test | metric | " + " | ".join(f"{v}: rms / max" for v in args.values) + " |")
    print("|---|---|" + "---|" * len(args.values))
    for key in sorted(results[args.values[0]]):
        cells = []
        for value in args.values:
            d = results[value].get(key)
            cells.append("–" if d is None else f"{np.sqrt(np.mean(d ** 2)):.3g} / {d.max():.3g}")
        print(f"| {key[0]} | {key[1]} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
