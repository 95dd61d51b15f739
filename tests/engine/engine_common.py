"""Helpers shared by the engine tests (tests/engine/test_*.py).

The binary is $JDEM if set, else build/jdem relative to the repository root (scripts/engines.py,
which runs it).  Each test prints
one line per check, "PASS name" or "FAIL name: detail", and exits non-zero if any check failed.
"""
import os
import sys
import tempfile

import h5py
import numpy as np

from scripts import engines

ROOT = engines.ROOT
SCENES = os.path.join(ROOT, "tests", "engine", "scenes")
JDEM = engines.JDEM
# The optimised build, for reference runs that only supply numbers to compare with (the
# O(N^2) all-pairs list): under the sanitizers they take minutes and check no code of interest.
JDEM_OPTIMISED = engines.JDEM_BUILD


class Checks:
    def __init__(self):
        self.failed = 0

    def check(self, name, ok, detail=""):
        if ok:
            print(f"PASS {name}")
        else:
            self.failed += 1
            print(f"FAIL {name}: {detail}")
        sys.stdout.flush()
        return ok

    def close_to(self, name, got, want, rel):
        err = abs(got - want) / abs(want)
        return self.check(name, err <= rel, f"got {got:.12g}, want {want:.12g} (rel. error {err:.3g} > {rel:g})")

    def built(self, *binaries):
        """True when every binary is built; else one FAIL line naming the make target."""
        for b in binaries:
            if not os.access(b, os.X_OK):
                return self.check("%s exists" % b, False, "make %s" % os.path.relpath(b, ROOT))
        return True

    def exit(self):
        sys.exit(1 if self.failed else 0)


def scene(name):
    return os.path.join(SCENES, name + ".yaml")


def run(scene_name, *args, env=None, check=True, binary=None):
    """Run `jdem run SCENE -o TMP/out.h5 --quiet ARGS` with binary (default $JDEM); returns
    (CompletedProcess, output path)."""
    out = os.path.join(tempfile.mkdtemp(prefix="jdem_engine_"), scene_name + ".h5")
    p = engines.jdem("run", scene(scene_name), "-o", out, *args, env=env, binary=binary or JDEM)
    if check and p.returncode != 0:
        raise RuntimeError(f"jdem run {scene_name} failed ({p.returncode}): {p.stderr.strip()}")
    return p, out


def load(path):
    """The trajectory as plain numpy arrays: particles, per-frame groups and observables."""
    with h5py.File(path, "r") as f:
        part = f["particles/all"]
        # a growing or shrinking set (inlets, domain) has per-frame ids: id[frame, row], -1 empty
        t = {k: part[k]["value"][()] if isinstance(part[k], h5py.Group) else part[k][()]
             for k in ("id", "species", "radius", "mass")}
        for k in ("position", "velocity", "angular_velocity", "force", "torque"):
            g = part[k]
            t[k] = g["value"][()]
            t[k + "_step"] = g["step"][()]
            t[k + "_time"] = g["time"][()]
        t["obs"] = {k: f["observables"][k]["value"][()] for k in f["observables"]}
        t["obs_time"] = f["observables/kinetic_energy/time"][()]
    return t


def energy_total(obs):
    """KE + RE + elastic + gravitational + damping + friction - wall_work, per sample."""
    return (obs["kinetic_energy"] + obs["rotational_energy"] + obs["elastic_energy"]
            + obs["gravitational_energy"] + obs["damping_dissipation"]
            + obs["friction_dissipation"] - obs["wall_work"])


__all__ = ["Checks", "run", "load", "scene", "energy_total", "np", "JDEM"]
