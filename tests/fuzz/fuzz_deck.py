#!/usr/bin/python3
"""Fuzz the deck generator (scripts/scene_to_liggghts.py) with hostile resolved scenes.

    tests/fuzz/fuzz_deck.py [--seconds N] [--seed S] [--run-every K] [--out DIR]

Seeds: `build/jdem resolve` of the scenes in tests/liggghts/scenes/ and tests/liggghts/bond_scenes/.
Each input is a seed with a few mutations: a string, number or list replaced by a hostile value
(line breaks, '#', '$', '&', quotes, `shell touch PWNED`, control and non-ASCII characters, huge,
NaN, inf, wrong types), a key deleted or added; or the YAML text itself cut or with bytes changed.
The generator runs in this process (main() with its arguments).  For every input it must
  - refuse with its own message ("scene_to_liggghts: ..." on stderr, exit status 2), or
  - write a deck in which LIGGGHTS' input rules (Input::file/parse of LIGGGHTS 3.8: '&'
    continuation, '#' comments and '$' substitution outside quotes, quoted words) find only the
    commands the generator writes, with no '$' substituted;
and every K-th deck (--run-every) is run by build/liggghts-jdem with `run 0`, where no file
named PWNED may appear and the exit status must be 0 or LIGGGHTS' error status 1 (never a signal).
Anything else (a Python exception, a crash) is written to OUT/deck_crash_N.yaml and fails the run.
Prints one line per check: PASS/FAIL fuzz_deck_<what>.
"""
import contextlib
import glob
import io
import os
import re
import subprocess
import sys
import time

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
from tests.fuzz.fuzz_common import ROOT, Findings, start  # noqa: E402
from scripts import engines, scene_to_liggghts


COMMANDS = {"units", "hard_particles", "atom_style", "atom_modify", "newton", "communicate", "boundary",
            "read_data", "fix", "pair_style", "pair_coeff", "neighbor", "neigh_modify", "group", "timestep",
            "thermo", "dump", "run"}
HOSTILE = ["a\nshell touch PWNED", "x\rshell touch PWNED", "#", "$x", "${x}", "$(1+1)", "a &", "&", "'", '"',
           "it's", 'say "x"', "a'b\"c", "shell touch PWNED", "; shell touch PWNED", "\x00", "\x1b[31m", "\t",
           "é", "名前", "\u2028", "", " ", "*", "%", "../../x", "x" * 5000, "\\", "{", "}"]
NUMBERS = [0, -1, 1, 1e308, -1e308, float("inf"), float("-inf"), float("nan"), 2 ** 63, -2 ** 63, 1e-320, 0.5]


def seeds(tmp):
    out = []
    for path in sorted(glob.glob(os.path.join(ROOT, "tests", "liggghts", "scenes", "*.yaml")) +
                       glob.glob(os.path.join(ROOT, "tests", "liggghts", "bond_scenes", "*.yaml"))):
        r = engines.resolve(path)
        if r.returncode == 0:
            out.append(yaml.load(r.stdout, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)))
    return out


def slots(node, path=()):
    """Every (container, key) in the tree."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else []
    for k, v in items:
        yield node, k
        yield from slots(v, path + (k,))


def hostile_value(rng):
    roll = rng.random()
    if roll < 0.5:
        return rng.choice(HOSTILE) + (rng.choice(HOSTILE) if rng.random() < 0.3 else "")
    if roll < 0.8:
        return rng.choice(NUMBERS)
    return rng.choice([[], {}, [rng.choice(HOSTILE)], {"k": rng.choice(NUMBERS)}, None, True])


def mutate_tree(scene, rng):
    for _ in range(rng.randint(1, 4)):
        all_slots = list(slots(scene))
        if not all_slots:
            break
        container, key = rng.choice(all_slots)
        roll = rng.random()
        if roll < 0.7:
            container[key] = hostile_value(rng)
        elif roll < 0.85 and isinstance(container, dict):
            del container[key]
        elif isinstance(container, dict):  # rename a key (e.g. a material) to a hostile name
            container[rng.choice(HOSTILE)] = container.pop(key)
    return scene


def mutate_text(text, rng):
    data = bytearray(text.encode())
    for _ in range(rng.randint(1, 8)):
        if not data:
            break
        k = rng.randrange(len(data))
        roll = rng.random()
        if roll < 0.4:
            data[k] = rng.randrange(256)
        elif roll < 0.7:
            del data[k:k + rng.randint(1, 64)]
        else:
            data[k:k] = rng.choice(HOSTILE).encode()
    return bytes(data)


def parsed_commands(deck_text):
    """The commands LIGGGHTS 3.8 would see in DECK_TEXT (Input::file and Input::parse), and the
    lines where a '$' would be substituted."""
    commands, substituted = [], []
    lines = deck_text.split("\n")
    k = 0
    while k < len(lines):
        line = lines[k]
        while line.rstrip().endswith("&") and k + 1 < len(lines):  # continuation
            k += 1
            line = line.rstrip()[:-1] + " " + lines[k]
        k += 1
        quote, cut = None, len(line)
        for i, ch in enumerate(line):  # '#' outside quotes starts a comment (quote tracking as LIGGGHTS)
            if ch == "#" and not quote:
                cut = i
                break
            if ch == "$" and not quote:
                substituted.append(line)
            if ch == quote:
                quote = None
            elif ch in "'\"":
                quote = ch
        words = line[:cut].split()
        if words:
            commands.append(words[0])
    return commands, substituted


def generate(resolved_path, deck_dir):
    """scene_to_liggghts.main() on RESOLVED_PATH; (exit status, stderr)."""
    err = io.StringIO()
    argv = sys.argv
    sys.argv = ["scene_to_liggghts.py", resolved_path, "-o", os.path.join(deck_dir, "in.jdem"),
                "--trajectory", os.path.join(deck_dir, "out.h5")]
    try:
        with contextlib.redirect_stderr(err):
            scene_to_liggghts.main()
        return 0, err.getvalue()
    except SystemExit as e:
        return (e.code if isinstance(e.code, int) else 1), err.getvalue()
    finally:
        sys.argv = argv


def run_deck(deck_dir):
    path = os.path.join(deck_dir, "in.jdem")
    with open(path) as f:
        text = re.sub(r"(?m)^run\s+\d+\s*$", "run 0", f.read())
    with open(path, "w") as f:
        f.write(text)
    try:
        r = engines.run_deck(deck_dir, timeout=60)
        return r.returncode
    except subprocess.TimeoutExpired:
        return "timeout"


def main():
    a, rng, tmp = start(__doc__, "jdem_fuzz_deck_",
                        lambda ap: ap.add_argument("--run-every", type=int, default=10))
    base = seeds(tmp)
    counts = {"inputs": 0, "refused": 0, "decks": 0, "ran": 0}
    bad = Findings(a.out, "deck")
    end = time.monotonic() + a.seconds
    while time.monotonic() < end:
        n = counts["inputs"]
        deck_dir = os.path.join(tmp, "d%d" % (n % 4))
        for f in glob.glob(os.path.join(deck_dir, "*")):
            os.remove(f)
        os.makedirs(deck_dir, exist_ok=True)
        src = os.path.join(tmp, "in%d.yaml" % (n % 4))
        scene = yaml.load(yaml.safe_dump(rng.choice(base)), Loader=yaml.CSafeLoader)
        if rng.random() < 0.2:
            data = mutate_text(yaml.safe_dump(scene), rng)
        else:
            data = yaml.safe_dump(mutate_tree(scene, rng), allow_unicode=rng.random() < 0.5).encode()
        with open(src, "wb") as f:
            f.write(data)
        counts["inputs"] += 1
        try:
            rc, err = generate(src, deck_dir)
        except Exception as e:  # noqa: BLE001 -- any escape from the generator is a finding
            rc, err = "exception", "%s: %s" % (type(e).__name__, e)
        problem = None
        if rc == 0:
            counts["decks"] += 1
            with open(os.path.join(deck_dir, "in.jdem"), errors="replace") as f:
                commands, substituted = parsed_commands(f.read())
            unknown = sorted(set(commands) - COMMANDS)
            if unknown or substituted:
                problem = "the deck gives LIGGGHTS the commands %s, substitutes in %s" % (unknown, substituted[:2])
            elif a.run_every and counts["decks"] % a.run_every == 0:
                counts["ran"] += 1
                status = run_deck(deck_dir)
                if status not in (0, 1) or glob.glob(os.path.join(deck_dir, "*PWNED*")):
                    problem = "liggghts-jdem exit %s, files %s" % (status, os.listdir(deck_dir))
        elif rc == scene_to_liggghts.EXIT_INPUT and err.startswith("scene_to_liggghts: ") and "Traceback" not in err:
            counts["refused"] += 1
        else:
            problem = "exit %s: %s" % (rc, err[-500:])
        if problem:
            bad.add(problem, data, ".yaml")
            if bad.full():
                break
    print("fuzz_deck: seed %d, %d inputs in %.0f s: %d refused with a message, %d decks, %d run by liggghts-jdem"
          % (a.seed, counts["inputs"], a.seconds, counts["refused"], counts["decks"], counts["ran"]))
    return bad.verdict("fuzz_deck_clean", counts["inputs"])


if __name__ == "__main__":
    sys.exit(main())
