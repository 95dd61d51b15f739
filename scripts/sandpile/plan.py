"""plan.py — the units of `make sandpile` for scripts/campaign.py (docs/sandpile.md).

    scripts/campaign.py scripts/sandpile/plan.py [--model CASE] [--engine ENGINE] [--unit NAME] [--list]

Per engine (jdem, liggghts-jdem) and per case of reference_runs/sandpile/sandpile.yaml (Del Cid's
Table 4.3: dry and kc = 1.07e7, mu_r = 0.1, 0.2, 0.4, 0.6) one unit, `ENGINE/CASE/pile`: the
case resolved into the unit's directory and run (the settling, the outlets vanishing at 0.8 s,
the discharge) into out/sandpile/ENGINE/CASE/pile.h5.  The run checkpoints (jdem every
CHECKPOINT_SECONDS of wall time, LIGGGHTS a restart file every RESTART_STEPS steps) and continues
after an interruption.  A unit's cost for the ETA is its particle-steps.  A case whose result is
committed (reference_runs/sandpile/results/summary.json, `make sandpile-report`) is skipped on a
machine without its output.
"""
import functools
import json
import os
import shlex
import subprocess

import yaml

from scripts.campaign import Unit
from scripts.mixing.plan_ch4 import fill_command, jdem, valid_trajectory

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(ROOT, "reference_runs", "sandpile", "sandpile.yaml")
OUT = os.path.join(ROOT, "out", "sandpile")
RESULTS = os.path.join(ROOT, "reference_runs", "sandpile", "results")
ENGINES = ("jdem", "liggghts-jdem")
CHECKPOINT_SECONDS = 300
RESTART_STEPS = 50000        # about 0.1 s of a run at the guard's dt
CARRIED = 0.8                # about the mean share of the spheres a run carries (only the ETA
                             # reads it: half leave within 0.3 s of the opening)


@functools.lru_cache(maxsize=None)
def cases():
    return subprocess.run([jdem(), "cases", SCENE], check=True, capture_output=True,
                          text=True).stdout.split()


@functools.lru_cache(maxsize=None)
def resolved():
    """The first case's resolved scene (dt, duration and particle count are the same in all)."""
    return yaml.load(subprocess.run([jdem(), "resolve", SCENE, "--case", cases()[0]], check=True,
                                    capture_output=True, text=True).stdout, Loader=yaml.CSafeLoader)


@functools.lru_cache(maxsize=None)
def committed_cases():
    try:
        with open(os.path.join(RESULTS, "summary.json")) as f:
            return {(r["engine"], r["case"]) for r in json.load(f)["runs"]}
    except (OSError, ValueError, KeyError):
        return set()


def pile_unit(engine, case):
    doc = resolved()
    resolve = f'{shlex.quote(jdem())} resolve {shlex.quote(SCENE)} --case {shlex.quote(case)} > "$1"'
    return Unit(f"{engine}/{case}/pile", [os.path.join(OUT, engine, case, "pile.h5")],
                fill_command(engine, "{dir}/pile.yaml", False, resolve, CHECKPOINT_SECONDS, RESTART_STEPS),
                case, engine, validate=valid_trajectory,
                cost=CARRIED * len(doc["particles"]) * doc["time"]["steps"], resumes=True,
                committed=lambda: os.path.relpath(os.path.join(RESULTS, "summary.json"), ROOT)
                if (engine, case) in committed_cases() else None)


def units(argv):
    import argparse
    argparse.ArgumentParser(prog="plan.py").parse_args(argv)
    return [pile_unit(engine, case) for case in cases() for engine in ENGINES]
