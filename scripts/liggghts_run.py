#!/usr/bin/python3
"""liggghts_run.py — run one case of a jdem scene in LIGGGHTS (build/liggghts-jdem).

    scripts/liggghts_run.py SCENE [--case NAME] -o OUT.h5 [--np N] [--force]

Resolves the scene with `build/jdem resolve`, generates the deck with scene_to_liggghts.py into
OUT minus .h5 plus `.deck/` (in.jdem, particles.data, resolved.yaml, log.lammps) and runs
build/liggghts-jdem there (through mpirun for N > 1; the root flags of Open MPI are added only
when running as root).  --force runs an unsafe time step anyway (fix jdem/guard ... force).
Exits non-zero on failure with the tail of the log.
"""
import argparse
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def tail(path, n=25):
    try:
        with open(path, errors="replace") as f:
            return "".join(f.readlines()[-n:])
    except OSError:
        return ""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--case", default=None)
    ap.add_argument("-o", "--output", required=True, help="trajectory (H5MD) to write")
    ap.add_argument("--np", type=int, default=1, help="MPI ranks (default 1)")
    ap.add_argument("--force", action="store_true", help="run even if the time step is unsafe")
    ap.add_argument("--jdem", default=os.path.join(ROOT, "build", "jdem"))
    ap.add_argument("--liggghts", default=os.path.join(ROOT, "build", "liggghts-jdem"))
    a = ap.parse_args()

    out = os.path.abspath(a.output)
    base = out[:-3] if out.endswith(".h5") else out
    deck_dir = base + ".deck"
    os.makedirs(deck_dir, exist_ok=True)
    for stale in (out, out + ".part"):
        if os.path.exists(stale):
            os.remove(stale)

    cmd = [a.jdem, "resolve", a.scene] + (["--case", a.case] if a.case else [])
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write("liggghts_run: %s failed:\n%s" % (" ".join(cmd), r.stderr))
        return 1
    resolved = os.path.join(deck_dir, "resolved.yaml")
    with open(resolved, "w") as f:
        f.write(r.stdout)
    deck = os.path.join(deck_dir, "in.jdem")
    r = subprocess.run([sys.executable, os.path.join(HERE, "scene_to_liggghts.py"), resolved,
                        "-o", deck, "--trajectory", out] + (["--force"] if a.force else []),
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write("liggghts_run: deck generation failed:\n%s" % r.stderr)
        return 1

    exe = os.path.abspath(a.liggghts)
    run = [exe, "-in", "in.jdem", "-log", "log.lammps", "-screen", "none"]
    if a.np > 1:
        mpirun = shutil.which("mpirun") or "mpirun"
        flags = ["--allow-run-as-root", "--oversubscribe"] if os.geteuid() == 0 else []
        run = [mpirun] + flags + ["-np", str(a.np)] + run
    r = subprocess.run(run, cwd=deck_dir, capture_output=True, text=True)
    log = os.path.join(deck_dir, "log.lammps")
    if r.returncode != 0 or not os.path.exists(out):
        sys.stderr.write("liggghts_run: %s failed (exit %d) in %s\n--- log tail ---\n%s%s%s" % (
            " ".join(run), r.returncode, deck_dir, tail(log), r.stdout[-2000:], r.stderr[-2000:]))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
