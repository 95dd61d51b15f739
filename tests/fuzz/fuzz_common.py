"""fuzz_common.py — what the Python fuzzers (fuzz_deck.py, fuzz_styles.py) share: their command
line (--seconds, --seed, --out), the seeded generator and scratch folder, and the findings, each
kept as its input under --out and reported in one PASS/FAIL line."""
import argparse
import os
import random
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MAX_FINDINGS = 20  # a run stops after this many: the first few say what is wrong


def start(doc, prefix, add_arguments=None):
    """Parse the command line (ADD_ARGUMENTS(parser) adds a fuzzer's own options); returns the
    arguments (seed filled in from the clock when not given), the seeded generator and a new
    scratch folder whose name starts with PREFIX."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--seed", type=int, default=None)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "fuzz"))
    if add_arguments:
        add_arguments(ap)
    a = ap.parse_args()
    a.seed = a.seed if a.seed is not None else int(time.time())
    os.makedirs(a.out, exist_ok=True)
    return a, random.Random(a.seed), tempfile.mkdtemp(prefix=prefix)


class Findings:
    """The inputs that broke something, each written to OUT/STEM_crash_N<suffix>."""

    def __init__(self, out, stem):
        self.out, self.stem, self.found = out, stem, []

    def add(self, problem, data, suffix):
        path = os.path.join(self.out, "%s_crash_%d%s" % (self.stem, len(self.found), suffix))
        with open(path, "wb" if isinstance(data, bytes) else "w") as f:
            f.write(data)
        self.found.append("%s (input %s)" % (problem, path))

    def full(self):
        return len(self.found) >= MAX_FINDINGS

    def verdict(self, check, inputs):
        """Print the PASS/FAIL line of CHECK (clean: no finding, and some input was tried);
        returns the exit status."""
        ok = not self.found and inputs > 0
        print("%s %s%s" % ("PASS" if ok else "FAIL", check, "" if ok else ": " + "; ".join(self.found[:5])))
        return 0 if ok else 1
