"""plan_ch4.py — the units of `make mixing` for scripts/campaign.py (docs/mixing.md §4).

    scripts/campaign.py scripts/mixing/plan_ch4.py [--model modelM] [--engine ENGINE] [--list]

Per engine (jdem, liggghts-jdem) and model 1-6: the first fill, the second-pass scene cut from
it, the second fill, and per pass the 9 cube scenes and their 9 compressions, under
out/mixing/ch4/ENGINE/modelM/.  The scenes use the target schema (docs/mixing.md §2): the units
run once the engines implement it.  A unit's cost for the ETA is its particle-steps.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
from campaign import Unit  # noqa: E402

PY = "/usr/bin/python3"
SCENE = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "models.yaml")
GENERATE = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "generate.py")
OUT = os.path.join(ROOT, "out", "mixing", "ch4")
MODELS = [f"model{m}" for m in range(1, 7)]
ENGINES = ("jdem", "liggghts-jdem")
FILL_COST = 41280 * 250_000   # 80 sections of 516 spheres over 25 s at dt = 1e-4 s
CUBE_COST = 400 * 100_000     # about 400 spheres in a 0.2 m cube, up to 10 s
SCENE_COST = 1e6              # cutting: a read of the deposit


def valid_trajectory(path):
    import h5py
    try:
        with h5py.File(path, "r") as f:
            frames = f["particles/all/position/value"].shape[0]
    except (OSError, KeyError) as e:
        return f"not a trajectory: {e}"
    return None if frames > 0 else "no frame"


def valid_scene(path):
    import yaml
    try:
        with open(path) as f:
            doc = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        return f"not a scene: {e}"
    return None if isinstance(doc, dict) and doc.get("jdem_scene") == 1 else "no jdem_scene: 1"


def run_command(engine, scene, out, case=None):
    sel = ["--case", case] if case else []
    if engine == "jdem":
        return [os.environ.get("JDEM", os.path.join(ROOT, "build", "jdem")), "run", scene, *sel,
                "-o", out, "--quiet"]
    return [PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), scene, *sel, "-o", out]


def pass_units(engine, model, p, deposit, base):
    """The 9 cube scenes of one deposit and their compressions."""
    name = f"{engine}/{model}/pass{p}"
    cube_dir = os.path.join(base, f"pass{p}_cubes")
    scenes = [os.path.join(cube_dir, f"cube{k}.yaml") for k in range(1, 10)]
    units = [Unit(f"{name}_cubes", scenes, [PY, GENERATE, "cubes", deposit, "--case", model,
                                            "-o", "{dir}"],
                  model, engine, needs=[f"{engine}/{model}/fill{p}"], validate=valid_scene,
                  cost=SCENE_COST)]
    for k, scene in enumerate(scenes, start=1):
        units.append(Unit(f"{name}_cube{k}", [os.path.join(base, f"pass{p}_cube{k}.h5")],
                          run_command(engine, scene, "{out0}"), model, engine,
                          needs=[f"{name}_cubes"], validate=valid_trajectory, cost=CUBE_COST))
    return units


def model_units(engine, model):
    base = os.path.join(OUT, engine, model)
    fill1, fill2 = os.path.join(base, "fill1.h5"), os.path.join(base, "fill2.h5")
    pass2 = os.path.join(base, "pass2.yaml")
    pre = f"{engine}/{model}"
    units = [
        Unit(f"{pre}/fill1", [fill1], run_command(engine, SCENE, "{out0}", model), model, engine,
             validate=valid_trajectory, cost=FILL_COST),
        Unit(f"{pre}/pass2_scene", [pass2], [PY, GENERATE, "second-pass", fill1, "--case", model,
                                             "-o", "{out0}"],
             model, engine, needs=[f"{pre}/fill1"], validate=valid_scene, cost=SCENE_COST),
        Unit(f"{pre}/fill2", [fill2], run_command(engine, pass2, "{out0}"), model, engine,
             needs=[f"{pre}/pass2_scene"], validate=valid_trajectory, cost=FILL_COST),
    ]
    return units + pass_units(engine, model, 1, fill1, base) + pass_units(engine, model, 2, fill2, base)


def units(argv):
    return [u for engine in ENGINES for model in MODELS for u in model_units(engine, model)]
