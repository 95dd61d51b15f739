#!/usr/bin/python3
"""ab_timing.py — compare jdem binaries on one scene by alternating runs (docs/performance.md).

    scripts/ab_timing.py SCENE BINARY [BINARY ...] [--runs 6] [--threads 1] [--field pairs]
                         [--env K:NAME=VALUE ...]

Runs `BINARY run SCENE --quiet --timing --threads T` for each binary in turn, RUNS rounds, and
prints each binary's values of one `jdem-timing` field (pairs, walls, integration, output, loop,
...) sorted, with their median.  On this kind of shared virtual machine, runs of one binary differ
by up to 2x as other tenants load the cache: only alternating runs of the binaries being compared
measure the same conditions, and the median and minimum of five or more are what to compare.
--env K:NAME=VALUE sets an environment variable for the K-th binary (from 1) only, e.g. a glibc
tunable; the same binary may be listed twice, with and without it.
"""
import argparse
import os
import statistics
import sys
import tempfile

from scripts import engines


def timing(binary, scene, threads, field, env, out):
    proc = engines.jdem("run", scene, "--quiet", "--timing", "--threads", str(threads), "-o", out,
                        binary=binary, env=env)
    values = engines.jdem_timing(proc.stdout + proc.stderr)
    if values is not None:
        if field not in values:
            sys.exit(f"ab_timing: no field '{field}' in jdem-timing; valid: {', '.join(values)}")
        return values[field]
    sys.exit(f"ab_timing: {binary} printed no jdem-timing line (exit status {proc.returncode}):\n"
             + proc.stderr[-2000:])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("binaries", nargs="+")
    ap.add_argument("--runs", type=int, default=6)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--field", default="pairs")
    ap.add_argument("--env", action="append", default=[], metavar="K:NAME=VALUE")
    a = ap.parse_args()
    env = [{} for _ in a.binaries]
    for e in a.env:
        k, _, assignment = e.partition(":")
        name, eq, value = assignment.partition("=")
        if not k.isdigit() or not 1 <= int(k) <= len(a.binaries) or not eq:
            sys.exit(f"ab_timing: --env {e}: expected K:NAME=VALUE with K from 1 to {len(a.binaries)}")
        env[int(k) - 1][name] = value
    values = [[] for _ in a.binaries]
    with tempfile.TemporaryDirectory(prefix="ab_timing_") as tmp:
        out = os.path.join(tmp, "run.h5")
        for _ in range(a.runs):
            for k, b in enumerate(a.binaries):
                values[k].append(timing(b, a.scene, a.threads, a.field, env[k], out))
    for k, b in enumerate(a.binaries):
        v = sorted(values[k])
        label = b + "".join(f" {n}={x}" for n, x in env[k].items())
        print(f"{label}: {a.field} median {statistics.median(v):.4f} s; " + " ".join(f"{x:.4f}" for x in v))


if __name__ == "__main__":
    main()
