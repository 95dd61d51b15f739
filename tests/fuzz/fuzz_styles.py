#!/usr/bin/python3
"""Fuzz the argument parsers of liggghts-jdem's styles with mutated input lines.

    tests/fuzz/fuzz_styles.py [--seconds N] [--seed S] [--out DIR]

Base decks: generated (scripts/scene_to_liggghts.py) from tests/liggghts/scenes/walls_and_options.yaml,
tests/liggghts/scenes/mpi_pile.yaml, tests/liggghts/bond_scenes/block_drop.yaml and
tests/inlet/fill_small.yaml, cut to a few steps.  Each input mutates one to three lines of our styles (one or two edits each) (pair_style gran/jiang, fix wall/jiang,
bond/jiang, jdem/watchdog, jdem/guard, jdem/loads, jdem/inlet, dump h5md/jdem): words deleted, repeated,
swapped, replaced by hostile numbers (0, -1, nan, inf, 1e308, 1e-320, 2^63, junk) or by the
style's own keywords, lines cut short.  build/liggghts-jdem must end with status 0, or 1 with an
"ERROR" line on stderr (LIGGGHTS' clean error path); a signal (a crash, an abort), another
status or a hang (60 s) is written to OUT/styles_crash_N.in and fails the run.
Prints one line per check: PASS/FAIL fuzz_styles_<what>.
"""
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
from scripts import engines
from tests.fuzz.fuzz_common import ROOT, Findings, start  # noqa: E402
SCENES = ["tests/liggghts/scenes/walls_and_options.yaml", "tests/liggghts/scenes/mpi_pile.yaml",
          "tests/liggghts/bond_scenes/block_drop.yaml", "tests/inlet/fill_small.yaml"]
OURS = re.compile(r"^(pair_style\s+gran/jiang|fix\s+\S+\s+\S+\s+(wall/jiang|bond/jiang|jdem/watchdog|jdem/guard|"
                  r"jdem/loads|jdem/inlet)|dump\s+\S+\s+\S+\s+h5md/jdem)\b")
JUNK = ["0", "-1", "1", "2", "nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "9223372036854775808",
        "99999999999", "0x10", "abc", "''", "1.5", "-0", "1e", "1,2", "plane", "cylinder", "type", "file",
        "/dev/zero", "/", "nonexistent.txt", "rule", "group", "all", "corners", "axis", "radius", "side",
        "velocity", "energy", "yes", "no", "off", "on", "kn", "kt", "sigma_c", "tau_c", "lambda", "damping",
        "bending", "max_bonds", "step", "max_gap", "overlap", "vmax", "coordination", "force", "scene",
        "case", "scene_yaml", "wall_rule", "tangential_limit", "mu_r", "rolling", "hertz", "jiang2021",
        "exact_restitution", "coulomb", "unconstrained", "inside", "outside", "I", "J_literal", "origin",
        "period", "offset", "first_id", "stop", "sections", "time", "height", "below_speed", "every",
        "record", "append_record"]


def base_decks(tmp):
    decks = []
    for k, scene in enumerate(SCENES):
        d = os.path.join(tmp, "base%d" % k)
        os.makedirs(d)
        r = engines.resolve(os.path.join(ROOT, scene))
        if r.returncode != 0:
            continue
        with open(os.path.join(d, "resolved.yaml"), "w") as f:
            f.write(r.stdout)
        r = engines.write_deck(os.path.join(d, "resolved.yaml"), os.path.join(d, "in.jdem"),
                               "--trajectory", os.path.join(d, "out.h5"), "--force")
        if r.returncode != 0:
            continue
        with open(os.path.join(d, "in.jdem")) as f:
            text = re.sub(r"(?m)^run\s+\d+\s*$", "run 3", f.read())
        decks.append((d, text))
    return decks


def mutate_line(line, rng):
    words = line.split()
    for _ in range(rng.randint(1, 2)):
        if len(words) < 2:
            break
        k = rng.randrange(1, len(words))
        roll = rng.random()
        if roll < 0.45:
            words[k] = rng.choice(JUNK)
        elif roll < 0.6:
            del words[k]
        elif roll < 0.7:
            words.insert(k, words[k])
        elif roll < 0.8:
            j = rng.randrange(1, len(words))
            words[k], words[j] = words[j], words[k]
        elif roll < 0.9:
            del words[k:]
        else:
            words.insert(k, rng.choice(JUNK))
    return " ".join(words)


def mutate(text, rng):
    lines = text.split("\n")
    ours = [i for i, ln in enumerate(lines) if OURS.match(ln)]
    for i in rng.sample(ours, min(len(ours), rng.randint(1, 3))):
        lines[i] = mutate_line(lines[i], rng)
    return "\n".join(lines)


def run_one(work, base_dir, text):
    for f in os.listdir(work):
        p = os.path.join(work, f)
        shutil.rmtree(p) if os.path.isdir(p) else os.remove(p)
    for f in os.listdir(base_dir):
        if f != "in.jdem":
            shutil.copy(os.path.join(base_dir, f), work)
    with open(os.path.join(work, "in.jdem"), "w") as f:
        f.write(text.replace(base_dir, work))
    try:
        r = engines.run_deck(work, timeout=60)
    except subprocess.TimeoutExpired:
        return "timeout", ""
    return r.returncode, r.stderr


def main():
    a, rng, tmp = start(__doc__, "jdem_fuzz_styles_")
    decks = base_decks(tmp)
    work = os.path.join(tmp, "work")
    os.makedirs(work)
    counts = {"inputs": 0, "ok": 0, "error": 0}
    bad = Findings(a.out, "styles")
    end = time.monotonic() + a.seconds
    while decks and time.monotonic() < end:
        base_dir, text = rng.choice(decks)
        mutant = mutate(text, rng)
        rc, err = run_one(work, base_dir, mutant)
        counts["inputs"] += 1
        if rc == 0:
            counts["ok"] += 1
        elif rc == 1 and "ERROR" in err:
            counts["error"] += 1
        else:
            bad.add("exit %s: %s" % (rc, err.strip()[-300:]), mutant, ".in")
            if bad.full():
                break
    shutil.rmtree(tmp, ignore_errors=True)
    print("fuzz_styles: seed %d, %d inputs in %.0f s: %d ran, %d stopped with an ERROR message"
          % (a.seed, counts["inputs"], a.seconds, counts["ok"], counts["error"]))
    return bad.verdict("fuzz_styles_clean", counts["inputs"])


if __name__ == "__main__":
    sys.exit(main())
