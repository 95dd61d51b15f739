"""Helpers shared by the fault-injection suite (tests/faults/test_*.py).

Each test file is a script that prints one line per check, "PASS name" or "FAIL name: detail"
(and "SKIP name: reason" for a check that cannot run here, e.g. not root), and exits non-zero if
any check failed.  tests/faults/run_faults.py runs every tests/faults/test_*.py in turn; it is
the suite `faults` of tests/run_tests.py, so a new file needs no registration.

API (import with `from tests.faults.faults_common import ...`):

  ROOT, PY, JDEM, LIGGGHTS_JDEM   repository root, /usr/bin/python3, the binaries ($JDEM and
                                  $LIGGGHTS_JDEM override build/jdem, build/liggghts-jdem)
  EXIT                            the exit codes of `jdem` by failure class (docs/scenes.md):
                                  EXIT["ok"|"internal"|"input"|"io"|"watchdog"|"memory"]
                                  and signal_exit(sig) = 128 + sig
  Checks()                        .check(name, ok, detail) -> ok; .skip(name, reason);
                                  .exit() (status 1 if a check failed)
  is_root()                       True when the suite may mount and bind
  scratch(prefix)                 a new empty directory under $TMPDIR (kept for a look)
  write_scene(dir, name, text)    write TEXT to DIR/NAME.yaml, return its path
  small_scene(**fields)           a valid one-sphere scene (str); keyword arguments replace its
                                  top-level `name`, `steps`, `every`, `dt` (see the template)
  tmpfs(size)                     context manager: a fresh tmpfs of SIZE ("64k", "1m") mounted
                                  on a scratch directory; yields its path, unmounts on exit
                                  (root only: raises NotRoot otherwise)
  read_only(dir)                  context manager: DIR bind-mounted read-only on a scratch
                                  directory; yields the read-only path (root only)
  run(cmd, timeout=120, mem_bytes=None, cwd=None, env=None)
                                  run CMD (a list) with stdout/stderr captured as text, under
                                  an address-space limit (RLIMIT_AS, `ulimit -v`) if mem_bytes;
                                  returns a Result(rc, out, err, timed_out)
  start(cmd, mem_bytes=None, cwd=None, env=None)
                                  the same, started: a subprocess.Popen (text pipes)
  finish(proc, timeout=60)        wait for a started process (killed after timeout); Result
  wait_for(predicate, timeout)    poll PREDICATE() every 10 ms until true; returns its value
                                  or None at the timeout
  wait_for_file(path, timeout)    wait until PATH exists (e.g. OUT.h5.part: the run is past
                                  its set-up); True/False
  files(dir)                      sorted relative paths of the files and links below DIR
  expect_files(c, name, dir, expected)
                                  check that files(dir) equals sorted(expected); the detail
                                  names what is missing and what is extra
  h5_readable(path)               None if PATH opens with h5py and has particles/all,
                                  else the reason (str)
  h5_frames(path)                 the step numbers of the position frames in PATH
"""
import contextlib
import os
import resource
import subprocess
import sys
import tempfile
import time

from scripts import engines
from scripts.engines import JDEM, LIGGGHTS_JDEM, PY, ROOT
from tests.engine.engine_common import Checks as EngineChecks

# The exit codes of `jdem` by failure class; `jdem --help` and docs/scenes.md document them.
EXIT = {"ok": 0, "internal": 1, "input": 2, "io": 3, "watchdog": 4, "memory": 5}


def signal_exit(sig):
    return 128 + int(sig)


class NotRoot(Exception):
    """Raised by tmpfs/read_only when the suite is not run as root."""


class Checks(EngineChecks):
    """The engine tests' checks (tests/engine/engine_common.py), and skip."""

    def skip(self, name, reason):
        print(f"SKIP {name}: {reason}")
        sys.stdout.flush()


def is_root():
    return os.geteuid() == 0


def scratch(prefix="jdem_faults_"):
    return tempfile.mkdtemp(prefix=prefix)


def write_scene(directory, name, text):
    path = os.path.join(directory, name + ".yaml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return path


SMALL_SCENE = """\
jdem_scene: 1
name: {name}
time: {{dt: {dt}, steps: {steps}}}
output: {{every: {every}}}
materials:
  glass: {{youngs_modulus: 4.8e10, poisson_ratio: 0.2, density: 2800}}
particles:
  - {{id: 1, material: glass, radius: 0.01, position: [0, 0, 0], velocity: [1, 0, 0]}}
  - {{id: 2, material: glass, radius: 0.01, position: [0.05, 0, 0], velocity: [-1, 0, 0]}}
"""


def small_scene(name="small", steps=100, every=10, dt="1.0e-6"):
    return SMALL_SCENE.format(name=name, steps=steps, every=every, dt=dt)


@contextlib.contextmanager
def tmpfs(size):
    if not is_root():
        raise NotRoot("mounting a tmpfs needs root")
    mnt = scratch("jdem_tmpfs_")
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size},mode=0777", "tmpfs", mnt],
                   check=True)
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", mnt], check=False)
        with contextlib.suppress(OSError):
            os.rmdir(mnt)


@contextlib.contextmanager
def read_only(directory):
    if not is_root():
        raise NotRoot("a read-only bind mount needs root")
    mnt = scratch("jdem_ro_")
    subprocess.run(["mount", "--bind", directory, mnt], check=True)
    try:
        subprocess.run(["mount", "-o", "remount,bind,ro", mnt], check=True)
        yield mnt
    finally:
        subprocess.run(["umount", "-l", mnt], check=False)
        with contextlib.suppress(OSError):
            os.rmdir(mnt)


class Result:
    def __init__(self, rc, out, err, timed_out=False):
        self.rc, self.out, self.err, self.timed_out = rc, out, err, timed_out

    def __repr__(self):
        timed_out = " (timed out)" if self.timed_out else ""
        return f"exit {self.rc}{timed_out}, stderr {self.err.strip()!r}"


def _limits(mem_bytes):
    if mem_bytes is None:
        return None

    def apply():
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
    return apply


def start(cmd, mem_bytes=None, cwd=None, env=None):
    # started here, not by engines.run: the checks limit its memory and signal it while it runs
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            errors="replace", cwd=cwd, env=engines.python_env(env), preexec_fn=_limits(mem_bytes))


def finish(proc, timeout=60):
    try:
        out, err = proc.communicate(timeout=timeout)
        return Result(proc.returncode, out, err)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        return Result(proc.returncode, out, err, timed_out=True)


def run(cmd, timeout=120, mem_bytes=None, cwd=None, env=None):
    return finish(start(cmd, mem_bytes=mem_bytes, cwd=cwd, env=env), timeout)


def wait_for(predicate, timeout):
    deadline = time.monotonic() + timeout
    while True:
        v = predicate()
        if v or time.monotonic() > deadline:
            return v or None
        time.sleep(0.01)


def wait_for_file(path, timeout):
    return bool(wait_for(lambda: os.path.lexists(path), timeout))


def files(directory):
    found = []
    for base, dirs, names in os.walk(directory):
        for n in names + [d for d in dirs if os.path.islink(os.path.join(base, d))]:
            found.append(os.path.relpath(os.path.join(base, n), directory))
    return sorted(found)


def expect_files(c, name, directory, expected):
    got, want = files(directory), sorted(expected)
    missing = [f for f in want if f not in got]
    extra = [f for f in got if f not in want]
    return c.check(name, got == want, f"in {directory}: missing {missing}, extra {extra}")


def h5_readable(path):
    import h5py
    try:
        with h5py.File(path, "r") as f:
            if "particles/all" not in f:
                return "no particles/all group"
    except OSError as e:
        return str(e)
    return None


def h5_frames(path):
    import h5py
    with h5py.File(path, "r") as f:
        return list(f["particles/all/position/step"][()])


__all__ = ["ROOT", "PY", "JDEM", "LIGGGHTS_JDEM", "EXIT", "signal_exit", "NotRoot", "Checks",
           "is_root", "scratch", "write_scene", "small_scene", "tmpfs", "read_only", "Result",
           "run", "start", "finish", "wait_for", "wait_for_file", "files", "expect_files",
           "h5_readable", "h5_frames"]
