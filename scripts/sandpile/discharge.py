#!/usr/bin/python3
"""discharge.py — the second stage of a sandpile: the outlets open under the settled deposit.

    python3 -m scripts.sandpile.discharge FILL.h5 --case CASE -o DISCHARGE.yaml [--scene SCENE] [--control]

The case of reference_runs/sandpile/sandpile.yaml as `jdem resolve` writes it (every default
explicit, the same dt), with its generated spheres replaced by the last frame of FILL.h5 (either
engine's trajectory; positions and velocities kept, particles_from) and the two outlet walls left
out: Zhou et al.'s "open the outlets instantly".  The run lasts DISCHARGE_TIME (her script: 3.08 s);
the report shows whether the material beside the plate has left and the pile has come to rest.
The fill must be one of the same case (its /parameters case_name).  Written atomically.

--control writes the restart's control instead: the same restart with the outlets kept, for
CONTROL_TIME.  The deposit was at rest, so whatever moves in it is the restart's own doing: the
contacts' history (tangential springs, MEPA's plastic overlap) starts afresh from the settled
overlaps (docs/sandpile.md); the report gives how far the spheres moved and the elastic energy.
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
CONTROL_TIME = 0.05           # [s]: the restart's control, the outlets kept (--control)
CONTROL_FRAME_TIME = 0.01     # [s] between its frames (its samples ten times as often)


def discharge_scene(resolved, fill, control=False):
    """The discharge stage of a resolved case (a dict), its spheres from trajectory `fill`; with
    `control`, the restart's control instead: the outlets kept, CONTROL_TIME long."""
    doc = dict(resolved)
    dt = doc["time"]["dt"]
    doc["time"] = dict(doc["time"], end_time=CONTROL_TIME if control else DISCHARGE_TIME)
    del doc["time"]["steps"]
    frame, sample = (CONTROL_FRAME_TIME, CONTROL_FRAME_TIME / 10) if control else (FRAME_TIME, OBSERVABLE_TIME)
    doc["output"] = dict(doc["output"], every=max(1, round(frame / dt)),
                         observables_every=max(1, round(sample / dt)))
    if not control:
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
    ap.add_argument("--control", action="store_true", help="the restart's control: the outlets kept")
    a = ap.parse_args()
    if case_of(a.fill) != a.case:
        sys.exit(f"discharge: {a.fill} is a fill of case {case_of(a.fill)}, not of {a.case}")
    jdem = os.environ.get("JDEM", os.path.join(ROOT, "build", "jdem"))
    text = subprocess.run([jdem, "resolve", a.scene, "--case", a.case], check=True,
                          capture_output=True, text=True).stdout
    doc = discharge_scene(yaml.load(text, Loader=yaml.CSafeLoader), a.fill, a.control)
    tmp = a.output + ".tmp"
    with open(tmp, "w") as f:
        what = "restart's control" if a.control else "discharge"
        f.write(f"# the {what} of sandpile case {a.case} from {os.path.abspath(a.fill)} "
                "(scripts/sandpile/discharge.py)\n")
        yaml.dump(doc, f, Dumper=yaml.CSafeDumper, sort_keys=False, default_flow_style=None)
    os.replace(tmp, a.output)


if __name__ == "__main__":
    main()
