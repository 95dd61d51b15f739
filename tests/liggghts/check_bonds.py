#!/usr/bin/python3
"""check_bonds.py — parallel bonds in LIGGGHTS (fix bond/jiang): against build/jdem, on 1 and 2
MPI ranks, and its guards.

    tests/liggghts/check_bonds.py [--out DIR] [--keep]

Scenes in tests/liggghts/bond_scenes/, run with build/jdem and scripts/liggghts_run.py:
  mpi_bonded_slide  a bonded 2x2x1 block slides across the rank boundary: the trajectories of
                    jdem and liggghts-jdem, and of liggghts-jdem on 1 and 2 MPI ranks, agree to
                    the scene's tolerance (bond states migrate, ghost partners get their forces
                    back by reverse communication), and its 4 bonds stay intact as one fragment;
  block_drop        a bonded 4x4x4 block breaks on a plate: jdem vs liggghts-jdem and 1 vs 2
                    ranks, the trajectories agree up to the first broken bond, and the
                    broken-bond events (step, ids, mode) and the fragment sizes at the end are
                    the same (the engines sum the forces in the same order, so they agree after
                    the first break too; a mismatch there is reported with the counts);
  ghost_cutoff      a soft unbreakable bond outgrows the ghost cutoff: the run stops (exit != 0)
                    on 1 and 2 ranks with the message naming the bond, OUT.part kept, nothing
                    under OUT; the reported length is that of the undamped two-body oscillator
                    (closed form) at the reported step;
a malformed bond file stops the run with a message naming the file and the line; and the
time-step guard (fix jdem/guard) refuses block_drop with stiffer bonds and a longer step, on 1
and 2 ranks, with the bond bound and the largest safe step of build/jdem's refusal.
Prints one PASS/FAIL line per check; exit 1 if any fails.
"""
import argparse
import math
import os
import re
import shutil
import sys
import tempfile

import h5py
import numpy as np
import yaml

from tests.liggghts.liggghts_common import (HERE, LIGGGHTS_JDEM, Checks, compare, jdem_run, liggghts_run,
                                            liggghts_run_log, observable, run_deck)

SCENES = os.path.join(HERE, "bond_scenes")
CHECKS = Checks()
check = CHECKS.check


def liggghts(scene, out, np_=1):
    return liggghts_run(os.path.join(SCENES, scene + ".yaml"), out, ranks=np_)


def jdem(scene, out):
    return jdem_run(os.path.join(SCENES, scene + ".yaml"), out, "--quiet")


def compare_check(name, a, b, until=None):
    ok, last, text = compare(a, b, *(["--until", str(until)] if until is not None else []))
    return check(name, ok, last + "\n" + text)


def events(path):
    with h5py.File(path, "r") as f:
        g = f["jdem/broken_bonds"]
        return [(int(s), int(i[0]), int(i[1]), int(m)) for s, i, m in zip(g["step"][()], g["ids"][()], g["mode"][()])]


def fragment_sizes(path):
    """Sizes of the connected components of the intact bonds at the last frame, over the particles
    ever bonded, largest first: /connectivity/bonds minus /connectivity/broken_bonds."""
    with h5py.File(path, "r") as f:
        formed = [tuple(int(v) for v in ids) for ids in f["connectivity/bonds"][()]]
        broken = [tuple(int(v) for v in ids) for ids in f["connectivity/broken_bonds"][()]]
    intact = list(formed)
    for b in broken:
        intact.remove(b)
    parent = {p: p for b in formed for p in b}

    def root(p):
        while parent[p] != p:
            parent[p] = parent[parent[p]]
            p = parent[p]
        return p

    for a, b in intact:
        parent[root(a)] = root(b)
    sizes = {}
    for p in parent:
        sizes[root(p)] = sizes.get(root(p), 0) + 1
    return sorted(sizes.values(), reverse=True)


def run_three(scene, work):
    """build/jdem, and liggghts-jdem on 1 and 2 ranks; the three trajectories or None."""
    paths = [os.path.join(work, "%s.%s.h5" % (scene, e)) for e in ("jdem", "np1", "np2")]
    rc, text = jdem(scene, paths[0])
    ok = check("bonds/%s: build/jdem runs" % scene, rc == 0, text[-1500:])
    for out, n in ((paths[1], 1), (paths[2], 2)):
        rc, text = liggghts(scene, out, n)
        ok = check("bonds/%s: liggghts-jdem runs on %d rank(s)" % (scene, n), rc == 0, text[-1500:]) and ok
    return paths if ok else None


def check_slide(work):
    paths = run_three("mpi_bonded_slide", work)
    if not paths:
        return
    j, a, b = paths
    compare_check("bonds/mpi_bonded_slide: jdem vs liggghts-jdem", j, a)
    compare_check("bonds/mpi_bonded_slide: liggghts-jdem 1 rank vs 2 ranks", a, b)
    nb, nf = observable(b, "bonds"), observable(b, "fragments")
    check("bonds/mpi_bonded_slide: 4 bonds (2x2x1 block) intact, 1 fragment, on 2 ranks",
          np.all(nb == 4) and np.all(nf == 1), "bonds %s fragments %s" % (nb, nf))


def summary(ev):
    return "%d broken (%d tension, %d shear), first at step %s" % (
        len(ev), sum(e[3] == 1 for e in ev), sum(e[3] == 2 for e in ev), ev[0][0] if ev else "-")


def check_block(work):
    paths = run_three("block_drop", work)
    if not paths:
        return
    j, a, b = paths
    ej = events(j)
    check("bonds/block_drop: bonds break in both modes (jdem: %s)" % summary(ej),
          len(ej) > 0 and {e[3] for e in ej} == {1, 2}, "expected breaks in both modes: %s" % ej[:10])
    if not ej:
        return
    first = ej[0][0]
    for label, x, y in (("jdem vs liggghts-jdem", j, a), ("liggghts-jdem 1 rank vs 2 ranks", a, b)):
        compare_check("bonds/block_drop: %s up to the first break (step %d)" % (label, first), x, y, until=first)
        ex, ey = events(x), events(y)
        check("bonds/block_drop: %s: broken-bond events (step, ids, mode)" % label, ex == ey,
              "%s vs %s" % (summary(ex), summary(ey)))
        fx, fy = fragment_sizes(x), fragment_sizes(y)
        nf = observable(y, "fragments")[-1]
        check("bonds/block_drop: %s: fragment sizes (%d fragments, largest %d)" % (label, len(fx), fx[0]),
              fx == fy and len(fy) == nf and sum(fx) == 64, "%s vs %s, observable %s" % (fx, fy, nf))


CUTOFF = re.compile(r"fix bond/jiang: step (\d+): bond 1-2 is (\S+) m long, not within the ghost cutoff (\S+) m")


def check_ghost_cutoff(work):
    scene = yaml.load(open(os.path.join(SCENES, "ghost_cutoff.yaml")), Loader=yaml.CSafeLoader)
    p = scene["particles"]
    bt = scene["bond_types"]["rubber"]
    R = float(p[0]["radius"])  # (PyYAML reads 1.0e6 as a string: convert every number)
    m = 4.0 * math.pi / 3.0 * R ** 3 * float(scene["materials"]["soft"]["density"])
    k = float(bt["normal_stiffness"]) * math.pi * (float(bt["radius_multiplier"]) * R) ** 2
    omega = math.sqrt(k / (m / 2.0))
    vrel = float(p[1]["velocity"][0]) - float(p[0]["velocity"][0])
    dt = float(scene["time"]["dt"])
    for n in (1, 2):
        out = os.path.join(work, "ghost.np%d.h5" % n)
        rc, text = liggghts("ghost_cutoff", out, n)
        log = liggghts_run_log(out)
        hit = CUTOFF.search(log)
        if not check("bonds/ghost_cutoff: the run stops on %d rank(s) with the bond named" % n,
                     rc != 0 and hit is not None, "exit %d, log tail:\n%s" % (rc, log[-800:])):
            continue
        check("bonds/ghost_cutoff: OUT.part kept, no OUT (%d rank(s))" % n,
              os.path.exists(out + ".part") and not os.path.exists(out), "files: %s" % os.listdir(work))
        step, length, cut = int(hit.group(1)), float(hit.group(2)), float(hit.group(3))
        exact = 2.0 * R + vrel / omega * math.sin(omega * step * dt)
        check("bonds/ghost_cutoff: reported length %.6g m at step %d = oscillator %.6g m (rel 1e-5), "
              "beyond the cutoff %.4g m (%d rank(s))" % (length, step, exact, cut, n),
              abs(length - exact) <= 1e-5 * exact and length >= cut, "length %r exact %r cut %r" % (length, exact, cut))


SAFE_DT = re.compile(r"largest safe dt = (\S+) s")


def check_guard(work):
    """block_drop with 10x stiffer bonds at dt 2e-7: both engines refuse it, the bond bound binds."""
    text = open(os.path.join(SCENES, "block_drop.yaml")).read()
    text = text.replace("normal_stiffness: 1.0e12, shear_stiffness: 5.0e11",
                        "normal_stiffness: 1.0e13, shear_stiffness: 5.0e12").replace("dt: 1.0e-7", "dt: 2.0e-7")
    scene = os.path.join(work, "unsafe_dt.yaml")
    with open(scene, "w") as f:
        f.write(text)
    rc, out = jdem_run(scene, os.path.join(work, "unsafe.jdem.h5"), "--quiet")
    ref = SAFE_DT.search(out)
    if not check("bonds/guard: build/jdem refuses the unsafe bonded scene (bond period)",
                 rc != 0 and ref is not None and "bond period" in out, out[-600:]):
        return
    for n in (1, 2):
        out_h5 = os.path.join(work, "unsafe.np%d.h5" % n)
        rc, _ = liggghts_run(scene, out_h5, ranks=n)
        log = liggghts_run_log(out_h5)
        got = SAFE_DT.search(log)
        check("bonds/guard: liggghts-jdem refuses it on %d rank(s), largest safe dt %s s as jdem" % (n, ref.group(1)),
              rc != 0 and got is not None and got.group(1) == ref.group(1) and "bond period" in log
              and not os.path.exists(out_h5) and not os.path.exists(out_h5 + ".part"),
              "exit %d, log tail:\n%s" % (rc, log[-600:]))


def check_bad_file(work):
    """A deck whose bond file has a line with one id: the message names the file and the line."""
    out = os.path.join(work, "bad.h5")
    rc, text = liggghts("ghost_cutoff", out)  # only to get a deck; it fails as checked above
    deck = os.path.join(work, "bad.deck")
    with open(os.path.join(deck, "bonds_rubber.txt"), "w") as f:
        f.write("# two lines\n1 2\n2\n")
    rc, log, _ = run_deck(deck, log="log.bad")
    check("bonds/bad bond file: stops naming the file and line 3", rc != 0 and
          "bonds_rubber.txt line 3: expected two different atom ids" in log, "exit %d, log tail:\n%s" % (rc, log[-600:]))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=None, help="work directory (default: a temporary one)")
    ap.add_argument("--keep", action="store_true", help="keep the temporary work directory")
    a = ap.parse_args()
    if not os.access(LIGGGHTS_JDEM, os.X_OK):
        check("bonds: build/liggghts-jdem present", False, "run make")
        return 1
    work = a.out or tempfile.mkdtemp(prefix="jdem-bonds-")
    os.makedirs(work, exist_ok=True)
    check_slide(work)
    check_block(work)
    check_ghost_cutoff(work)
    check_bad_file(work)
    check_guard(work)
    if not a.out and not a.keep and not CHECKS.failed:
        shutil.rmtree(work, ignore_errors=True)
    elif not a.out:
        print("work directory: %s" % work)
    return 1 if CHECKS.failed else 0


if __name__ == "__main__":
    sys.exit(main())
