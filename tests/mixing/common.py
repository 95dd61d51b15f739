"""Shared by the tests of tests/mixing: the PASS/FAIL line convention and the import path."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

FAILED = []


def check(name, ok, detail=""):
    """Print PASS name, or FAIL name: detail (and remember the failure)."""
    if ok:
        print(f"PASS {name}", flush=True)
    else:
        FAILED.append(name)
        print(f"FAIL {name}: {detail}", flush=True)


def close(name, got, want, tol):
    """|got - want| <= tol (absolute)."""
    check(name, abs(got - want) <= tol, f"got {got!r}, expected {want!r} (tolerance {tol:g})")


def finish():
    sys.exit(1 if FAILED else 0)
