#!/usr/bin/python3
"""check_restart.py — LIGGGHTS restart files with our styles (docs/liggghts.md, "Restarts").

    tests/liggghts/check_restart.py [--out DIR] [--keep]

The decks are tests/liggghts/restart_decks/*.in (common.in reads the data file, or a restart
file when `resume` names one).  The reference of every check is the same deck run without
interruption by build/liggghts-jdem: a continued run must equal it bit for bit (==, no
tolerance) in the final frame of its dump h5md/jdem -- positions, velocities and angular
velocities by atom id, and every observable (energies, contacts, wall forces, servo state,
stress tensor, bond energies) -- on 1 and 2 MPI ranks:
  bed    96 spheres settle with friction and rolling resistance on a plane in a cylinder that
         moves sideways, one held, one pushed (contact, rolling and wall histories, a moving
         wall's position, fix jdem/loads' work);
  block  a bonded 4x4x4 block thrown onto a plate: bonds formed at step 0, the file written
         during the impact, while bonds break (the bond lists and bond states, the fragments);
  servo  the servo cube of tests/liggghts/scenes/mpi_servo_cube.yaml (the servo wall's
         position, speed and hold count);
  inlet  a conveyor inlet (fix jdem/inlet) written with sections still to come (the stream's
         position; the continued run inserts the same particles at the same steps);
  mesh_box   64 spheres settle in a static meshed box with a funnel floor (fix mesh/surface +
         fix wall/jiang mesh: the mesh history slots, face, edge and corner contacts);
  mesh_drum  48 spheres in a meshed drum turned by fix move/mesh rotate (the mesh's position
         and the wall velocity at the contacts);
  mesh_belt  32 spheres on a surface_vel belt carried against a meshed end wall that fix
         move/mesh linear lifts (two mesh fixes; their energy sums, which the watchdog reads);
each written by `restart N` (half way; the block at a quarter) and continued with read_restart; and the bed killed with
SIGKILL while it writes a restart file every 400 steps, continued from the last complete one.
The continued deck is the same deck: LIGGGHTS' `restart N` rebuilds the neighbour lists at the
steps it writes, so the uninterrupted run must write at the same steps (it does: same deck).
A continuation that differed would fail here: the file's forces, the contact history or any
fix state left out change the trajectory in its last bits within a step.
Across pair styles: LIGGGHTS' own pair_style gran read into the bed with gran/jiang, and the bed's
file read into LIGGGHTS' own pair_style and walls, continue with a warning that the contact
history is dropped (its exact text), from the file's positions (== the writer's last frame);
the bed's file read with `rolling off` stops with the message naming the file's options, a
clean line of printable text; the meshed box's file read by a deck whose wall of that ID is a
plane stops with the message naming both kinds; the drum's file continued without its fix
move/mesh warns that the mesh stays where the file put it.
Prints one PASS/FAIL line per check; exit 1 if any fails.
"""
import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np
from tests.mesh.stl_files import write_ascii_stl_double

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DECKS = os.path.join(HERE, "restart_decks")
LIGGGHTS = os.path.join(ROOT, "build", "liggghts-jdem")

failed = 0


def check(name, ok, detail=""):
    global failed
    print(("PASS %s" % name) if ok else ("FAIL %s: %s" % (name, detail)), flush=True)
    failed += 0 if ok else 1
    return ok


# ---- the particles -------------------------------------------------------------------------

def lattice(origin, spacing, counts, jitter, rng):
    """Points of a jittered cubic lattice, x fastest."""
    pts = []
    for k in range(counts[2]):
        for j in range(counts[1]):
            for i in range(counts[0]):
                p = np.array(origin) + spacing * np.array([i, j, k], float)
                pts.append(p + jitter * spacing * rng.uniform(-1.0, 1.0, 3))
    return pts


def write_data(path, box, atoms, velocity=None):
    """A LIGGGHTS data file of granular atoms: (type, diameter, density, x) per atom."""
    with open(path, "w") as f:
        f.write("restart test particles\n\n%d atoms\n2 atom types\n\n" % len(atoms))
        for (lo, hi), ax in zip(box, "xyz"):
            f.write("%r %r %slo %shi\n" % (lo, hi, ax, ax))
        f.write("\nAtoms\n\n")
        for n, (t, d, rho, x) in enumerate(atoms, 1):
            f.write("%d %d %r %r %r %r %r\n" % (n, t, d, rho, x[0], x[1], x[2]))
        if velocity is not None:
            f.write("\nVelocities\n\n")
            for n in range(1, len(atoms) + 1):
                f.write("%d %r %r %r 0 0 0\n" % ((n,) + tuple(velocity)))


def particles(case, path):
    rng = np.random.RandomState(7)
    if case == "bed":
        pts = lattice([-0.0315, -0.0315, 0.012], 0.021, [4, 4, 6], 0.05, rng)
        atoms = [(1, 2 * (0.0095 + 0.0005 * (n % 2)), 2500.0, p) for n, p in enumerate(pts)]
        write_data(path, [(-0.2, 0.2), (-0.2, 0.2), (-0.05, 0.4)], atoms)
    elif case == "block":
        pts = lattice([-0.003, -0.003, 0.00102], 0.002, [4, 4, 4], 0.0, rng)
        atoms = [(1, 0.002, 2500.0, p) for p in pts]
        write_data(path, [(-0.05, 0.05), (-0.05, 0.05), (-0.01, 0.02)], atoms, velocity=(1.5, 0.5, -4.0))
    elif case == "inlet":
        return  # the box starts empty: fix jdem/inlet brings the particles
    elif case in MESHES:
        origin, counts, box, velocity = MESH_BEDS[case]
        pts = lattice(origin, 0.021, counts, 0.05, rng)
        atoms = [(1, 2 * (0.0095 + 0.0005 * (n % 2)), 2500.0, p) for n, p in enumerate(pts)]
        write_data(path, box, atoms, velocity)
        for name, tris in MESHES[case]().items():
            write_ascii_stl_double(os.path.join(os.path.dirname(path), name + ".stl"), tris)
    else:
        pts = lattice([0.0295, 0.0295, 0.0145], 0.0282, [6, 6, 6], 0.05, rng)
        atoms = [(1, 2 * (0.013 if rng.uniform() < 0.5 else 0.014), 2500.0, p) for p in pts]
        write_data(path, [(-0.3, 0.5), (-0.3, 0.5), (-0.3, 0.6)], atoms)


# ---- the meshes of the mesh-wall cases (STL files written next to the data file) -------------

def grid(corner, du, dv, nu, nv, lift=None):
    """An nu x nv grid of quadrilaterals from `corner` along du and dv, two triangles each
    (diagonals alternating, so that the contacts meet edges of both directions); lift(p)
    moves each grid point (e.g. onto a funnel's slope)."""
    lift = lift or (lambda p: p)
    at = lambda i, j: tuple(lift(np.asarray(corner) + i * np.asarray(du) + j * np.asarray(dv)))
    tris = []
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
            tris += [(a, b, c), (a, c, d)] if (i + j) % 2 == 0 else [(a, b, d), (b, c, d)]
    return tris


def box_mesh():
    """A box of half width 0.05 m whose floor is a funnel: z = 0.02 max(|x|, |y|) / 0.05."""
    w, h = 0.05, 0.15
    funnel = lambda p: p + np.array([0.0, 0.0, 0.02 * max(abs(p[0]), abs(p[1])) / w])
    tris = grid((-w, -w, 0.0), (w / 2, 0, 0), (0, w / 2, 0), 4, 4, funnel)
    for s in (-w, w):
        tris += grid((s, -w, 0.0), (0, w / 2, 0), (0, 0, h / 6), 4, 6)
        tris += grid((-w, s, 0.0), (w / 2, 0, 0), (0, 0, h / 6), 4, 6)
    return {"box": tris}


def drum_mesh(radius=0.08, half_length=0.03, n=24):
    """A drum about the y axis: n lateral strips and two end caps as fans."""
    ring = [(radius * np.cos(2 * np.pi * k / n), radius * np.sin(2 * np.pi * k / n)) for k in range(n + 1)]
    tris = []
    for k in range(n):
        (x0, z0), (x1, z1) = ring[k], ring[k + 1]
        tris += [((x0, -half_length, z0), (x1, -half_length, z1), (x1, half_length, z1)),
                 ((x0, -half_length, z0), (x1, half_length, z1), (x0, half_length, z0))]
        for y in (-half_length, half_length):
            tris.append(((0.0, y, 0.0), (x0, y, z0), (x1, y, z1)))
    return {"drum": tris}


def belt_mesh():
    """The belt z = 0 and an end wall across it at x = 0.006 (the bed reaches it)."""
    return {"belt": grid((-0.12, -0.06, 0.0), (0.03, 0, 0), (0, 0.03, 0), 8, 4),
            "stop": grid((0.006, -0.06, -0.02), (0, 0.03, 0), (0, 0, 0.02), 4, 4)}


MESHES = {"mesh_box": box_mesh, "mesh_drum": drum_mesh, "mesh_belt": belt_mesh}
# the bed's lattice (origin, counts; spacing 0.021 m), the simulation box and the initial
# velocity of each mesh case: thrown at the walls, so that the beds slide on the mesh with
# friction well before the restart file is written
MESH_BEDS = {"mesh_box": ([-0.0315, -0.0315, 0.025], [4, 4, 4], [(-0.1, 0.1), (-0.1, 0.1), (-0.05, 0.3)],
                          (0.3, 0.15, -0.6)),
             "mesh_drum": ([-0.0315, -0.0105, -0.059], [4, 2, 3], [(-0.1, 0.1), (-0.1, 0.1), (-0.1, 0.1)],
                           (0.2, 0.1, -0.4)),
             "mesh_belt": ([-0.07, -0.0315, 0.012], [4, 4, 2], [(-0.15, 0.15), (-0.1, 0.1), (-0.05, 0.2)],
                           (0.15, 0.0, 0.0))}

# steps, restart cadence (half way), dump cadence of each case
CASES = {"bed": (3000, 1500, 100), "block": (1200, 300, 100), "servo": (3000, 1500, 100),
         "inlet": (6000, 3000, 500), "mesh_box": (3000, 1500, 100), "mesh_drum": (3000, 1500, 100),
         "mesh_belt": (3000, 1500, 100)}


# ---- running -------------------------------------------------------------------------------

def command(np_, deck, variables):
    mpi = [] if np_ == 1 else ["mpirun"] + (["--allow-run-as-root", "--oversubscribe"] if os.geteuid() == 0 else []) + \
        ["-np", str(np_)]
    # LIGGGHTS' STL reader writes to the screen: with -screen none it would crash
    screen = "screen.txt" if "stl" in variables else "none"
    args = mpi + [LIGGGHTS, "-in", deck, "-log", "log.lammps", "-screen", screen, "-var", "decks", DECKS]
    for k, v in variables.items():
        args += ["-var", k, str(v)]
    return args


def run_dir(tmp, name):
    d = os.path.join(tmp, name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "restarts"))
    return d


def variables(d, data, n, restart_every, dump_every, resume="none", case=None):
    var = {"data": data, "out": os.path.join(d, "out.h5"), "rdir": os.path.join(d, "restarts"),
           "n": n, "restart_every": restart_every, "dump_every": dump_every, "resume": resume,
           "resuming": 0 if resume == "none" else 1}
    if case in MESHES:  # the STL files next to the data file: stl, and stl_<name> for the others
        names = list(MESHES[case]().keys())
        for k, name in enumerate(names):
            var["stl" if k == 0 else "stl_end"] = os.path.join(os.path.dirname(data), name + ".stl")
    return var


def run(d, np_, deck, var):
    r = subprocess.run(command(np_, deck, var), cwd=d, capture_output=True, text=True)
    log = read_log(d)
    return r.returncode, log + r.stdout + r.stderr


def read_log(d):
    try:
        with open(os.path.join(d, "log.lammps"), errors="replace") as f:
            return f.read()
    except OSError:
        return ""


# ---- comparing -----------------------------------------------------------------------------

def frame(path, index=-1):
    """The frame `index` of a dump h5md/jdem file: step, {quantity: values ordered by id},
    {observable: value at that step}."""
    with h5py.File(path, "r") as f:
        part = f["particles/all"]
        step = int(part["position/step"][index])
        ids = part["id"][()] if isinstance(part["id"], h5py.Dataset) else part["id/value"][index]
        order = np.argsort(ids)
        order = order[ids[order] >= 0]  # a growing set's empty slots have id -1
        q = {k: part[k + "/value"][index][order] for k in ("position", "velocity", "angular_velocity")}
        q["id"] = ids[order]
        obs = {}

        def visit(name, node):
            if isinstance(node, h5py.Group) and "value" in node and "step" in node:
                steps = node["step"][()]
                hit = np.nonzero(steps == step)[0]
                obs[name] = node["value"][hit[0]] if len(hit) else None
        f["observables"].visititems(visit)
    return step, q, obs


def observable_at(path, name, step):
    """Observable `name` of a dump h5md/jdem file at `step` (None if not recorded then)."""
    with h5py.File(path, "r") as f:
        node = f["observables"][name]
        hit = np.nonzero(node["step"][()] == step)[0]
        return node["value"][hit[0]] if len(hit) else None


def same_bits(a, b):
    """== to the bit (a NaN of the reference, e.g. a stress tensor without a box, matches only
    the same NaN)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def same_final_frame(name, ref, cont):
    try:
        sa, qa, oa = frame(ref)
        sb, qb, ob = frame(cont)
    except (OSError, KeyError) as e:
        return check(name + "_readable", False, str(e))
    check(name + "_final_step", sa == sb, "reference ends at step %d, the continued run at %d" % (sa, sb))
    for k in qa:
        diff = "n/a" if qa[k].shape != qb[k].shape else "%g" % np.max(np.abs(qa[k] - qb[k]))
        check("%s_%s" % (name, k), same_bits(qa[k], qb[k]), "max |difference| %s" % diff)
    bad = [k for k in oa if oa[k] is None or ob.get(k) is None or not same_bits(oa[k], ob[k])]
    check(name + "_observables", len(oa) > 0 and not bad and sorted(oa) == sorted(ob),
          "%d observables, differing or missing: %s" % (len(oa), bad[:6]))


def half_way(tmp, case, np_):
    """The case run uninterrupted, and continued from its restart file half way."""
    n, every, dump_every = CASES[case]
    deck = os.path.join(DECKS, case + ".in")
    ref = run_dir(tmp, "%s_np%d_ref" % (case, np_))
    data = os.path.join(ref, "particles.data")
    particles(case, data)
    rc, log = run(ref, np_, deck, variables(ref, data, n, every, dump_every, case=case))
    if not check("%s_np%d_reference_runs" % (case, np_), rc == 0, log[-1500:]):
        return
    if case in MESHES:
        touching = observable_at(os.path.join(ref, "out.h5"), "wall_contacts", every)
        check("%s_np%d_mesh_contacts_at_restart" % (case, np_), touching > 0,
              "%s mesh wall contacts when the file is written: the case tests no mesh history" % touching)
    cont = run_dir(tmp, "%s_np%d_cont" % (case, np_))
    resume = os.path.join(ref, "restarts", "r.%d" % every)
    rc, log = run(cont, np_, deck, variables(cont, data, n - every, every, dump_every, resume, case))
    if check("%s_np%d_continued_runs" % (case, np_), rc == 0, log[-1500:]):
        same_final_frame("%s_np%d" % (case, np_), os.path.join(ref, "out.h5"), os.path.join(cont, "out.h5"))


def killed(tmp, np_):
    """The bed writing a restart file every 400 steps, killed (SIGKILL) after its third, and
    continued from the last complete one (the one before the newest)."""
    n, every, dump_every = 6000, 400, 200
    deck = os.path.join(DECKS, "bed.in")
    name = "bed_killed_np%d" % np_
    ref = run_dir(tmp, name + "_ref")
    data = os.path.join(ref, "particles.data")
    particles("bed", data)
    rc, log = run(ref, np_, deck, variables(ref, data, n, every, dump_every))
    if not check(name + "_reference_runs", rc == 0, log[-1500:]):
        return
    victim = run_dir(tmp, name)
    proc = subprocess.Popen(command(np_, deck, variables(victim, data, n, every, dump_every)), cwd=victim,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    rdir = os.path.join(victim, "restarts")
    deadline = time.time() + 300
    while proc.poll() is None and time.time() < deadline and len(os.listdir(rdir)) < 3:
        time.sleep(0.01)
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    rc = proc.wait()
    written = sorted(int(f.split(".")[-1]) for f in os.listdir(rdir))
    if not check(name + "_was_killed", rc == -signal.SIGKILL and len(written) >= 2 and written[-1] < n,
                 "exit %s, restart files at steps %s" % (rc, written)):
        return
    last = written[-2]
    cont = run_dir(tmp, name + "_cont")
    rc, log = run(cont, np_, deck, variables(cont, data, n - last, every, dump_every,
                                             os.path.join(rdir, "r.%d" % last)))
    if check(name + "_continued_runs", rc == 0, log[-1500:]):
        same_final_frame(name, os.path.join(ref, "out.h5"), os.path.join(cont, "out.h5"))


# ---- across pair styles ----------------------------------------------------------------------

STOCK_PAIR = "pair_style      gran model hertz tangential history"
STOCK_WALLS = ("fix floor all wall/gran model hertz tangential history primitive type 2 zplane 0.0\n"
               "fix can all wall/gran model hertz tangential history primitive type 2 zcylinder 0.06 0.0 0.0\n")


def stock_bed(tmp):
    """bed.in with LIGGGHTS' own pair style and walls (no fixes of ours but the dump)."""
    with open(os.path.join(DECKS, "bed.in")) as f:
        text = f.read()
    text = text.replace("pair_style      gran/jiang rolling on", STOCK_PAIR)
    text = re.sub(r"(?m)^fix floor .*\n^fix can .*\n", STOCK_WALLS, text)
    text = re.sub(r"(?m)^fix (watchdog|observables|loads) .*\n", "", text)
    text = text.replace("h5md/jdem ${dump_every} ${out}", "h5md/jdem ${dump_every} ${out} energy no")
    path = os.path.join(tmp, "stock_bed.in")
    with open(path, "w") as f:
        f.write(text)
    return path


DROPPED = ("read_restart: the contact history in the restart file belongs to %s, which %s cannot "
           "continue: every contact starts from zero history (positions, velocities and the other "
           "fixes' states continue)")
OURS, STOCK = "pair_style gran/jiang", "LIGGGHTS' own pair_style gran"


def across(tmp, name, writer_deck, reader_deck, want):
    """A file of writer_deck at step 1000 read by reader_deck: the warning `want`, once, and the
    continued run starts from the file's state (its frame at step 1000 == the writer's)."""
    w = run_dir(tmp, name + "_writer")
    data = os.path.join(w, "particles.data")
    particles("bed", data)
    rc, log = run(w, 1, writer_deck, variables(w, data, 1000, 1000, 100))
    if not check(name + "_writer_runs", rc == 0, log[-1500:]):
        return
    r = run_dir(tmp, name + "_reader")
    rc, log = run(r, 1, reader_deck, variables(r, data, 500, 500, 100, os.path.join(w, "restarts", "r.1000")))
    if not check(name + "_reader_runs", rc == 0, log[-1500:]):
        return
    check(name + "_warning", log.count("WARNING: " + want) == 1, "expected once %r in %r" % (want, log[-2500:]))
    try:
        sa, qa, _ = frame(os.path.join(w, "out.h5"))
        sb, qb, _ = frame(os.path.join(r, "out.h5"), 0)
    except (OSError, KeyError) as e:
        return check(name + "_readable", False, str(e))
    check(name + "_starts_from_the_file", sa == sb == 1000 and all(same_bits(qa[k], qb[k]) for k in qa),
          "writer's last frame at step %d, reader's first at %d" % (sa, sb))


def history_lengths():
    """The doubles of a contact's and a rolling history with energy, without MEPA
    (kernel/jdem_kernel.h's JD_CONTACT_ENERGY_LEN and JD_ROLLING_STATE_LEN)."""
    with open(os.path.join(ROOT, "kernel", "jdem_kernel.h")) as f:
        text = f.read()
    return tuple(int(re.search(r"#define %s (\d+)" % name, text).group(1))
                 for name in ("JD_CONTACT_ENERGY_LEN", "JD_ROLLING_STATE_LEN"))


def option_mismatch(tmp):
    """The bed's file continued with `rolling off`: the error names the file's options."""
    with open(os.path.join(DECKS, "bed.in")) as f:
        text = f.read().replace("gran/jiang rolling on", "gran/jiang rolling off")
    deck = os.path.join(tmp, "bed_rolling_off.in")
    with open(deck, "w") as f:
        f.write(text)
    w = run_dir(tmp, "mismatch_writer")
    data = os.path.join(w, "particles.data")
    particles("bed", data)
    rc, log = run(w, 1, os.path.join(DECKS, "bed.in"), variables(w, data, 200, 200, 100))
    if not check("mismatch_writer_runs", rc == 0, log[-1500:]):
        return
    r = run_dir(tmp, "mismatch_reader")
    rc, log = run(r, 2, deck, variables(r, data, 100, 100, 100, os.path.join(w, "restarts", "r.200")))
    contact, rolling = history_lengths()  # the writer: rolling and energy; the reader: energy only
    want = ("ERROR: pair_style gran/jiang: the restart file was written with pair_style gran/jiang "
            "wall_rule hertz damping jiang2021 tangential_limit coulomb tangential_stiffness jiang2021 "
            "mu_r 1 rolling on energy yes (%d values of history per contact); this pair_style keeps %d: "
            "give the rolling, energy and normal_law options of the run that wrote it (" % (contact + rolling, contact))
    check("mismatch_fails", rc != 0, "exit status 0")
    lines = [l for l in log.splitlines() if l.startswith("ERROR")]
    check("mismatch_message", any(l.startswith(want) and re.search(r"\([\w./]+:\d+\)$", l) for l in lines),
          "expected %r in %r" % (want, lines))
    check("mismatch_clean_text", all(c.isprintable() or c in "\n\t" for c in log),
          "non-printable bytes in the log: %r" % [c for c in log if not (c.isprintable() or c in "\n\t")][:8])


def mesh_restart_at_200(tmp, name, case, deck):
    """Run `deck` (case `case`) for 200 steps on 1 rank in the run directory `name`, writing its
    restart file restarts/r.200; (directory, particle data file), or None after a failed check
    NAME_runs."""
    w = run_dir(tmp, name)
    data = os.path.join(w, "particles.data")
    particles(case, data)
    rc, log = run(w, 1, deck, variables(w, data, 200, 200, 100, case=case))
    return (w, data) if check(f"{name}_runs", rc == 0, log[-1500:]) else None


def mesh_shape_mismatch(tmp):
    """The meshed box's file continued by a deck whose fix of the mesh wall's ID is a plane
    wall: an error that names both kinds (never a plane continuing from a mesh's history)."""
    box = os.path.join(DECKS, "mesh_box.in")
    written = mesh_restart_at_200(tmp, "mesh_mismatch_writer", "mesh_box", box)
    if not written:
        return
    w, data = written
    with open(box) as f:
        text = f.read().replace("fix walls all wall/jiang mesh n_meshes 1 meshes box",
                                "fix walls all wall/jiang plane corners -0.1 -0.1 0.0 0.1 -0.1 0.0 "
                                "0.1 0.1 0.0 -0.1 0.1 0.0 type 2")
    deck = os.path.join(tmp, "mesh_box_plane.in")
    with open(deck, "w") as f:
        f.write(text)
    r = run_dir(tmp, "mesh_mismatch_reader")
    rc, log = run(r, 1, deck, variables(r, data, 100, 100, 100, os.path.join(w, "restarts", "r.200"), "mesh_box"))
    want = "ERROR: fix walls (wall/jiang): the restart file's wall of this ID is a mesh, not a plane ("
    check("mesh_mismatch_fails", rc != 0, "exit status 0")
    lines = [l for l in log.splitlines() if l.startswith("ERROR")]
    check("mesh_mismatch_message", any(l.startswith(want) and re.search(r"\([\w./]+:\d+\)$", l) for l in lines),
          "expected %r in %r" % (want, lines))


UNCLAIMED_MOTION = ("read_restart: the restart file holds the motion of fix turn (move/mesh), which "
                    "this script does not define before its first run: that mesh stays where the file put it")


def drum_without_motion(tmp):
    """The drum's file continued by the drum's deck without its fix move/mesh: the warning
    that names the motion left behind, once (the full deck, in the half-way cases, has none)."""
    drum = os.path.join(DECKS, "mesh_drum.in")
    written = mesh_restart_at_200(tmp, "drum_motion_writer", "mesh_drum", drum)
    if not written:
        return
    w, data = written
    resume = os.path.join(w, "restarts", "r.200")
    r = run_dir(tmp, "drum_motion_kept")
    rc, log = run(r, 1, drum, variables(r, data, 100, 200, 100, resume, "mesh_drum"))
    check("drum_motion_kept_no_warning", rc == 0 and "(move/mesh), which" not in log, log[-1500:])
    with open(drum) as f:
        text = re.sub(r"(?m)^fix turn .*\n", "", f.read())
    deck = os.path.join(tmp, "mesh_drum_still.in")
    with open(deck, "w") as f:
        f.write(text)
    r = run_dir(tmp, "drum_motion_left")
    rc, log = run(r, 1, deck, variables(r, data, 100, 200, 100, resume, "mesh_drum"))
    check("drum_motion_left_warning", rc == 0 and log.count("WARNING: " + UNCLAIMED_MOTION) == 1,
          "expected once %r in %r" % (UNCLAIMED_MOTION, log[-2500:]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="keep the runs under DIR")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    args = ap.parse_args()
    if not os.access(LIGGGHTS, os.X_OK):
        print("FAIL build: %s missing (make build/liggghts-jdem)" % LIGGGHTS)
        return 1
    tmp = os.path.abspath(args.out) if args.out else tempfile.mkdtemp(prefix="jdem_restart_")
    os.makedirs(tmp, exist_ok=True)
    try:
        for case in CASES:
            for np_ in (1, 2):
                half_way(tmp, case, np_)
        for np_ in (1, 2):
            killed(tmp, np_)
        stock = stock_bed(tmp)
        bed = os.path.join(DECKS, "bed.in")
        across(tmp, "stock_to_jiang", stock, bed, DROPPED % (STOCK, OURS))
        across(tmp, "jiang_to_stock", bed, stock, DROPPED % (OURS, STOCK))
        option_mismatch(tmp)
        mesh_shape_mismatch(tmp)
        drum_without_motion(tmp)
    finally:
        if not args.out and not args.keep:
            shutil.rmtree(tmp, ignore_errors=True)
    print("%d failed" % failed)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
