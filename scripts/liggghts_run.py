#!/usr/bin/python3
"""liggghts_run.py — run one case of a jdem scene in LIGGGHTS (build/liggghts-jdem).

    scripts/liggghts_run.py SCENE [--case NAME] -o OUT.h5 [--np N [--processors PX PY PZ]] [--force]
                            [--checkpoint-every N [--resume]] [--inlet-record FILE]

Resolves the scene with `build/jdem resolve` first (a bad scene changes nothing on disk), then
takes an exclusive lock on the deck directory OUT minus .h5 plus `.deck/` (in.jdem,
particles.data, resolved.yaml, log.lammps): a second run on the same OUT is refused while one
runs.  It generates the deck with scene_to_liggghts.py there and runs build/liggghts-jdem in it
(through mpirun for N > 1; the root flags of Open MPI are added only when running as root).
The dump writes OUT.h5.part and renames it, with its OUT.xdmf, only once the run is complete: an
earlier OUT.h5 and OUT.xdmf stay in place until then, and a stopped run leaves OUT.h5.part.
While LIGGGHTS runs, a line `liggghts_run: step S/N (P %), ETA T` goes to stderr every minute,
S the newest step that its log's thermo output or its newest restart file shows.  A deck with
inlets writes progress.txt (fix print: the step, the particles present and the work the inlets
still bring, fix jdem/inlet's f_ID), and the ETA is then the work left in particle-steps over the
particle-steps per second measured so far, as build/jdem's, not the steps left: a fill whose
particle count grows 40-fold takes far longer per step at its end.
SIGINT and SIGTERM are forwarded to LIGGGHTS (or to mpirun's ranks) and waited for: it stops at its next
step and keeps OUT.h5.part.  --force runs an unsafe time step anyway (fix jdem/guard ... force).
--inlet-record FILE writes the inlets' insertions as `jdem run --inlet-record` does.

--checkpoint-every N writes a LIGGGHTS restart file every N steps, restart.STEP in the deck
directory; the two newest are kept.  --resume then continues an interrupted run (killed, or
stopped by a signal) of the same resolved scene from the older of the two, which is complete
however the run ended (the newer may have been cut off while it was written): the deck reads it
instead of creating the particles, and its dump continues OUT.h5.part (dump h5md/jdem resume
yes).  The result equals the uninterrupted run's with the same N, bit for bit.  A run
interrupted before its second restart file, or whose scene has changed since, starts again from
the beginning (it says so); a completed run removes its restart files.

Exit status (the classes of `jdem`'s):
  0        the trajectory OUT.h5 is complete
  1        internal error (LIGGGHTS failed without a message, or wrote no trajectory)
  2        bad input: the scene, the deck generator's refusal or a LIGGGHTS error
  3        I/O: another run holds OUT's lock, or writing the deck or the trajectory failed
  4        the watchdog stopped the run (OUT.h5.part kept)
  5        out of memory
  128 + N  stopped by signal N (130 SIGINT, 143 SIGTERM; OUT.h5.part kept)
On failure the tail of the log follows the message.
"""
import argparse
import errno
import fcntl
import math
import os
import re
import signal
import subprocess
import sys
import time

import yaml

from scripts import engines
from scripts.scene_to_liggghts import PROGRESS_FILE   # the inlet decks' step, particles, pending work

EXIT_OK, EXIT_INTERNAL, EXIT_INPUT, EXIT_IO, EXIT_WATCHDOG, EXIT_MEMORY = 0, 1, 2, 3, 4, 5

# the failure class of a LIGGGHTS error line (the first pattern that matches; else bad input)
ERROR_CLASSES = [
    (re.compile(r"jdem: watchdog:"), EXIT_WATCHDOG),
    (re.compile(r"out of memory|Failed to allocate|std::bad_alloc", re.I), EXIT_MEMORY),
    (re.compile(r"HDF5|cannot (create|write|open|rename)|No space left|Read-only file system|"
                r"Permission denied|Disk quota", re.I), EXIT_IO),
]


def say(msg):
    sys.stderr.write("liggghts_run: %s\n" % msg)
    sys.stderr.flush()


def tail(path, n=25):
    try:
        with open(path, errors="replace") as f:
            return "".join(f.readlines()[-n:])
    except OSError:
        return ""


def error_class(log_text):
    """The exit status of a LIGGGHTS run that failed with ERROR lines in its log."""
    errors = [line for line in log_text.splitlines() if line.startswith("ERROR") or "jdem: watchdog:" in line]
    if not errors:
        return EXIT_INTERNAL
    for pattern, code in ERROR_CLASSES:
        if any(pattern.search(line) for line in errors):
            return code
    return EXIT_INPUT


def lock_deck(deck_dir):
    """An exclusive flock on the deck directory, or None when another run holds it."""
    fd = os.open(deck_dir, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as e:
        os.close(fd)
        if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
            return None
        raise
    return fd


class Child:
    """LIGGGHTS (or mpirun) in a process group of its own, so that a terminal's ^C reaches it
    once, through us: SIGINT/SIGTERM to this script are forwarded to it, and it is waited for.
    A signal before it starts is forwarded when it does (or ends the script before it)."""

    def __init__(self):
        self.proc = None
        self.mpirun = False
        self.signal = 0
        self.forwarded = 0  # signals sent: a second one takes LIGGGHTS' default action
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self.forward)

    def forward(self, sig, _frame):
        self.signal = sig
        if self.proc is not None and self.proc.poll() is None:
            self.forwarded += 1
            self.signal_run(sig)

    def signal_run(self, sig):
        """SIG to LIGGGHTS, or to mpirun's ranks once they run.  Open MPI 4 passes a SIGTERM on
        to its ranks only about a second later and kills them a second after that
        (odls_base_sigkill_timeout), which can cut off the last frame of a large run; a rank sent
        the signal itself stops at its next step, and mpirun then ends with it."""
        ranks = subprocess.run(["pgrep", "-P", str(self.proc.pid)], capture_output=True, text=True).stdout.split()
        for pid in (ranks if self.mpirun else []) or [self.proc.pid]:
            try:
                os.kill(int(pid), sig)
            except ProcessLookupError:
                pass

    def run(self, cmd, cwd, lock_fd, every=None):
        """Run CMD in CWD; (status, stdout, stderr).  EVERY: called every few seconds meanwhile."""
        # the lock is passed on: it holds while LIGGGHTS runs, even if this script is killed
        self.mpirun = os.path.basename(cmd[0]) == "mpirun"
        self.proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, errors="replace", process_group=0, pass_fds=(lock_fd,))
        if self.signal and not self.forwarded:
            self.forwarded += 1
            self.signal_run(self.signal)
        while True:
            try:
                out, err = self.proc.communicate(timeout=5.0)
                return self.proc.returncode, out, err
            except subprocess.TimeoutExpired:
                if every:
                    every()


def resolve(a):
    """The resolved scene (text), or the exit status of `jdem resolve` with its message shown."""
    try:
        r = engines.resolve(a.scene, a.case, binary=a.jdem)
    except engines.EngineError as e:
        say(str(e))
        return None, EXIT_INTERNAL
    if r.returncode != 0:
        say("%s failed (exit %d); nothing was written:\n%s" % (" ".join(r.args), r.returncode, r.stderr))
        return None, r.returncode if 0 < r.returncode < 128 else EXIT_INPUT
    return r.stdout, EXIT_OK


def write_deck(a, text, deck_dir, out, resume=None):
    """resolved.yaml and the deck in DECK_DIR (continuing from the restart file RESUME); 0 or
    the exit status of a failure (shown)."""
    resolved = os.path.join(deck_dir, "resolved.yaml")
    try:
        with open(resolved, "w") as f:
            f.write(text)
    except OSError as e:
        say("cannot write %s: %s" % (resolved, e))
        return EXIT_IO
    restart = ["--restart-every", str(a.checkpoint_every)] if a.checkpoint_every else []
    r = engines.write_deck(resolved, os.path.join(deck_dir, "in.jdem"), "--trajectory", out,
                           *(["--force"] if a.force else []), *restart,
                           *(["--resume", resume] if resume else []),
                           *(["--processors", *a.processors] if a.processors else []),
                           *(["--skin", repr(a.skin)] if a.skin is not None else []),
                           *(["--sort-every", str(a.sort_every)] if a.sort_every else []),
                           *(["--inlet-record", os.path.abspath(a.inlet_record)] if a.inlet_record else []))
    if r.returncode != 0:
        say("deck generation failed (exit %d):\n%s" % (r.returncode, r.stderr))
        return r.returncode if r.returncode in (EXIT_INPUT, EXIT_IO) else EXIT_INTERNAL
    return EXIT_OK


RESTART_NAME = re.compile(r"^restart\.(\d+)$")
KEEP_RESTARTS = 2


def restart_files(deck_dir):
    """The restart files restart.STEP in DECK_DIR, oldest first."""
    try:
        names = os.listdir(deck_dir)
    except OSError:
        return []
    found = [(int(m.group(1)), os.path.join(deck_dir, n)) for n in names for m in [RESTART_NAME.match(n)] if m]
    return [path for _, path in sorted(found)]


def prune_restart_files(deck_dir):
    """All but the KEEP_RESTARTS newest (complete: LIGGGHTS writes one file at a time)."""
    for path in restart_files(deck_dir)[:-KEEP_RESTARTS]:
        try:
            os.unlink(path)
        except FileNotFoundError:
            pass


def resume_file(a, deck_dir, text, out):
    """The restart file to continue from (None: start from the beginning), after saying why."""
    present = restart_files(deck_dir)
    if not a.resume:
        return None
    try:
        with open(os.path.join(deck_dir, "resolved.yaml")) as f:
            same_scene = f.read() == text
    except OSError:
        same_scene = False
    kept = any(os.path.exists(out + suffix) for suffix in (".part", ".resume"))
    why = ("no interrupted run to continue" if not kept or not present else
           "the scene differs from the interrupted run's" if not same_scene else
           "the interrupted run wrote one restart file only" if len(present) < 2 else None)
    if why:
        say("--resume: %s; starting from the beginning" % why)
        return None
    say("--resume: continuing from %s" % present[-2])
    return present[-2]


THERMO_STEP = re.compile(r"^\s*(\d+)\s+\S")


class Progress:
    """The run's step from its log (thermo lines) and its restart files, shown every minute; with
    the deck's progress.txt (inlet decks) the ETA counts particle-steps."""

    def __init__(self, deck_dir, total_steps, every=60.0):
        self.deck_dir, self.total, self.every = deck_dir, total_steps, every
        self.start = self.last_shown = time.monotonic()
        self.first_step = None
        # the newest (step, particles) seen and when it appeared, the particle-steps since the
        # first sample, and when that appeared
        self.sample_seen, self.sample_time, self.work_done, self.work_start = None, None, 0.0, None

    def step(self):
        steps = [int(f.rsplit(".", 1)[1]) for f in restart_files(self.deck_dir)]
        for line in tail(os.path.join(self.deck_dir, "log.lammps"), 40).splitlines():
            m = THERMO_STEP.match(line)
            if m:
                steps.append(int(m.group(1)))
        return max(steps) if steps else None

    def sample(self):
        """(step, particles, pending particle-steps) of progress.txt's last line, or None."""
        for line in reversed(tail(os.path.join(self.deck_dir, PROGRESS_FILE), 3).splitlines()):
            words = line.split()
            try:
                if len(words) == 3 and not line.startswith("#"):
                    return int(float(words[0])), float(words[1]), float(words[2])
            except ValueError:
                pass
        return None

    def work_eta(self, now):
        """The ETA in seconds from the work in particle-steps, or None before two samples: the
        work between two samples is the trapezoid of their particle counts, timed from when
        each sample was first seen; the work left is the particles present times the steps left
        plus what the inlets still bring, less what went on since the newest sample appeared.
        A step lower than the last one seen (a new attempt's file) starts the count again."""
        got = self.sample()
        if got is None:
            return None
        step, atoms, pending = got
        if self.sample_seen is None or step < self.sample_seen[0]:
            self.sample_seen, self.work_done, self.work_start = (step, atoms), 0.0, now
            self.sample_time = now
            return None
        s0, a0 = self.sample_seen
        if step > s0:
            self.work_done += (step - s0) * 0.5 * (a0 + atoms)
            self.sample_seen, self.sample_time = (step, atoms), now
        if self.work_done <= 0.0 or self.sample_time <= self.work_start:
            return None
        rate = self.work_done / (self.sample_time - self.work_start)
        left = (atoms * max(self.total - step, 0) + pending) / rate
        return max(left - (now - self.sample_time), 0.0)

    def __call__(self):
        now = time.monotonic()
        if not self.total or (self.first_step is not None and now - self.last_shown < self.every):
            return
        s = self.step()
        if s is None:
            return
        if self.first_step is None:   # the first step seen (a continued run's is its file's)
            self.first_step, self.start = s, now
            self.work_eta(now)
            return
        self.last_shown = now
        done = s - self.first_step
        seconds = self.work_eta(now)
        if seconds is None and done > 0:
            seconds = (self.total - s) * (now - self.start) / done
        eta = "%.0f s" % seconds if seconds is not None else "unknown"
        say("step %d/%d (%.0f %%), ETA %s" % (s, self.total, 100.0 * s / self.total, eta))


def total_steps(text):
    try:
        return int(yaml.load(text, Loader=yaml.CSafeLoader)["time"]["steps"])
    except (yaml.YAMLError, KeyError, TypeError, ValueError):
        return 0


def remove_restart_files(deck_dir):
    for path in restart_files(deck_dir):
        try:
            os.unlink(path)
        except FileNotFoundError:
            pass


def liggghts_command(a, deck_dir):
    """The run of DECK_DIR/in.jdem; with the screen kept for a deck that reads an STL mesh."""
    screen = engines.deck_reads_stl(os.path.join(deck_dir, "in.jdem"))
    return engines.liggghts_command("in.jdem", a.np, binary=os.path.abspath(a.liggghts), screen=screen)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--case", default=None)
    ap.add_argument("-o", "--output", required=True, help="trajectory (H5MD) to write")
    ap.add_argument("--np", type=int, default=1, help="MPI ranks (default 1)")
    ap.add_argument("--processors", nargs=3, metavar=("PX", "PY", "PZ"),
                    help="their grid (LIGGGHTS' processors command; default: LIGGGHTS chooses)")
    ap.add_argument("--force", action="store_true", help="run even if the time step is unsafe")
    ap.add_argument("--skin", type=float, metavar="F",
                    help="the neighbour skin over the largest radius (scene_to_liggghts.py --skin)")
    ap.add_argument("--sort-every", type=int, default=0, metavar="N",
                    help="LIGGGHTS sorts the atoms every N steps (scene_to_liggghts.py --sort-every)")
    ap.add_argument("--checkpoint-every", type=int, default=0, metavar="N",
                    help="write a restart file every N steps (restart.STEP in the deck directory)")
    ap.add_argument("--resume", action="store_true",
                    help="continue an interrupted run from its restart files, if it left them")
    ap.add_argument("--inlet-record", metavar="FILE",
                    help="write every inlet insertion (CSV) as `jdem run --inlet-record` does")
    ap.add_argument("--jdem", default=engines.JDEM)
    ap.add_argument("--liggghts", default=engines.LIGGGHTS_JDEM)
    a = ap.parse_args()
    if a.processors and "*" not in a.processors and \
            all(c.isdigit() for c in a.processors) and math.prod(map(int, a.processors)) != a.np:
        say("--processors %s makes %d ranks, --np is %d; valid: a grid whose product is --np "
            "(or '*' in one place)" % (" ".join(a.processors), math.prod(map(int, a.processors)), a.np))
        return EXIT_INPUT
    if a.resume and a.checkpoint_every <= 0:
        say("--resume needs --checkpoint-every N > 0, the cadence of the interrupted run's restart files")
        return EXIT_INPUT
    child = Child()

    if os.path.isdir(a.output):  # build/jdem's message and exit status (io/h5md_file.c)
        say("output path '%s' is a directory (give a file name, e.g. '%s/run.h5')" % (a.output, a.output))
        return EXIT_IO
    out = os.path.abspath(a.output)
    base = out[:-3] if out.endswith(".h5") else out
    deck_dir = base + ".deck"
    text, rc = resolve(a)
    if text is None:
        return rc
    if child.signal:
        return 128 + child.signal
    try:
        os.makedirs(deck_dir, exist_ok=True)
        lock = lock_deck(deck_dir)
    except OSError as e:
        say("cannot create the deck directory %s: %s" % (deck_dir, e))
        return EXIT_IO
    if lock is None:
        say("another run is writing %s (it holds the lock on %s); this one is not started" % (out, deck_dir))
        return EXIT_IO
    resume = resume_file(a, deck_dir, text, out)
    if resume is None:
        remove_restart_files(deck_dir)
    rc = write_deck(a, text, deck_dir, out, resume)
    if rc != EXIT_OK:
        return rc
    if child.signal:
        return 128 + child.signal

    run = liggghts_command(a, deck_dir)
    try:   # an earlier attempt's; LIGGGHTS writes it anew, and until then it would time its work
        os.remove(os.path.join(deck_dir, PROGRESS_FILE))
    except FileNotFoundError:
        pass
    progress = Progress(deck_dir, total_steps(text))

    def meanwhile():
        prune_restart_files(deck_dir)
        progress()

    rc, stdout, stderr = child.run(run, deck_dir, lock, meanwhile)
    log = os.path.join(deck_dir, "log.lammps")
    if rc < 0:
        rc = 128 - rc
    if rc == 0 and os.path.exists(out):
        remove_restart_files(deck_dir)
        return EXIT_OK
    if rc >= 128:
        status = rc
    elif child.signal:  # mpirun exits 1 when its ranks stopped on the forwarded signal
        status = 128 + child.signal
    elif rc == 0:
        status = EXIT_INTERNAL  # exit 0 without the trajectory
    else:
        status = error_class(tail(log, 200) + stderr)
    say("%s failed (exit %d) in %s\n--- log tail ---\n%s%s%s" % (
        " ".join(run), rc, deck_dir, tail(log), stdout[-2000:], stderr[-2000:]))
    return status


if __name__ == "__main__":
    sys.exit(main())
