#!/usr/bin/python3
"""Insertion into an occupied place (kernel/jdem_inlet.h) in both engines, against closed forms.

One line per check, `PASS name` or `FAIL name: detail`.  The scene is tests/inlet/occupied.yaml:
four lanes of one belt, no gravity, spheres resting just past the inlet plane in lanes A, C
(a bonded pair) and D.  Nothing moves a resting sphere unless a particle is inserted in its lane,
so which particles are skipped follows from the closed-form stream (tests/inlet/test_inlet.py's
reference_stream) and the resting positions alone.

* default rule (any overlap, LIGGGHTS' overlap check): lanes A, C and D are skipped in every
  copy, lane B is inserted: the record holds exactly lane B's three ids, skipped_particles is
  12, and the skipped ids never occupy a trajectory row; the first skip report names the
  resting sphere and the closed-form overlap fraction.
* max_insert_overlap 0.05 (the scene's): lane D's copy 0 overlaps by 0.020-0.021 (closed form),
  below it, so it is inserted; lane A and the whole block of lane C are still skipped.
* .inf (the literal rule: every particle inserted): copy 0's five particles are all inserted,
  and the watchdog stops the run at the next step on the resting sphere of lane A, the ram that
  the rule prevents.
* liggghts-jdem (the deck scene_to_liggghts.py writes), 1 and 2 ranks: the same record bytes and
  the same skipped_particles as build/jdem for both rules; with the default, where no inserted
  particle touches anything, the same frames within the cross-engine tolerance.
"""
import csv
import os
import re
import tempfile

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.engines import JDEM, ROOT
from tests.engine.engine_common import Checks
from tests.inlet.test_inlet import reference_stream
from tests.inlet.test_inlet_liggghts import h5md_frames, worst_difference

SCENE = os.path.join(ROOT, "tests", "inlet", "occupied.yaml")
LANES = {"A": 0, "B": 1, "C": (2, 3), "D": 4}  # section indices
checks = Checks()
check = checks.check


def variant(tmp, name, limit, end_time=None):
    """The scene with max_insert_overlap LIMIT (None: the key removed, the default)."""
    sc = yaml.load(open(SCENE), Loader=yaml.CSafeLoader)
    inlet = sc["inlets"][0]
    if limit is None:
        del inlet["max_insert_overlap"]
    else:
        inlet["max_insert_overlap"] = limit
    if end_time:
        sc["time"]["end_time"] = end_time
    path = os.path.join(tmp, name + ".yaml")
    with open(path, "w") as f:
        yaml.safe_dump(sc, f)
    return path


def overlap_fraction(a, ra, b, rb):
    return (ra + rb - float(np.linalg.norm(np.subtract(a, b)))) / min(ra, rb)


def expected(sc):
    """Closed form: {id: (step, copy, section index, worst overlap with a resting sphere)}."""
    inlet = sc["inlets"][0]
    n = len(inlet["section"]["particles"])
    rest = [(p["position"], p["radius"]) for p in sc["particles"]]
    steps = sc["time"]["steps"]
    out = {}
    for k, pid, x, _ in reference_stream(sc, inlet, steps):
        p = (pid - inlet["first_id"]) % n
        r = inlet["section"]["particles"][p]["radius"]
        worst = max(overlap_fraction(x, r, c, rr) for c, rr in rest)
        out[pid] = (k, (pid - inlet["first_id"]) // n, p, worst)
    return out


def lane_ids(exp, lane, copies=None):
    idx = LANES[lane] if isinstance(LANES[lane], tuple) else (LANES[lane],)
    return sorted(i for i, e in exp.items() if e[2] in idx and (copies is None or e[1] in copies))


def record_ids(path):
    with open(path) as f:
        return [int(r["id"]) for r in csv.DictReader(f)]


def skipped_observable(h5):
    with h5py.File(h5, "r") as h:
        return h["/observables/skipped_particles/value"][:]


def jdem_run(tmp, scene, name):
    h5, rec = os.path.join(tmp, name + ".h5"), os.path.join(tmp, name + ".csv")
    r = engines.jdem("run", scene, "-o", h5, "--inlet-record", rec)
    return r, h5, rec


def default_rule(tmp):
    scene = variant(tmp, "default", None)
    sc = yaml.load(engines.resolve(scene, check=True).stdout, Loader=yaml.CSafeLoader)
    check("default-resolved", sc["inlets"][0]["max_insert_overlap"] == 0.0,
          repr(sc["inlets"][0]["max_insert_overlap"]))
    exp = expected(sc)
    r, h5, rec = jdem_run(tmp, scene, "default")
    if not check("default-run", r.returncode == 0, r.stderr[-600:]):
        return None
    got = record_ids(rec)
    check("default-inserted", got == lane_ids(exp, "B"), "record %s, lane B %s" % (got, lane_ids(exp, "B")))
    skipped = skipped_observable(h5)
    check("default-skipped", skipped[-1] == 12 == len(exp) - len(lane_ids(exp, "B")),
          "skipped_particles %s" % skipped[-1])
    with h5py.File(h5, "r") as h:
        seen = set(np.unique(h["/particles/all/id/value"][:]).tolist())
    never = set(exp) - set(got)
    check("default-no-rows", not (seen & never), "skipped ids in the trajectory: %s" % sorted(seen & never))
    first = lane_ids(exp, "A", copies=(0,))[0]
    m = re.search(r"step (\d+): inlet 'belt' skips particle id %d: particle id 1 overlaps its place by "
                  r"(\S+) of the smaller radius" % first, r.stderr)
    check("default-report", m is not None and int(m.group(1)) == exp[first][0] and
          abs(float(m.group(2)) - exp[first][3]) <= 1e-5, r.stderr[:400])
    block = lane_ids(exp, "C", copies=(0,))
    check("default-block-closed-form", exp[block[0]][3] > 1.0 and exp[block[1]][3] < 0.0,
          "lower %g, upper %g" % (exp[block[0]][3], exp[block[1]][3]))
    check("default-block-report", "skips particle id %d: with its bonded block" % block[1] in r.stderr,
          r.stderr[:600])
    return scene, h5, rec


def scene_rule(tmp):
    scene = variant(tmp, "limit", 0.05)
    sc = yaml.load(engines.resolve(scene, check=True).stdout, Loader=yaml.CSafeLoader)
    exp = expected(sc)
    r, h5, rec = jdem_run(tmp, scene, "limit")
    if not check("limit-run", r.returncode == 0, r.stderr[-600:]):
        return None
    got = set(record_ids(rec))
    d0 = lane_ids(exp, "D", copies=(0,))[0]
    check("limit-lane-d-closed-form", 0.0 < exp[d0][3] < 0.05, "overlap %g" % exp[d0][3])
    check("limit-lane-d-inserted", d0 in got, "record %s" % sorted(got))
    check("limit-lanes-a-c-skipped", not (got & set(lane_ids(exp, "A") + lane_ids(exp, "C"))),
          "record %s" % sorted(got))
    check("limit-lane-b-inserted", set(lane_ids(exp, "B")) <= got, "record %s" % sorted(got))
    check("limit-skipped-count", skipped_observable(h5)[-1] == len(exp) - len(got),
          "skipped_particles %s, due %d, recorded %d" % (skipped_observable(h5)[-1], len(exp), len(got)))
    return scene, h5, rec


def literal_rule(tmp):
    scene = variant(tmp, "literal", float("inf"), end_time=0.0502)
    sc = yaml.load(engines.resolve(scene, check=True).stdout, Loader=yaml.CSafeLoader)
    exp = expected(sc)
    r, h5, rec = jdem_run(tmp, scene, "literal")
    copy0 = sorted(i for i, e in exp.items() if e[1] == 0)
    check("literal-all-inserted", record_ids(rec) == copy0, "record %s" % record_ids(rec))
    step = exp[copy0[0]][0] + 1
    check("literal-rams", r.returncode != 0 and re.search(
        r"watchdog: step %d: overlap fraction \S+ for particle\(s\) 1, %d exceeds" % (step, copy0[0]),
        r.stderr) is not None, "exit %d: %s" % (r.returncode, r.stderr[-400:]))


def liggghts(tmp, name, scene, jdem_h5, jdem_rec, compare_frames):
    resolved = os.path.join(tmp, name + ".resolved.yaml")
    with open(resolved, "w") as f:
        f.write(engines.resolve(scene, check=True).stdout)
    sc = yaml.load(open(resolved), Loader=yaml.CSafeLoader)
    deck_dir = os.path.join(tmp, name + ".deck")
    for np_ in (1, 2):
        rec, traj = os.path.join(deck_dir, "np%d.csv" % np_), os.path.join(tmp, "%s.np%d.h5" % (name, np_))
        r = engines.write_deck(resolved, os.path.join(deck_dir, "in.np%d" % np_), "--trajectory", traj,
                               "--inlet-record", rec, "--force")
        if not check("%s-deck-np%d" % (name, np_), r.returncode == 0, r.stderr[-400:]):
            continue
        r = engines.run_deck(deck_dir, "in.np%d" % np_, np_, log="log.np%d" % np_)
        if not check("%s-liggghts-np%d" % (name, np_), r.returncode == 0,
                     open(os.path.join(deck_dir, "log.np%d" % np_), errors="replace").read()[-600:]):
            continue
        check("%s-record-np%d" % (name, np_), open(rec).read() == open(jdem_rec).read())
        a, b = skipped_observable(traj)[-1], skipped_observable(jdem_h5)[-1]
        check("%s-skipped-np%d" % (name, np_), a == b, "liggghts-jdem %s, jdem %s" % (a, b))
        if compare_frames:
            jf, _ = h5md_frames(jdem_h5)
            lf, _ = h5md_frames(traj)
            R, v = 0.015, 1.0
            scales = np.array([R] * 3 + [v] * 3 + [v / R] * 3)
            tol = float((sc.get("output") or {}).get("compare_tolerance", 1e-10))
            same = all(set(jf[s]) == set(lf[s]) for s in jf if s in lf)
            worst = worst_difference(jf, lf, scales)
            check("%s-frames-np%d" % (name, np_), same and worst <= tol and len(set(jf) & set(lf)) > 5,
                  "same particles %s, largest scaled difference %.3g" % (same, worst))


def main():
    if not checks.built(JDEM, engines.LIGGGHTS_JDEM):
        return
    with tempfile.TemporaryDirectory() as tmp:
        d = default_rule(tmp)
        s = scene_rule(tmp)
        literal_rule(tmp)
        if d:
            liggghts(tmp, "default", *d, compare_frames=True)
        if s:
            liggghts(tmp, "limit", *s, compare_frames=False)


if __name__ == "__main__":
    main()
    checks.exit()
