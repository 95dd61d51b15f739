#!/usr/bin/python3
"""Bonded blocks in an inlet's repeated section (docs/scenes.md "Bonded blocks in an inlet
section") in jdem, against references computed here.

One line per check, `PASS name` or `FAIL name: detail`.  The scene is tests/inlet/bonded_section.yaml:
two sections of one 2 x 2 x 8 weakly bonded block and one big sphere.

* insertion: each copy's block is inserted at min over its members of the closed-form crossing
  step k*(c, p) (the spec's formula, evaluated here), every member at that step at its rigid
  belt position; the big sphere at its own k*.
* bonds: per copy exactly the face neighbours of the 2 x 2 x 8 lattice, (a-1)bc + a(b-1)c +
  ab(c-1) = 60 of them, with the stream's ids (first_id + c n + i), formed at the block's
  insertion step, listed in increasing (id_a, id_b).
* unstressed: at insertion every bonded pair is one lattice spacing apart (the section's
  distance), and the bond elastic energy at copy 0's insertion step is exactly 0.
* free fall: until the first wall contact no contact, no break and the bond elastic energy
  stays below 1e-12 J (a weak bond breaks at 9e-3 J in pure tension).
* floor: the impact speed sqrt(2 g h) gives a bond stress v sqrt(kn A m) / A (one sphere
  stopped against its bonded neighbour), at least twice the weak strength: bonds break, none
  before the first wall contact.
* axis: the Ch. 5 section with `axis: x` (tests/scenes/good/inlet_blocks.yaml) resolves into 16
  groups of 32 spheres, each 8 spheres long along x and 2 across in y and z.
* sanitizer: build/san/jdem runs the scene clean and records the same insertions.
* liggghts-jdem: tests/inlet/test_bonded_inlet_liggghts.py (suite inlet-bonded-cross-engine).
"""
import csv
import math
import os
import subprocess
import tempfile

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.engines import JDEM, ROOT
from tests.engine.engine_common import Checks

SCENE = os.path.join(ROOT, "tests", "inlet", "bonded_section.yaml")
AXIS_SCENE = os.path.join(ROOT, "tests", "scenes", "good", "inlet_blocks.yaml")
SAN = os.path.join(ROOT, "build", "san", "jdem")

checks = Checks()
check = checks.check


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]  # left to right, as the spec writes it


def crossing_step(inlet, dt, rel, c):
    """k*(c, p): the smallest k >= 0 with a + k w >= 0 (docs/mixing.md 2.1)."""
    v, N, P = inlet["velocity"], inlet["plane"]["normal"], inlet["plane"]["point"]
    speed = math.sqrt(dot(v, v))
    u = [v[0] / speed, v[1] / speed, v[2] / speed]
    back = inlet["offset"] + c * inlet["period"]
    a = dot(N, [inlet["origin"][i] + rel[i] - P[i] for i in range(3)]) - back * dot(N, u)
    w = dot(N, v) * dt
    k = max(0, math.ceil(-a / w))
    while k > 0 and a + (k - 1) * w >= 0.0:
        k -= 1
    while a + k * w < 0.0:
        k += 1
    return k


def face_pairs(a, b, c):
    """Face-neighbour pairs of an a x b x c lattice, sites i + a (j + b k)."""
    site = lambda i, j, k: i + a * (j + b * k)
    pairs = []
    for k in range(c):
        for j in range(b):
            for i in range(a):
                if i + 1 < a:
                    pairs.append((site(i, j, k), site(i + 1, j, k)))
                if j + 1 < b:
                    pairs.append((site(i, j, k), site(i, j + 1, k)))
                if k + 1 < c:
                    pairs.append((site(i, j, k), site(i, j, k + 1)))
    return sorted(pairs)


def read_record(path):
    with open(path) as f:
        return {int(r["id"]): (int(r["step"]), [float(r[k]) for k in "xyz"]) for r in csv.DictReader(f)}


def check_insertion(user, inlet, dt, rec):
    blk = user["inlets"][0]["section"]["blocks"][0]["lattice"]
    a, b, c = blk["counts"]
    n, first = len(inlet["section"]["particles"]), inlet["first_id"]
    rels = [q["position"] for q in inlet["section"]["particles"]]
    starts = []
    for copy in range(inlet["stop"]["sections"]):
        members = range(a * b * c)
        start = min(crossing_step(inlet, dt, rels[p], copy) for p in members)
        own = [crossing_step(inlet, dt, rels[p], copy) for p in members]
        got = [rec[first + copy * n + p][0] for p in members]
        check(f"copy {copy}: every block member inserted at min k* = {start}",
              got == [start] * len(got), f"steps {sorted(set(got))}")
        check(f"copy {copy}: some members are still behind the plane at insertion",
              max(own) > start, f"own crossing steps {min(own)}..{max(own)}")
        big = n - 1
        check(f"copy {copy}: the big sphere at its own k*",
              rec[first + copy * n + big][0] == crossing_step(inlet, dt, rels[big], copy))
        speed = math.sqrt(dot(inlet["velocity"], inlet["velocity"]))
        u = [x / speed for x in inlet["velocity"]]
        back = inlet["offset"] + copy * inlet["period"]
        want = [[((inlet["origin"][i] + rels[p][i]) - back * u[i]) + inlet["velocity"][i] * (start * dt)
                 for i in range(3)] for p in members]
        check(f"copy {copy}: members at x(c, p, start), bit for bit",
              all(rec[first + copy * n + p][1] == want[p] for p in members))
        starts.append(start)
    return starts, (a, b, c), blk["spacing"]


def check_bonds(inlet, f, starts, abc, spacing, rec):
    a, b, c = abc
    n, first = len(inlet["section"]["particles"]), inlet["first_id"]
    ids = f["jdem/bonds/ids"][()]
    formed = f["jdem/bonds/formed_step"][()]
    pairs = face_pairs(a, b, c)
    closed = (a - 1) * b * c + a * (b - 1) * c + a * b * (c - 1)
    check(f"face neighbours of {a}x{b}x{c}: {closed} (closed form)", len(pairs) == closed)
    for copy, start in enumerate(starts):
        base = first + copy * n
        want = [(base + i, base + j) for i, j in pairs]
        mine = [tuple(r) for r, s in zip(ids, formed) if base <= r[0] < base + n]
        check(f"copy {copy}: {closed} bonds with the stream's ids", mine == want,
              f"{len(mine)} bonds, first {mine[:3]}")
        steps = {int(s) for r, s in zip(ids, formed) if base <= r[0] < base + n}
        check(f"copy {copy}: formed at the block's insertion step", steps == {start}, f"{steps}")
        lengths = [math.dist(rec[i][1], rec[j][1]) for i, j in want]
        worst = max(abs(d - spacing) for d in lengths)
        check(f"copy {copy}: unstressed: every bond one spacing long at insertion", worst < 1e-12 * spacing,
              f"worst |d - spacing| {worst:.3g} m")
    order = [tuple(r) for r in ids]
    check("bond list in increasing (id_a, id_b)", order == sorted(order))


def check_fall_and_floor(sc, f, starts):
    obs = {k: f["observables"][k]["value"][()] for k in
           ("bonds", "bond_elastic_energy", "contacts", "wall_contacts")}
    step = f["observables/bonds/step"][()]
    at = {int(s): k for k, s in enumerate(step)}
    check("bond elastic energy exactly 0 at copy 0's insertion", obs["bond_elastic_energy"][at[starts[0]]] == 0.0,
          f"{obs['bond_elastic_energy'][at[starts[0]]]!r}")
    hit = int(step[np.argmax(obs["wall_contacts"] > 0)])
    window = (step >= starts[0]) & (step < hit)
    check("free fall: no contact until the first wall contact", not obs["contacts"][window].any())
    check("free fall: bond elastic energy below 1e-12 J", obs["bond_elastic_energy"][window].max() < 1e-12,
          f"{obs['bond_elastic_energy'][window].max():.3g} J")
    check("free fall: the blocks stay whole (60, then 120 bonds)",
          set(obs["bonds"][window].astype(int)) == {60, 120})
    broken = f["jdem/broken_bonds/step"][()]
    check("free fall: no break before the first wall contact", broken.size == 0 or broken.min() >= hit,
          f"first break at step {broken.min() if broken.size else None}, wall contact at {hit}")
    weak = sc["bond_types"]["weak"]
    small = sc["materials"]["small"]
    r = sc["inlets"][0]["section"]["particles"][0]["radius"]
    A = math.pi * (weak["radius_multiplier"] * r) ** 2
    m = small["density"] * 4.0 / 3.0 * math.pi * r ** 3
    bottom = sc["inlets"][0]["origin"][2] + min(q["position"][2] for q in sc["inlets"][0]["section"]["particles"])
    v = math.sqrt(2.0 * 9.81 * (bottom - r))
    sigma = v * math.sqrt(weak["normal_stiffness"] * A * m) / A
    check(f"floor: estimated bond stress {sigma:.3g} Pa >= 2 x strength {weak['tensile_strength']:g} Pa",
          sigma >= 2.0 * weak["tensile_strength"])
    check("floor: weak blocks break on the floor", broken.size > 0 and obs["bonds"][-1] < 120,
          f"{broken.size} broken, {obs['bonds'][-1]} intact")


def check_axis():
    sc = yaml.load(engines.resolve(AXIS_SCENE, binary=JDEM, check=True).stdout, Loader=yaml.CSafeLoader)
    sec = sc["inlets"][0]["section"]
    x = np.array([q["position"] for q in sec["particles"]])
    parent = list(range(len(x)))

    def find(i):
        while parent[i] != i:
            i = parent[i]
        return i
    for bond in sec["bonds"]:
        i, j = bond["pair"]
        parent[max(find(i), find(j))] = min(find(i), find(j))
    groups = {}
    for i in range(len(x)):
        groups.setdefault(find(i), []).append(i)
    blocks = [g for g in groups.values() if len(g) == 32]
    check("axis x: 16 blocks of 32 spheres and 960 + 1 bonds",
          len(blocks) == 16 and len(sec["bonds"]) == 961, f"{len(blocks)} blocks, {len(sec['bonds'])} bonds")
    spans = {tuple(np.round(np.ptp(x[g], axis=0), 9)) for g in blocks}
    check("axis x: every block 8 long along x, 2 across y and z", spans == {(0.231, 0.033, 0.033)}, f"{spans}")


def main():
    user = yaml.load(open(SCENE), Loader=yaml.CSafeLoader)
    with tempfile.TemporaryDirectory() as tmp:
        traj, rec_path = os.path.join(tmp, "b.h5"), os.path.join(tmp, "rec.csv")
        run = engines.jdem("run", SCENE, "-o", traj, "--inlet-record", rec_path, "--quiet", binary=JDEM)
        check("run", run.returncode == 0, run.stderr.strip())
        if run.returncode:
            return
        sc = yaml.load(engines.resolve(SCENE, binary=JDEM, check=True).stdout, Loader=yaml.CSafeLoader)
        inlet, dt = sc["inlets"][0], sc["time"]["dt"]
        rec = read_record(rec_path)
        starts, abc, spacing = check_insertion(user, inlet, dt, rec)
        with h5py.File(traj, "r") as f:
            check_bonds(inlet, f, starts, abc, spacing, rec)
            check_fall_and_floor(sc, f, starts)
        check_axis()
        if os.path.exists(SAN):
            san_rec = os.path.join(tmp, "san.csv")
            p = subprocess.run([SAN, "run", SCENE, "-o", os.path.join(tmp, "san.h5"), "--inlet-record",
                                san_rec, "--quiet"], capture_output=True, text=True)
            check("sanitizer build: clean run", p.returncode == 0 and "runtime error" not in p.stderr
                  and "Sanitizer" not in p.stderr, p.stderr[-400:])
            check("sanitizer build: the same insertions", p.returncode == 0 and
                  open(san_rec).read() == open(rec_path).read())
        else:
            check("sanitizer build present", False, f"{SAN} missing (make build/san/jdem)")


if __name__ == "__main__":
    main()
    checks.exit()
