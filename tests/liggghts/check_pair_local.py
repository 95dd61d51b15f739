#!/usr/bin/python3
"""check_pair_local.py — `compute pair/gran/local` with pair_style gran/jiang reports our contacts.

    tests/liggghts/check_pair_local.py

Builds nothing (run `make` first).  Two scenes of tests/liggghts/scenes/ run in build/jdem, and
their generated LIGGGHTS decks run with `compute pgl all pair/gran/local id force torque` written
by `dump local` at every frame (full precision).  The only forces on the two spheres are their
contact's.  Checks: one row at exactly the frames where the spheres overlap (LIGGGHTS' own count
of the rows); for the elastic, frictionless head-on impact, whose force depends on the positions
only, the row's force and torque are build/jdem's force and torque on the row's first particle
(1e-10 of the largest); for the oblique impact with friction and damping, the rows carry a
torque.  (The compute re-evaluates the contact at the end of the step, with the velocities after
the last half kick, as it does for LIGGGHTS' own pairs: velocity-dependent forces differ from
the ones applied during the step.)  One PASS/FAIL line per check.
"""
import os
import sys
import tempfile

import h5py
import numpy as np

from scripts.engines import EngineError
from tests.liggghts.liggghts_common import HERE, Checks, edit_deck, jdem_run, make_deck, run_deck

EVERY = 10  # the scene's output.every


def local_rows(path):
    """{step: [(id1, id2, periodic, fx, fy, fz, tx, ty, tz), ...]} from a dump local file."""
    rows, step, lines = {}, None, open(path).read().splitlines()
    k = 0
    while k < len(lines):
        if lines[k].startswith("ITEM: TIMESTEP"):
            step = int(lines[k + 1])
            rows[step] = []
            k += 2
        elif lines[k].startswith("ITEM: ENTRIES"):
            k += 1
            while k < len(lines) and not lines[k].startswith("ITEM:"):
                rows[step].append([float(v) for v in lines[k].split()])
                k += 1
        else:
            k += 1
    return rows


def with_pair_local(text):
    """The deck with compute pair/gran/local dumped (full precision) every EVERY steps."""
    at = text.rindex("\nrun ")
    return (text[:at] + "\ncompute pgl all pair/gran/local id force torque\n"
            "dump dl all local %d pgl.txt c_pgl[1] c_pgl[2] c_pgl[3] c_pgl[4] c_pgl[5] "
            "c_pgl[6] c_pgl[7] c_pgl[8] c_pgl[9]\ndump_modify dl format \"%s\"" % (EVERY, " ".join(["%.17g"] * 9)) +
            text[at:])


def check_scene(c, name, exact):
    """Runs scene NAME in both engines; checks the rows (and their values when EXACT)."""
    scene = os.path.join(HERE, "scenes", name + ".yaml")
    with tempfile.TemporaryDirectory() as tmp:
        ref = os.path.join(tmp, "jdem.h5")
        rc, out = jdem_run(scene, ref, "--quiet")
        if not c.check(name + ": build/jdem runs", rc == 0, out[-1500:]):
            return
        try:
            make_deck(scene, tmp, trajectory=os.path.join(tmp, "lig.h5"))
        except EngineError as e:
            c.check(name + ": the deck is generated", False, str(e)[-1500:])
            return
        c.check(name + ": the deck is generated", True)
        edit_deck(tmp, with_pair_local)
        rc, log, out = run_deck(tmp)
        if not c.check(name + ": liggghts-jdem runs the deck with compute pair/gran/local", rc == 0,
                       out[-1500:] + log[-1500:]):
            return
        rows = local_rows(os.path.join(tmp, "pgl.txt"))
        with h5py.File(ref, "r") as f:
            steps = f["particles/all/force/step"][()]
            force = f["particles/all/force/value"][()]
            pos = f["particles/all/position/value"][()]
            radius = f["particles/all/radius"][()]
            torque = f["particles/all/torque/value"][()]
        scale = np.abs(force).max()
        worst, missing, extra, nrows, torqued = 0.0, [], [], 0, 0
        for k, step in enumerate(steps):
            here = rows.get(int(step), [])
            overlap = np.linalg.norm(pos[k][1] - pos[k][0]) < radius[0] + radius[1]
            if overlap and len(here) != 1:
                missing.append(int(step))
            if not overlap and here:
                extra.append(int(step))
            for r in here:
                nrows += 1
                first = int(r[0]) - 1  # ids 1, 2 are rows 0, 1 of the trajectory
                torqued += np.abs(np.array(r[6:9])).max() > 0.0
                worst = max(worst, np.abs(np.array(r[3:6]) - force[k][first]).max() / scale,
                            np.abs(np.array(r[6:9]) - torque[k][first]).max() /
                            max(np.abs(torque).max(), 1e-300))
        c.check("%s: one row at every frame where the spheres overlap (%d rows)" % (name, nrows),
                not missing and nrows > 0, "not one row at steps %s" % missing[:10])
        c.check(name + ": no row where they do not", not extra, "rows at steps %s" % extra[:10])
        if exact:
            c.check("%s: the rows' force and torque are build/jdem's (max scaled difference %.3g)"
                    % (name, worst), worst <= 1e-10, "max scaled difference %.3g > 1e-10" % worst)
        else:
            c.check("%s: rows with friction carry a torque (%d of %d)" % (name, torqued, nrows),
                    torqued > 0, "every torque is zero")


def main():
    c = Checks()
    check_scene(c, "two_sphere_headon", exact=True)
    check_scene(c, "two_sphere_oblique", exact=False)
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
