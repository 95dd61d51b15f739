#!/usr/bin/python3
"""test_bonded_inlet_liggghts.py — bonded blocks in an inlet section (Jiang (2021) Ch. 5) in
liggghts-jdem (fix jdem/inlet's "bond I J T" section lines, forming in fix bond/jiang) against
build/jdem, on 1 MPI rank and on 2 split along the belt.

    tests/inlet/test_bonded_inlet_liggghts.py

The scene is tests/inlet/bonded_section.yaml (two sections of one 2 x 2 x 8 weakly bonded block
and a big sphere, falling onto a floor where bonds break); the deck is the generator's.  Checks:

* stream: the insertion record (ids, steps, positions, velocities) is jdem's, line for line;
* bonds: /connectivity/bonds, their formation steps and types equal jdem's exactly (120 bonds:
  two copies of the 60 face-neighbour bonds of a 2 x 2 x 8 lattice);
* breakage: the broken bonds (pairs, steps, modes) equal jdem's, the first break included, and
  some bonds break (the floor impact; the weak bond's strength is exceeded);
* trajectories: every frame holds the same particles, and positions, velocities and spins agree
  with jdem's within the cross-engine tolerance 1e-10 (scaled by R, v and v/R): sphere-sphere
  contacts are not bitwise across the engines (docs/liggghts.md);
* restart: the run killed (SIGKILL) once its LIGGGHTS restart file of step 9000 exists, and
  continued from the file of step 8000 (after the first breaks) with scripts/liggghts_run.py --resume equals the uninterrupted
  run with the same restart cadence bit for bit (every dataset but /h5md), on 1 and 2 ranks; and
  killed after step 3000, continued from step 2000, while the second copy's block is still on the
  belt (its bonds formed by the continued run, as in a campaign fill resumed mid-stream);
* sorting: with LIGGGHTS sorting the atoms every 500 steps (--sort-every, as the campaigns'
  fills), the bonds travel with their atoms: on 1 rank the bonds, breaks and states are again
  jdem's, and on 2 ranks the continued run is again the uninterrupted one bit for bit;
* energy: both engines write the inflow (observables/inlet_energy) alike (1e-12), and in each the
  balance, with the bonds' elastic, damping and breakage energy booked, closes to 1e-3 of the
  inflow (the time discretisation of the floor impacts; some breakage energy is booked);
* breakage diagnostics: scripts/mixing/breakage.py, from the trajectory's bond records alone
  (formed and broken, with steps), gives the intact bonds and the fragments (connected components
  of the intact bonds, scipy) that each engine's own `bonds` and `fragments` observables count
  from its live state, at every 250th sample;
* guard: with bonds stiff enough to set the time step, fix jdem/guard refuses the deck with
  build/jdem's message (the same fastest bond period, from the section's future bonds);
* bad input: a section bond line naming a particle that does not exist, and a bond type without
  its fix bond/jiang, get their exact messages.
One PASS/FAIL line per check.
"""
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.engines import JDEM, LIGGGHTS_JDEM, ROOT
from scripts.mixing import breakage
from tests.engine.engine_common import Checks
from tests.liggghts.check_runner_resume import datasets, kill_session, restart_steps, same_bits

SCENE = os.path.join(ROOT, "tests", "inlet", "bonded_section.yaml")
PY = "/usr/bin/python3"
TOL = 1e-10


def run_liggghts(scene, out, ranks, *extra):
    r = subprocess.run([PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), scene, "-o", out,
                        "--np", str(ranks), *extra], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def read(path):
    with h5py.File(path, "r") as f:
        get = lambda k: f[k][()] if k in f else np.zeros((0,))
        p = f["particles/all"]
        return {"bonds": get("connectivity/bonds"), "formed": get("jdem/bonds/formed_step"),
                "type": get("jdem/bonds/type"), "broken": get("connectivity/broken_bonds"),
                "broken_step": get("jdem/broken_bonds/step"), "mode": get("jdem/broken_bonds/mode"),
                "ids": p["id/value"][()], "steps": p["position/step"][()],
                "state": [p["%s/value" % k][()] for k in ("position", "velocity", "angular_velocity")]}


def scaled_difference(a, b, scales):
    worst = 0.0
    for k, s in enumerate(scales):
        x, y = a["state"][k], b["state"][k]
        both = np.isfinite(x) & np.isfinite(y)
        if both.any():
            worst = max(worst, float(np.max(np.abs(x[both] - y[both])) / s))
    return worst


BOOKED = ("kinetic_energy", "rotational_energy", "elastic_energy", "gravitational_energy",
          "damping_dissipation", "friction_dissipation", "bond_elastic_energy",
          "bond_damping_dissipation", "bond_breakage_energy")


def energy(path):
    """(inflow, the balance's largest residual over the inflow, the breakage energy) at the end."""
    with h5py.File(path, "r") as f:
        o = {k: f["observables/%s/value" % k][()] for k in BOOKED + ("wall_work", "inlet_energy")
             if "observables/%s/value" % k in f}
    if "inlet_energy" not in o:
        return None, None, None
    total = sum(o[k] for k in BOOKED) - o["wall_work"]
    inflow = o["inlet_energy"]
    return inflow, float(np.max(np.abs(total - inflow)) / np.max(np.abs(inflow))), float(o["bond_breakage_energy"][-1])


def check_energy(c, jd_path, lg_path, ranks):
    (a, ra, ba), (b, rb, bb) = energy(jd_path), energy(lg_path)
    if not c.check("energy: liggghts-jdem writes observables/inlet_energy (%d rank(s))" % ranks, b is not None):
        return
    c.check("energy: the same inflow, %.12g J against jdem's %.12g J (%d rank(s))" % (b[-1], a[-1], ranks),
            a.shape == b.shape and np.allclose(a, b, rtol=1e-12, atol=0.0))
    c.check("energy: the balance closes with the bonds' energies booked, largest residual %.2g (jdem) "
            "and %.2g (liggghts-jdem) of the inflow <= 1e-3; breakage %.3g J (%d rank(s))" % (ra, rb, bb, ranks),
            ra <= 1e-3 and rb <= 1e-3 and ba > 0.0 and bb > 0.0)


def check_breakage_records(c, path, who):
    rec = breakage.read_bonds(path)
    with h5py.File(path, "r") as f:
        steps = f["observables/fragments/step"][()]
        fragments, bonds = f["observables/fragments/value"][()], f["observables/bonds/value"][()]
    picked = range(0, len(steps), 250)
    wrong = [int(steps[k]) for k in picked
             if len(breakage.fragment_sizes(rec, int(steps[k]))) != fragments[k]
             or len(breakage.intact_at(rec, int(steps[k]))) != bonds[k]]
    end = breakage.broken_fraction(rec, int(steps[-1]))
    c.check("breakage diagnostics from the records equal %s's bonds and fragments observables at %d "
            "samples (at the end %d fragments, %d of %d bonds broken: %.3f tension, %.3f shear)"
            % (who, len(picked), fragments[-1], end["broken"], end["formed"], end["tension"], end["shear"]),
            not wrong and end["broken"] > 0, "differ at steps %s" % wrong[:5])


def compare(c, jd, lg, ranks, scales, tag=None):
    tag = tag or "%d rank(s)" % ranks
    c.check("bonds: the same 120 bonds, formation steps and types as jdem (%s)" % tag,
            len(jd["bonds"]) == 120 and all(np.array_equal(jd[k], lg[k]) for k in ("bonds", "formed", "type")),
            "jdem %d bonds, liggghts-jdem %d" % (len(jd["bonds"]), len(lg["bonds"])))
    first = lambda d: (tuple(d["broken"][0]), int(d["broken_step"][0]), int(d["mode"][0])) if len(d["broken"]) else None
    c.check("breakage: the first break, pair %s at step %s in mode %s, and all %d broken bonds as "
            "jdem's (%s)" % (*(first(jd) or ("-", "-", "-")), len(jd["broken"]), tag),
            len(jd["broken"]) > 0 and all(np.array_equal(jd[k], lg[k]) for k in ("broken", "broken_step", "mode")),
            "liggghts-jdem: %d broken, first %s" % (len(lg["broken"]), first(lg)))
    same_set = np.array_equal(jd["steps"], lg["steps"]) and np.array_equal(jd["ids"], lg["ids"])
    if c.check("trajectories: the same frames with the same particles (%s)" % tag, same_set):
        worst = scaled_difference(jd, lg, scales)
        c.check("trajectories: states within %g of jdem's, scaled (largest %.2g; %s)" % (TOL, worst, tag),
                worst <= TOL)


RESTART_EVERY, KILL_AFTER = 1000, 9000   # it continues from step 8000, after the first breaks (7184)
# killed after step 3000, it continues from step 2000: the first copy's block is in the box with
# its bonds (inserted at step 1330), the second copy's still on the belt (2730), so the continued
# run forms a copy's bonds itself, as a campaign fill resumed mid-stream does
KILL_MID_STREAM = 3000
SORT = ["--sort-every", "500"]


def check_restart(c, tmp, ranks, *extra, kill_after=KILL_AFTER):
    """EXTRA: more runner options (SORT), named in the checks and the files; killed once the
    restart file of step kill_after exists."""
    runner = [PY, os.path.join(ROOT, "scripts", "liggghts_run.py"), SCENE, "--np", str(ranks),
              "--checkpoint-every", str(RESTART_EVERY), *extra]
    tag = "%d rank(s)%s" % (ranks, ", sorted every %s steps" % extra[-1] if extra else "")
    name = "np%d%s_kill%d" % (ranks, "_sorted" if extra else "", kill_after)
    ref = os.path.join(tmp, "restart_ref_%s.h5" % name)
    r = subprocess.run(runner + ["-o", ref], capture_output=True, text=True)
    if not c.check("restart: the uninterrupted run with restart files (%s)" % tag, r.returncode == 0,
                   r.stderr[-800:]):
        return
    out = os.path.join(tmp, "restart_cont_%s.h5" % name)
    deck = out[:-3] + ".deck"
    proc = subprocess.Popen(runner + ["-o", out], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.time() + 300
    while proc.poll() is None and time.time() < deadline and max(restart_steps(deck) or [0]) < kill_after:
        time.sleep(0.001)
    rc = kill_session(proc)
    r = subprocess.run(runner + ["-o", out, "--resume"], capture_output=True, text=True)
    if not c.check("restart: killed after step %d (exit %s), continued from step %d (%s)" % (kill_after, rc, kill_after - RESTART_EVERY, tag),
                   rc == -signal.SIGKILL and r.returncode == 0 and
                   "--resume: continuing from %s/restart.%d" % (deck, kill_after - RESTART_EVERY) in r.stderr,
                   r.stderr[-800:]):
        return
    a, b = datasets(ref), datasets(out)
    differ = sorted(n for n in a if n not in b or not same_bits(a[n], b[n]))
    c.check("restart: the continued run equals the uninterrupted one bit for bit (%d datasets, bonds "
            "and breaks included; %s)" % (len(a), tag),
            not differ and sorted(a) == sorted(b) and "connectivity/broken_bonds" in a, differ[:8])


def check_guard(c, tmp):
    text = open(SCENE).read().replace("normal_stiffness: 1.0e6, shear_stiffness: 1.0e6",
                                      "normal_stiffness: 1.0e13, shear_stiffness: 1.0e13")
    scene = os.path.join(tmp, "stiff.yaml")
    with open(scene, "w") as f:
        f.write(text)
    r = subprocess.run([JDEM, "run", scene, "-o", os.path.join(tmp, "stiff.h5"), "--quiet"],
                       capture_output=True, text=True)
    rc, log = run_liggghts(scene, os.path.join(tmp, "stiff_lig.h5"), 1)
    period = lambda s: (re.findall(r"fastest bond period \(([^)]*)\)", s) or [None])[0]
    c.check("guard: fix jdem/guard refuses the stiff bonded section as build/jdem does (fastest bond "
            "period %s, liggghts-jdem %s)" % (period(r.stderr), period(log)),
            r.returncode != 0 and rc != 0 and period(r.stderr) is not None and period(r.stderr) == period(log),
            r.stderr[-300:] + log[-300:])


def check_bad_sections(c, tmp):
    resolved = os.path.join(tmp, "resolved.yaml")
    with open(resolved, "w") as f:
        f.write(engines.resolve(SCENE, check=True).stdout)
    deck_dir = os.path.join(tmp, "bad_deck")
    r = engines.write_deck(resolved, os.path.join(deck_dir, "in.jdem"), "--trajectory", os.path.join(tmp, "bad.h5"))
    if not c.check("bad input: the deck is written", r.returncode == 0, r.stderr):
        return
    section = os.path.join(deck_dir, "inlet_belt.txt")
    good = open(section).read()
    cases = (("bond 0 99 0\n", "fix jdem/inlet: section file inlet_belt.txt: bond 0 99 joins a particle "
              "that does not exist; valid: indices 0 to 32 (the particle lines in order)"),
             ("bond 0 31 1\n", "fix in_belt jdem/inlet: a section bond has type 1, but the input defines 1 "
              "fix bond/jiang; valid: types 0 to 0 (the n-th fix bond/jiang is type n - 1)"))
    for line, want in cases:
        with open(section, "w") as f:
            f.write(good + line)
        p = subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", "1", LIGGGHTS_JDEM,
                            "-in", "in.jdem"], cwd=deck_dir, capture_output=True, text=True)
        got = [l for l in (p.stdout + p.stderr).splitlines() if l.startswith("ERROR")]
        c.check("bad input: '%s' is refused with its message" % line.strip(),
                p.returncode != 0 and got and got[0].startswith("ERROR: " + want), got[:1])
    with open(section, "w") as f:
        f.write(good)


def check_rigid(c, tmp):
    """Ch. 6's rigid cements (.inf strengths): every bond intact in both engines, and the two
    trajectories, a growing particle set, within the tolerance (scripts/compare_trajectories.py)."""
    doc = yaml.load(open(SCENE), Loader=yaml.CSafeLoader)
    doc["bond_types"]["weak"].update(tensile_strength=float("inf"), shear_strength=float("inf"))
    doc["watchdog"] = {"max_overlap_fraction": 1.5}   # a big sphere lands on a block: beyond the default 0.5
    scene = os.path.join(tmp, "rigid.yaml")
    with open(scene, "w") as f:
        yaml.safe_dump(doc, f)
    jd_h5, lg_h5 = os.path.join(tmp, "rigid_jdem.h5"), os.path.join(tmp, "rigid_lig.h5")
    r = subprocess.run([JDEM, "run", scene, "-o", jd_h5, "--quiet"], capture_output=True, text=True)
    rc, log = run_liggghts(scene, lg_h5, 1)
    if not c.check("rigid: both engines run the section with unbreakable bonds",
                   r.returncode == 0 and rc == 0, r.stderr + log[-1500:]):
        return
    for name, path in (("jdem", jd_h5), ("liggghts-jdem", lg_h5)):
        d = read(path)
        c.check("rigid: all %d bonds formed and none broken in %s" % (len(d["bonds"]), name),
                len(d["bonds"]) == 120 and len(d["broken"]) == 0, "%d broken" % len(d["broken"]))
    p = engines.run(engines.script("compare_trajectories", jd_h5, lg_h5))
    c.check("rigid: the trajectories agree (compare_trajectories.py on a growing set: %s)" %
            p.stdout.strip().splitlines()[-1], p.returncode == 0, p.stdout[-1500:] + p.stderr[-800:])


def main():
    c = Checks()
    if not c.built(JDEM, LIGGGHTS_JDEM):
        return 1
    sc = yaml.load(engines.resolve(SCENE, check=True).stdout, Loader=yaml.CSafeLoader)
    inlet = sc["inlets"][0]
    R = max(p["radius"] for p in inlet["section"]["particles"])
    v = float(np.linalg.norm(inlet["velocity"]))
    scales = (R, v, v / R)
    with tempfile.TemporaryDirectory() as tmp:
        jd_h5, jd_rec = os.path.join(tmp, "jdem.h5"), os.path.join(tmp, "jdem.csv")
        r = subprocess.run([JDEM, "run", SCENE, "-o", jd_h5, "--inlet-record", jd_rec, "--quiet"],
                           capture_output=True, text=True)
        if not c.check("jdem runs the bonded section", r.returncode == 0, r.stderr):
            return 1
        jd = read(jd_h5)
        check_breakage_records(c, jd_h5, "jdem")
        for ranks in (1, 2):
            lg_h5 = os.path.join(tmp, "lig_np%d.h5" % ranks)
            # 2 ranks split along the belt: the falling blocks cross the subdomain boundary, so
            # bonds are formed and evaluated with their partners on the other rank
            split = ["--processors", "2", "1", "1"] if ranks == 2 else []
            rc, log = run_liggghts(SCENE, lg_h5, ranks, *split,
                                   "--inlet-record", os.path.join(tmp, "lig_np%d.csv" % ranks))
            if not c.check("liggghts-jdem runs the generated deck on %d rank(s)" % ranks, rc == 0, log[-1500:]):
                continue
            rec = open(os.path.join(tmp, "lig_np%d.csv" % ranks)).read()
            c.check("stream: the insertion record equals jdem's (%d lines; %d rank(s))" % (rec.count("\n"), ranks),
                    rec == open(jd_rec).read())
            compare(c, jd, read(lg_h5), ranks, scales)
            check_energy(c, jd_h5, lg_h5, ranks)
            if ranks == 2:
                check_breakage_records(c, lg_h5, "liggghts-jdem on 2 ranks")
        lg_h5 = os.path.join(tmp, "lig_sorted.h5")
        rc, log = run_liggghts(SCENE, lg_h5, 1, *SORT)
        if c.check("liggghts-jdem runs the deck sorting its atoms every %s steps" % SORT[-1], rc == 0, log[-1500:]):
            compare(c, jd, read(lg_h5), 1, scales, "1 rank, sorted every %s steps" % SORT[-1])
        resumed_at = KILL_MID_STREAM - RESTART_EVERY
        inserted = np.loadtxt(jd_rec, delimiter=",", skiprows=1, usecols=1)
        c.check("restart mid-stream: at step %d copies are in the box and to come (insertion steps %s)"
                % (resumed_at, sorted(set(inserted.astype(int).tolist()))),
                (inserted < resumed_at).any() and (inserted > resumed_at).any())
        for ranks in (1, 2):
            check_restart(c, tmp, ranks)
            check_restart(c, tmp, ranks, kill_after=KILL_MID_STREAM)
        check_restart(c, tmp, 2, *SORT)
        check_guard(c, tmp)
        check_bad_sections(c, tmp)
        check_rigid(c, tmp)
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
