#!/usr/bin/python3
"""Engine test: the servo-controlled wall (kernel/jdem_servo.h, docs/scenes.md "Servo walls").

1. servo_sphere: a servo wall presses one frictionless sphere onto a fixed floor, no gravity.
   At rest both contacts carry F = sigma A, so Hertz (k_n = (4/3) E/(1 - nu^2) sqrt(R), the
   default wall rule) puts the wall at 2R - 2 (F/k_n)^(2/3).  Checks: the test completes (the
   wall stops for good) with the stress within the tolerance of the target; the wall's position
   against that closed form at the measured stress and inside the band the tolerance allows; the
   wall forces (floor and top: -+F along z) and the stress tensor (sigma_zz = F/A, the rest 0).
2. Threads (thread_checks): the wall forces are summed in a fixed order -- servo_columns (wall
   contacts only) is the same bits on 1 and 2 threads; mpi_servo_cube (tests/liggghts/scenes,
   216 spheres under gravity) is reproducible bit for bit on 2 threads and within round-off of
   1 thread.

Run:  /usr/bin/python3 tests/engine/test_servo.py     (JDEM=path/to/jdem to override)
"""
import os
import tempfile
from math import sqrt

import h5py

from scripts import engines
from tests.engine.engine_common import JDEM, ROOT, Checks, np, run

R, E, NU = 0.01, 1.0e7, 0.3
AREA = 0.02 * 0.02
TOP0, TARGET, TOL, HOLD_STEPS, DT = 0.02005, 1000.0, 10.0, 5000, 1.0e-5
K_N = 4.0 / 3.0 * E / (1.0 - NU * NU) * sqrt(R)


def series(f, name):
    g = f["observables"][name]
    return g["step"][()], g["value"][()]


def wall_position(stress):
    """The top wall's displacement along its normal (down) at rest under this stress [m]."""
    delta = (stress * AREA / K_N) ** (2.0 / 3.0)
    return TOP0 - (2.0 * R - 2.0 * delta)


def sphere_checks(c):
    _, out = run("servo_sphere")
    with h5py.File(out, "r") as f:
        steps, stress = series(f, "servo_stress/top")
        _, pos = series(f, "servo_position/top")
        force = {(w, a): series(f, "wall_force/%s/%s" % (w, a))[1]
                 for w in ("floor", "top") for a in "xyz"}
        tensor = {k: series(f, "stress_tensor/" + k)[1]
                  for k in ("xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz")}
    # the hold: the last HOLD_STEPS steps of samples within tolerance, the wall standing still
    held = steps >= steps[-1] - HOLD_STEPS
    c.check("servo_sphere: stress within tolerance over the hold",
            np.all(np.abs(stress[held] - TARGET) <= TOL),
            "stress over the last %d steps in [%.6g, %.6g] Pa" % (HOLD_STEPS, stress[held].min(),
                                                                 stress[held].max()))
    c.check("servo_sphere: the wall holds (no motion over the hold)",
            np.ptp(pos[held]) == 0.0, "moved %.3g m" % np.ptp(pos[held]))
    moved = np.nonzero(np.diff(pos))[0]
    c.check("servo_sphere: the test completed before the end",
            len(moved) and steps[moved[-1] + 1] + HOLD_STEPS <= steps[-1],
            "last motion at step %s of %d" % (steps[moved[-1] + 1] if len(moved) else None, steps[-1]))
    s_end, p_end = stress[-1], pos[-1]
    # at rest: the closed form at the measured stress (the sphere has come to rest: 1e-9 of the
    # overlaps is far above the round-off), and within the band of the tolerance
    delta = (s_end * AREA / K_N) ** (2.0 / 3.0)
    c.check("servo_sphere: position = Hertz closed form at the measured stress",
            abs(p_end - wall_position(s_end)) <= 1e-9 * 2 * delta,
            "position %.12g m, closed form %.12g m" % (p_end, wall_position(s_end)))
    lo, hi = wall_position(TARGET - TOL), wall_position(TARGET + TOL)
    c.check("servo_sphere: position inside the tolerance band of the target",
            lo <= p_end <= hi, "position %.9g m not in [%.9g, %.9g]" % (p_end, lo, hi))
    F = s_end * AREA
    c.close_to("servo_sphere: top wall force z = +F", force[("top", "z")][-1], F, 1e-12)
    c.close_to("servo_sphere: floor force z = -F", force[("floor", "z")][-1], -F, 1e-5)
    lateral = max(abs(force[(w, a)][-1]) for w in ("floor", "top") for a in "xy")
    c.check("servo_sphere: no lateral wall force", lateral <= 1e-12 * F, "%.3g N" % lateral)
    c.close_to("servo_sphere: stress tensor zz = F / A", tensor["zz"][-1], s_end, 1e-5)
    others = max(abs(tensor[k][-1]) for k in tensor if k != "zz")
    c.check("servo_sphere: stress tensor otherwise 0", others <= 1e-9 * s_end, "%.3g Pa" % others)


WALL_OBSERVABLES = ("wall_force", "servo_stress", "servo_position", "stress_tensor")


def same_bits(a, b, observables):
    """The first difference between two trajectories' particle data and the given top-level
    observables, or None."""
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        names = []
        fa.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) and (
            n.startswith("particles") or n.split("/")[:2][-1] in observables) else None)
        for n in names:
            if n not in fb or not np.array_equal(fa[n][()], fb[n][()], equal_nan=True):
                return n
    return None


def run_threads(c, scene, label, threads, tag=""):
    out = os.path.join(tempfile.mkdtemp(prefix="jdem_servo_"), "%s_t%d%s.h5" % (label, threads, tag))
    p = engines.jdem("run", scene, "-o", out, "--quiet", "--threads", str(threads), binary=JDEM)
    ok = c.check("%s: runs on %d thread(s)" % (label, threads), p.returncode == 0,
                 p.stderr.strip()[-400:])
    return out if ok else None


def all_observables(path):
    with h5py.File(path, "r") as f:
        return tuple(f["observables"])


def thread_checks(c):
    """servo_columns has wall contacts only, so its particles' forces do not depend on the
    threads: the run (particles and wall observables) is the same bits on 1 and 2 threads when
    the wall forces are summed in list order.  (The energy observables are not: the walls' work
    is summed per thread, as before the servo.)  mpi_servo_cube has pair contacts, whose sums the
    threads reorder (sim.h, "Threads"): two 2-thread runs are the same bits, 1 vs 2 threads agree
    to round-off (compare_trajectories.py's default 1e-10)."""
    columns = os.path.join(ROOT, "tests", "engine", "scenes", "servo_columns.yaml")
    one, two = (run_threads(c, columns, "servo_columns", t) for t in (1, 2))
    if one and two:
        with h5py.File(one, "r") as f:
            n_wall = f["observables/wall_contacts/value"][-1]
        c.check("servo_columns: all 36 spheres touch both walls", n_wall == 72, "%g wall contacts" % n_wall)
        diff = same_bits(one, two, WALL_OBSERVABLES)
        c.check("servo_columns: 1 and 2 threads give the same bits (particles, wall observables)",
                diff is None, "first difference in %s" % diff)
    cube = os.path.join(ROOT, "tests", "liggghts", "scenes", "mpi_servo_cube.yaml")
    one, two, again = (run_threads(c, cube, "mpi_servo_cube", t, tag)
                       for t, tag in ((1, ""), (2, ""), (2, "b")))
    if not (one and two and again):
        return
    diff = same_bits(two, again, all_observables(two))
    c.check("mpi_servo_cube: two 2-thread runs give the same bits", diff is None,
            "first difference in %s" % diff)
    p = engines.run(engines.script("compare_trajectories", one, two))
    c.check("mpi_servo_cube: 1 vs 2 threads within the round-off tolerance", p.returncode == 0,
            p.stdout.strip().splitlines()[-1] if p.stdout.strip() else p.stderr.strip()[-300:])


c = Checks()
sphere_checks(c)
thread_checks(c)
c.exit()
