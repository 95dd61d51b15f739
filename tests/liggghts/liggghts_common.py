"""Helpers shared by the LIGGGHTS checks (tests/liggghts/check_*.py), as tests/engine/engine_common.py
is for the engine tests: running a scene in build/jdem and in LIGGGHTS (scripts/liggghts_run.py),
a deck of one's own in build/liggghts-jdem on N ranks, reading what they wrote, and comparing the
two engines' trajectories (scripts/compare_trajectories.py).  Every run goes through
scripts/engines.py; the binaries are $JDEM and $LIGGGHTS_JDEM when set, else build/jdem and
build/liggghts-jdem.  Checks prints the PASS/FAIL lines that tests/run_tests.py counts.
"""
import os
import shutil

import h5py
import numpy as np

from scripts import engines
from tests.engine.engine_common import Checks

ROOT = engines.ROOT
HERE = os.path.join(ROOT, "tests", "liggghts")
JDEM = engines.JDEM
LIGGGHTS_JDEM = engines.LIGGGHTS_JDEM
STATE = ("position", "velocity", "angular_velocity", "force", "torque")


GRANULAR_DECK_HEAD = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block %s units box
create_box 2 box
neighbor 0.002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5.e6 5.e6
fix m2 all property/global poissonsRatio peratomtype %s 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5
fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5
"""


def granular_deck_head(box, poisson="0.45"):
    """The opening of the hand-written decks of the LIGGGHTS checks: two atom types (1 the
    particles, 2 the walls) with their material properties, in the box "xlo xhi ylo yhi zlo zhi";
    poisson is type 1's Poisson ratio (a str.format field such as "{nu}" passes through)."""
    return GRANULAR_DECK_HEAD % (box, poisson)


def run(cmd, cwd=None):
    """(exit status, stdout + stderr) of CMD."""
    r = engines.run(cmd, cwd=cwd)
    return r.returncode, r.stdout + r.stderr


def jdem_run(scene, out, *args):
    """`jdem run SCENE -o OUT ARGS`: (exit status, its output)."""
    return run([JDEM, "run", scene, "-o", out, *args])


def liggghts_run(scene, out, *args, case=None, ranks=1):
    """SCENE [CASE] in LIGGGHTS on RANKS ranks into OUT (scripts/liggghts_run.py ARGS): (exit
    status, its output)."""
    r = engines.liggghts_run(scene, out, *args, case=case, ranks=ranks)
    return r.returncode, r.stdout + r.stderr


def liggghts_run_log(out):
    """The LIGGGHTS log of liggghts_run(..., OUT)."""
    with open(engines.liggghts_log(out), errors="replace") as f:
        return f.read()


def make_deck(scene, deck_dir, *args, case=None, trajectory=None):
    """DECK_DIR/resolved.yaml (`jdem resolve SCENE`) and its deck DECK_DIR/in.jdem writing
    TRAJECTORY (default DECK_DIR/out.h5), with scene_to_liggghts.py's ARGS; both checked."""
    os.makedirs(deck_dir, exist_ok=True)
    resolved = os.path.join(deck_dir, "resolved.yaml")
    with open(resolved, "w") as f:
        f.write(engines.resolve(scene, case, check=True).stdout)
    engines.write_deck(resolved, os.path.join(deck_dir, "in.jdem"), "--trajectory",
                       trajectory or os.path.join(deck_dir, "out.h5"), *args, check=True)
    return os.path.join(deck_dir, "in.jdem")


def edit_deck(deck_dir, edit, deck="in.jdem"):
    """Replace DECK_DIR/DECK by EDIT(its text)."""
    path = os.path.join(deck_dir, deck)
    with open(path) as f:
        text = edit(f.read())
    with open(path, "w") as f:
        f.write(text)


def run_deck(deck_dir, deck="in.jdem", ranks=1, log="log.lammps"):
    """build/liggghts-jdem on DECK_DIR/DECK on RANKS ranks, its log in DECK_DIR/LOG: (exit status,
    the log, its output)."""
    r = engines.run_deck(deck_dir, deck, ranks, LIGGGHTS_JDEM, log)
    log = os.path.join(deck_dir, log)
    text = ""
    if os.path.exists(log):
        with open(log, errors="replace") as f:
            text = f.read()
    return r.returncode, text, r.stdout + r.stderr


def last_line(text):
    """The last non-blank line of TEXT without a leading PASS/FAIL tag (one PASS/FAIL line per
    check: tests/run_tests.py counts them)."""
    lines = [line for line in text.strip().splitlines() if line.strip()]
    line = lines[-1] if lines else ""
    for tag in ("PASS ", "FAIL "):
        if line.startswith(tag):
            line = line[len(tag):]
    return line


def compare(a, b, *args):
    """scripts/compare_trajectories.py A B ARGS (--tol, --until): (same, its last line, all it
    printed)."""
    rc, out = run(engines.script("compare_trajectories", a, b, *args))
    return rc == 0, last_line(out), out


def observable(path, name):
    """The values of the observable NAME in the trajectory PATH."""
    with h5py.File(path, "r") as f:
        return f["observables/%s/value" % name][()]


def observable_names(path):
    with h5py.File(path, "r") as f:
        return sorted(f["observables"]) if "observables" in f else []


def part_frames(out):
    """A stopped run's OUT.part: (its frame steps, whether every state value is finite, the steps
    of its kinetic energy); OSError if it cannot be read."""
    with h5py.File(out + ".part", "r") as f:
        steps = f["particles/all/position/step"][()]
        finite = all(np.isfinite(f["particles/all/%s/value" % k][()]).all() for k in STATE)
        obs_steps = f["observables/kinetic_energy/step"][()]
    return steps, finite, obs_steps


def finish(checks, tmp, keep):
    """Keep TMP (printing where) or remove it; the exit status of CHECKS."""
    if keep:
        print("runs kept in %s" % tmp)
    else:
        shutil.rmtree(tmp, ignore_errors=True)
    return 1 if checks.failed else 0


__all__ = ["Checks", "ROOT", "HERE", "JDEM", "LIGGGHTS_JDEM", "run", "jdem_run", "liggghts_run",
           "liggghts_run_log", "make_deck", "edit_deck", "run_deck", "last_line", "compare", "observable",
           "observable_names", "part_frames", "finish"]
