#!/usr/bin/python3
"""check_observables_cadence.py — the /observables cadence across engines.

    tests/liggghts/check_observables_cadence.py

Builds nothing (run `make` first).  Runs tests/liggghts/scenes/mpi_pile.yaml, shortened to 2100
steps with output.every 200, in build/jdem and through scripts/liggghts_run.py, for
output.observables_every 100 (smaller than every), 200 (equal) and 300 (not a divisor); and the
bonded block drop of tests/liggghts/bond_scenes/block_drop.yaml (3000 steps, bonds breaking) with
every 400 and observables_every 150, on 1 and 2 MPI ranks, whose bond observables (bonds,
fragments, bond energies) are then sampled between frames too.  Checks, for each: every
observable has the same step list in both files, and that list is build/jdem's rule
(docs/scenes.md): 0, the multiples of observables_every, the last step; then the values agree by
scripts/compare_trajectories.py at the scene's tolerance, and the bond and fragment counts are
the same integers at every sample.  One PASS/FAIL line per check.
"""
import os
import sys
import tempfile

import h5py
import yaml

from tests.liggghts.liggghts_common import HERE, Checks, compare, jdem_run, liggghts_run

PILE = os.path.join(HERE, "scenes", "mpi_pile.yaml")
BLOCK = os.path.join(HERE, "bond_scenes", "block_drop.yaml")


def observable_steps(path):
    with h5py.File(path, "r") as f:
        return {name: f["observables"][name]["step"][()].tolist() for name in f["observables"]}


def observable_values(path, name):
    with h5py.File(path, "r") as f:
        return f["observables"][name]["value"][()].tolist()


def expected_steps(steps, obs_every):
    return sorted(set([0, steps] + list(range(0, steps + 1, obs_every))))


def check(c, tmp, source, steps, every, obs_every, ranks=1):
    label = "%s_observables_every_%d%s" % (os.path.basename(source)[:-5], obs_every,
                                           "_np%d" % ranks if ranks > 1 else "")
    with open(source) as f:
        scene = yaml.load(f, Loader=yaml.CSafeLoader)
    scene["time"]["steps"] = steps
    scene["output"] = {"every": every, "observables_every": obs_every}
    path = os.path.join(tmp, label + ".yaml")
    with open(path, "w") as f:
        yaml.safe_dump(scene, f)
    a, b = os.path.join(tmp, label + ".jdem.h5"), os.path.join(tmp, label + ".liggghts.h5")
    for (rc, out), what in ((jdem_run(path, a, "--quiet"), "build/jdem"),
                            (liggghts_run(path, b, ranks=ranks), "liggghts_run.py")):
        out = out.strip()
        if rc != 0:
            c.check(label, False, "%s exit %d:\n%s" % (what, rc, out[-1500:]))
            return
    sa, sb = observable_steps(a), observable_steps(b)
    want = expected_steps(steps, obs_every)
    if sorted(sa) != sorted(sb):
        c.check(label + "_names", False, "jdem %s, liggghts %s" % (sorted(sa), sorted(sb)))
    bad = [n for n in sorted(set(sa) & set(sb)) if sa[n] != want or sb[n] != want]
    n = bad[0] if bad else None
    c.check("%s_steps (%d observables, %d samples each)" % (label, len(sa), len(want)), not bad,
            n and "%s: jdem %d samples %s..., liggghts %d samples %s..., want %d %s..."
            % (n, len(sa[n]), sa[n][:6], len(sb[n]), sb[n][:6], len(want), want[:6]))
    same, _, out = compare(a, b)
    line = out.strip().splitlines()[-1] if out.strip() else ""
    c.check("%s_values: %s" % (label, line.split(" ", 1)[-1]), same, "the trajectories differ")
    for name in ("bonds", "fragments"):
        if name in sa:
            va, vb = observable_values(a, name), observable_values(b, name)
            c.check("%s_%s (%g to %g)" % (label, name, va[0], va[-1]), va == vb,
                    "jdem %s, liggghts %s" % (va, vb))


def main():
    c = Checks()
    with tempfile.TemporaryDirectory() as tmp:
        for m in (100, 200, 300):
            check(c, tmp, PILE, 2100, 200, m)
        for ranks in (1, 2):
            check(c, tmp, BLOCK, 3000, 400, 150, ranks)
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
