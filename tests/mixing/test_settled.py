#!/usr/bin/python3
"""Runs that start from a settled deposit, whose contacts overlap (docs/scenes.md
"particles_from" and "settled"; docs/mixing.md 2.1 `from_deposit`): the compression cubes and the
second mixing pass of Jiang's Chapter 4 are cut from such deposits.

A source bed (64 soft spheres in a simple cubic stack of 4 x 4 x 4 columns, dropped 0.1 mm onto a
floor, 0.6 s) settles under its weight; its last frame holds contact overlaps of several per cent
of the radius, far beyond the start-overlap tolerance of 1e-6 R.  One line per check.

* the closed form of the source: the bottom sphere of a column carries the weight of the three
  above it, so its overlaps with the floor and with the sphere above follow Hertz's
  F = 4/3 E* sqrt(R*) delta^(3/2) (the floor's K_n = 2 K_p of the jiang2021 wall rule) for 4 and
  3 weights; the frame's overlaps must match within 1 %.
* settled restart: `particles_from` of that frame resolves (every particle `settled: true`), and
  the restarted bed is in static equilibrium: in 0.05 s no particle moves by more than 1e-3 of
  its radius, where a bed whose overlaps carried no force would fall g t^2 / 2 = 2.5 R.
* the rules around it: the same resolved scene without `settled` is refused by the start-overlap
  rule, and with a watchdog max_overlap_fraction below the deposit's largest overlap the settled
  scene is refused too, each with its exact message and exit status 2.
* section from_deposit: an inlet whose section is two cells of the deposit (regions and
  translations) resolves into the deposit's particles, settled, at the deposit positions plus the
  translations, bit for bit; build/jdem and the LIGGGHTS deck (fix jdem/inlet with overlap_tol)
  insert the same stream: their insertion records are the same bytes.
* bad input: a from_deposit region that keeps no particle is refused with the path
  inlets.0.section.from_deposit.0.region.
"""
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
JDEM = os.path.join(ROOT, "build", "jdem")
LIG = os.path.join(ROOT, "build", "liggghts-jdem")
PY = sys.executable

E, NU, RHO, R, G = 1.0e5, 0.3, 2500.0, 0.005, 9.81
HEADER = """jdem_scene: 1
name: %s
gravity: [0, 0, -9.81]
materials:
  soft: {youngs_modulus: 1.0e5, poisson_ratio: 0.3, density: 2500, restitution: 0.3, friction: 0.4}
  wall: {restitution: 0.3, friction: 0.4}
walls:
  - {name: floor, type: plane, corners: [[-0.2,-0.1,0],[0.2,-0.1,0],[0.2,0.1,0],[-0.2,0.1,0]], material: wall}
"""
SOURCE = HEADER % "settled_source" + """time: {dt: auto, end_time: 0.6}
output: {every: 100000}
generate:
  - lattice: {material: soft, radius: 0.005, origin: [0.005, 0.005, 0.0051], spacing: 0.0101, counts: [4, 4, 4]}
"""

failed = 0


def check(name, ok, detail=""):
    global failed
    print("PASS %s" % name if ok else "FAIL %s: %s" % (name, detail))
    sys.stdout.flush()
    failed += not ok
    return ok


def write(path, text):
    with open(path, "w") as f:
        f.write(text)
    return path


def resolve(path):
    r = subprocess.run([JDEM, "resolve", path], capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""


def last_frame(path):
    with h5py.File(path, "r") as f:
        p = f["particles/all"]
        return p["id"][()], p["position/value"][-1], p["radius"][()]


def hertz_overlap(force, r_star, e_star):
    return (force / (4.0 / 3.0 * e_star * math.sqrt(r_star))) ** (2.0 / 3.0)


def check_source_closed_form(ids, x):
    """Column bottoms: floor overlap under 4 weights, overlap with the sphere above under 3."""
    w = 4.0 / 3.0 * math.pi * R ** 3 * RHO * G
    e_pp = E / (2.0 * (1.0 - NU * NU))            # two spheres of one material
    want_floor = hertz_overlap(4 * w, R, 2.0 * e_pp)   # K_n = 2 K_p: the sphere against a rigid wall
    want_pair = hertz_overlap(3 * w, R / 2.0, e_pp)
    bottom = np.argsort(x[:, 2])[:16]
    floor = R - x[bottom, 2]
    pair = []
    for b in bottom:
        d = np.linalg.norm(x - x[b], axis=1)
        d[b] = np.inf
        above = np.argmin(np.where(x[:, 2] > x[b, 2], d, np.inf))
        pair.append(2 * R - d[above])
    check("source_floor_overlap", np.allclose(floor, want_floor, rtol=0.01),
          "floor overlaps %s, Hertz %g" % (floor.min(), want_floor))
    check("source_pair_overlap", np.allclose(pair, want_pair, rtol=0.01),
          "pair overlaps %s..%s, Hertz %g" % (min(pair), max(pair), want_pair))
    return max(max(pair), want_pair) / R


def check_restart(tmp, src, largest):
    scene = write(os.path.join(tmp, "restart.yaml"), HEADER % "settled_restart" +
                  "time: {dt: auto, end_time: 0.05}\noutput: {every: 100000}\n"
                  "particles_from:\n  - {file: %s, frame: -1}\n" % src)
    rc, out, err = resolve(scene)
    if not check("restart_resolves", rc == 0, err):
        return
    parts = yaml.load(out, Loader=yaml.CSafeLoader)["particles"]
    check("restart_particles_settled", len(parts) == 64 and all(p.get("settled") for p in parts),
          "%d particles, %d settled" % (len(parts), sum(bool(p.get("settled")) for p in parts)))
    h5 = os.path.join(tmp, "restart.h5")
    r = subprocess.run([JDEM, "run", scene, "-o", h5, "--quiet"], capture_output=True, text=True)
    if check("restart_runs", r.returncode == 0, r.stderr.strip()[-400:]):
        with h5py.File(h5, "r") as f:
            pos = f["particles/all/position/value"][()]
        moved = np.abs(pos[-1] - pos[0]).max()
        check("restart_static_equilibrium", moved < 1e-3 * R,
              "moved %.3g m = %.3g R in 0.05 s (free fall: %.3g R)" % (moved, moved / R, 0.5 * G * 0.05 ** 2 / R))
    plain = write(os.path.join(tmp, "plain.yaml"), out.replace(", settled: true", ""))
    rc, _, err = resolve(plain)
    check("unsettled_refused", rc == 2 and "overlap by" in err and
          err.endswith("valid: an overlap of at most 1e-06 of the smaller radius"), "rc %d: %s" % (rc, err))
    tight = write(os.path.join(tmp, "tight.yaml"), open(scene).read() +
                  "watchdog: {max_overlap_fraction: %g}\n" % (0.5 * largest))
    rc, _, err = resolve(tight)
    check("settled_beyond_watchdog_refused", rc == 2 and err.endswith(
          "valid: an overlap of at most %g of the smaller radius (watchdog.max_overlap_fraction, "
          "for two particles of a settled deposit)" % (0.5 * largest)), "rc %d: %s" % (rc, err))


INLET = """time: {dt: auto, end_time: 0.2}
output: {every: 100000}
inlets:
  - name: belt
    section:
      from_deposit:
        - {file: %(src)s, frame: -1, region: {lo: [0, 0, 0], hi: [0.0202, 0.045, 0.04]}, translate: [-0.03, 0, 0.05]}
        - {file: %(src)s, frame: -1, region: {lo: [0.0202, 0, 0], hi: [0.045, 0.045, 0.04]}, translate: [-0.08, 0, 0.05]}
    origin: [0, 0, 0]
    velocity: [0.5, 0, 0]
    plane: {point: [0, 0, 0], normal: [1, 0, 0]}
    period: 1.0
    stop: {sections: 1}
"""


def check_section(tmp, src):
    ids, x, _ = last_frame(src)
    scene = write(os.path.join(tmp, "inlet.yaml"), HEADER % "settled_inlet" + INLET % {"src": src})
    rc, out, err = resolve(scene)
    if not check("section_resolves", rc == 0, err):
        return
    resolved = write(os.path.join(tmp, "inlet.resolved.yaml"), out)
    parts = yaml.load(out, Loader=yaml.CSafeLoader)["inlets"][0]["section"]["particles"]
    order = np.argsort(ids)
    xs = x[order]
    a, b = xs[:, 0] < 0.0202, xs[:, 0] >= 0.0202
    want = np.concatenate([xs[a] + [-0.03, 0, 0.05], xs[b] + [-0.08, 0, 0.05]])
    got = np.array([p["position"] for p in parts])
    check("section_positions_bitwise", got.shape == want.shape and np.array_equal(got, want),
          "section %s, deposit cells %s" % (got.shape, want.shape))
    check("section_settled", all(p.get("settled") for p in parts), "a section particle is not settled")
    jrec, lrec = os.path.join(tmp, "jdem.csv"), os.path.join(tmp, "deck", "lig.csv")
    r = subprocess.run([JDEM, "run", scene, "-o", os.path.join(tmp, "inlet.h5"), "--quiet",
                        "--inlet-record", jrec], capture_output=True, text=True)
    if not check("section_jdem_runs", r.returncode == 0, r.stderr.strip()[-400:]):
        return
    deck = os.path.join(tmp, "deck", "in.jdem")
    r = subprocess.run([PY, os.path.join(ROOT, "scripts", "scene_to_liggghts.py"), resolved, "-o", deck,
                        "--trajectory", os.path.join(tmp, "inlet.lig.h5"), "--inlet-record", lrec],
                       capture_output=True, text=True)
    if not check("section_deck", r.returncode == 0 and " overlap_tol " in open(deck).read(), r.stderr.strip()):
        return
    r = subprocess.run([LIG, "-in", "in.jdem", "-log", "log.lammps", "-screen", "none"],
                       cwd=os.path.dirname(deck), capture_output=True, text=True)
    if not check("section_liggghts_runs", r.returncode == 0, (r.stdout + r.stderr).strip()[-400:]):
        return
    jtext, ltext = open(jrec).read(), open(lrec).read()
    check("section_records_same_bytes", jtext == ltext and jtext.count("\n") == 1 + 64,
          "jdem %d lines, liggghts-jdem %d lines" % (jtext.count("\n"), ltext.count("\n")))
    bad = write(os.path.join(tmp, "inlet_bad.yaml"), HEADER % "settled_inlet_bad" +
                (INLET % {"src": src}).replace("hi: [0.0202, 0.045, 0.04]", "hi: [0.001, 0.045, 0.04]"))
    rc, _, err = resolve(bad)
    check("section_region_keeps_nothing", rc == 2 and
          "key 'inlets.0.section.from_deposit.0.region': region [0.0, 0.0, 0.0]..[0.001, 0.045, 0.04] "
          "keeps no particle of the deposit; valid: a region holding at least one particle centre" in err,
          "rc %d: %s" % (rc, err))


def main():
    tmp = tempfile.mkdtemp(prefix="jdem_settled_")
    src_scene = write(os.path.join(tmp, "source.yaml"), SOURCE)
    src = os.path.join(tmp, "source.h5")
    r = subprocess.run([JDEM, "run", src_scene, "-o", src, "--quiet"], capture_output=True, text=True)
    if check("source_runs", r.returncode == 0, r.stderr.strip()[-400:]):
        ids, x, _ = last_frame(src)
        largest = check_source_closed_form(ids, x)
        check_restart(tmp, src, largest)
        check_section(tmp, src)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
