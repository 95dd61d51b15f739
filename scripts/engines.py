"""engines.py — the one way to start each engine and to time a run.

The engines: build/jdem (`run`, `resolve`, `cases`), build/liggghts-jdem or stock LIGGGHTS with a
deck in its directory (on N MPI ranks through mpirun), and the scripts that drive them
(scripts/liggghts_run.py: a scene in LIGGGHTS; scripts/scene_to_liggghts.py: the deck generator),
started with the repository root on PYTHONPATH so that their package imports resolve.

Timing, three measures:
  timed(cmd)          the wall time of the whole process (monotonic clock);
  gnu_timed(cmd, ...) GNU time's wall and CPU (user + system) seconds and peak RSS, with a
                      time-out that kills the process group (mpirun and its ranks included);
  cpu_timed(cmd)      wall time and the CPU time of the finished children (getrusage);
and the engines' own lines: `jdem run --timing` (jdem_timing) and LIGGGHTS' "Loop time of"
(liggghts_loops).

Every failure to start or a failed run that the caller asks to check raises EngineError, whose
message names the command, its exit status and the tail of what it printed.
"""
import os
import re
import resource
import shutil
import signal
import subprocess
import time
from typing import NamedTuple

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = "/usr/bin/python3"
# The builds under test: $JDEM and $LIGGGHTS_JDEM (relative to the repository root) when set, as
# tests/run_tests.py sets JDEM for the suites of the sanitized stepper; JDEM_BUILD is the
# optimised stepper whatever $JDEM says.
JDEM_BUILD = os.path.join(ROOT, "build", "jdem")
JDEM = os.path.join(ROOT, os.environ["JDEM"]) if os.environ.get("JDEM") else JDEM_BUILD
LIGGGHTS_JDEM = os.path.join(ROOT, os.environ.get("LIGGGHTS_JDEM", os.path.join("build", "liggghts-jdem")))
LIGGGHTS = "/usr/bin/liggghts"   # stock LIGGGHTS (Debian's), for the decks written with --builtin
GNU_TIME = "/usr/bin/time"
TAIL_CHARS = 2000                # of stdout and of stderr, in an EngineError's message


class EngineError(RuntimeError):
    """An engine or script that could not be started, or that failed when checked."""


def python_env(env=None):
    """os.environ with ENV's entries and the repository root as the module path."""
    return {**os.environ, **(env or {}), "PYTHONPATH": ROOT}


def script(name, *args):
    """The command line of scripts/NAME.py with ARGS."""
    return [PY, os.path.join(ROOT, "scripts", name + ".py"), *args]


def case_args(case):
    return ["--case", case] if case else []


def failure(cmd, returncode, stdout, stderr):
    return EngineError("%s failed (exit %d):\n%s%s" % (" ".join(cmd), returncode,
                                                      (stdout or "")[-TAIL_CHARS:], (stderr or "")[-TAIL_CHARS:]))


def run(cmd, cwd=None, env=None, check=False, merge=False, stdout=None, timeout=None, capture=True):
    """Run CMD to its end; its CompletedProcess (text; stderr into stdout if MERGE, stdout into
    the open file STDOUT if given; with CAPTURE false both go where ours go).  CHECK: a non-zero exit raises EngineError.  TIMEOUT [s]:
    subprocess.TimeoutExpired after it (the process killed)."""
    out = stdout if stdout is not None else subprocess.PIPE if capture else None
    err = subprocess.STDOUT if merge else subprocess.PIPE if capture else None
    try:
        r = subprocess.run(cmd, cwd=cwd, env=python_env(env), text=True, errors="replace", stdout=out,
                           stderr=err, timeout=timeout)
    except OSError as e:
        raise EngineError("cannot run %s: %s" % (cmd[0], e)) from e
    if check and r.returncode != 0:
        raise failure(cmd, r.returncode, r.stdout, r.stderr)
    return r


def jdem(*args, binary=JDEM, **kw):
    """`jdem ARGS` (run, resolve, cases, ...) with run()'s keywords."""
    return run([binary, *args], **kw)


def resolve(scene, case=None, binary=JDEM, **kw):
    """`jdem resolve SCENE [--case CASE]`: the resolved scene is the CompletedProcess' stdout."""
    return jdem("resolve", scene, *case_args(case), binary=binary, **kw)


def cases(scene, binary=JDEM, cwd=None):
    """The case names of SCENE (`jdem cases`)."""
    return jdem("cases", scene, binary=binary, cwd=cwd, check=True).stdout.split()


def mpirun(ranks, *flags):
    """The mpirun prefix of a run on RANKS MPI ranks ([] for one): Open MPI's root flags only
    when running as root, then FLAGS."""
    if ranks <= 1:
        return []
    root = ["--allow-run-as-root", "--oversubscribe"] if os.geteuid() == 0 else []
    return [shutil.which("mpirun") or "mpirun", *root, *flags, "-np", str(ranks)]


def liggghts_command(deck, ranks=1, binary=LIGGGHTS_JDEM, log="log.lammps", mpi_flags=(), screen=False):
    """LIGGGHTS on DECK (a path relative to the deck's directory, where it runs), its log in LOG;
    screen: keep the screen output (LIGGGHTS 3.8's STL reader crashes under -screen none, so a
    deck with fix mesh/surface needs it)."""
    return mpirun(ranks, *mpi_flags) + [binary, "-in", deck, "-log", log] + ([] if screen else ["-screen", "none"])


def deck_reads_stl(deck_path):
    """1 when the deck has a `fix ID group mesh/surface` line (it reads an STL file)."""
    with open(deck_path, errors="replace") as f:
        return any(line.split()[:1] == ["fix"] and line.split()[3:4] == ["mesh/surface"] for line in f)


def run_deck(deck_dir, deck="in.jdem", ranks=1, binary=LIGGGHTS_JDEM, log="log.lammps", mpi_flags=(), **kw):
    """Run LIGGGHTS on DECK_DIR/DECK in DECK_DIR (run()'s keywords); the screen kept for a deck
    that reads an STL file."""
    screen = deck_reads_stl(os.path.join(deck_dir, deck))
    return run(liggghts_command(deck, ranks, binary, log, mpi_flags, screen), cwd=deck_dir, **kw)


def write_deck(resolved, deck, *args, **kw):
    """scripts/scene_to_liggghts.py RESOLVED -o DECK ARGS (--trajectory, --builtin, --force ...)."""
    return run(script("scene_to_liggghts", resolved, "-o", deck, *args), **kw)


def liggghts_run(scene, out, *args, case=None, ranks=1, **kw):
    """scripts/liggghts_run.py: SCENE [CASE] in build/liggghts-jdem on RANKS ranks, into OUT."""
    ranks_args = ["--np", str(ranks)] if ranks > 1 else []
    return run(script("liggghts_run", scene, *case_args(case), "-o", out, *ranks_args, *args), **kw)


def liggghts_log(out):
    """The log of scripts/liggghts_run.py's run into OUT (its deck directory OUT minus .h5 + .deck)."""
    base = out[:-3] if out.endswith(".h5") else out
    return os.path.join(base + ".deck", "log.lammps")


# ---------------------------------------------------------------------------------------------
# Timing

def timed(cmd, **kw):
    """run(CMD, **KW) and its wall time [s]: (CompletedProcess, seconds)."""
    start = time.monotonic()
    r = run(cmd, **kw)
    return r, time.monotonic() - start


def cpu_timed(cmd, cwd=None):
    """Run CMD (checked); {"wall": s, "cpu": s, "load": the 1-minute load average before}, cpu =
    user + system time of its processes (less sensitive than wall to other jobs on the machine)."""
    r, times = cpu_timed_run(cmd, cwd)
    if r.returncode != 0:
        raise failure(cmd, r.returncode, r.stdout, r.stderr)
    return times


def cpu_timed_run(cmd, cwd=None):
    """Run CMD unchecked: (its CompletedProcess, the times of cpu_timed), for a caller that
    handles a failure class itself (e.g. a run the watchdog stopped)."""
    def cpu():
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        return r.ru_utime + r.ru_stime
    load, wall, cpu0 = os.getloadavg()[0], time.monotonic(), cpu()
    r = run(cmd, cwd=cwd)
    return r, {"wall": time.monotonic() - wall, "cpu": cpu() - cpu0, "load": load}


class GnuTimed(NamedTuple):
    wall: float       # [s]
    cpu: float        # user + system [s]
    rss: int          # peak resident set [bytes] (of the largest process)
    stdout: str
    stderr: str
    returncode: int


def gnu_timed(cmd, cwd, timeout):
    """Run CMD in CWD under GNU time (its record in CWD/.time).  After TIMEOUT seconds the whole
    process group (GNU time, mpirun, the engine) is killed and EngineError raised."""
    tf = os.path.join(cwd, ".time")
    full = [GNU_TIME, "-o", tf, "-f", "%e %U %S %M"] + cmd
    p = subprocess.Popen(full, cwd=cwd, env=python_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, start_new_session=True)
    try:
        so, se = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        raise EngineError("no result after %.0f s (--timeout), killed: %s" % (timeout, " ".join(cmd)))
    try:
        e, u, s, m = open(tf).read().split()[-4:]
        wall, cpu, rss = float(e), float(u) + float(s), int(m) * 1024
    except (OSError, ValueError):
        wall, cpu, rss = float("nan"), float("nan"), 0
    return GnuTimed(wall, cpu, rss, so, se, p.returncode)


TIMING_RE = re.compile(r"jdem-timing: (.*)")
LOOP_RE = re.compile(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms")


def jdem_timing(stderr):
    """The last `jdem-timing:` line of `jdem run --timing` as {name: value} (seconds of the time
    loop and its parts, and the counts it prints), or None."""
    m = TIMING_RE.findall(stderr)
    if not m:
        return None
    return {k: float(v) for k, v in (kv.split("=") for kv in m[-1].split())}


def liggghts_loops(log_text):
    """LIGGGHTS' "Loop time of S on P procs for N steps with A atoms" lines of a log, as strings
    (S, P, N, A), in order."""
    return LOOP_RE.findall(log_text)


def liggghts_loop_seconds(log_path):
    """The last run's Loop time [s] in the log LOG_PATH."""
    with open(log_path, errors="replace") as f:
        loops = liggghts_loops(f.read())
    if not loops:
        raise EngineError("no 'Loop time' in " + log_path)
    return float(loops[-1][0])


def guard_dt(scene, binary=JDEM):
    """The stepper's largest safe dt for SCENE [s], from its guard's refusal (6 digits): the
    scene's own dt must exceed it (bench.py and accuracy.py first write dt = 1 s)."""
    r = jdem("run", scene, "-o", "/dev/null/x.h5", binary=binary)
    m = re.search(r"largest safe dt = ([0-9.eE+-]+)", r.stderr)
    if not m:
        raise EngineError("no safe dt in the stepper's message:\n" + r.stderr)
    return float(m.group(1))
