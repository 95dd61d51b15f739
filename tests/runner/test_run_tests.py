#!/usr/bin/python3
"""The test runner itself (tests/run_tests.py) on dummy suites, 2 cores:

- every suite's checks are counted once, a crash without a FAIL line as one failure, also when
  the suites end in another order than they started;
- a WIDE suite never runs beside another one, and the one-core suites do run two at a time
  (each dummy records when it ran; the intervals are compared);
- no more than 2 suites at once.
n1 sleeps long enough (1.5 s) that the suites started after it overlap it however slow the
machine is to start them.
"""
import os
import tempfile

from tests import run_tests
from tests.mixing.common import check, finish


def dummy(log_dir, name, seconds, body):
    """A suite that records its start and end, sleeps, then runs body (shell)."""
    log = os.path.join(log_dir, name)
    script = (f"date +%s.%N > {log}; sleep {seconds}; date +%s.%N >> {log}; {body}")
    return (name, ["sh", "-c", script], "lines", {})


def intervals(log_dir, names):
    out = {}
    for n in names:
        with open(os.path.join(log_dir, n)) as f:
            a, b = (float(x) for x in f.read().split())
        out[n] = (a, b)
    return out


def overlap(p, q):
    return p[0] < q[1] and q[0] < p[1]


def main():
    d = tempfile.mkdtemp()
    suites = [dummy(d, "n1", 1.5, "echo PASS a; echo PASS b; echo PASS c"),
              dummy(d, "n2", 0.2, "echo PASS d; echo 'FAIL e: detail'"),
              dummy(d, "n3", 0.4, "echo PASS f; exit 3"),          # a crash: one failure
              dummy(d, "w1", 0.3, "echo PASS g"),
              dummy(d, "n4", 0.3, "echo PASS h"),
              dummy(d, "w2", 0.2, "echo PASS i")]
    run_tests.WIDE, run_tests.LONG = {"w1", "w2"}, ()
    lines = []
    passed, failed = run_tests.run_side_by_side(suites, 2, emit=lines.append)
    check("runner_counts_passed", passed == 8, f"{passed} passed")
    check("runner_counts_failed_and_crash", failed == 2, f"{failed} failed")
    t = intervals(d, ["n1", "n2", "n3", "n4", "w1", "w2"])
    for w in ("w1", "w2"):
        others = [n for n in t if n != w and overlap(t[w], t[n])]
        check(f"runner_{w}_alone", not others, f"{w} overlapped {others}")
    narrow = ["n1", "n2", "n3", "n4"]
    pairs = [(a, b) for i, a in enumerate(narrow) for b in narrow[i + 1:] if overlap(t[a], t[b])]
    check("runner_one_core_suites_side_by_side", len(pairs) >= 2, f"overlapping pairs {pairs}")
    at_once = max(sum(a <= s < b for a, b in t.values()) for s, _ in t.values())
    check("runner_at_most_two_at_once", at_once <= 2, f"{at_once} suites at once")
    check("runner_reports_every_suite", sorted(x.split(":")[0] for x in lines)
          == ["== " + n for n in sorted(t)], f"{lines}")


main()
finish()
