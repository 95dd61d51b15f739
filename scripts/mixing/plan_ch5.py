"""plan_ch5.py — the units of `make mixing-bonded` for scripts/campaign.py (docs/mixing.md §11).

    scripts/campaign.py scripts/mixing/plan_ch5.py [--model groupG_modelM] [--engine ENGINE]
                        [--unit NAME] [--list] [-- --ranks N]

Per engine (jdem, liggghts-jdem) and case of reference_runs/mixing/ch5/models.yaml (Groups 1-3
x Models 1-6): the fill, `ENGINE/groupG_modelM/fill` into out/mixing/ch5/ENGINE/CASE/fill.h5, at
the seed's dt = 1e-4 s, which the guard accepts for Table 5-1's softer small spheres (largest
safe dt 1.28e-4 s; Chapter 4's needs --force, docs/mixing.md §6).  Each fill is resumable the way plan_ch4's are (jdem's checkpoints,
LIGGGHTS' restart files), and writes its scene first: `jdem resolve` of the case, the one scene
both engines run.  --ranks N runs each liggghts-jdem fill on N MPI ranks.  The Ch. 5
measurements (the 27 points, the cubes of the middle clip under 5 kPa) are not units yet.
"""
import os
import shlex

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
from scripts.campaign import Unit
from scripts.mixing.plan_ch4 import (ENGINES, FILL_PARTICLES, FILL_TIME, SEED_DT, fill_command,
                                     fill_ranks, jdem, resumable, valid_trajectory)

SCENE = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "models.yaml")
OUT = os.path.join(ROOT, "out", "mixing", "ch5")
CASES = [f"group{g}_model{m}" for g in range(1, 4) for m in range(1, 7)]


def fill_unit(engine, case, ranks):
    resolve = f'{shlex.quote(jdem())} resolve {shlex.quote(SCENE)} --case {case} > "$1"'
    return Unit(f"{engine}/{case}/fill", [os.path.join(OUT, engine, case, "fill.h5")],
                fill_command(engine, "{dir}/fill.yaml", False, resolve, ranks=ranks), case, engine,
                validate=valid_trajectory, cost=FILL_PARTICLES * FILL_TIME / SEED_DT,
                resumes=resumable(engine), ranks=fill_ranks(engine, ranks))


def units(argv):
    import argparse
    ap = argparse.ArgumentParser(prog="plan_ch5.py")
    ap.add_argument("--ranks", type=int, default=1,
                    help="MPI ranks of each liggghts-jdem fill (default 1; jdem runs its own threads)")
    a = ap.parse_args(argv)
    if a.ranks < 1:
        ap.error("--ranks %d: valid: a positive number of MPI ranks" % a.ranks)
    return [fill_unit(engine, case, a.ranks) for engine in ENGINES for case in CASES]
