"""plan_ch4.py — the units of `make mixing` for scripts/campaign.py (docs/mixing.md §4).

    scripts/campaign.py scripts/mixing/plan_ch4.py [--model modelM] [--engine ENGINE] [--list]
                        [-- --dt seed|guard|half] [--ranks N]

Per engine (jdem, liggghts-jdem) and model 1-6: the first fill, the second-pass scene cut from
it, the second fill, and per pass the 9 cube scenes and their 9 compressions; for Model 3 also
two realisations of the first fill with the stream shifted by 1 and 2 micrometres (the run-to-run
spread).  After them, per model, the cross-engine horizon (`cross/modelM/horizon`: the first
seconds of the first fill in both engines, compared particle by particle).  --dt picks the
time-step variant of the error-against-run-time study: `seed` (default) the seed's dt = 1e-4 s
under out/mixing/ch4/, run with --force because the guard refuses it (docs/mixing.md §6);
`guard` the guard's dt (what `time.dt: auto` resolves to) under out/mixing/ch4_dt_guard/; `half` half of it under
out/mixing/ch4_dt_half/.  --ranks N runs each liggghts-jdem fill on N MPI ranks (a run on more
ranks sums forces in another order: another realisation, as the spread's are).  A unit's cost for
the ETA is its particle-steps.

A unit whose result is committed (reference_runs/mixing/ch4/results/: summary.json of
report_ch4.py, horizon/summary.json of horizon_ch4.py; the seed-dt variant only) is skipped on a
machine without its outputs unless a unit that runs reads them (scripts/campaign.py).

A unit whose engine lacks a feature it needs is "not yet runnable": the plan asks the engine
itself, by reading a probe scene that uses the feature (jdem resolve; for liggghts-jdem also the
deck generator), so the gate lifts by itself once the feature lands.
"""
import functools
import json
import os
import shlex
import subprocess
import tempfile

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
from scripts.campaign import Unit

PY = "/usr/bin/python3"
SCENE = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "models.yaml")
GENERATE = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "generate.py")
RESULTS = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "results")
# each time-step variant's committed results (make mixing-report DT=guard|half writes them)
VARIANT_RESULTS = {"seed": RESULTS,
                   "guard": os.path.join(ROOT, "reference_runs", "mixing", "ch4_dt_guard", "results"),
                   "half": os.path.join(ROOT, "reference_runs", "mixing", "ch4_dt_half", "results")}
OUT = {"seed": os.path.join(ROOT, "out", "mixing", "ch4"),
       "guard": os.path.join(ROOT, "out", "mixing", "ch4_dt_guard"),
       "half": os.path.join(ROOT, "out", "mixing", "ch4_dt_half")}
MODELS = [f"model{m}" for m in range(1, 7)]
ENGINES = ("jdem", "liggghts-jdem")
SEED_DT = 1.0e-4
FILL_PARTICLES, FILL_TIME = 41280, 25.0   # 80 sections of 516 spheres over 25 s
CUBE_PARTICLES, CUBE_TIME = 400, 10.0     # about 400 spheres in a 0.2 m cube, up to 10 s
CHECKPOINT_SECONDS = 300                  # a killed jdem fill loses at most this much of its work
RESTART_STEPS = 2000                      # liggghts-jdem: a restart file every 0.2 s of a fill
SCENE_COST = 1e6                          # cutting: a read of the deposit
SPREAD_REALISATIONS = {"jdem": {m: 2 if m == "model3" else 1 for m in MODELS},  # the run-to-run
                       "liggghts-jdem": {"model3": 2}}  # spread's fills: every model once in jdem,
                       # which the pool over the models needs (agreement_ch4.spreads); Model 3
                       # (obstacles: phi_v > 0) twice, and in the other engine too, which checks
                       # that the spread is the fill's, not an engine's
JITTER = 1.0e-6           # [m] a realisation's stream shift per step of K (generate.py --jitter,
                          # horizon_ch5.py realisation): far below every length of the scenes
LIGGGHTS_SKIN = 0.5      # liggghts-jdem's neighbour skin over R_max in the fills and cubes: without
                          # jdem's per-particle skins LIGGGHTS rebuilds its lists every 6 steps at
                          # jdem's 0.2 and runs a fill 20 % faster at 0.5 (docs/performance.md);
                          # the horizons keep 0.2, the lists of jdem
LIGGGHTS_SORT_EVERY = 1000   # [steps] liggghts-jdem's spatial sort of the atoms in the fills and cubes:
                             # a quarter off a pass-2 fill's loop (docs/performance.md); a divisor of
                             # RESTART_STEPS (bit-for-bit continuations); the horizons keep jdem's order
HORIZON_TIME, HORIZON_FRAME_TIME = 4.0, 0.02      # [s] the cross-engine horizon's fill and frames
HORIZON_COST = 3.3        # both engines: liggghts-jdem takes 2.3 x jdem's CPU (47 s and 106 s, model1, 4 s)


def shift_stream(doc, jitter):
    """Move the scene doc's stream (its first inlet's origin) by jitter x JITTER in y, a
    realisation of its fill (both chapters' generate.py --jitter); returns the words that say so
    in the scene's description ("" for none)."""
    if not jitter:
        return ""
    doc["inlets"][0]["origin"] = shifted_origin(doc["inlets"][0]["origin"], jitter)
    return f", stream shifted by {jitter} x {JITTER} m in y (run-to-run spread)"


def shifted_origin(origin, jitter):
    """An inlet's origin [m] moved by jitter x JITTER in y: the stream of a realisation."""
    return [float(origin[0]), float(origin[1]) + JITTER * jitter, float(origin[2])]


def jdem():
    return os.environ.get("JDEM", os.path.join(ROOT, "build", "jdem"))


def valid_trajectory(path):
    import h5py
    try:
        with h5py.File(path, "r") as f:
            frames = f["particles/all/position/value"].shape[0]
    except (OSError, KeyError) as e:
        return f"not a trajectory: {e}"
    return None if frames > 0 else "no frame"


def read_committed(path):
    """A committed summary's JSON, {} when it is absent or unreadable (then nothing counts as
    committed and the units run)."""
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


@functools.lru_cache(maxsize=None)
def committed_ch4(variant="seed"):
    return read_committed(os.path.join(VARIANT_RESULTS[variant], "summary.json")).get("results", {})


@functools.lru_cache(maxsize=None)
def committed_horizons():
    return {m.get("case") for m in read_committed(os.path.join(RESULTS, "horizon", "summary.json"))
            .get("models", [])}


def committed_entry(engine, model, key, count=1, variant="seed"):
    """f() for Unit.committed: where report_ch4.py's committed summary of the time-step variant
    holds the result key of the engine's model ("fill1", "fill2", "passP_cubes", "jitter"), a
    list of at least `count` entries for the lists; None when it does not."""
    def where():
        entry = committed_ch4(variant).get(engine, {}).get(model, {}).get(key)
        if not entry or (isinstance(entry, list) and len(entry) < count):
            return None
        source = (entry[count - 1] if isinstance(entry, list) else entry).get("source", "?")
        summary = os.path.join(VARIANT_RESULTS[variant], "summary.json")
        return "%s: %s of commit %s" % (os.path.relpath(summary, ROOT), key, source)
    return where


def valid_scene(path):
    try:
        with open(path) as f:
            doc = yaml.load(f, Loader=yaml.CSafeLoader)
    except (OSError, yaml.YAMLError) as e:
        return f"not a scene: {e}"
    return None if isinstance(doc, dict) and doc.get("jdem_scene") == 1 else "no jdem_scene: 1"


# ---- what the engines can run: probe scenes, each using one feature -------------------------
PROBE_MATERIALS = ("materials: {m: {youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 1000,"
                   " restitution: 0.5, friction: 0.3}, wall: {restitution: 0.5, friction: 0.3}}\n")
PROBE_FLOOR = ("  - {name: floor, type: plane, corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],"
               " material: wall}\n")
PROBES = {
    "servo wall": "jdem_scene: 1\nname: probe_servo\ntime: {dt: 1.0e-5, steps: 1}\n"
                  + PROBE_MATERIALS
                  + "particles: [{material: m, radius: 0.01, position: [0.5, 0.5, 0.5]}]\n"
                    "walls:\n" + PROBE_FLOOR
                  + "  - {name: top, type: plane, material: wall, corners: [[0, 0, 1], [0, 1, 1],"
                    " [1, 1, 1], [1, 0, 1]], servo: {target: 1000.0, gain: 1.0e-4,"
                    " tolerance: 10.0, max_speed: 0.02, hold: 0.05}}\n",
    "conveyor inlet": "jdem_scene: 1\nname: probe_inlet\ntime: {dt: 1.0e-5, steps: 1}\n"
                      + PROBE_MATERIALS
                      + "inlets:\n  - {name: belt, section: {particles: [{material: m, radius: 0.01,"
                        " position: [0, 0, 0]}]}, origin: [0.0, 0.5, 0.5], velocity: [1, 0, 0],"
                        " plane: {point: [0.05, 0, 0], normal: [1, 0, 0]}, period: 0.1,"
                        " stop: {sections: 1}}\nwalls:\n" + PROBE_FLOOR,
    "inlet section from a deposit": "jdem_scene: 1\nname: probe_from_deposit\n"
                                    "time: {dt: 1.0e-5, steps: 1}\n" + PROBE_MATERIALS
                                    + "inlets:\n  - {name: belt, section: {from_deposit: [{file:"
                                      " probe_missing_deposit.h5}]}, origin: [0, 0.5, 0.5],"
                                      " velocity: [1, 0, 0], plane: {point: [0.05, 0, 0],"
                                      " normal: [1, 0, 0]}, stop: {sections: 1}}\n"
                                      "walls:\n" + PROBE_FLOOR,
}


def last_line(text):
    """The engine's last message, from the key it names on (not the probe's temporary path)."""
    lines = [line for line in text.strip().splitlines() if line.strip()]
    line = lines[-1] if lines else "(no message)"
    return line[line.find("key '"):] if "key '" in line else line


@functools.lru_cache(maxsize=None)
def missing(engine, feature):
    """None when `engine` reads the probe scene of `feature`, else why not (its own words).
    jdem: an "unknown key" from `jdem resolve`; liggghts-jdem: any refusal of the deck generator
    for the resolved probe."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "probe.yaml")
        with open(scene, "w") as f:
            f.write(PROBES[feature])
        r = subprocess.run([jdem(), "resolve", scene], capture_output=True, text=True, cwd=tmp)
        if r.returncode != 0:
            return (f"jdem has no {feature}: {last_line(r.stderr)}" if "unknown key" in r.stderr
                    else None)
        if engine == "jdem":
            return None
        d = subprocess.run([PY, os.path.join(ROOT, "scripts", "scene_to_liggghts.py"), "-",
                            "-o", os.path.join(tmp, "deck", "in.jdem"), "--trajectory",
                            os.path.join(tmp, "probe.h5")], input=r.stdout, capture_output=True,
                           text=True, cwd=tmp)
        return None if d.returncode == 0 else \
            f"liggghts-jdem has no {feature}: {last_line(d.stderr)}"


def gate(engine, *features):
    return lambda: next((m for m in (missing(engine, f) for f in features) if m), None)


# ---- time steps -----------------------------------------------------------------------------
@functools.lru_cache(maxsize=None)
def guard_dt(model):
    """The guard's largest safe dt [s] for a case (jdem resolve of `time.dt: auto`)."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "fill.yaml")
        subprocess.run([PY, GENERATE, "fill", "--case", model, "--dt", "auto", "-o", scene],
                       check=True)
        r = subprocess.run([jdem(), "resolve", scene], capture_output=True, text=True, check=True)
        return float(yaml.load(r.stdout, Loader=yaml.CSafeLoader)["time"]["dt"])


def variant_dt(variant, model):
    """(the --dt argument of generate.py, the dt in s for the cost) of a variant."""
    if variant == "seed":
        return repr(SEED_DT), SEED_DT
    if variant == "guard":   # the number, not auto: generate.py then rescales the output cadence
        return repr(guard_dt(model)), guard_dt(model)
    return repr(0.5 * guard_dt(model)), 0.5 * guard_dt(model)


# ---- units ----------------------------------------------------------------------------------
def rank_args(ranks):
    """liggghts_run.py's arguments for a fill on `ranks` MPI ranks: the grid splits y only, the
    box's and the stream's plane of symmetry (y = 0.5 m), so the ranks share the deposit and the
    falling stream about equally; LIGGGHTS' own choice splits z, leaving one rank the stream."""
    return [] if ranks == 1 else ["--np", str(ranks), "--processors", "1", str(ranks), "1"]


def fill_ranks(engine, ranks):
    """The MPI ranks a fill of the engine runs on (jdem: one process)."""
    return ranks if engine == "liggghts-jdem" else 1


def run_command(engine, scene, out, force, ranks=1, skin=LIGGGHTS_SKIN, sort_every=LIGGGHTS_SORT_EVERY):
    """argv running `scene` (a path or a "{...}" placeholder) into `out`; liggghts-jdem on
    `ranks` MPI ranks with the neighbour skin `skin` R_max (None: the deck generator's, jdem's)
    and its atoms sorted every `sort_every` steps (0: never, jdem's pair order)."""
    extra = ["--force"] if force else []
    if engine == "jdem":
        return [jdem(), "run", scene, "-o", out, *extra]   # its progress line shows in the log
    return [PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), scene, "-o", out, *extra,
            *(["--skin", repr(skin)] if skin is not None else []),
            *(["--sort-every", str(sort_every)] if sort_every else []), *rank_args(ranks)]


def resumable(engine):
    """Whether the engine's fills checkpoint and continue after an interruption (both: jdem's
    checkpoints, LIGGGHTS' restart files through scripts/liggghts_run.py)."""
    return engine in ENGINES


def fill_command(engine, scene, force, generate=None, checkpoint_seconds=CHECKPOINT_SECONDS,
                 restart_steps=RESTART_STEPS, ranks=1):
    """sh argv running `scene` into "{out0}" (after the shell line `generate`, which writes it).
    jdem checkpoints every checkpoint_seconds of wall time and, when an interrupted run left
    its checkpoint in the unit's directory, continues from it; liggghts-jdem writes a restart
    file every restart_steps steps and continues from the last complete one (docs/mixing.md §4)."""
    run = " ".join(a if a in ('"$1"', '"$2"') else shlex.quote(a)
                   for a in run_command(engine, '"$1"', '"$2"', force, ranks))
    if engine == "jdem":
        run += f" --checkpoint-seconds {checkpoint_seconds}"
        # no braces: the campaign driver fills the "{...}" placeholders of every word
        run = (f'ck="$(dirname "$2")/$(basename "$2" .h5).ckpt.h5"; '
               f'if [ -f "$ck" ]; then {run} --resume "$ck"; else {run}; fi')
    else:   # the runner continues from its deck directory's restart files, if any
        run += f" --checkpoint-every {restart_steps} --resume"
    return ["sh", "-c", (generate + " && " if generate else "") + run, "fill", scene, "{out0}"]


def fill1_command(engine, model, dt_arg, force, jitter=0, ranks=1):
    """Write the case's scene with the variant's dt (and the stream's jitter) into the unit's
    directory, then run it."""
    name = f"fill1_jitter{jitter}" if jitter else "fill1"
    return fill_command(engine, "{dir}/%s.yaml" % name, force,
                        f'{shlex.quote(PY)} {shlex.quote(GENERATE)} fill --case {model} '
                        f'--dt {dt_arg} --jitter {jitter} -o "$1"', ranks=ranks)


def spread_units(engine, model, variant, ranks):
    """The run-to-run spread: the first fill again with the stream shifted by K micrometres
    (generate.py --jitter), K = 1..SPREAD_REALISATIONS[engine][model], the seed's dt only."""
    if variant != "seed":
        return []
    base = os.path.join(OUT[variant], engine, model)
    dt_arg, dt = variant_dt(variant, model)
    return [Unit(f"{engine}/{model}/fill1_jitter{k}", [os.path.join(base, f"fill1_jitter{k}.h5")],
                 fill1_command(engine, model, dt_arg, True, k, ranks), model, engine,
                 validate=valid_trajectory, cost=FILL_PARTICLES * FILL_TIME / dt,
                 blocked=gate(engine, "conveyor inlet"), resumes=resumable(engine),
                 ranks=fill_ranks(engine, ranks), committed=committed_entry(engine, model, "jitter", k))
            for k in range(1, SPREAD_REALISATIONS[engine].get(model, 0) + 1)]


def pass_units(engine, model, p, deposit, base, dt_arg, dt, force, variant):
    """The 9 cube scenes of one deposit and their compressions (variant: whose committed results
    count)."""
    name = f"{engine}/{model}/pass{p}"
    cubes_kept = committed_entry(engine, model, f"pass{p}_cubes", 9, variant)
    cube_dir = os.path.join(base, f"pass{p}_cubes")
    scenes = [os.path.join(cube_dir, f"cube{k}.yaml") for k in range(1, 10)]
    units = [Unit(f"{name}_cubes", scenes, [PY, GENERATE, "cubes", deposit, "--case", model,
                                            "--dt", dt_arg, "-o", "{dir}",
                                            "--scene-dir", cube_dir],
                  model, engine, needs=[f"{engine}/{model}/fill{p}"], validate=valid_scene,
                  cost=SCENE_COST, committed=cubes_kept)]
    for k, scene in enumerate(scenes, start=1):
        units.append(Unit(f"{name}_cube{k}", [os.path.join(base, f"pass{p}_cube{k}.h5")],
                          run_command(engine, scene, "{out0}", force), model, engine,
                          needs=[f"{name}_cubes"], validate=valid_trajectory,
                          cost=CUBE_PARTICLES * CUBE_TIME / dt,
                          blocked=gate(engine, "servo wall"), committed=cubes_kept))
    return units


def model_units(engine, model, variant, ranks):
    base = os.path.join(OUT[variant], engine, model)
    fill1, fill2 = os.path.join(base, "fill1.h5"), os.path.join(base, "fill2.h5")
    pass2 = os.path.join(base, "pass2.yaml")
    pre = f"{engine}/{model}"
    dt_arg, dt = variant_dt(variant, model)
    force = variant == "seed"   # the guard refuses the seed's dt (docs/mixing.md §6)
    fill_cost = FILL_PARTICLES * FILL_TIME / dt
    kept = lambda key: committed_entry(engine, model, key, variant=variant)
    units = [
        Unit(f"{pre}/fill1", [fill1], fill1_command(engine, model, dt_arg, force, ranks=ranks), model, engine,
             validate=valid_trajectory, cost=fill_cost, blocked=gate(engine, "conveyor inlet"),
             resumes=resumable(engine), ranks=fill_ranks(engine, ranks), committed=kept("fill1")),
        Unit(f"{pre}/pass2_scene", [pass2], [PY, GENERATE, "second-pass", fill1, "--case", model,
                                             "--dt", dt_arg, "-o", "{out0}",
                                             "--scene-dir", base],
             model, engine, needs=[f"{pre}/fill1"], validate=valid_scene, cost=SCENE_COST,
             committed=kept("fill2")),   # an intermediate: settled with the fill it feeds
        Unit(f"{pre}/fill2", [fill2], fill_command(engine, pass2, force, ranks=ranks), model, engine,
             needs=[f"{pre}/pass2_scene"], validate=valid_trajectory, cost=fill_cost,
             resumes=resumable(engine), ranks=fill_ranks(engine, ranks),
             blocked=gate(engine, "conveyor inlet", "inlet section from a deposit"),
             committed=kept("fill2")),
    ]
    return units + pass_units(engine, model, 1, fill1, base, dt_arg, dt, force, variant) \
        + pass_units(engine, model, 2, fill2, base, dt_arg, dt, force, variant) \
        + spread_units(engine, model, variant, ranks)


def valid_json(what, *keys):
    """A unit's validator for a JSON result (`what` names it in the message) that must hold
    every one of keys."""
    def validate(path):
        try:
            with open(path) as f:
                doc = json.load(f)
        except (OSError, ValueError) as e:
            return f"not a {what} result: {e}"
        return None if all(k in doc for k in keys) else "no " + " or ".join(keys)
    return validate


valid_horizon = valid_json("horizon", "divergence")


def horizon_unit(model, variant):
    """The cross-engine horizon (scripts/mixing/horizon_ch4.py): the first HORIZON_TIME s of the
    first fill in both engines, frames every HORIZON_FRAME_TIME s, compared particle by particle."""
    dt_arg, dt = variant_dt(variant, model)
    out = os.path.join(OUT[variant], "cross", model, "horizon.json")
    inserted = FILL_PARTICLES * HORIZON_TIME / FILL_TIME
    return Unit(f"cross/{model}/horizon", [out],
                [PY, os.path.join(HERE, "horizon_ch4.py"), "run", "--case", model, "--dt", dt_arg,
                 *(["--force"] if variant == "seed" else []), "--end-time", repr(HORIZON_TIME),
                 "--frame-every", str(max(1, round(HORIZON_FRAME_TIME / dt))), "--dir", "{dir}",
                 "-o", "{out0}"],
                model, "cross", validate=valid_horizon,
                cost=HORIZON_COST * inserted * HORIZON_TIME / dt,
                blocked=gate("liggghts-jdem", "conveyor inlet"),   # it asks jdem too
                committed=(lambda: os.path.relpath(os.path.join(RESULTS, "horizon", "summary.json"), ROOT)
                           if model in committed_horizons() else None) if variant == "seed" else None)


def units(argv):
    import argparse
    ap = argparse.ArgumentParser(prog="plan_ch4.py")
    ap.add_argument("--dt", choices=sorted(OUT), default="seed",
                    help="time-step variant: the seed's 1e-4 s, the guard's dt, half of it")
    ap.add_argument("--ranks", type=int, default=1,
                    help="MPI ranks of each liggghts-jdem fill (default 1; jdem runs its own threads)")
    a = ap.parse_args(argv)
    if a.ranks < 1:
        ap.error("--ranks %d: valid: a positive number of MPI ranks" % a.ranks)
    return [u for engine in ENGINES for model in MODELS for u in model_units(engine, model, a.dt, a.ranks)] \
        + [horizon_unit(model, a.dt) for model in MODELS]
