#!/usr/bin/python3
"""check_tutorials.py — LIGGGHTS' public tutorials, converted to gran/jiang, against stock LIGGGHTS.

    tests/liggghts/check_tutorials.py [--keep] [--only NAME,...]

Builds nothing (run `make build/liggghts-jdem` first).  Each tutorial of
reference_runs/liggghts_tutorials/ has a shortened stock deck (run by Debian's /usr/bin/liggghts)
and a shortened converted deck (gran/jiang, every wall a fix wall/jiang; run by
build/liggghts-jdem).  Both run in a scratch directory beside the tutorial's meshes (Debian's
liggghts-doc), each writing its particles to final.txt (LIGGGHTS' own `dump custom`).  The
checks assert numbers against references that neither engine computes: the count the insertion
fix's parameters give, the closed-form growth of fix adapt, the container's geometry (no
particle outside a wall or an STL mesh), a free-fall bound on the speeds, the belt speed of a
conveyor, the conservation of heat; and the stock and converted beds against each other within
a tolerance argued in reference_runs/liggghts_tutorials/README.md.  One PASS/FAIL line per check.
"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

from tests.liggghts.liggghts_common import ROOT, Checks, LIGGGHTS_JDEM, finish

TUTORIALS = os.path.join(ROOT, "reference_runs", "liggghts_tutorials")
STOCK_TUTORIALS = "/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public"
STOCK = "/usr/bin/liggghts"
G = 9.81
# A sphere that passed through a wall would sit a radius or more beyond it; a sphere pressed
# against it overlaps it by a fraction of its radius (the packing's growth presses the spheres
# into the walls by up to 0.19 R in stock LIGGGHTS, 0.11 R with gran/jiang).
OVERLAP = 0.25


def frames(path):
    """Every frame of a LIGGGHTS `dump custom` text file: {step: {column: array}}."""
    out = {}
    for block in open(path).read().split("ITEM: TIMESTEP")[1:]:
        lines = block.strip().splitlines()
        k = next(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
        cols = lines[k].split()[2:]
        rows = np.array([l.split() for l in lines[k + 1:] if l.strip()], dtype=float).reshape(-1, len(cols))
        out[int(lines[0])] = {c: rows[:, j] for j, c in enumerate(cols)}
    return out


def run(tmp, name, deck, engine, stock_dir):
    """Run reference_runs/liggghts_tutorials/NAME/DECK with ENGINE ('stock' or 'jiang') in
    TMP/NAME.ENGINE beside STOCK_DIR's meshes: (exit status, log text, frames of final.txt)."""
    d = os.path.join(tmp, "%s.%s" % (name, engine))
    os.makedirs(os.path.join(d, "post"))
    shutil.copy(os.path.join(TUTORIALS, name, deck), os.path.join(d, "in.deck"))
    meshes = os.path.join(STOCK_TUTORIALS, stock_dir, "meshes")
    if os.path.isdir(meshes):
        os.symlink(meshes, os.path.join(d, "meshes"))
    binary = STOCK if engine == "stock" else LIGGGHTS_JDEM
    # LIGGGHTS 3.8's STL reader writes to the screen: -screen none would crash it
    r = subprocess.run([binary, "-in", "in.deck", "-log", "log.lammps", "-screen", "screen.txt"],
                       cwd=d, capture_output=True, text=True)
    log = open(os.path.join(d, "log.lammps"), errors="replace").read() if os.path.exists(
        os.path.join(d, "log.lammps")) else ""
    final = os.path.join(d, "final.txt")
    return r.returncode, log, frames(final) if r.returncode == 0 and os.path.exists(final) else {}


def last(fr):
    return fr[max(fr)]


def speed(f):
    return np.sqrt(f["vx"] ** 2 + f["vy"] ** 2 + f["vz"] ** 2)


def sphere_volume(r):
    return 4.0 * math.pi / 3.0 * r ** 3


def number_weights(mass_fractions, radii, density):
    """particledistribution/discrete's weights are mass fractions: the number fractions."""
    n = np.array(mass_fractions) / (density * sphere_volume(np.array(radii)))
    return n / n.sum()


def inside_box(f, lo, hi, tol):
    """Every centre at least radius - tol inside the box [lo, hi] (3-vectors)."""
    r = f["radius"]
    ok = True
    for k, c in enumerate("xyz"):
        ok = ok and bool(np.all(f[c] >= lo[k] + r - tol) and np.all(f[c] <= hi[k] - r + tol))
    return ok


def inside_cylinder(f, radius, z0, z1, tol):
    rho = np.hypot(f["x"], f["y"])
    r = f["radius"]
    return bool(np.all(rho <= radius - r + tol) and np.all(f["z"] >= z0 + r - tol) and
                np.all(f["z"] <= z1 - r + tol))


def free_fall_bound(f, v_insert, height, wall_speed=0.0):
    """No speed above an insertion at |v_insert| falling the whole HEIGHT, plus the fastest wall
    (energy conservation: contacts and walls at rest only take energy away)."""
    return float(speed(f).max()) <= math.sqrt(v_insert ** 2 + 2 * G * height) + 2 * wall_speed


# ---------------------------------------------------------------------------------------------
# One function per tutorial: (stock frames, jiang frames, their logs) -> checks.


def packing(c, fr, logs):
    # insert/pack volumefraction_region 0.25 in the 0.1 x 0.1 x 0.15 box: int(x + U[0,1)) atoms
    w = number_weights([0.3, 0.7], [0.005, 0.008], 2500.0)
    x = 0.25 * 0.1 * 0.1 * 0.15 / float(np.dot(w, sphere_volume(np.array([0.005, 0.008]))))
    # fix adapt every 40 steps over 2000 steps, at set-up too: 51 growths by (0.5/0.25)^(40/6000)
    growth = (0.5 / 0.25) ** (40.0 / (3.0 * 2000.0) * 51)
    for e in ("stock", "jiang"):
        f = last(fr[e])
        n = len(f["id"])
        c.check("packing %s: %d particles inserted, int(%.2f + U) of insert/pack's volume fraction" % (e, n, x),
                math.floor(x) <= n <= math.floor(x) + 1)
        radii = np.unique(np.round(f["radius"] / growth, 9))
        c.check("packing %s: radii grown to (0.005, 0.008) x %.6f (fix adapt's closed form): %s" % (e, growth, radii),
                np.allclose(radii, [0.005, 0.008], rtol=1e-5))
        c.check("packing %s: every particle inside the six walls" % e,
                inside_box(f, (-0.05, -0.05, 0.0), (0.05, 0.05, 0.15), OVERLAP * 0.005))
    zs, zj = np.mean(last(fr["stock"])["z"]), np.mean(last(fr["jiang"])["z"])
    c.check("packing: mean height stock %.5f, jiang %.5f m, within 2 %% of the box height" % (zs, zj),
            abs(zs - zj) <= 0.02 * 0.15)


def insert_stream(c, fr, logs):
    # insert/stream particlerate 1000 over the steps 1 ... 20001 at dt 1e-5 (nparticles 5000 not reached)
    for e in ("stock", "jiang"):
        f = last(fr[e])
        n = len(f["id"])
        c.check("insert_stream %s: %d particles, particlerate 1000 x 0.2 s of insertion (+- 1 per insertion of 0.3 s period)" % (e, n),
                abs(n - 1000 * 0.2) <= 0.3 * 1000 + 1)
        c.check("insert_stream %s: speeds within free fall from the insertion at 2.06 m/s" % e,
                free_fall_bound(f, math.hypot(0.5, 2.0), 2.9))
    a, b = last(fr["stock"]), last(fr["jiang"])
    same = np.array_equal(a["id"], b["id"]) or len(a["id"]) == len(b["id"])
    dz = abs(np.mean(a["z"]) - np.mean(b["z"]))
    c.check("insert_stream: the same stream (free fall, both velocity Verlet): mean z differs %.2e m <= 1e-3 m" % dz,
            same and dz <= 1e-3)


def mesh_gran(c, fr, logs):
    # the chute STL, scaled 0.001 and turned -90 degrees about x: x in [-0.008, 0.508],
    # y in [-0.058, 0.008], z >= -1.209 (the channel's walls and floor)
    for e in ("stock", "jiang"):
        f = last(fr[e])
        n = len(f["id"])
        c.check("meshGran %s: %d particles, particlerate 1000 x 0.15 s (3000 steps of 5e-5 s), +-10 %%" % (e, n),
                abs(n - 150) <= 15)
        inside = (np.all(f["x"] >= -0.008) and np.all(f["x"] <= 0.508) and np.all(f["y"] >= -0.058)
                  and np.all(f["y"] <= 0.008) and np.all(f["z"] >= -1.209))
        c.check("meshGran %s: no particle through the STL chute" % e, bool(inside))
        c.check("meshGran %s: speeds within free fall from 1 m/s over the 1.2 m chute" % e,
                free_fall_bound(f, 1.0, 1.23))
    zs, zj = np.mean(last(fr["stock"])["z"]), np.mean(last(fr["jiang"])["z"])
    c.check("meshGran: mean height of the flow stock %.4f, jiang %.4f m: within 0.02 m" % (zs, zj), abs(zs - zj) <= 0.02)


def moving_mesh_gran(c, fr, logs):
    for e in ("stock", "jiang"):
        f = last(fr[e])
        c.check("movingMeshGran %s: %d particles, insert/pack particles_in_region 150" % (e, len(f["id"])),
                len(f["id"]) == 150)
        c.check("movingMeshGran %s: every particle inside the six box walls" % e,
                inside_box(f, (-1.0, -0.5, -0.5), (1.0, 0.5, 0.5), OVERLAP * 0.04))
        # the bucket moves at 0.58 m/s, then turns at 2 pi/2 s about y (its tip within 1 m: 3.2 m/s)
        c.check("movingMeshGran %s: speeds within free fall from 0.8 m/s over 1 m, plus the bucket's 3.2 m/s" % e,
                free_fall_bound(f, 0.8, 1.0, 3.2))


def conveyor(c, fr, logs):
    # insert/stream massrate 30 kg/s, one insertion per extrude_length / |v| = 0.1 s (steps 1,
    # 10001, ... 40001): 5 x 3 kg by step 45000, / mass_expect of the mass-weighted templates
    m = 2500.0 * sphere_volume(np.array([0.015, 0.025]))
    expect = 5 * 3.0 / float(np.dot([0.3, 0.7] / m / np.sum([0.3, 0.7] / m), m))
    for e in ("stock", "jiang"):
        f = last(fr[e])
        n = len(f["id"])
        c.check("conveyor %s: %d particles, 15 kg / mass_expect = %.1f (+-2 %%)" % (e, n, expect),
                abs(n - expect) <= 0.02 * expect)
        c.check("conveyor %s: every particle inside box.stl (open at the top, below the insertion's 0.3 m)" % e,
                inside_box(f, (-0.5, -0.2, -0.2), (0.5, 0.2, 0.3), OVERLAP * 0.015))
        # a sphere that rolls on the belt without slipping has the belt's velocity at its contact
        # point: v_x - R omega_y = surface_vel (-4.5 m/s)
        on = (np.abs(f["z"] - f["radius"]) < 2e-3) & (f["x"] > -0.1)
        contact_v = np.median(f["vx"][on] - f["radius"][on] * f["omegay"][on])
        c.check("conveyor %s: %d spheres on the belt, median contact-point velocity %.3f m/s = -4.5 +- 2 %%"
                % (e, on.sum(), contact_v), on.sum() >= 20 and abs(contact_v + 4.5) <= 0.02 * 4.5)


def chute_wear(c, fr, logs):
    for e in ("stock", "jiang"):
        f = last(fr[e])
        n = len(f["id"])
        # massrate 0.1 kg/s inserted every 1000 steps, 10 insertions over 0.1 s
        m = 2500.0 * sphere_volume(np.array([0.0015, 0.0025]))
        expect = 0.1 * 0.1 / float(np.dot([0.3, 0.7] / m / np.sum([0.3, 0.7] / m), m))
        c.check("chute_wear %s: %d particles, 0.1 kg/s x 0.1 s / mass_expect = %.1f (+-10 %%)" % (e, n, expect),
                abs(n - expect) <= 0.1 * expect)
        inside = (np.all(f["x"] >= -0.3615) and np.all(f["x"] <= 0.05) and np.all(np.abs(f["y"]) <= 0.15)
                  and np.all(f["z"] >= -0.2434))
        c.check("chute_wear %s: no particle through the STL chute" % e, bool(inside))
    zs, zj = np.mean(last(fr["stock"])["z"]), np.mean(last(fr["jiang"])["z"])
    c.check("chute_wear: mean height stock %.4f, jiang %.4f m: within 0.01 m" % (zs, zj), abs(zs - zj) <= 0.01)


def cylinder_bed(c, fr, name, count, r, settle_tol):
    for e in ("stock", "jiang"):
        f = last(fr[e])
        c.check("%s %s: %d particles, insert/pack's %d" % (name, e, len(f["id"]), count), len(f["id"]) == count)
        c.check("%s %s: every particle inside the cylinder and its two planes" % (name, e),
                inside_cylinder(f, 0.05, 0.0, 0.15, 0.1 * r))
        c.check("%s %s: speeds within free fall over the 0.15 m container" % (name, e),
                free_fall_bound(f, 0.5, 0.15))
    zs, zj = np.median(last(fr["stock"])["z"]), np.median(last(fr["jiang"])["z"])
    c.check("%s: median height stock %.5f, jiang %.5f m: within %.2f particle radii" % (name, zs, zj, settle_tol),
            abs(zs - zj) <= settle_tol * r)


def no_cohesion(c, fr, logs):
    cylinder_bed(c, fr, "noCohesion", 250, 0.0015, 0.5)


def contact_models(c, fr, logs):
    cylinder_bed(c, fr, "contactModels", 600, 0.0025, 0.5)


def heat_transfer(c, fr, logs):
    # insert/pack volumefraction_region 0.08 of the r = 0.045, h = 0.15 cylinder, r = 4 mm
    x = 0.08 * math.pi * 0.045 ** 2 * 0.15 / sphere_volume(0.004)
    for e in ("stock", "jiang"):
        n = len(last(fr[e])["id"])
        c.check("heatTransfer %s: %d particles, int(%.2f + U) of the volume fraction" % (e, n, x),
                math.floor(x) <= n <= math.floor(x) + 1)
        c.check("heatTransfer %s: inside the cylinder" % e, inside_cylinder(last(fr[e]), 0.05, 0.0, 0.15, 0.0004))
        # set region halfbed (x >= 0) Temp 800 at step 8000; heat/gran moves heat between
        # particles only: sum m c T stays what the set gave (c is one constant)
        at = fr[e][8000]
        heat0 = float(np.sum(at["mass"] * np.where(at["x"] >= 0.0, 800.0, 300.0)))
        f = last(fr[e])
        heat = float(np.sum(f["mass"] * f["f_Temp[0]"]))
        moved = np.count_nonzero((f["f_Temp[0]"] > 300.001) & (f["f_Temp[0]"] < 799.999))
        c.check("heatTransfer %s: sum m T %.7g = %.7g after the set (1e-6), %d particles between 300 and 800 K"
                % (e, heat, heat0, moved), abs(heat - heat0) <= 1e-6 * heat0 and moved > 10)


# ---------------------------------------------------------------------------------------------
# Our fixes with LIGGGHTS' insertion, on decks derived from the tutorials.

POUR = """atom_style granular
atom_modify map array
boundary m m m
newton off
communicate single vel yes
units si
region reg block -0.05 0.05 -0.05 0.05 0. 0.15 units box
create_box 1 reg
neighbor 0.002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype {E}
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.9
fix m4 all property/global coefficientFriction peratomtypepair 1 0.05
pair_style gran/jiang
pair_coeff * *
timestep {dt}
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
{floor}
region bc cylinder z 0.01 0.01 0.025 0.05 0.0603 units box
fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.0015
fix pdd1 all particledistribution/discrete 15485867 1 pts1 1.0
fix ins all insert/pack seed 32452843 distributiontemplate pdd1 maxattempt 100 insert_every once &
    overlapcheck yes all_in yes vel constant 0.0 0.0 -0.2 region bc particles_in_region 50
fix integr all nve/sphere
{extra}
run {steps}
"""
FLOOR_UP = "fix floor all wall/jiang plane corners -0.05 -0.05 0 0.05 -0.05 0 0.05 0.05 0 -0.05 0.05 0 type 1"
FLOOR_DOWN = "fix floor all wall/jiang plane corners -0.05 0.05 0 0.05 0.05 0 0.05 -0.05 0 -0.05 -0.05 0 type 1"


def run_text(tmp, name, text):
    d = os.path.join(tmp, name)
    os.makedirs(d)
    open(os.path.join(d, "in.deck"), "w").write(text)
    # insert/pack's region writes to the screen: -screen none would crash LIGGGHTS 3.8
    r = subprocess.run([LIGGGHTS_JDEM, "-in", "in.deck", "-log", "log.lammps", "-screen", "screen.txt"],
                       cwd=d, capture_output=True, text=True)
    log = os.path.join(d, "log.lammps")
    return r.returncode, open(log, errors="replace").read() if os.path.exists(log) else "", d


def guard_templates(c, tmp):
    """The run starts with no atoms: the guard judges insert/pack's template (R 1.5 mm, 2500
    kg/m^3).  E = 5e8 Pa makes 20 % of its Rayleigh step shorter than dt = 1e-5 s."""
    E, R, rho, nu = 5e8, 0.0015, 2500.0, 0.45
    # the shortest Hertz contact: a sphere against a rigid wall, E* = E/(1-nu^2), R* = R, at
    # the template's insertion speed 0.2 m/s (vmax 0: only the template gives a speed):
    # t_c = 3.2181 (m/k)^(2/5) v^(-1/5), k = 4/3 E* sqrt(R*) (docs/model.md, section 8)
    m = rho * sphere_volume(R)
    k = 4.0 / 3.0 * E / (1 - nu ** 2) * math.sqrt(R)
    bound = 3.2181 * (m / k) ** 0.4 * 0.2 ** -0.2 / 50.0
    guard = "fix g all jdem/guard vmax 0"
    rc, log, _ = run_text(tmp, "guard_stiff", POUR.format(E=E, dt=1e-5, floor=FLOOR_UP, extra=guard, steps=100))
    line = next((l for l in log.splitlines() if l.startswith("ERROR: jdem: time step")), "")
    m = re.search(r"Hertz contact time \(([0-9.e+-]+) s\)", line)
    c.check("guard: a deck inserting too stiff particles is refused at set-up, bound %.6g s (%s)" % (bound, line[:120]),
            rc != 0 and m is not None and abs(float(m.group(1)) - bound) <= 1e-4 * bound
            and "Loop time" not in log, log[-300:])
    rc, log, _ = run_text(tmp, "guard_safe", POUR.format(E=5e6, dt=2e-6, floor=FLOOR_UP, extra=guard, steps=100))
    c.check("guard: the same deck with E = 5e6 Pa and dt = 2e-6 s runs (50 particles inserted)",
            rc == 0 and "for 100 steps with 50 atoms" in log, log[-300:])


def guard_cannot_check(c, tmp):
    """A template the guard cannot read (a multisphere) is named, and a run with nothing to judge
    says so (LIGGGHTS then stops this deck itself: multispheres need fix multisphere)."""
    deck = POUR.format(E=5e6, dt=2e-6, floor=FLOOR_UP, extra="fix g all jdem/guard vmax 0", steps=10).replace(
        "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.0015",
        "fix pts1 all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 2 "
        "ntry 1000000 spheres 0 0 0 0.0015 0.001 0 0 0.0015 type 1")
    rc, log, _ = run_text(tmp, "guard_multisphere", deck)
    lines = log.splitlines()
    for want in ("WARNING: fix jdem/guard cannot check the particles that fix ins (insert/pack) will insert: "
                 "its template pts1 (particletemplate/multisphere) is not one sphere of absolute radius; "
                 "it checks the atoms present and the other insertions",
                 "WARNING: fix jdem/guard: no particles and no insertion template to check at this run's "
                 "set-up: the time step is not checked until a run starts with some"):
        c.check("guard: says %r" % want[9:60], any(l.startswith(want) for l in lines), log[-300:])


def watchdog_insertion(c, tmp):
    """insert/stream into free space with the watchdog's energy check every 100 steps: the
    booked inflow equals the energy of the inserted atoms (conserved in free flight by velocity
    Verlet, so any later frame gives it), and without it the account would jump by more than the
    watchdog's limit."""
    deck = open(os.path.join(TUTORIALS, "insert_stream", "in.insert_stream.jiang.short")).read()
    deck = deck.replace("fix\t\tintegr nve_group nve/sphere",
                        "fix\t\tintegr nve_group nve/sphere\nfix\t\twd all jdem/watchdog 100 energy 0.05")
    deck = deck.replace("run\t\t20000", "run\t\t6000")
    d = os.path.join(tmp, "watchdog")
    os.makedirs(d)
    os.symlink(os.path.join(STOCK_TUTORIALS, "insert_stream", "meshes"), os.path.join(d, "meshes"))
    open(os.path.join(d, "in.deck"), "w").write(deck.replace("final.txt id", "final.txt id").replace(
        "dump fin all custom 20000", "dump fin all custom 6000"))
    with open(os.path.join(d, "in.deck")) as fh:
        text = fh.read()
    with open(os.path.join(d, "in.deck"), "w") as fh:
        fh.write(re.sub(r"(dump fin .*\n)", r"\1dump_modify fin first yes format '%d %d" + " %.17g" * 11 + r"'\n", text))
    r = subprocess.run([LIGGGHTS_JDEM, "-in", "in.deck", "-log", "log.lammps", "-screen", "screen.txt"],
                       cwd=d, capture_output=True, text=True)
    log = open(os.path.join(d, "log.lammps"), errors="replace").read()
    booked = [float(x) for x in re.findall(r"jdem/watchdog: booked the energy of \d+ atoms inserted by fix insert: (\S+) J", log)]
    c.check("watchdog: an insert/stream run with the energy check is not stopped (exit %d)" % r.returncode,
            r.returncode == 0 and booked, log[-400:])
    if r.returncode or not booked:
        return
    # the dump starts after `run 1`: its first frame is the end of step 1, the insertion step
    # (insert/stream then moves the atoms at constant velocity until they leave the extruded
    # volume, so later frames differ)
    f = frames(os.path.join(d, "final.txt"))[1]
    energy = float(np.sum(0.5 * f["mass"] * speed(f) ** 2 + 0.5 * 0.4 * f["mass"] * f["radius"] ** 2 *
                          (f["omegax"] ** 2 + f["omegay"] ** 2 + f["omegaz"] ** 2) + f["mass"] * G * f["z"]))
    c.check("watchdog: booked inflow %.9g J = sum 1/2 m v^2 + 1/2 I w^2 - m g.x of the %d atoms, %.9g J (1e-9)"
            % (booked[-1], len(f["id"]), energy), abs(booked[-1] - energy) <= 1e-9 * abs(energy))
    c.check("watchdog: unbooked, this inflow (all of the energy in play) would exceed the 0.05 jump limit",
            abs(booked[-1]) > 0.05 * abs(energy))


def wound_plane(c, tmp):
    """A floor wound downward under the inserted particles: refused at the set-up of the run
    after the insertion, with the way to wind it; wound upward it runs."""
    two_runs = "run 1\nrun 10"
    rc, log, _ = run_text(tmp, "plane_down", POUR.format(E=5e6, dt=2e-6, floor=FLOOR_DOWN, extra="", steps=1).replace(
        "run 1\n", two_runs + "\n"))
    want = ("ERROR: fix floor wall/jiang plane: its active side, normal (0, 0, -1) = (P2-P1) x (P3-P1), "
            "faces away from the particles: all 50 particles of group all over the plane are behind it, "
            "so they would pass through it. List the corners counter-clockwise as seen from the "
            "particles: reverse their order (P4 P3 P2 P1), which turns the normal to (0, 0, 1)")
    c.check("plane: a floor wound away from the particles is refused with the winding to use",
            rc != 0 and any(l.startswith(want) for l in log.splitlines()), log[-400:])
    rc, log, _ = run_text(tmp, "plane_up", POUR.format(E=5e6, dt=2e-6, floor=FLOOR_UP, extra="", steps=1).replace(
        "run 1\n", two_runs + "\n"))
    c.check("plane: wound towards the particles it runs", rc == 0 and "for 10 steps with 50 atoms" in log, log[-300:])


def pair_swapped_only(c, tmp):
    """The issue's new user: insert_stream's stock deck with only its pair_style line replaced.
    Its characteristicVelocity and cohesionEnergyDensity (without cohesion) have no effect on
    gran/jiang: each is named once, in a warning."""
    deck = open(os.path.join(TUTORIALS, "insert_stream", "in.insert_stream.stock.short")).read()
    deck = re.sub(r"^pair_style gran model.*$", "pair_style gran/jiang", deck, flags=re.M)
    deck = deck.replace("run\t\t20000", "run\t\t100")
    d = os.path.join(tmp, "pair_only")
    os.makedirs(d)
    os.symlink(os.path.join(STOCK_TUTORIALS, "insert_stream", "meshes"), os.path.join(d, "meshes"))
    open(os.path.join(d, "in.deck"), "w").write(deck)
    r = subprocess.run([LIGGGHTS_JDEM, "-in", "in.deck", "-log", "log.lammps", "-screen", "screen.txt"],
                       cwd=d, capture_output=True, text=True)
    log = open(os.path.join(d, "log.lammps"), errors="replace").read()
    for fix, name in (("m5", "characteristicVelocity"), ("m6", "cohesionEnergyDensity")):
        want = "WARNING: fix %s (property/global %s) is not used by pair_style gran/jiang" % (fix, name)
        n = sum(1 for l in log.splitlines() if l.startswith(want))
        c.check("pair swapped only: %s named once in a warning (%d)" % (name, n), r.returncode == 0 and n == 1)


# name, deck stem, folder of the stock tutorial, checks
CASES = [
    ("packing", "in.packing", "packing", packing),
    ("insert_stream", "in.insert_stream", "insert_stream", insert_stream),
    ("meshGran", "in.meshGran", "meshGran", mesh_gran),
    ("movingMeshGran", "in.movingMeshGran", "movingMeshGran", moving_mesh_gran),
    ("conveyor", "in.conveyor", "conveyor", conveyor),
    ("chute_wear", "in.chute_wear", "chute_wear", chute_wear),
    ("noCohesion", "in.noCohesion", "cohesion", no_cohesion),
    ("contactModels", "in.newModels", "contactModels", contact_models),
    ("heatTransfer", "in.heatGran", "heatTransfer_1", heat_transfer),
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    only = [s for s in args.only.split(",") if s]
    c = Checks()
    tmp = tempfile.mkdtemp(prefix="jdem_tutorials_")
    for name, stem, stock_dir, checks in CASES:
        if only and name not in only:
            continue
        fr, logs, ok = {}, {}, True
        for e in ("stock", "jiang"):
            rc, logs[e], fr[e] = run(tmp, name, "%s.%s.short" % (stem, e), e, stock_dir)
            ok = c.check("%s %s: the shortened deck runs (exit %d)" % (name, e, rc), rc == 0 and bool(fr[e])) and ok
        if ok:
            c.check("%s jiang: no stock wall/gran left (no mixing warning)" % name,
                    "evaluates its wall with LIGGGHTS' own contact model" not in logs["jiang"])
            checks(c, fr, logs)
    if not only or "fixes" in only:
        guard_templates(c, tmp)
        guard_cannot_check(c, tmp)
        watchdog_insertion(c, tmp)
        wound_plane(c, tmp)
        pair_swapped_only(c, tmp)
    return finish(c, tmp, args.keep)


if __name__ == "__main__":
    sys.exit(main())
