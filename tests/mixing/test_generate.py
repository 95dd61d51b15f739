#!/usr/bin/python3
"""reference_runs/mixing/ch4/generate.py on a synthetic deposit: the second pass's 8 cells
(regions, order, queue on the belt) and the 9 cubes (regions, walls, servo), and its messages;
reference_runs/mixing/ch5/generate.py's 9 middle-clip cubes (spec §2.3-2.4: points 10-18 of
Table 5-2, overlapping in z, each its own scene; 5 kPa; wall friction 0.2; the case's bond
types, the deposit's bonds kept)."""
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import yaml

from tests.mixing.common import ROOT, check, finish

GEN = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "generate.py")
GEN5 = os.path.join(ROOT, "reference_runs", "mixing", "ch5", "generate.py")


def write_deposit(path, top):
    """A simple-cubic bed of small spheres over the 1 x 1 m floor, `top` m deep."""
    g = np.arange(0.015, 1.0, 0.03)
    x = np.array(np.meshgrid(g, g, np.arange(0.015, top, 0.03), indexing="ij")).reshape(3, -1).T
    n = len(x)
    r = np.full(n, 0.015)
    with h5py.File(path, "w") as f:
        p = f.create_group("particles/all")
        p["id"] = np.arange(1, n + 1)
        p["species"] = np.zeros(n, np.int32)
        p["radius"] = r
        p["mass"] = 4000 * 4 / 3 * math.pi * r ** 3
        p["position/value"] = x[None]
        p["position/step"] = np.array([0])
        p["position/time"] = np.array([0.0])


def gen(*args, script=GEN):
    return subprocess.run([sys.executable, script, *args], capture_output=True, text=True)


tmp = tempfile.mkdtemp()
dep = os.path.join(tmp, "dep.h5")
write_deposit(dep, 1.1)
out = os.path.join(tmp, "pass2.yaml")
r = gen("second-pass", dep, "--case", "model5", "-o", out)
check("second_pass_runs", r.returncode == 0, r.stderr)
doc = yaml.load(open(out), Loader=yaml.CSafeLoader)
cells = doc["inlets"][0]["section"]["from_deposit"]
los = [tuple(c["region"]["lo"]) for c in cells]
want = [(0.0, 0.5 * (q % 2), 0.25 * (q // 2)) for q in range(8)]
check("second_pass_cells_bottom_to_top", los == want, f"{los}")
# each cell dilated about its centre until its closest pair is 1.1 times the sum of the radii
# apart (the simple-cubic bed's neighbours touch: 1.1 exactly), then queued end to end with the
# 0.06 m gap, the first front 0.005 m behind the plane x = 0.05, every cell's bottom at z = 1.8
# and centred at y = 0.5 (dilated lengths 1.1, 0.55, 0.275 m)
check("second_pass_dilation", all(c["dilate"] == 1.1 for c in cells), f"{[c.get('dilate') for c in cells]}")
front = [0.045 - q * (1.1 + 0.06) for q in range(8)]
centre = [[0.5, 0.25 + 0.5 * (q % 2), 0.125 + 0.25 * (q // 2)] for q in range(8)]
t = [c["translate"] for c in cells]
ok = all(abs(t[q][0] + centre[q][0] + 0.55 - front[q]) < 1e-12 for q in range(8))
ok &= all(abs(t[q][2] + centre[q][2] - 0.1375 - 1.8) < 1e-12 for q in range(8))
ok &= all(abs(t[q][1] + centre[q][1] - 0.5) < 1e-12 for q in range(8))
check("second_pass_queue", ok, f"{[c['translate'] for c in cells]}")
# the deposit named relative to the folder the scene is read from: beside it by default, or
# --scene-dir's (the campaign writes into a partial folder and moves the scene to its final one)
check("second_pass_deposit_beside", {c["file"] for c in cells} == {"dep.h5"}, f"{cells[0]['file']}")
os.makedirs(os.path.join(tmp, "partial"))
r = gen("second-pass", dep, "--case", "model5", "-o", os.path.join(tmp, "partial", "p.yaml"),
        "--scene-dir", os.path.join(tmp, "final", "model5"))
moved = yaml.load(open(os.path.join(tmp, "partial", "p.yaml")), Loader=yaml.CSafeLoader) if r.returncode == 0 else {}
check("second_pass_deposit_from_scene_dir", r.returncode == 0 and
      moved["inlets"][0]["section"]["from_deposit"][0]["file"] == "../../dep.h5", r.stderr)
check("second_pass_inserted_once", doc["inlets"][0]["stop"] == {"sections": 1}, f"{doc['inlets'][0]}")
check("second_pass_keeps_model", doc["walls"][5]["present"] and doc["walls"][6]["axis"][0][0] == 0.7,
      f"{doc['walls'][5:]}")
r = gen("cubes", dep, "--case", "model2", "-o", os.path.join(tmp, "cubes"))
check("cubes_run", r.returncode == 0, r.stderr)
c5 = yaml.load(open(os.path.join(tmp, "cubes", "cube5.yaml")), Loader=yaml.CSafeLoader)
region = c5["particles_from"][0]["region"]
check("cube_deposit_relative", c5["particles_from"][0]["file"] == "../dep.h5",
      f"{c5['particles_from'][0]['file']}")
check("cube5_region", region == {"lo": [0.4, 0.4, 0.4], "hi": [0.6, 0.6, 0.6]}, f"{region}")
top = c5["walls"][-1]
normal = np.cross(np.subtract(top["corners"][1], top["corners"][0]),
                  np.subtract(top["corners"][2], top["corners"][0]))
check("cube_servo_top_faces_down", top["name"] == "top" and normal[2] < 0
      and top["servo"]["target"] == 1000.0 and top["servo"]["tolerance"] == 10.0, f"{top}")
r = gen("cubes", dep, "--case", "group3_model2", "-o", os.path.join(tmp, "cubes5"), script=GEN5)
check("ch5_cubes_run", r.returncode == 0, r.stderr)
names = sorted(os.listdir(os.path.join(tmp, "cubes5"))) if r.returncode == 0 else []
check("ch5_cubes_middle_clip", names == ["cube%d.yaml" % k for k in range(10, 19)], f"{names}")
docs = {k: yaml.load(open(os.path.join(tmp, "cubes5", "cube%d.yaml" % k)), Loader=yaml.CSafeLoader) for k in (10, 14, 18)} \
    if names else {}
regions = {k: d["particles_from"][0]["region"] for k, d in docs.items()}
check("ch5_cube_regions", regions == {10: {"lo": [0.15, 0.4, 0.1], "hi": [0.35, 0.6, 0.3]},
                                      14: {"lo": [0.4, 0.4, 0.2], "hi": [0.6, 0.6, 0.4]},
                                      18: {"lo": [0.65, 0.4, 0.3], "hi": [0.85, 0.6, 0.5]}}, f"{regions}")
d14 = docs.get(14, {"walls": [{}], "materials": {}})
check("ch5_cube_servo_5kPa", d14["walls"][-1].get("servo", {}).get("target") == 5000.0
      and d14["walls"][-1]["servo"]["tolerance"] == 50.0, f"{d14['walls'][-1]}")
check("ch5_cube_wall_friction", d14["materials"].get("wall", {}).get("friction") == 0.2, f"{d14['materials']}")
check("ch5_cube_bonds_from_deposit", "strong" in d14.get("bond_types", {}) and "bonds" not in d14
      and d14.get("particles_from", [{}])[0].get("bonds", "keep") == "keep" and "inlets" not in d14,
      f"{sorted(d14)}")
shallow = os.path.join(tmp, "shallow.h5")
write_deposit(shallow, 0.5)
r = gen("second-pass", shallow, "--case", "model1", "-o", os.path.join(tmp, "x.yaml"))
check("second_pass_too_shallow", r.returncode != 0 and r.stderr.strip() ==
      f"generate.py: {shallow}: the deposit is 0.510 m deep; valid: at least 1.0 m for the "
      f"second pass", r.stderr)
r = gen("cubes", shallow, "--case", "model1", "-o", os.path.join(tmp, "c"))
check("cube_outside_deposit", r.returncode != 0 and "region [0.15, 0.4, 0.4]..[0.35, 0.6, 0.6] "
      "lies outside the" in r.stderr, r.stderr)
r = gen("cubes", os.path.join(tmp, "none.h5"), "--case", "model1", "-o", os.path.join(tmp, "c"))
check("deposit_missing", r.returncode != 0 and "none.h5: no such file" in r.stderr, r.stderr)
r = gen("cubes", dep, "--case", "model7", "-o", os.path.join(tmp, "c"))
check("case_unknown", r.returncode != 0 and "case 'model7' is not in" in r.stderr
      and "valid: model1, model2, model3, model4, model5, model6" in r.stderr, r.stderr)

# fill: a case with another dt keeps its frames at the same times (1 s, 0.1 s: the scene's
# 10000 and 1000 steps of 1e-4 s) and the scene's other output keys (no energy accounts), and a
# reduced stream; the cubes' cadence follows the dt too
fill = os.path.join(tmp, "fill.yaml")
r = gen("fill", "--case", "model3", "--dt", "2.5e-05", "--sections", "4", "--end-time", "0.5",
        "-o", fill)
doc = yaml.load(open(fill), Loader=yaml.CSafeLoader) if r.returncode == 0 else {}
check("fill_dt_cadence", doc.get("time", {}).get("dt") == 2.5e-05 and doc.get("output") ==
      {"every": 40000, "observables_every": 4000, "energy": False}, f"{r.stderr}{doc.get('time')} {doc.get('output')}")
check("fill_reduced", doc.get("inlets", [{}])[0].get("stop") == {"sections": 4}
      and doc["time"]["end_time"] == 0.5 and doc["walls"][5]["present"], f"{doc.get('inlets')}")
r = gen("fill", "--case", "model1", "--dt", "auto", "-o", fill)
doc = yaml.load(open(fill), Loader=yaml.CSafeLoader) if r.returncode == 0 else {}
check("fill_dt_auto", doc.get("time", {}).get("dt") == "auto" and doc.get("output") ==
      {"every": 10000, "observables_every": 1000, "energy": False}, f"{r.stderr}{doc.get('output')}")
r = gen("cubes", dep, "--case", "model2", "--dt", "5e-05", "-o", os.path.join(tmp, "cubes_dt"))
c1 = yaml.load(open(os.path.join(tmp, "cubes_dt", "cube1.yaml")), Loader=yaml.CSafeLoader) if r.returncode == 0 else {}
check("cubes_dt_cadence", c1.get("time", {}).get("dt") == 5e-05 and c1.get("output") ==
      {"every": 2000, "observables_every": 200}, f"{r.stderr}{c1.get('output')}")
r = gen("fill", "--case", "model1", "--dt", "-1", "-o", fill)
check("fill_dt_bad", r.returncode == 2 and r.stderr.strip().endswith(
      "generate.py fill: error: argument --dt: '-1' is not valid; valid: a number > 0 [s], or "
      "auto"), r.stderr)
# --frame-every: the horizon's dense frames, in steps of the scene's dt (after a --dt rescale)
r = gen("fill", "--case", "model2", "--dt", "5e-05", "--frame-every", "400", "-o", fill)
doc = yaml.load(open(fill), Loader=yaml.CSafeLoader) if r.returncode == 0 else {}
check("fill_frame_every", doc.get("output") == {"every": 400, "observables_every": 2000, "energy": False},
      f"{r.stderr}{doc.get('output')}")
r = gen("fill", "--case", "model1", "--frame-every", "0", "-o", fill)
check("fill_frame_every_bad", r.returncode == 2 and r.stderr.strip().endswith(
      "generate.py fill: error: argument --frame-every: '0' is not valid; valid: a whole number "
      "of steps >= 1"), r.stderr)
finish()
