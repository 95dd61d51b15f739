"""plan.py — the units of `make sandpile` for scripts/campaign.py (docs/sandpile.md).

    scripts/campaign.py scripts/sandpile/plan.py [--model CASE] [--engine ENGINE] [--unit NAME] [--list]

Per engine (jdem, liggghts-jdem) and per case of reference_runs/sandpile/sandpile.yaml (Del Cid's
Table 4.3: dry and kc = 1.07e7, mu_r = 0.1, 0.2, 0.4, 0.6): the settling with the outlets shut
(`fill`), the discharge scene written from its last frame (`discharge_scene`) and the discharge
(`discharge`), under out/sandpile/ENGINE/CASE/; and the restart's control (`control_scene`,
`control`: the same restart with the outlets kept, 0.05 s, discharge.py --control).  Both runs checkpoint (jdem every
CHECKPOINT_SECONDS of wall time, LIGGGHTS a restart file every RESTART_STEPS steps) and continue
after an interruption.  A unit's cost for the ETA is its particle-steps.  A case whose result is
committed (reference_runs/sandpile/results/summary.json, `make sandpile-report`) is skipped on a
machine without its outputs.
"""
import functools
import json
import os
import shlex
import subprocess

import yaml

from scripts.campaign import Unit
from scripts.mixing.plan_ch4 import fill_command, jdem, valid_scene, valid_trajectory
from scripts.sandpile.discharge import CONTROL_TIME, DISCHARGE_TIME, SCENE

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
PY = "/usr/bin/python3"
OUT = os.path.join(ROOT, "out", "sandpile")
RESULTS = os.path.join(ROOT, "reference_runs", "sandpile", "results")
ENGINES = ("jdem", "liggghts-jdem")
CHECKPOINT_SECONDS = 300
RESTART_STEPS = 50000        # about 0.07 s of a run at the guard's dt
DISCHARGED = 0.7             # about the mean share of the spheres a discharge carries (only the ETA
                             # reads it: the outlets release about half at once, the rest stays)


@functools.lru_cache(maxsize=None)
def resolved():
    """The first case's resolved scene (dt, duration and particle count are the same in all)."""
    args = [jdem(), "resolve", SCENE, "--case", cases()[0]]
    return yaml.load(subprocess.run(args, check=True, capture_output=True, text=True).stdout,
                     Loader=yaml.CSafeLoader)


@functools.lru_cache(maxsize=None)
def cases():
    return subprocess.run([jdem(), "cases", SCENE], check=True, capture_output=True,
                          text=True).stdout.split()


@functools.lru_cache(maxsize=None)
def committed_cases():
    try:
        with open(os.path.join(RESULTS, "summary.json")) as f:
            return {(r["engine"], r["case"]) for r in json.load(f)["runs"]}
    except (OSError, ValueError, KeyError):
        return set()


def case_units(engine, case):
    base = os.path.join(OUT, engine, case)
    fill, scene, discharge, control_scene, control = (
        os.path.join(base, n) for n in ("fill.h5", "discharge.yaml", "discharge.h5", "control.yaml", "control.h5"))
    pre = f"{engine}/{case}"
    doc = resolved()
    n, dt = len(doc["particles"]), doc["time"]["dt"]
    kept = (lambda: os.path.relpath(os.path.join(RESULTS, "summary.json"), ROOT)
            if (engine, case) in committed_cases() else None)
    resolve = f'{shlex.quote(jdem())} resolve {shlex.quote(SCENE)} --case {shlex.quote(case)} > "$1"'
    return [
        Unit(f"{pre}/fill", [fill],
             fill_command(engine, "{dir}/fill.yaml", False, resolve, CHECKPOINT_SECONDS, RESTART_STEPS),
             case, engine, validate=valid_trajectory, cost=n * doc["time"]["steps"],
             resumes=True, committed=kept),
        Unit(f"{pre}/discharge_scene", [scene],
             [PY, os.path.join(HERE, "discharge.py"), fill, "--case", case, "-o", "{out0}"],
             case, engine, needs=[f"{pre}/fill"], validate=valid_scene, cost=n, committed=kept),
        Unit(f"{pre}/discharge", [discharge],
             fill_command(engine, scene, False, None, CHECKPOINT_SECONDS, RESTART_STEPS),
             case, engine, needs=[f"{pre}/discharge_scene"], validate=valid_trajectory,
             cost=DISCHARGED * n * DISCHARGE_TIME / dt, resumes=True, committed=kept),
        Unit(f"{pre}/control_scene", [control_scene],
             [PY, os.path.join(HERE, "discharge.py"), fill, "--case", case, "--control", "-o", "{out0}"],
             case, engine, needs=[f"{pre}/fill"], validate=valid_scene, cost=n, committed=kept),
        Unit(f"{pre}/control", [control], fill_command(engine, control_scene, False),
             case, engine, needs=[f"{pre}/control_scene"], validate=valid_trajectory,
             cost=n * CONTROL_TIME / dt, committed=kept),
    ]


def units(argv):
    import argparse
    argparse.ArgumentParser(prog="plan.py").parse_args(argv)
    return [u for case in cases() for engine in ENGINES for u in case_units(engine, case)]
