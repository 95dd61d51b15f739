"""plan_ch5.py — the units of `make mixing-bonded` for scripts/campaign.py (docs/mixing.md §11).

    scripts/campaign.py scripts/mixing/plan_ch5.py [--model groupG_modelM] [--engine ENGINE]
                        [--unit NAME] [--list] [-- --ranks N]

Per engine (jdem, liggghts-jdem) and case of reference_runs/mixing/ch5/models.yaml (Groups 1-3
x Models 1-6): the fill, `ENGINE/groupG_modelM/fill` into out/mixing/ch5/ENGINE/CASE/fill.h5 (a
liggghts-jdem fill and its cubes at plan_ch4.LIGGGHTS_SKIN, as Chapter 4's: the same stream), at
the seed's dt = 1e-4 s, which the guard accepts for Table 5-1's softer small spheres (largest
safe dt 1.28e-4 s; Chapter 4's needs --force, docs/mixing.md §6).  Each fill is resumable the way plan_ch4's are (jdem's checkpoints,
LIGGGHTS' restart files), and writes its scene first: `jdem resolve` of the case, the one scene
both engines run.  --ranks N runs each liggghts-jdem fill on N MPI ranks.  After each fill:
`ENGINE/CASE/cubes`, the 9 cube scenes of the middle clip (reference_runs/mixing/ch5/generate.py:
points 10-18 of Table 5-2 under 5 kPa, each with its own copy of the deposit and its intact
bonds), and `ENGINE/CASE/cubeK`, K = 10..18, their compressions, into
out/mixing/ch5/ENGINE/CASE/cubeK.h5 (the 27 points' phi_v are read from the fill itself).
Chapter 6's rigid cements add two fills per engine, rigid_model1 and rigid_model3 (Figs 6-1 and
6-2), drawn but not compressed (the seed measures nothing in them).  SPREAD_REALISATIONS's cases
run their fill again with the stream shifted by K micrometres (`ENGINE/CASE/fill_jitterK`, not
compressed): the run-to-run spread of whole fills (agreement_ch5.py).  Last, per bonded case
(Groups 2 and 3), the cross-engine horizon (`cross/groupG_modelM/horizon`: the first
HORIZON_TIME s of the fill in both engines, compared particle by particle and break by break,
scripts/mixing/horizon_ch5.py), and each engine's runs of it with the stream shifted by K =
1..6 micrometres (`cross/groupG_modelM/jitterK`, `.../liggghts-jdem_jitterK`: the run-to-run
spread of the breaks).  A unit whose result is committed (reference_runs/mixing/ch5/results/:
summary.json of report_ch5.py, horizon/summary.json of horizon_ch5.py) is skipped on a machine
without its outputs unless a unit that runs reads them (scripts/campaign.py).
"""
import functools
import os
import shlex

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
from scripts.campaign import Unit
from scripts.mixing.plan_ch4 import (CUBE_PARTICLES, CUBE_TIME, ENGINES, FILL_PARTICLES, FILL_TIME,
                                     HORIZON_COST, PY, SCENE_COST, SEED_DT, fill_command, fill_ranks, jdem,
                                     read_committed, resumable, run_command, valid_json, valid_scene,
                                     valid_trajectory)

from scripts.mixing.horizon_ch5 import END_TIME as HORIZON_TIME, REALISATIONS, realisation_path

SCENE = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "models.yaml")
GENERATE = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "generate.py")
CUBES = range(10, 19)     # Table 5-2's middle clip
OUT = os.path.join(ROOT, "out", "mixing", "ch5")
RESULTS = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "results")
CASES = [f"group{g}_model{m}" for g in range(1, 4) for m in range(1, 7)]
RIGID_CASES = ["rigid_model1", "rigid_model3"]   # Ch. 6, Figs 6-1 and 6-2: pictures, no cubes
# the cross-engine horizons: the bonded groups (Group 1 has no bonds; its horizon is Ch. 4's)
HORIZON_CASES = [c for c in CASES if not c.startswith("group1_")]
# the run-to-run spread of whole fills, against which the engines' fills are weighed
# (agreement_ch5.py): the fill again with the stream shifted by K micrometres, K = 1..N.  Model 5
# (two obstacles; φv at the middle clip 0.037, 0.032 and 0.027 in Groups 1-3 in jdem, where Model
# 3's Group 3 fill has 0.0036, under the tenth of the ideal that measures no φv spread) once per
# group in jdem, which the group's pool needs, and Group 3's (the only group whose bonds neither
# all break nor are absent) in liggghts-jdem too, which checks that the spread is the fill's, not
# an engine's.  Groups 1 and 2 twice: one realisation gave a std of one degree of freedom, and
# Group 1's (φv 0.0383 against the fill's 0.0372) sat far under the engines' difference on the
# same cases (0.0088 in Model 5, 0.0110 in Model 3)
SPREAD_REALISATIONS = {"jdem": {"group1_model5": 2, "group2_model5": 2, "group3_model5": 1},
                       "liggghts-jdem": {"group3_model5": 1}}


@functools.lru_cache(maxsize=None)
def committed_ch5():
    return read_committed(os.path.join(RESULTS, "summary.json")).get("results", {})


@functools.lru_cache(maxsize=None)
def committed_horizons():
    return read_committed(os.path.join(RESULTS, "horizon", "summary.json"))


def committed_fill(engine, case, cubes=False):
    """f() for Unit.committed: where report_ch5.py's committed summary holds the engine's fill of
    the case (with cubes: and its 9 compressions)."""
    def where():
        entry = committed_ch5().get(f"{engine}/{case}")
        if not entry or (cubes and len(entry.get("cubes") or []) < len(CUBES)):
            return None
        return "%s: %s/%s%s of commit %s" % (os.path.relpath(os.path.join(RESULTS, "summary.json"), ROOT),
                                            engine, case, ", cubes" if cubes else "",
                                            entry.get("source", "?"))
    return where


def committed_realisation(engine, case, k):
    """f() for Unit.committed: where report_ch5.py's committed summary holds the engine's
    realisation K of the case's fill."""
    def where():
        entry = committed_ch5().get(f"{engine}/{case}") or {}
        if not any(r.get("jitter") == k for r in entry.get("realisations", [])):
            return None
        return "%s: %s/%s, realisation %d" % (os.path.relpath(os.path.join(RESULTS, "summary.json"), ROOT),
                                              engine, case, k)
    return where


def committed_horizon(case, engine=None, k=None):
    """f() for Unit.committed: where horizon_ch5.py's committed summary holds the case's horizon
    (engine and k: that engine's realisation K)."""
    def where():
        h = committed_horizons()
        if engine is None:
            found = any(c.get("case") == case for c in h.get("cases", []))
        else:
            found = any(r.get("jitter") == k for r in h.get("realisations", {}).get(case, {}).get(engine, []))
        return os.path.relpath(os.path.join(RESULTS, "horizon", "summary.json"), ROOT) if found else None
    return where


# The fills that keep the energy accounts: jdem's Models 2 and 4 (one obstacle and two) in every
# group, the energy balance over a whole bonded fill ("give the worst fill").  Every other
# fill runs the case with output.energy: false: the same trajectory bit for bit (suite cross-engine,
# the energy-off checks), and the pair loops then keep 7 doubles of history a contact instead of 23,
# 1.57x faster in liggghts-jdem on a Group 2 deposit and 1.9x in jdem (docs/mixing.md §11).
ENERGY_MODELS = ("model2", "model4")
# what the accounts multiply a jdem fill's time by, for the ETA (docs/performance.md, "The energy
# accounts on an AMD EPYC of family 26": time loop 7.5 s against 4.0 s)
ENERGY_COST = 1.9


def keeps_energy(engine, case):
    """Whether ENGINE's fill of CASE keeps the energy accounts (ENERGY_MODELS)."""
    return engine == "jdem" and case in CASES and case.split("_")[1] in ENERGY_MODELS


def fill_cost(energy):
    """A fill's cost for the ETA: its particle-steps, times ENERGY_COST if it keeps the accounts."""
    return FILL_PARTICLES * FILL_TIME / SEED_DT * (ENERGY_COST if energy else 1.0)


def no_energy_scene(case, jitter=0):
    """The shell line writing the case without energy accounts (the stream shifted by jitter
    micrometres) into "$1"."""
    return (f'{shlex.quote(PY)} {shlex.quote(GENERATE)} fill --case {case} --no-energy '
            + (f'--jitter {jitter} ' if jitter else '') + '-o "$1"')


def fill_unit(engine, case, ranks):
    if keeps_energy(engine, case):
        resolve = f'{shlex.quote(jdem())} resolve {shlex.quote(SCENE)} --case {case} > "$1"'
    else:
        resolve = no_energy_scene(case)
    return Unit(f"{engine}/{case}/fill", [os.path.join(OUT, engine, case, "fill.h5")],
                fill_command(engine, "{dir}/fill.yaml", False, resolve, ranks=ranks), case, engine,
                validate=valid_trajectory, cost=fill_cost(keeps_energy(engine, case)),
                resumes=resumable(engine), ranks=fill_ranks(engine, ranks),
                committed=committed_fill(engine, case))


def spread_units(engine, case, ranks):
    """The case's fill again with the stream shifted by K micrometres (generate.py --jitter),
    K = 1..SPREAD_REALISATIONS[engine][case], into out/mixing/ch5/ENGINE/CASE/fill_jitterK.h5;
    without energy accounts, and not compressed: the deposit's statistics are what the spread
    is of."""
    return [Unit(f"{engine}/{case}/fill_jitter{k}", [os.path.join(OUT, engine, case, f"fill_jitter{k}.h5")],
                 fill_command(engine, "{dir}/fill_jitter%d.yaml" % k, False, no_energy_scene(case, k),
                              ranks=ranks),
                 case, engine, validate=valid_trajectory, cost=fill_cost(False),
                 resumes=resumable(engine), ranks=fill_ranks(engine, ranks),
                 committed=committed_realisation(engine, case, k))
            for k in range(1, SPREAD_REALISATIONS[engine].get(case, 0) + 1)]


def cube_units(engine, case):
    """The middle clip's 9 cube scenes of the fill's deposit, and their compressions."""
    base = os.path.join(OUT, engine, case)
    scenes = [os.path.join(base, "cubes", f"cube{k}.yaml") for k in CUBES]
    units = [Unit(f"{engine}/{case}/cubes", scenes,
                  [PY, GENERATE, "cubes", os.path.join(base, "fill.h5"), "--case", case,
                   "-o", "{dir}", "--scene-dir", os.path.join(base, "cubes")],
                  case, engine, needs=[f"{engine}/{case}/fill"],
                  validate=valid_scene, cost=SCENE_COST, committed=committed_fill(engine, case, True))]
    for k, scene in zip(CUBES, scenes):
        units.append(Unit(f"{engine}/{case}/cube{k}", [os.path.join(base, f"cube{k}.h5")],
                          run_command(engine, scene, "{out0}", False), case, engine,
                          needs=[f"{engine}/{case}/cubes"], validate=valid_trajectory,
                          cost=CUBE_PARTICLES * CUBE_TIME / SEED_DT,
                          committed=committed_fill(engine, case, True)))
    return units


def horizon_particle_steps():
    """About the particle-steps of one engine's run of a horizon's first HORIZON_TIME s."""
    return FILL_PARTICLES * HORIZON_TIME / FILL_TIME * HORIZON_TIME / SEED_DT


def horizon_unit(case):
    """The cross-engine horizon of a bonded fill (scripts/mixing/horizon_ch5.py): its first
    HORIZON_TIME s in both engines, compared particle by particle and break by break."""
    out = os.path.join(OUT, "cross", case, "horizon.json")
    return Unit(f"cross/{case}/horizon", [out],
                [PY, os.path.join(HERE, "horizon_ch5.py"), "run", "--case", case,
                 "--end-time", repr(HORIZON_TIME), "--dir", "{dir}", "-o", "{out0}"],
                case, "cross", validate=valid_json("horizon", "breaks", "divergence"),
                cost=HORIZON_COST * horizon_particle_steps(), committed=committed_horizon(case))


def realisation_units(case):
    """Each engine's runs of a case's horizon with the stream shifted by K micrometres
    (scripts/mixing/horizon_ch5.py realisation): the run-to-run spread of its breaks at
    HORIZON_TIME (engine "cross": they serve the cross-engine comparison and run with it)."""
    return [Unit(f"cross/{case}/jitter{k}" if engine == "jdem" else f"cross/{case}/{engine}_jitter{k}",
                 [realisation_path(OUT, case, k, engine)],
                 [PY, os.path.join(HERE, "horizon_ch5.py"), "realisation", "--case", case,
                  "--engine", engine, "--jitter", str(k), "--end-time", repr(HORIZON_TIME),
                  "--dir", "{dir}", "-o", "{out0}"],
                 case, "cross", validate=valid_json("realisation", "totals"),
                 cost=(1.0 if engine == "jdem" else HORIZON_COST - 1.0) * horizon_particle_steps(),
                 committed=committed_horizon(case, engine, k))
            for engine in ENGINES for k in REALISATIONS]


def units(argv):
    import argparse
    ap = argparse.ArgumentParser(prog="plan_ch5.py")
    ap.add_argument("--ranks", type=int, default=1,
                    help="MPI ranks of each liggghts-jdem fill (default 1; jdem runs its own threads)")
    a = ap.parse_args(argv)
    if a.ranks < 1:
        ap.error("--ranks %d: valid: a positive number of MPI ranks" % a.ranks)
    return [u for engine in ENGINES for case in CASES + RIGID_CASES
            for u in [fill_unit(engine, case, a.ranks)] +
            (cube_units(engine, case) if case in CASES else []) + spread_units(engine, case, a.ranks)] + \
        [u for case in HORIZON_CASES for u in [horizon_unit(case)] + realisation_units(case)]
