#!/usr/bin/python3
"""Faults on the LIGGGHTS side: the deck generator (scripts/scene_to_liggghts.py), the wrapper
(scripts/liggghts_run.py) and the input handling of liggghts-jdem's styles.  Each case asserts
the exit status, the message and what is on disk:

  injection       names with a line break, another control character or a quote are refused by
                  the generator (no `shell` runs); names with '#', '$', '&' are written
                  literally and land in /parameters as they are
  paths           -o with '#', a space, '$' works at exactly that path; '*' is refused
  concurrent      a second wrapper on the same OUT is refused (exit 3), the first completes
  typo            a bad scene leaves the earlier OUT.h5 and OUT.xdmf as they were
  watchdog        a watchdog trip through the wrapper exits 4, OUT.h5.part kept
  sigterm         SIGTERM to the wrapper stops LIGGGHTS or mpirun (143, OUT.h5.part kept, nothing
                  left running), on 1 and 2 ranks
  rank errors     an error on one rank (Error::one) reaches stderr and the log, stdout a pipe,
                  on 1 and 2 ranks; no garbage line after a LIGGGHTS error
  bad files       bond file, loads file and scene_yaml: directory, /dev/zero, empty, binary,
                  duplicates: one message naming the file (and line)
  setup watchdog  a trip before the first frame names no .part that does not exist

$LIGGGHTS_RUN and $SCENE_TO_LIGGGHTS override the scripts (to run these cases on older ones).
"""
import os
import re
import shutil
import signal
import time

import yaml

from scripts import engines
from tests.faults.faults_common import (EXIT, JDEM, LIGGGHTS_JDEM, PY, ROOT, Checks, files, h5_frames,
                                        h5_readable, run, scratch, signal_exit, start, finish,
                                        wait_for_file, write_scene)

RUN = os.environ.get("LIGGGHTS_RUN", os.path.join(ROOT, "scripts", "liggghts_run.py"))
GEN = os.environ.get("SCENE_TO_LIGGGHTS", os.path.join(ROOT, "scripts", "scene_to_liggghts.py"))

# Two spheres at rest, apart: nothing happens, so the run's length is only its step count.
RESTING = """\
jdem_scene: 1
name: {name}
time: {{dt: 1.0e-6, steps: {steps}}}
output: {{every: {every}}}
materials:
  glass: {{youngs_modulus: 4.8e10, poisson_ratio: 0.2, density: 2800}}
particles:
  - {{id: 1, material: glass, radius: 0.01, position: [0, 0, 0]}}
  - {{id: 2, material: glass, radius: 0.01, position: [0.05, 0, 0]}}
"""
LONG_STEPS = 6000000  # some 3-6 s of LIGGGHTS

# Sphere 1 held and bonded to 2 and 3 (bonds_cement.txt, loads.txt in the deck).
BONDED = """\
jdem_scene: 1
name: bonded
time: {dt: 1.0e-7, steps: 20}
output: {every: 10}
materials:
  clay: {youngs_modulus: 1.0e8, poisson_ratio: 0.3, density: 2600}
bond_types:
  cement: {normal_stiffness: 2.0e12, shear_stiffness: 1.0e12, tensile_strength: 5.0e6,
           shear_strength: 5.0e6}
particles:
  - {id: 1, material: clay, radius: 0.001, position: [0, 0, 0], fixed: true}
  - {id: 2, material: clay, radius: 0.001, position: [0.002, 0, 0]}
  - {id: 3, material: clay, radius: 0.001, position: [-0.002, 0, 0]}
bonds:
  - {ids: [1, 2], type: cement}
  - {ids: [1, 3], type: cement}
"""


def resting(d, name="rest", steps=200, every=100):
    return write_scene(d, name, RESTING.format(name=name, steps=steps, every=every))


def wrapper(scene, out, *extra, cwd=None, timeout=300):
    return run([PY, RUN, scene, "-o", out] + list(extra), cwd=cwd, timeout=timeout)


def resolved_text(scene):
    r = run([JDEM, "resolve", scene])
    if r.rc != 0:
        raise RuntimeError("jdem resolve %s: %r" % (scene, r))
    return r.out


def deck_of(d, scene_text, name="deck"):
    """Generate the deck of SCENE_TEXT in D/NAME/ (by the generator); returns the deck dir."""
    scene = write_scene(d, name + "_scene", scene_text)
    deck = os.path.join(d, name)
    os.makedirs(deck)
    with open(os.path.join(deck, "resolved.yaml"), "w") as f:
        f.write(resolved_text(scene))
    r = run([PY, GEN, os.path.join(deck, "resolved.yaml"), "-o", os.path.join(deck, "in.jdem"),
             "--trajectory", os.path.join(deck, "out.h5")])
    if r.rc != 0:
        raise RuntimeError("deck generation: %r" % r)
    return deck


def edit_deck(deck, old, new):
    path = os.path.join(deck, "in.jdem")
    with open(path) as f:
        text = f.read()
    if old not in text:
        raise RuntimeError("the deck has no %r" % old)
    with open(path, "w") as f:
        f.write(text.replace(old, new, 1))


def liggghts(deck, np_=1, timeout=120):
    """liggghts-jdem on DECK, stdout and stderr pipes (as under the wrapper, with the screen)."""
    r = run(engines.mpirun(np_) + [LIGGGHTS_JDEM, "-in", "in.jdem", "-log", "log.lammps"], cwd=deck, timeout=timeout)
    try:
        with open(os.path.join(deck, "log.lammps"), errors="replace") as f:
            log = f.read()
    except OSError:
        log = ""
    return r, log


# ---- injection and names ---------------------------------------------------------------------

def generator_refuses(c, d, label, path_in_scene, value, expect):
    """A resolved scene with VALUE at PATH_IN_SCENE (keys): the generator exits 2 with EXPECT in
    its message and writes no in.jdem; nothing named PWNED appears."""
    scene = yaml.load(resolved_text(resting(d, "inj_" + label)), Loader=yaml.CSafeLoader)
    node = scene
    for k in path_in_scene[:-1]:
        node = node[k]
    if path_in_scene[-1] == "<material>":  # rename the material everywhere
        old = next(iter(scene["materials"]))
        scene["materials"] = {value: scene["materials"][old]}
        for p in scene["particles"]:
            p["material"] = value
        for i in scene.get("interactions") or []:
            i["materials"] = [value, value]
    else:
        node[path_in_scene[-1]] = value
    deck = os.path.join(d, "gen_" + label)
    os.makedirs(deck)
    res = os.path.join(deck, "resolved.yaml")
    with open(res, "w") as f:
        yaml.safe_dump(scene, f)
    r = run([PY, GEN, res, "-o", os.path.join(deck, "in.jdem"), "--trajectory", os.path.join(deck, "o.h5")],
            cwd=deck)
    c.check("gen_%s_exit" % label, r.rc == EXIT["input"], repr(r))
    c.check("gen_%s_message" % label, expect in r.err, "expected %r in %r" % (expect, r.err))
    c.check("gen_%s_no_deck" % label, not os.path.exists(os.path.join(deck, "in.jdem")), "in.jdem written")
    c.check("gen_%s_no_injected_file" % label, not any("PWNED" in f for f in files(d)), files(deck))


def injection(c, d):
    for label, where, value, expect in (
            ("scene_name_newline", ["name"], "a\nshell touch PWNED", "scene name 'a\\nshell touch PWNED' holds "
             "the control character(s) 0x0a, which a LIGGGHTS input line cannot hold"),
            ("case_name_cr", ["case"], "a\rshell touch PWNED", "holds the control character(s) 0x0d"),
            ("material_newline", ["<material>"], "m\nshell touch PWNED", "material name"),
            ("single_quote", ["name"], "it's", "holds a quote character"),
            ("double_quote", ["case"], 'say "x"', "holds a quote character"),
            ("wall_rule", ["model", "wall_rule"], "hertz\nshell touch PWNED", "model.wall_rule is"),
            # found by tests/fuzz/fuzz_deck.py: a short Velocities line segfaulted read_data
            ("short_vector", ["particles", 1, "angular_velocity"], [0, 0],
             "expected a vector of three numbers, got [0, 0]"),
            ("radius_zero", ["particles", 0, "radius"], 0.0, "particle 1: radius must be a finite number > 0"),
    ):
        generator_refuses(c, d, label, where, value, expect)

    # through the wrapper: whichever stage refuses, exit 2, no command ran, no trajectory
    w = os.path.join(d, "wrap")
    os.makedirs(w)
    scene = write_scene(w, "inj", RESTING.format(name='"a\\nshell touch PWNED"', steps=20, every=10))
    r = wrapper(scene, os.path.join(w, "i.h5"), cwd=w)
    c.check("wrapper_injection_exit", r.rc == EXIT["input"], repr(r))
    c.check("wrapper_injection_nothing_ran", not any("PWNED" in f for f in files(w)), files(w))
    c.check("wrapper_injection_no_output", not os.path.exists(os.path.join(w, "i.h5")), files(w))

    # names LIGGGHTS would cut ('#'), substitute ('$') or continue ('&' at the end): the scene
    # reader refuses them (names are data: a safe character set) ...
    name = "odd #name $x ${y} $(1+1) &"
    scene = write_scene(w, "odd", RESTING.format(name='"%s"' % name, steps=20, every=10))
    out = os.path.join(w, "odd.h5")
    r = wrapper(scene, out, cwd=w)
    c.check("odd_name_refused_by_reader", r.rc == EXIT["input"] and "not allowed in a name" in r.err,
            repr(r)[-1500:])
    c.check("odd_name_no_output", not os.path.exists(out) and not os.path.exists(out + ".part"), files(w))
    # ... and a resolved scene that holds one anyway (hand-edited) is written literally by the deck
    # generator, and stored as it is
    resolved = yaml.load(resolved_text(resting(w, "odd_ok", steps=20, every=10)), Loader=yaml.CSafeLoader)
    resolved["name"] = name
    deck = os.path.join(w, "odd_deck")
    os.makedirs(deck)
    with open(os.path.join(deck, "resolved.yaml"), "w") as f:
        yaml.safe_dump(resolved, f)
    out = os.path.join(deck, "out.h5")
    g = run([PY, GEN, os.path.join(deck, "resolved.yaml"), "-o", os.path.join(deck, "in.jdem"),
             "--trajectory", out])
    r, _ = liggghts(deck) if g.rc == 0 else (g, "")
    if c.check("odd_name_deck_runs", g.rc == 0 and r.rc == 0 and h5_readable(out) is None, repr(r)[-1500:]):
        import h5py
        with h5py.File(out, "r") as f:
            got = f["parameters"].attrs.get("scene_name")
        got = got.decode() if isinstance(got, bytes) else got
        c.check("odd_name_stored_literally", got == name, "scene_name %r, expected %r" % (got, name))


def paths(c, d):
    scene = resting(d, "paths", steps=20, every=10)
    for label, rel in (("hash", "x/has#hash.h5"), ("space", "x/has space.h5"), ("dollar", "x/dol$HOME.h5"),
                       ("ampersand", "x/amp&.h5")):
        out = os.path.join(d, rel)
        os.makedirs(os.path.dirname(out), exist_ok=True)
        r = wrapper(scene, out, cwd=d)
        c.check("path_%s_exit" % label, r.rc == 0, repr(r)[-1500:])
        c.check("path_%s_written_there" % label, h5_readable(out) is None, "%s: %s; files %s" % (
            out, h5_readable(out), files(os.path.dirname(out))))
    # a directory as the output: build/jdem's message and exit status, nothing run or written
    outdir = os.path.join(d, "outdir")
    os.makedirs(outdir)
    r = wrapper(scene, outdir, cwd=d)
    want = "output path '%s' is a directory (give a file name, e.g. '%s/run.h5')" % (outdir, outdir)
    c.check("path_directory_exit", r.rc == EXIT["io"], repr(r)[-1500:])
    c.check("path_directory_message", want in r.err and "Traceback" not in r.err, r.err[-1500:])
    c.check("path_directory_nothing", files(outdir) == [] and not os.path.exists(outdir + ".deck"),
            "%s; deck %s" % (files(outdir), os.path.exists(outdir + ".deck")))
    r = run([JDEM, "run", scene, "-o", outdir, "--quiet"])
    c.check("path_directory_same_as_jdem", r.rc == EXIT["io"] and want in r.err, repr(r)[-1500:])
    star = os.path.join(d, "x", "star*.h5")
    r = wrapper(scene, star, cwd=d)
    c.check("path_star_refused", r.rc == EXIT["input"] and "LIGGGHTS dumps expand '*' and '%'" in r.err, repr(r))
    c.check("path_star_nothing", not os.path.exists(star), files(os.path.join(d, "x")))


# ---- the wrapper: concurrency, earlier results, signals ---------------------------------------

def concurrent(c, d):
    long_scene = resting(d, "long", steps=LONG_STEPS, every=LONG_STEPS // 6)
    short_scene = resting(d, "short", steps=200, every=100)
    out = os.path.join(d, "z.h5")
    first = start([PY, RUN, long_scene, "-o", out])
    if not c.check("concurrent_first_started", wait_for_file(out + ".part", 60), "no z.h5.part after 60 s"):
        first.kill()
        return
    second = run([PY, RUN, short_scene, "-o", out])
    first_r = finish(first, 300)
    c.check("concurrent_second_refused", second.rc == EXIT["io"] and "another run is writing" in second.err,
            repr(second))
    c.check("concurrent_first_completes", first_r.rc == 0, repr(first_r)[-1500:])
    frames = h5_frames(out) if h5_readable(out) is None else []
    c.check("concurrent_output_is_first_run", frames and frames[-1] == LONG_STEPS,
            "frames %s (the long run ends at %d)" % (frames, LONG_STEPS))


def typo_keeps_result(c, d):
    scene = resting(d, "good", steps=20, every=10)
    out = os.path.join(d, "g.h5")
    r = wrapper(scene, out)
    if not c.check("typo_first_run", r.rc == 0, repr(r)):
        return
    before = {f: open(os.path.join(d, f), "rb").read() for f in ("g.h5", "g.xdmf")}
    bad = write_scene(d, "bad", "jdem_scene: 1\nbogus: 1\n")
    r = wrapper(bad, out)
    c.check("typo_exit", r.rc == EXIT["input"], repr(r))
    c.check("typo_message", "key 'bogus'" in r.err, r.err)
    after = {f: open(os.path.join(d, f), "rb").read() if os.path.exists(os.path.join(d, f)) else None
             for f in before}
    c.check("typo_keeps_h5_and_xdmf", after == before, "changed: %s" % [f for f in before if after[f] != before[f]])


def watchdog_class(c, d):
    """A watchdog trip through the wrapper exits 4 (jdem's class), OUT.h5.part kept."""
    out = os.path.join(d, "wd.h5")
    r = wrapper(os.path.join(ROOT, "tests", "engine", "scenes", "watchdog_blowup.yaml"), out, "--case", "overlap",
                "--force")
    c.check("watchdog_exit", r.rc == EXIT["watchdog"], repr(r)[-800:])
    c.check("watchdog_message", "jdem: watchdog: step" in r.err, r.err[-800:])
    c.check("watchdog_files", not os.path.exists(out) and h5_readable(out + ".part") is None, files(d))


def processes_in(directory):
    """Pids of the processes whose working directory is DIRECTORY."""
    pids = []
    for p in os.listdir("/proc"):
        if p.isdigit():
            try:
                if os.readlink("/proc/%s/cwd" % p) == directory:
                    pids.append(int(p))
            except OSError:
                pass
    return pids


def sigterm(c, d):
    for np_ in (1, 2):  # liggghts-jdem itself, and mpirun (which forwards the signal to its ranks)
        name = "sigterm_np%d" % np_
        scene = resting(d, "long%d" % np_, steps=LONG_STEPS, every=LONG_STEPS // 6)
        out = os.path.join(d, "w%d.h5" % np_)
        proc = start([PY, RUN, scene, "-o", out, "--np", str(np_)])
        if not c.check(name + "_started", wait_for_file(out + ".part", 60), "no .part after 60 s"):
            proc.kill()
            continue
        proc.send_signal(signal.SIGTERM)
        r = finish(proc, 60)
        c.check(name + "_exit", r.rc == signal_exit(signal.SIGTERM), repr(r))
        c.check(name + "_message", "terminated (SIGTERM)" in r.err and out + ".part" in r.err, r.err[-1500:])
        left = processes_in(os.path.join(d, "w%d.deck" % np_))
        c.check(name + "_child_gone", not left, "still running in the deck: %s" % left)
        time.sleep(1.0)
        c.check(name + "_no_output_later", not os.path.exists(out), "the trajectory appeared after the wrapper exited")
        c.check(name + "_part_readable", h5_readable(out + ".part") is None, str(h5_readable(out + ".part")))


# ---- liggghts-jdem: errors on a rank, bad files, the set-up watchdog --------------------------

def rank_errors(c, d):
    for np_ in (1, 2):
        deck = deck_of(d, BONDED, "maxbonds_np%d" % np_)
        edit_deck(deck, "max_bonds 2", "max_bonds 1")
        if np_ == 2:  # the spheres on two ranks: the error is raised by the rank owning sphere 1
            edit_deck(deck, "\nread_data", "\nprocessors 2 1 1\nread_data")
        r, log = liggghts(deck, np_)
        want = "fix bond/jiang: atom 1 would have more than 1 bonds (raise max_bonds)"
        c.check("rank_error_np%d_exit" % np_, r.rc != 0, repr(r))
        c.check("rank_error_np%d_stderr" % np_, re.search(r"ERROR on proc \d: " + re.escape(want), r.err),
                "stderr %r" % r.err[-800:])
        c.check("rank_error_np%d_log" % np_, want in log, "log tail %r" % log[-800:])
    deck = deck_of(d, BONDED, "unknown")
    edit_deck(deck, "\nrun ", "\nbogus_command 1\nrun ")
    r, log = liggghts(deck)
    text = r.out + r.err + log
    after = [ln for ln in text.splitlines() if "input.cpp" in ln and not ln.startswith("ERROR")]
    c.check("error_no_garbage_line", not after and "ERROR: Unknown command: bogus_command 1" in r.err,
            "lines after the error: %r" % after)


def bad_file(c, deck, label, want, np_=1):
    r, log = liggghts(deck, np_)
    c.check("%s_exit" % label, r.rc == 1, repr(r)[-800:])
    c.check("%s_message" % label, want in r.err and want in log, "expected %r in stderr and the log; stderr %r" % (
        want, r.err[-800:]))
    c.check("%s_no_trajectory" % label, not os.path.exists(os.path.join(deck, "out.h5")), files(deck))


def bad_files(c, d):
    empty = os.path.join(d, "empty.txt")
    open(empty, "w").close()
    binary = os.path.join(d, "binary.bin")
    with open(binary, "wb") as f:
        f.write(b"1 2\n\x00\x01\x02\xff\n")
    a_dir = os.path.join(d, "a_dir")
    os.makedirs(a_dir)
    for label, path, reason in (("dir", a_dir, "is a directory, not a file"),
                                ("dev_zero", "/dev/zero", "is not a regular file (a device, FIFO or socket)"),
                                ("empty", empty, "is empty"),
                                ("binary", binary, "line 2: binary data (byte 0x00); expected text")):
        deck = deck_of(d, BONDED, "bondfile_" + label)
        edit_deck(deck, "file bonds_cement.txt", "file %s" % path)
        sep = " " if reason.startswith("line") else ": "
        bad_file(c, deck, "bond_file_" + label, "fix bond/jiang: bond file %s%s%s" % (path, sep, reason))
        deck = deck_of(d, BONDED, "sceneyaml_" + label)
        edit_deck(deck, "scene_yaml '%s'" % os.path.join(deck, "resolved.yaml"), "scene_yaml '%s'" % path)
        if label != "binary":
            bad_file(c, deck, "scene_yaml_" + label, "dump h5md/jdem: scene_yaml %s: %s" % (path, reason))
    deck = deck_of(d, BONDED, "bondfile_twice")
    with open(os.path.join(deck, "bonds_cement.txt"), "a") as f:
        f.write("2 1\n")
    bad_file(c, deck, "bond_file_duplicate", "fix bond/jiang: %s line 4: the bond 1-2 is listed twice (first on line 2)"
             % "bonds_cement.txt")
    deck = deck_of(d, BONDED, "loads_twice")
    with open(os.path.join(deck, "loads.txt"), "a") as f:
        f.write("1 0.0 0.0 0.0 1\n")
    bad_file(c, deck, "loads_duplicate", "fix jdem/loads: loads.txt line 3: atom id 1 is listed twice (first on line 2)")
    deck = deck_of(d, BONDED, "loads_dir")
    edit_deck(deck, "file loads.txt", "file %s" % a_dir)
    bad_file(c, deck, "loads_file_dir", "fix jdem/loads: file %s: is a directory, not a file" % a_dir)


def setup_watchdog(c, d):
    """An infinite force from the set-up on (fix addforce 1e300*1e300, before the watchdog): the
    watchdog trips at step 0, before the first frame: nothing is written, and the message says so."""
    deck = deck_of(d, BONDED, "setup_trip")
    edit_deck(deck, "\nfix watchdog", "\nvariable fx equal 1e300*1e300\nfix boom all addforce v_fx 0 0\nfix watchdog")
    r, log = liggghts(deck)
    out = os.path.join(deck, "out.h5")
    c.check("setup_watchdog_exit", r.rc == 1, repr(r)[-800:])
    trip = [ln for ln in log.splitlines() if "jdem: watchdog: step 0:" in ln]
    c.check("setup_watchdog_trips", trip and trip[0] in r.err, "log %r, stderr %r" % (log[-800:], r.err[-800:]))
    msg = trip[0] if trip else ""
    c.check("setup_watchdog_names_no_missing_part", ".part" not in msg or os.path.exists(out + ".part"),
            "the message names %s.part, which does not exist: %r" % (out, msg))
    c.check("setup_watchdog_says_nothing_written", "no trajectory was written (%s: the run failed before its "
            "first frame)" % out in msg, msg)
    c.check("setup_watchdog_no_files", not os.path.exists(out) and not os.path.exists(out + ".part"), files(deck))


def skin(c, d):
    """--skin F: LIGGGHTS' neighbour skin F R_max (the resting scene's R_max = 10 mm), jdem's 0.2 by
    default; a skin that is not a positive number is refused with exit 2 and no deck."""
    res = os.path.join(d, "resolved.yaml")
    with open(res, "w") as f:
        f.write(resolved_text(resting(d)))
    for label, extra, want in (("default", [], "neighbor        0.002 bin\n"),
                               ("half", ["--skin", "0.5"], "neighbor        0.005 bin\n")):
        deck = os.path.join(d, label, "in.jdem")
        r = run([PY, GEN, res, "-o", deck, "--trajectory", os.path.join(d, "o.h5"), *extra])
        text = open(deck).read() if os.path.exists(deck) else ""
        c.check("skin_" + label, r.rc == 0 and want in text, "%r; want %r" % (r, want))
    for label, value in (("zero", "0"), ("nan", "nan"), ("negative", "-1")):
        deck = os.path.join(d, "bad_" + label, "in.jdem")
        r = run([PY, GEN, res, "-o", deck, "--trajectory", os.path.join(d, "o.h5"), "--skin", value])
        c.check("skin_refused_" + label, r.rc == EXIT["input"] and "--skin %s: valid: a positive number "
                "(the skin over the largest radius)" % float(value) in r.err
                and not os.path.exists(deck), repr(r))


def sort_every(c, d):
    """--sort-every N: LIGGGHTS sorts the atoms every N steps (default: never, the standalone
    engine's pair order); N < 0, or N not dividing --restart-every (a continued run would not be
    the uninterrupted one), is refused with exit 2 and no deck."""
    res = os.path.join(d, "resolved.yaml")
    with open(res, "w") as f:
        f.write(resolved_text(resting(d)))
    for label, extra, want in (("default", [], "atom_modify     map array sort 0 0.0"),
                               ("every_500", ["--sort-every", "500", "--restart-every", "2000"],
                                "atom_modify     map array sort 500 0.0")):
        deck = os.path.join(d, label, "in.jdem")
        r = run([PY, GEN, res, "-o", deck, "--trajectory", os.path.join(d, "o.h5"), *extra])
        text = open(deck).read() if os.path.exists(deck) else ""
        c.check("sort_" + label, r.rc == 0 and want in text, "%r; want %r" % (r, want))
    for label, extra, msg in (
            ("negative", ["--sort-every", "-1"], "--sort-every -1: valid: 0 (no sorting) or a positive number of steps"),
            ("not_a_divisor", ["--sort-every", "300", "--restart-every", "2000"],
             "--sort-every 300 does not divide --restart-every 2000: a run continued from a restart file "
             "would not be the uninterrupted run; valid: a divisor of 2000")):
        deck = os.path.join(d, "bad_" + label, "in.jdem")
        r = run([PY, GEN, res, "-o", deck, "--trajectory", os.path.join(d, "o.h5"), *extra])
        c.check("sort_refused_" + label, r.rc == EXIT["input"] and msg in r.err and not os.path.exists(deck),
                repr(r))


def main():
    c = Checks()
    d = scratch("jdem_faults_liggghts_")
    for name, case in (("injection", injection), ("paths", paths), ("concurrent", concurrent),
                       ("typo", typo_keeps_result), ("watchdog", watchdog_class), ("sigterm", sigterm), ("rank_errors", rank_errors),
                       ("bad_files", bad_files), ("setup_watchdog", setup_watchdog), ("skin", skin),
                       ("sort_every", sort_every)):
        sub = os.path.join(d, name)
        os.makedirs(sub)
        case(c, sub)
    if not c.failed:
        shutil.rmtree(d, ignore_errors=True)
    c.exit()


if __name__ == "__main__":
    main()
