#!/usr/bin/python3
"""discharge.py — the second stage of a sandpile: the outlets open under the settled deposit.

    python3 -m scripts.sandpile.discharge FILL.h5 --case CASE -o DISCHARGE.yaml [--scene SCENE]

The case of reference_runs/sandpile/sandpile.yaml as `jdem resolve` writes it (every default
explicit, the same dt), with its generated spheres replaced by the last frame of FILL.h5 (either
engine's trajectory; positions and velocities kept, particles_from) and the two outlet walls left
out: Zhou et al.'s "open the outlets instantly".  The run lasts DISCHARGE_TIME (her script: 3.08 s);
the report shows whether the material beside the plate has left and the pile has come to rest.
The fill must be one of the same case (its /parameters case_name).  Written atomically.
"""
import argparse
import os
import subprocess
import sys

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(ROOT, "reference_runs", "sandpile", "sandpile.yaml")
OUTLETS = ("outlet_left", "outlet_right")
DISCHARGE_TIME = 1.5          # [s] after the outlets open
FRAME_TIME = 0.05             # [s] between trajectory frames
OBSERVABLE_TIME = 0.005       # [s] between observable samples


def discharge_scene(resolved, fill):
    """The discharge stage of a resolved case (a dict), its spheres from trajectory `fill`."""
    doc = dict(resolved)
    dt = doc["time"]["dt"]
    doc["time"] = dict(doc["time"], end_time=DISCHARGE_TIME)
    del doc["time"]["steps"]
    doc["output"] = dict(doc["output"], every=max(1, round(FRAME_TIME / dt)),
                         observables_every=max(1, round(OBSERVABLE_TIME / dt)))
    doc["walls"] = [w for w in doc["walls"] if w["name"] not in OUTLETS]
    if len(doc["walls"]) != len(resolved["walls"]) - len(OUTLETS):
        sys.exit(f"discharge: the case has no walls named {' and '.join(OUTLETS)}")
    doc.pop("particles", None)
    doc["particles_from"] = [{"file": os.path.abspath(fill), "frame": -1, "velocities": "keep"}]
    return doc


def case_of(trajectory):
    """The case a trajectory of either engine ran (its /parameters case_name)."""
    import h5py
    with h5py.File(trajectory, "r") as f:
        name = f["parameters"].attrs["case_name"]
    return name.decode() if isinstance(name, bytes) else str(name)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("fill")
    ap.add_argument("--case", required=True)
    ap.add_argument("--scene", default=SCENE)
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()
    if case_of(a.fill) != a.case:
        sys.exit(f"discharge: {a.fill} is a fill of case {case_of(a.fill)}, not of {a.case}")
    jdem = os.environ.get("JDEM", os.path.join(ROOT, "build", "jdem"))
    text = subprocess.run([jdem, "resolve", a.scene, "--case", a.case], check=True,
                          capture_output=True, text=True).stdout
    doc = discharge_scene(yaml.load(text, Loader=yaml.CSafeLoader), a.fill)
    tmp = a.output + ".tmp"
    with open(tmp, "w") as f:
        f.write(f"# the discharge of sandpile case {a.case} from {os.path.abspath(a.fill)} "
                "(scripts/sandpile/discharge.py)\n")
        yaml.dump(doc, f, Dumper=yaml.CSafeDumper, sort_keys=False, default_flow_style=None)
    os.replace(tmp, a.output)


if __name__ == "__main__":
    main()
