#!/usr/bin/python3
"""The conveyor inlet in LIGGGHTS (fix jdem/inlet) against build/jdem on the same scene.

One line per check, `PASS name` or `FAIL name: detail`.  The scene is tests/inlet/fill_small.yaml
(3 sections of 9 spheres, 0.4 s) run by `build/jdem run --inlet-record` and by the deck that
scripts/scene_to_liggghts.py writes from it (--inlet-record), on 1 and 2 MPI ranks.

* stream: the insertion records of the two engines are the same bytes (ids, steps, positions and
  velocities bit for bit, in insertion order), on 1 and on 2 ranks; jdem's is checked against
  the closed form by tests/inlet/test_inlet.py.
* frames: at each of jdem's frames the particles present in LIGGGHTS (a `dump custom` of the
  same deck, on 1 and 2 ranks) are
  exactly those jdem has inserted, and their positions, velocities and spins agree within the
  cross-engine tolerance (output.compare_tolerance, default 1e-10, scaled as
  scripts/compare_trajectories.py: by the largest radius, the belt speed, and their ratio); 2
  ranks agree with 1 rank the same way.
* builtin: the --builtin deck (LIGGGHTS' own hertz/history law) inserts the same stream.
* energy: the inflow energy fix jdem/inlet reports equals jdem's inlet_energy observable and the
  sum of 1/2 m v^2 - m g.x over the record (masses 4/3 pi R^3 rho of the resolved scene), and the
  run passes fix jdem/watchdog's energy check while that inflow is far beyond its 5 % limit.
* stop rules: a time and a deposit-height rule that admit one section where the sections rule
  admits two give the same records in both engines (the rules are the kernel's); so does a
  scene with a second inlet (one record, the inlets' lines of a step in the scene's order).
* the deck's own trajectory: the unmodified deck writes dump h5md/jdem, a growing particle set
  (ids -1 in empty slots), whose live particles at every frame are jdem's, within the same
  tolerance.
* progress: the deck's progress.txt (fix print of fix jdem/inlet's f_ID) gives at each of its
  steps the particles the record inserted by then (exactly) and the work still to come: the sum
  of last - k over the record's later insertion steps k, to within one step per insertion counted
  (the kernel sums each particle's copies as an arithmetic series, kernel/jdem_inlet.h, and the
  big sphere's copies here come 1401 and 1400 steps apart, at 1600, 3001 and 4401, by the
  round-off of its crossing times); scripts/liggghts_run.py's ETA from two such lines against
  its closed form.
* bad input: each malformed fix jdem/inlet argument stops LIGGGHTS with its exact message.
"""
import csv
import math
import os
import re
import shutil
import tempfile

import h5py
import numpy as np
import yaml

from scripts import engines
from scripts.engines import JDEM, ROOT
from tests.engine.engine_common import Checks

SCENE = os.path.join(ROOT, "tests", "inlet", "fill_small.yaml")

checks = Checks()
check = checks.check
DUMP_COLUMNS = "id x y z vx vy vz omegax omegay omegaz"


def run_deck(deck_dir, deck, log, np_=1):
    r = engines.run_deck(deck_dir, deck, np_, log=log)
    with open(os.path.join(deck_dir, log), errors="replace") as f:
        return r.returncode, f.read()


def custom_dump_deck(text, every, path):
    """The deck with dump custom instead of dump h5md/jdem (and without the fix that samples
    the h5md dump's observables)."""
    lines = []
    for line in text.splitlines(keepends=True):
        if " jdem/observables " in line:
            continue
        if line.startswith("dump ") and " h5md/jdem " in line:
            lines.append("dump d all custom %d %s %s\n" % (every, path, DUMP_COLUMNS))
            lines.append('dump_modify d sort id format "%%d%s"\n' % (" %.17g" * 9))
            continue
        lines.append(line)
    return "".join(lines)


def read_custom_dump(path):
    """{step: {id: row of 9 floats}}."""
    frames, step, lines = {}, None, iter(open(path))
    for line in lines:
        if line.startswith("ITEM: TIMESTEP"):
            step = int(next(lines))
            frames[step] = {}
        elif line.startswith("ITEM: ATOMS"):
            continue
        elif line.startswith("ITEM:"):
            next(lines)  # NUMBER OF ATOMS / BOX BOUNDS values
            if "BOX" in line:
                next(lines), next(lines)
        elif step is not None and line.strip():
            w = line.split()
            frames[step][int(w[0])] = [float(x) for x in w[1:]]
    return frames


def h5md_frames(path):
    """{step: {id: row of 9 floats}} of the live particles of an H5MD trajectory of either
    engine (a changing set: the per-frame ids, -1 in empty slots), and the last inlet_energy
    (None when the file has no such observable)."""
    with h5py.File(path, "r") as h:
        p = h["/particles/all"]
        per_frame = isinstance(p["id"], h5py.Group)
        ids = p["id/value"][:] if per_frame else p["id"][:]
        steps = p["position/step"][:]
        data = [p["%s/value" % k][:] for k in ("position", "velocity", "angular_velocity")]
        obs = h.get("/observables/inlet_energy/value")
        inlet_energy = float(obs[-1]) if obs is not None else None
    out = {}
    for f, s in enumerate(steps):
        row = np.concatenate([d[f] for d in data], axis=1)
        frame_ids = ids[f] if per_frame else ids
        out[int(s)] = {int(i): list(row[r]) for r, i in enumerate(frame_ids)
                       if i >= 0 and np.all(np.isfinite(row[r]))}
    return out, inlet_energy


def worst_difference(a, b, scales):
    """Largest scaled difference over the common frames of two frame sets with equal id sets."""
    worst = 0.0
    for s in a:
        if s not in b:
            continue
        for i, ra in a[s].items():
            d = np.abs(np.array(ra) - np.array(b[s][i])) / scales
            worst = max(worst, float(np.max(d)))
    return worst


def same_particles(a, b):
    """The steps of a (also in b) whose id sets differ."""
    return [s for s in a if s in b and set(a[s]) != set(b[s])]


def inflow_from_record(rows, sc):
    mass = {}
    inlet = sc["inlets"][0]
    n = len(inlet["section"]["particles"])
    for p, q in enumerate(inlet["section"]["particles"]):
        rho = sc["materials"][q["material"]]["density"]
        mass[p] = 4.0 * math.pi / 3.0 * q["radius"] * q["radius"] * q["radius"] * rho
    g = sc["gravity"]
    total = 0.0
    for r in rows:
        m = mass[(int(r["id"]) - inlet["first_id"]) % n]
        v = [float(r[k]) for k in ("vx", "vy", "vz")]
        x = [float(r[k]) for k in "xyz"]
        total += 0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - m * (g[0] * x[0] + g[1] * x[1] + g[2] * x[2])
    return total


def check_progress(path, rows, last):
    """The deck's progress.txt against the insertion record (see the module's docstring)."""
    steps = [int(r["step"]) for r in rows]
    lines = [w.split() for w in open(path) if not w.startswith("#")] if os.path.exists(path) else []
    bad = []
    for w in lines:
        s, n, pending = int(w[0]), float(w[1]), float(w[2])
        later = [k for k in steps if k > s]
        want = (sum(k <= s for k in steps), float(sum(last - k for k in later)))
        if n != want[0] or abs(pending - want[1]) >= max(len(later), 1):
            bad.append("step %d: %g particles, %r pending; from the record %d, %r (within %d)"
                       % ((s, n, pending) + want + (len(later),)))
    check("progress-pending-work", len(lines) >= 7 and not bad and any(float(w[2]) > 0 for w in lines),
          "%d lines; %s" % (len(lines), "; ".join(bad[:3])))


def check_progress_eta(tmp):
    """liggghts_run's ETA from progress.txt: 10 particles at step 100, then 30 at step 200 and
    100 particle-steps still to come, 10 s apart: 2000 particle-steps done at 200 a second, and
    30 x (1000 - 200) + 100 = 24100 left, 120.5 s; read again 20 s later with no new line, 100.5 s;
    a line of a lower step (a new attempt) starts the count again: no ETA."""
    from scripts.liggghts_run import PROGRESS_FILE, Progress
    d = os.path.join(tmp, "eta")
    os.makedirs(d)
    progress = Progress(d, 1000)
    path = os.path.join(d, PROGRESS_FILE)
    with open(path, "w") as f:
        f.write("# step particles pending_particle_steps\n100 10 500\n")
    first = progress.work_eta(0.0)
    with open(path, "a") as f:
        f.write("200 30 100\n")
    second = progress.work_eta(10.0)
    later = progress.work_eta(30.0)
    with open(path, "a") as f:
        f.write("50 5 900\n")
    again = progress.work_eta(40.0)
    check("progress-eta", first is None and second is not None and abs(second - 120.5) < 1e-12
          and later is not None and abs(later - 100.5) < 1e-12 and again is None,
          "%r, %r, %r, %r" % (first, second, later, again))


def cross_engine(tmp):
    jdem_h5, jdem_rec = os.path.join(tmp, "fill.jdem.h5"), os.path.join(tmp, "jdem.csv")
    r = engines.jdem("run", SCENE, "-o", jdem_h5, "--inlet-record", jdem_rec, "--quiet")
    if not check("jdem-run", r.returncode == 0, r.stderr.strip()):
        return None
    resolved = os.path.join(tmp, "resolved.yaml")
    with open(resolved, "w") as f:
        f.write(engines.resolve(SCENE, check=True).stdout)
    sc = yaml.load(open(resolved), Loader=yaml.CSafeLoader)
    deck_dir = os.path.join(tmp, "deck")
    lig_rec = os.path.join(deck_dir, "lig.csv")
    r = engines.write_deck(resolved, os.path.join(deck_dir, "in.jdem"), "--trajectory", os.path.join(tmp, "fill.lig.h5"),
                           "--inlet-record", lig_rec)
    if not check("deck", r.returncode == 0, r.stderr.strip()):
        return None
    deck_text = open(os.path.join(deck_dir, "in.jdem")).read()
    every = int(sc["output"]["every"])
    jf, jdem_inflow = h5md_frames(jdem_h5)
    jrec = open(jdem_rec).read()
    R = max(p["radius"] for p in sc["inlets"][0]["section"]["particles"])
    v = math.sqrt(sum(c * c for c in sc["inlets"][0]["velocity"]))
    scales = np.array([R] * 3 + [v] * 3 + [v / R] * 3)
    tol = float((sc.get("output") or {}).get("compare_tolerance", 1e-10))
    lig_frames = {}
    for np_ in (1, 2):
        dump = "final_np%d.dump" % np_
        rec = os.path.join(deck_dir, "lig_np%d.csv" % np_)
        deck = "in.custom_np%d" % np_
        with open(os.path.join(deck_dir, deck), "w") as f:
            f.write(custom_dump_deck(deck_text.replace(lig_rec, rec), every, dump))
        rc, log = run_deck(deck_dir, deck, "log.np%d" % np_, np_)
        if not check("liggghts-run-np%d" % np_, rc == 0, "exit %d:\n%s" % (rc, log[-1500:])):
            continue
        lrec = open(rec).read()
        check("stream-identical-np%d" % np_, lrec == jrec and lrec.count("\n") == 28,
              "%d lines vs jdem's %d; first difference at line %s" % (
                  lrec.count("\n"), jrec.count("\n"),
                  next((k for k, (a, b) in enumerate(zip(lrec.splitlines(), jrec.splitlines())) if a != b), "-")))
        lf = read_custom_dump(os.path.join(deck_dir, dump))
        lig_frames[np_] = lf
        differ = same_particles(jf, lf)
        check("frames-particle-set-np%d" % np_, not differ and set(jf) <= set(lf),
              "frames %s of jdem missing in LIGGGHTS, steps with other particles: %s" % (
                  sorted(set(jf) - set(lf)), differ))
        worst = worst_difference(jf, lf, scales)
        check("frames-state-np%d" % np_, worst <= tol, "largest scaled difference %.3g > %g" % (worst, tol))
        m = re.search(r"jdem/inlet: inserted (\d+) particles, skipped (\d+), inflow energy (\S+) J", log)
        if np_ == 1 and check("inflow-reported", m is not None, log[-800:]):
            rows = list(csv.DictReader(open(rec)))
            want = inflow_from_record(rows, sc)
            got = float(m.group(3))
            check("inflow-energy", int(m.group(1)) == 27 and int(m.group(2)) == 0 and abs(got - want) <= 1e-12 * abs(want) and
                  abs(jdem_inflow - want) <= 1e-12 * abs(want),
                  "liggghts-jdem %r, jdem %r, from the record %r" % (got, jdem_inflow, want))
            # each later section brings as much as all before it: an unbooked inflow would be a
            # jump of ~100 % at the next energy check, twenty times the deck's limit
            n = len(sc["inlets"][0]["section"]["particles"])
            per_copy = [inflow_from_record(rows[c * n:(c + 1) * n], sc) for c in range(3)]
            check("inflow-beyond-watchdog-limit", "jdem/watchdog" in deck_text and "energy 0.05" in deck_text and
                  per_copy[1] > 0.05 * per_copy[0] and per_copy[2] > 0.05 * (per_copy[0] + per_copy[1]),
                  "inflow per section %s; deck watchdog line present: %s" % (per_copy, "jdem/watchdog" in deck_text))
        if np_ == 1:
            check_progress(os.path.join(deck_dir, "progress.txt"), list(csv.DictReader(open(rec))),
                           int(sc["time"]["steps"]))
    if 1 in lig_frames and 2 in lig_frames:
        worst = worst_difference(lig_frames[1], lig_frames[2], scales)
        check("ranks-1-vs-2", not same_particles(lig_frames[1], lig_frames[2]) and worst <= tol,
              "largest scaled difference %.3g" % worst)
    builtin = os.path.join(tmp, "builtin")
    brec = os.path.join(builtin, "rec.csv")
    r = engines.write_deck(resolved, os.path.join(builtin, "in.jdem"), "--trajectory", os.path.join(tmp, "b.h5"),
                           "--builtin", "--inlet-record", brec)
    if check("builtin-deck", r.returncode == 0, r.stderr.strip()):
        with open(os.path.join(builtin, "in.custom"), "w") as f:
            f.write(custom_dump_deck(open(os.path.join(builtin, "in.jdem")).read(), every, "b.dump"))
        rc, log = run_deck(builtin, "in.custom", "log.custom")
        check("builtin-stream-identical", rc == 0 and open(brec).read() == jrec,
              "exit %d: %s" % (rc, log[-600:]))
    rc, log = run_deck(deck_dir, "in.jdem", "log.h5md", 1)
    lig_h5 = os.path.join(tmp, "fill.lig.h5")
    if check("deck-trajectory-h5md", rc == 0 and os.path.exists(lig_h5), "exit %d:\n%s" % (rc, log[-800:])):
        hf, _ = h5md_frames(lig_h5)
        worst = worst_difference(jf, hf, scales)
        check("deck-trajectory-h5md-frames", not same_particles(jf, hf) and set(jf) <= set(hf) and
              worst <= tol, "particle sets differ at %s; largest scaled difference %.3g" % (
                  same_particles(jf, hf), worst))
    return deck_dir, custom_dump_deck(deck_text, every, "bad.dump")


# (name, what the fix line becomes or the section file holds, the exact message)
BAD = [
    ("unknown-keyword", lambda l: l.rstrip("\n") + " speed 3\n",
     "fix jdem/inlet: unknown keyword 'speed'; valid: file, origin, velocity, plane, period, offset, "
     "first_id, stop, overlap_tol, max_insert_overlap, record, append_record"),
    ("negative-max-insert-overlap", lambda l: l.rstrip("\n") + " max_insert_overlap -1\n",
     "fix jdem/inlet: max_insert_overlap must be a number >= 0 (a fraction of the smaller radius) or inf"),
    ("missing-period", lambda l: re.sub(r" period \S+", "", l),
     "fix jdem/inlet: missing keyword 'period'; usage: fix ID group jdem/inlet file SECTION"),
    ("not-a-number", lambda l: re.sub(r" origin (\S+) (\S+) (\S+)", r" origin \1 \2 abc", l),
     "fix jdem/inlet: origin: 'abc' is not a finite number"),
    ("too-few-numbers", lambda l: re.sub(r" plane (\S+ ){6}", " ", l).rstrip("\n") + " plane 0.05 0 0\n",
     "fix jdem/inlet: plane needs 6 numbers"),
    ("bad-stop", lambda l: re.sub(r" stop sections \d+", " stop forever", l),
     "fix jdem/inlet: stop needs 'sections N', 'time T' or 'height H [below_speed V] [every N]'"),
    ("zero-sections", lambda l: re.sub(r" stop sections \d+", " stop sections 0", l),
     "fix jdem/inlet: stop sections must be an integer >= 1"),
    ("two-stops", lambda l: l.rstrip("\n") + " stop time 1\n",
     "fix jdem/inlet: stop is given twice; valid: one stop rule"),
    ("bad-first-id", lambda l: re.sub(r" first_id \d+", " first_id 0", l),
     "fix jdem/inlet: first_id must be an integer >= 1"),
    ("never-crosses", lambda l: re.sub(r" velocity \S+ \S+ \S+", " velocity -1 0 0", l),
     "fix jdem/inlet: the belt never crosses the inlet plane: velocity . normal = -1 <= 0; valid: a "
     "velocity with a positive component along the normal (towards the domain)"),
    ("period-overlap", lambda l: re.sub(r" period \S+", " period 0.05", l),
     "fix jdem/inlet: the section overlaps itself across the period: particle"),
    ("already-inside", lambda l: re.sub(r" origin \S+", " origin 0.2", l),
     "fix jdem/inlet: section particle 0 is already past the inlet plane at step 0"),
    ("outside-box", lambda l: re.sub(r" origin (\S+) (\S+) \S+", r" origin \1 \2 40", l),
     "lies outside the simulation box; valid: a simulation box that holds the inlet plane's crossing points"),
    ("no-section-file", lambda l: re.sub(r" file \S+", " file nothere.txt", l),
     "fix jdem/inlet: section file nothere.txt: No such file or directory"),
    ("record-unwritable", lambda l: re.sub(r" record \S+", " record /nonexistent/dir/r.csv", l),
     "fix jdem/inlet: record file /nonexistent/dir/r.csv: No such file or directory"),
    ("section-bad-type", "9 0.015 4000 0 0 0\n",
     'fix jdem/inlet: section file inlet_belt.txt line 2: expected "TYPE RADIUS DENSITY X Y Z" with TYPE '
     'between 1 and 3, RADIUS > 0 and DENSITY > 0'),
    ("section-empty", "",
     'fix jdem/inlet: section file inlet_belt.txt: holds no particles (lines "TYPE RADIUS DENSITY X Y Z")'),
]


def bad_input(deck_dir, deck_text):
    fix_line = next(l for l in deck_text.splitlines(keepends=True) if " jdem/inlet " in l)
    section = os.path.join(deck_dir, "inlet_belt.txt")
    original = open(section).read()
    for name, change, expect in BAD:
        if callable(change):
            text = deck_text.replace(fix_line, change(fix_line))
            with open(section, "w") as f:
                f.write(original)
        else:
            text = deck_text
            with open(section, "w") as f:
                f.write(original.splitlines(keepends=True)[0] + change)
        deck = "in.bad_" + name
        with open(os.path.join(deck_dir, deck), "w") as f:
            f.write(text)
        rc, log = run_deck(deck_dir, deck, "log.bad_" + name)
        errors = [l for l in log.splitlines() if l.startswith("ERROR")]
        check("bad-" + name, rc != 0 and any(expect in l for l in errors),
              "exit %d, errors %s, expected %r" % (rc, errors[:2], expect))
    with open(section, "w") as f:
        f.write(original)


def stop_rules(tmp):
    """The time and deposit-height stop rules: the same records in both engines, one section
    where the sections rule gives two by 0.2 s (copy 1 starts at step 2700: 0.135 s)."""
    base = yaml.load(open(SCENE), Loader=yaml.CSafeLoader)
    base["time"]["end_time"] = 0.2
    second = dict(base["inlets"][0], name="belt2", origin=[0.01, 0.1, 0.35], stop={"sections": 2}, first_id=1000)
    for name, stop, more in (("time", {"time": 0.125}, []),
                             ("height", {"deposit_height": {"height": 0.3, "below_speed": 10.0, "every": 500}}, []),
                             ("two-inlets", {"time": 0.125}, [second])):
        doc = dict(base, inlets=[dict(base["inlets"][0], stop=stop)] + more)
        scene = os.path.join(tmp, "stop_%s.yaml" % name)
        with open(scene, "w") as f:
            yaml.safe_dump(doc, f)
        rec = os.path.join(tmp, "stop_%s.jdem.csv" % name)
        r = engines.jdem("run", scene, "-o", os.path.join(tmp, "stop_%s.h5" % name), "--inlet-record", rec, "--quiet")
        if not check("stop-%s-jdem" % name, r.returncode == 0, r.stderr.strip()):
            continue
        resolved = os.path.join(tmp, "stop_%s.resolved.yaml" % name)
        with open(resolved, "w") as f:
            f.write(engines.resolve(scene, check=True).stdout)
        deck_dir = os.path.join(tmp, "stop_%s.deck" % name)
        lrec = os.path.join(deck_dir, "lig.csv")
        engines.write_deck(resolved, os.path.join(deck_dir, "in.jdem"), "--trajectory", os.path.join(tmp, "x.h5"),
                           "--inlet-record", lrec, check=True)
        with open(os.path.join(deck_dir, "in.custom"), "w") as f:
            f.write(custom_dump_deck(open(os.path.join(deck_dir, "in.jdem")).read(), 1000, "d.dump"))
        rc, log = run_deck(deck_dir, "in.custom", "log.custom")
        if not check("stop-%s-liggghts" % name, rc == 0, log[-800:]):
            continue
        a, b = open(rec).read(), open(lrec).read()
        want = 10 + 18 * len(more)  # the header, one section of the first inlet, two of the second
        check("stop-%s-stream" % name, a == b and a.count("\n") == want,
              "jdem %d lines, liggghts-jdem %d (want %d)" % (a.count("\n"), b.count("\n"), want))


def main():
    for exe in (JDEM, engines.LIGGGHTS_JDEM):
        if not check("built-" + os.path.basename(exe), os.access(exe, os.X_OK), "run make"):
            return
    tmp = tempfile.mkdtemp(prefix="inlet-cross-")
    got = cross_engine(tmp)
    check_progress_eta(tmp)
    stop_rules(tmp)
    if got:
        bad_input(*got)
    if not checks.failed:
        shutil.rmtree(tmp, ignore_errors=True)
    else:
        print("work directory: %s" % tmp)


if __name__ == "__main__":
    main()
    checks.exit()
