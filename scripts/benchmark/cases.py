"""The eight Chung & Ooi tests: where their scenes, tools and trajectories live, their cases.

`scene_path` is looked up through this module at call time (cases.scene_path), so a caller may
replace it (use_model_options: chung_ooi.py --model, scripts/model_option_evidence.py), and the
runner and the case lists follow.
"""
import os

import yaml

from scripts import engines
from scripts.engines import ROOT

LIGGGHTS = engines.LIGGGHTS_JDEM
TESTS = range(1, 9)
ENGINE_LABEL = {"jdem": "jdem", "liggghts": "LIGGGHTS"}


# Representative subset for `make test` (--quick): both materials of Tests 1-2, and in the swept
# tests the ends of each sweep plus points in stick, transition and gross sliding.
QUICK_CASES = {
    1: ["glass", "limestone"],
    2: ["al_alloy", "mg_alloy"],
    3: [f"{m}_{e}_{d}" for m in ("al_oxide", "cast_iron") for e in ("e010", "e050", "e100")
        for d in ("jiang2021", "exact")],
    4: [f"al_oxide_theta{a:02d}" for a in (5, 20, 40, 60, 85)] + ["al_alloy_theta45"],
    5: [f"steel_psi{p}" for p in ("00p50", "05p00", "10p00", "20p00", "30p00")],
    6: [f"al_alloy_omega{w}" for w in ("00p175", "02p000", "07p464", "22p860")]
       + ["nylon_omega15p000"],
    7: ["al_alloy_omega00p175", "al_alloy_omega22p860", "copper_omega08p000"],
    8: [f"al_alloy_caseB_omega{w}" for w in ("00p175", "02p000", "09p000", "22p860")]
       + ["nylon_caseA_omega15p000"],
}


def scene_path(test):
    return os.path.join(ROOT, "reference_runs", "chung_ooi", f"test{test}", "scene.yaml")


reference_scene_path = scene_path


def use_model_options(options, work):
    """Replace scene_path by one returning each test's scene with the `model:` options set
    (options: {OPTION: VALUE}), written once under WORK/scenes/."""
    global scene_path
    reference = reference_scene_path

    def with_options(test):
        path = os.path.join(work, "scenes", f"test{test}.yaml")
        if not os.path.exists(path):
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(reference(test)) as f:
                scene = yaml.load(f, Loader=yaml.CSafeLoader)
            scene.setdefault("model", {}).update(options)
            with open(path, "w") as f:
                yaml.safe_dump(scene, f)
        return path
    scene_path = with_options


def trajectory_path(out, test, case, engine):
    return os.path.join(out, f"test{test}", f"{case}.{engine}.h5")


def list_cases(test):
    return engines.cases(scene_path(test))


def selected_cases(test, quick):
    cases = list_cases(test)
    if not quick:
        return cases
    missing = set(QUICK_CASES[test]) - set(cases)
    if missing:
        raise SystemExit(f"QUICK_CASES of test {test} not in the scene: {sorted(missing)}")
    return QUICK_CASES[test]


def material_of(case):
    """Material prefix of a case name (everything before the last sweep value)."""
    return case.rsplit("_", 1)[0]


TITLES = {1: "Test 1: elastic normal impact of two identical spheres",
          2: "Test 2: elastic normal impact of a sphere with a rigid plane",
          3: "Test 3: normal impact with different restitution coefficients",
          4: "Test 4: oblique impact, constant speed, varying incident angle",
          5: "Test 5: oblique impact, constant normal velocity, varying tangential velocity",
          6: "Test 6: spinning sphere on a rigid plane",
          7: "Test 7: two identical spheres with mirror-symmetric spins",
          8: "Test 8: small spinning sphere on a big sphere"}
