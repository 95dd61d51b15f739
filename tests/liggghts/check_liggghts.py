#!/usr/bin/python3
"""check_liggghts.py — cross-engine checks: build/jdem against build/liggghts-jdem.

    tests/liggghts/check_liggghts.py [--out DIR] [--chung-ooi] [--keep]

Builds nothing (run `make` first).  For every scene in tests/liggghts/scenes/ it runs the
standalone engine (build/jdem run) and LIGGGHTS (scripts/liggghts_run.py) and compares the
trajectories with scripts/compare_trajectories.py (tolerance: the scene's output.compare_tolerance,
default 1e-10, scaled as documented there);
the scenes named mpi_*.yaml are also run on 2 MPI ranks and compared with the 1-rank LIGGGHTS
run.  Both engines must write the same observables.  A scene with output.energy: false (gran/jiang
`energy no`: the short contact history) is also run in LIGGGHTS with the energy bookkeeping on
(the full history, the reference path): the trajectories must be identical bit for bit; and its
deck, with the dump or the watchdog asking for energies, must stop at init with a message naming
them and leave no trajectory.  With
--chung-ooi the cases of reference_runs/chung_ooi/test*/scene.yaml are checked too.
Prints one PASS/FAIL line per check and exits 1 if any check fails.
"""
import argparse
import glob
import os
import shutil
import sys
import tempfile

import yaml

from tests.liggghts.liggghts_common import (HERE, JDEM, LIGGGHTS_JDEM, ROOT, compare, jdem_run, last_line,
                                            liggghts_run, observable_names, run, run_deck)


def indented(text):
    return "".join("    " + l + "\n" for l in text.rstrip().splitlines())


def energy_off_checks(scene, stem, label):
    """The scene has output.energy: false.  Returns the number of failed checks."""
    failures = 0
    # reference path: the same scene with the energy bookkeeping (full contact history)
    with open(scene) as f:
        doc = yaml.load(f, Loader=yaml.CSafeLoader)
    doc.setdefault("output", {})["energy"] = True
    full = stem + ".energy_on.yaml"
    with open(full, "w") as f:
        yaml.safe_dump(doc, f)
    rc, out = liggghts_run(full, stem + ".energy_on.h5")
    if rc != 0:
        print("FAIL %s: liggghts_run.py with energy on:\n%s" % (label, indented(out.strip()[-1500:])))
        return 1
    ok, summary, text = compare(stem + ".energy_on.h5", stem + ".lig.h5", "--tol", repr(0.0))
    print("%s %s: liggghts-jdem short history (energy no) vs full history: %s" % (
        "PASS" if ok else "FAIL", label, summary))
    if not ok:
        failures += 1
        sys.stdout.write(indented(text))
    # a consumer of the energies in a deck whose pair style keeps none: a clear error at init
    deck_dir = os.path.abspath(stem + ".lig.deck")
    with open(os.path.join(deck_dir, "in.jdem")) as f:
        deck = f.read()
    for what, old, new, expect in (
            ("dump", " energy no\nrun", "\nrun",
             "dump d (h5md/jdem) writes the energy observables: add 'energy no' to the dump"),
            ("watchdog", "energy off", "energy 0.05",
             "fix watchdog (jdem/watchdog) checks the energy balance: add 'energy off' to the fix")):
        if old not in deck:
            print("FAIL %s: the generated deck has no '%s'" % (label, old))
            failures += 1
            continue
        bad = os.path.join(deck_dir, "in.%s_wants_energy" % what)
        traj = os.path.join(deck_dir, "%s_wants_energy.h5" % what)
        text = deck.replace(old, new, 1).replace(os.path.abspath(stem + ".lig.h5"), traj)
        with open(bad, "w") as f:
            f.write(text)
        log = "log.%s_wants_energy" % what
        for p in (traj, traj + ".part", os.path.join(deck_dir, log)):  # from an earlier run in the same --out
            if os.path.exists(p):
                os.remove(p)
        rc, said, _ = run_deck(deck_dir, bad, log=log)  # the log: the screen of an aborted run is not flushed
        left = [p for p in (traj, traj + ".part") if os.path.exists(p)]
        ok = rc != 0 and "pair_style gran/jiang energy no" in said and expect in said and not left
        print("%s %s: energy no with the %s asking for energies: %s" % (
            "PASS" if ok else "FAIL", label, what,
            "exit %d, clear message, no trajectory" % rc if ok else
            "exit %d, files left %s, output:\n%s" % (rc, left, indented(said.strip()[-800:]))))
        failures += 0 if ok else 1
    return failures


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=None, help="work directory (default: a temporary one)")
    ap.add_argument("--chung-ooi", action="store_true", help="also check the Chung-Ooi scenes")
    ap.add_argument("--keep", action="store_true", help="keep the temporary work directory")
    a = ap.parse_args()
    for exe in (JDEM, LIGGGHTS_JDEM):
        if not os.access(exe, os.X_OK):
            print("FAIL liggghts: %s is missing (run make)" % os.path.relpath(exe, ROOT))
            return 1
    work = a.out or tempfile.mkdtemp(prefix="jdem-liggghts-")
    os.makedirs(work, exist_ok=True)

    cases = [(p, None) for p in sorted(glob.glob(os.path.join(HERE, "scenes", "*.yaml")))]
    if a.chung_ooi:
        for p in sorted(glob.glob(os.path.join(ROOT, "reference_runs", "chung_ooi", "test*", "scene.yaml"))):
            rc, out = run([JDEM, "cases", p])
            if rc != 0:
                print("FAIL %s: jdem cases: %s" % (os.path.relpath(p, ROOT), last_line(out)))
                continue
            cases += [(p, c) for c in out.split()]

    failures = 0
    for scene, case in cases:
        name = os.path.splitext(os.path.basename(scene))[0]
        if os.path.basename(scene) == "scene.yaml":
            name = os.path.basename(os.path.dirname(scene))
        label = name + ("/" + case if case else "")
        stem = os.path.join(work, label.replace("/", "_"))
        rc, out = jdem_run(scene, stem + ".jdem.h5", *(["--case", case] if case else []), "--quiet")
        if rc != 0:
            print("FAIL %s: build/jdem run: %s" % (label, last_line(out)))
            failures += 1
            continue
        rc, out = liggghts_run(scene, stem + ".lig.h5", case=case)
        if rc != 0:
            print("FAIL %s: liggghts_run.py:\n%s" % (label, indented(out.strip()[-1500:])))
            failures += 1
            continue
        ok, summary, full = compare(stem + ".jdem.h5", stem + ".lig.h5")
        names = (observable_names(stem + ".jdem.h5"), observable_names(stem + ".lig.h5"))
        if ok and names[0] != names[1]:
            ok, summary = False, "observables differ: jdem %s, liggghts-jdem %s" % names
        print("%s %s: jdem vs liggghts-jdem: %s" % ("PASS" if ok else "FAIL", label, summary))
        if not ok:
            failures += 1
            sys.stdout.write(indented(full))
        with open(scene) as f:
            energy = ((yaml.load(f, Loader=yaml.CSafeLoader) or {}).get("output") or {}).get("energy", True)
        if not energy and case is None:
            failures += energy_off_checks(scene, stem, label)
        if name.startswith("mpi_"):
            rc, out = liggghts_run(scene, stem + ".np2.h5", case=case, ranks=2)
            if rc != 0:
                print("FAIL %s: liggghts_run.py --np 2:\n%s" % (label, indented(out.strip()[-1500:])))
                failures += 1
                continue
            ok, summary, full = compare(stem + ".lig.h5", stem + ".np2.h5")
            print("%s %s: liggghts-jdem 1 rank vs 2 ranks: %s" % ("PASS" if ok else "FAIL", label, summary))
            if not ok:
                failures += 1
                sys.stdout.write(indented(full))

    print("%d checks failed" % failures if failures else "all checks passed")
    if not a.out and not a.keep and not failures:
        shutil.rmtree(work, ignore_errors=True)
    elif not a.out:
        print("work directory: %s" % work)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
