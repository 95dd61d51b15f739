"""bench_runs.py — the bench's timed runs (scripts/bench.py, step 3): jdem by its loop timer and
run(S) - run(1) CPU time, LIGGGHTS by its Loop time, all under GNU time (scripts/engines.py), and
the scene-specialisation check (feature_check)."""
import json
import os
import re
import statistics

import numpy as np

from scripts import engines
from scripts.bench_beds import h5_last_frame, make_bed
from scripts.bench_config import RUN_TIMEOUT_S, log

ENGINE_BINARY = {"jdem": engines.JDEM, "liggghts-jdem": engines.LIGGGHTS_JDEM, "liggghts": engines.LIGGGHTS}
from scripts.bench_scenes import scene_path


def calibrate_liggghts(deck, engine, timeout=RUN_TIMEOUT_S):
    """CPU seconds of a 1-step run of the same deck (reading the data file, set-up, one step):
    subtracted from the S-step run's CPU time it leaves the CPU time of the loop, a measure that
    other jobs on the machine disturb less than wall time."""
    d = os.path.dirname(deck)
    one = os.path.join(d, "in.bench1")
    with open(deck) as f:
        text = f.read()
    with open(one, "w") as f:
        f.write(re.sub(r"(?m)^run\s+\d+\s*$", "run             1", text))
    w, c, rss, so, se, rc = engines.gnu_timed(engines.liggghts_command("in.bench1", binary=ENGINE_BINARY[engine],
                                                                      log="log.calib"), d, timeout)
    remove_files(os.path.join(d, "out.h5"))
    if rc:
        raise RuntimeError("%s 1-step calibration failed:\n%s" % (engine, se[-2000:]))
    return dict(wall_s=w, cpu_s=c, peak_rss=rss)


LOOP_PARTS = ("neighbour", "pairs", "walls", "integration", "output")  # jdem --timing's parts of the loop


def jdem_loop_seconds(split):
    """jdem's wall time of the time loop: its loop timer (loop=), or for runs recorded before
    jdem printed one, the sum of the loop's parts (which leaves out only the per-step checks)."""
    return split["loop"] if "loop" in split else sum(split[k] for k in LOOP_PARTS)


def remove_files(*paths):
    """Delete the large files of a finished timing (at 1M a trajectory of two frames is ~240 MB, a
    scene copy 125 MB: a full sweep would otherwise fill the disk)."""
    for p in paths:
        for q in (p, p[:-3] + ".xdmf" if p.endswith(".h5") else None):
            if q and os.path.exists(q):
                os.remove(q)


def run_jdem(out, size, variant, scene, steps, n, threads=1, extra=(), tag="", keep_trajectory=False,
             timeout=RUN_TIMEOUT_S):
    """Time `jdem run SCENE --threads T [extra]`: wall time by jdem's loop timer, CPU time as
    run(S) - run(1); returns the record.  The trajectories and the 1-step scene are deleted once
    read unless keep_trajectory."""
    d = os.path.join(out, "runs", "%s_%s" % (size, variant), "jdem%s_t%d" % (tag, threads))
    os.makedirs(d, exist_ok=True)
    one = os.path.join(d, "one.yaml")
    with open(scene) as f:
        text = f.read()
    text = re.sub(r"(?m)^  steps: \d+", "  steps: 1", text)
    text = re.sub(r"(?m)^  (every|observables_every): \d+", r"  \1: 1", text)
    with open(one, "w") as f:
        f.write(text)
    opts = ["--quiet", "--timing", "--threads", str(threads)] + list(extra)
    w1, c1, _, _, e1, rc1 = engines.gnu_timed([engines.JDEM, "run", one, "-o", os.path.join(d, "one.h5")] + opts, d,
                                              timeout)
    traj = os.path.join(d, "out.h5")
    w, c, rss, _, e, rc = engines.gnu_timed([engines.JDEM, "run", scene, "-o", traj] + opts, d, timeout)
    if rc or rc1:
        raise RuntimeError("jdem failed:\n" + e + e1)
    fr = h5_last_frame(traj)
    remove_files(one, os.path.join(d, "one.h5"))
    if not keep_trajectory:
        remove_files(traj)
    split = engines.jdem_timing(e)
    if not split:
        raise RuntimeError("jdem printed no --timing line:\n" + e)
    return dict(wall_s=jdem_loop_seconds(split), diff_wall_s=w - w1, cpu_s=c - c1, total_wall_s=w,
                setup_wall_s=w1, peak_rss=rss, contacts_per_particle=2.0 * fr["contacts"] / n,
                timing="jdem loop timer", bonds_start=fr["bonds_start"], bonds_end=fr["bonds"],
                jdem_split=split, trajectory=traj if keep_trajectory else None)


def run_liggghts(out, size, variant, deck, engine, ranks, steps, n, timeout=RUN_TIMEOUT_S):
    d = os.path.dirname(deck)
    cmd = engines.liggghts_command(os.path.basename(deck), ranks, binary=ENGINE_BINARY[engine], log="log.%d" % ranks,
                                   mpi_flags=("--bind-to", "none"))
    w, c, rss, so, se, rc = engines.gnu_timed(cmd, d, timeout)
    logtext = open(os.path.join(d, "log.%d" % ranks), errors="replace").read()
    m = engines.liggghts_loops(logtext)
    if rc or not m:
        raise RuntimeError("%s failed (exit %d):\n%s\n%s" % (engine, rc, logtext[-3000:], se[-2000:]))
    loop, procs, nsteps, natoms = m[-1]
    if int(natoms) != n:
        raise RuntimeError("%s lost atoms: %s of %d" % (engine, natoms, n))
    bonds = (None, None)
    if engine == "liggghts-jdem":
        fr = h5_last_frame(os.path.join(d, "out.h5"))
        cpp = 2.0 * fr["contacts"] / n
        bonds = (fr["bonds_start"], fr["bonds"])
        remove_files(os.path.join(d, "out.h5"))
    else:  # thermo: step atoms ke c_csum  (contact/atom counts each contact at both atoms)
        rows = re.findall(r"(?m)^\s*(\d+)\s+(\d+)\s+\S+\s+(\S+)\s*$", logtext)
        cpp = float(rows[-1][2]) / n if rows else float("nan")
    tail = logtext[logtext.rfind("Loop time of"):]
    split = {k.strip().lower(): float(v) for k, v in
             re.findall(r"(?m)^(Pair|Neigh|Comm|Outpt|Other|Modify)\s+time \(%\) = \S+ \(([0-9.eE+-]+)\)", tail)}
    return dict(wall_s=float(loop), cpu_s=c, total_wall_s=w, peak_rss=rss, contacts_per_particle=cpp,
                bonds_start=bonds[0], bonds_end=bonds[1],
                timing="LIGGGHTS loop time", liggghts_split_percent=split)


def same_final_state(a, b):
    """1 when two trajectories end in bit-identical positions, velocities and spins."""
    import h5py
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        return all(np.array_equal(fa["particles/all/%s/value" % k][-1], fb["particles/all/%s/value" % k][-1])
                   for k in ("position", "velocity", "angular_velocity"))


# The bonds of the feature check's general scene: every touching pair bonded at step 0 (as in the
# bonded variants) by springs of zero stiffness, which carry no load.
IDLE_BONDS = """bond_types:
  idle: {normal_stiffness: 0.0, shear_stiffness: 0.0, tensile_strength: 1.0e9, shear_strength: 1.0e9}
bond_rules:
  - {type: idle, time: 0.0, max_gap: 1e-09}

"""


def feature_check(out, size, steps, repeats, timeout=RUN_TIMEOUT_S):
    """The scene-specialisation check: the soft monodisperse bed without damping,
    rolling resistance and bonds (restitution 1, rolling friction 0), run by the loop
    specialised for it, against the same scene with those laws enabled at zero coefficients:
    the general contact loop (--all-laws: damping, rolling and mu_R evaluated with zero
    coefficients) and zero-stiffness bonds between all touching pairs.  Also against the general
    contact loop alone (no bonds), which shows what the contact loop's specialisation saves by
    itself.  Speed ratios (medians of `repeats` timings, 1 thread, runs alternated: wall by jdem's
    loop timer less its output, CPU as run(S) - run(1)) and whether the trajectories are
    identical bit for bit.  Writes OUT/feature_check.json (kept: delete it to re-measure)."""
    path = os.path.join(out, "feature_check.json")
    if os.path.exists(path):
        return
    src = scene_path(out, size, "soft_mono")
    with open(src) as f:
        text = f.read()
    plain = re.sub(r"restitution: 0\.5", "restitution: 1.0", text)
    if plain.count("restitution: 1.0") != 2 or plain.count("\nparticles:\n") != 1 or "bond_" in plain:
        raise RuntimeError("feature check: cannot switch off the damping in " + src)
    scenes = {"plain": scene_path(out, size, "soft_mono_plain"),
              "idle_bonds": scene_path(out, size, "soft_mono_plain_idle_bonds")}
    for key, body in (("plain", plain), ("idle_bonds", plain.replace("\nparticles:\n", "\n" + IDLE_BONDS + "particles:\n"))):
        with open(scenes[key], "w") as f:
            f.write(body)
    n = int(np.load(make_bed(out, size, "mono"))["id"].shape[0])
    loops = (("specialised", "plain", []), ("general_contact_laws", "plain", ["--all-laws"]),
             ("general", "idle_bonds", ["--all-laws"]))
    # alternately, so that a change in the machine's load falls on every loop alike
    timed = {tag: [] for tag, _, _ in loops}
    for _ in range(repeats):
        for tag, key, extra in loops:
            timed[tag].append(run_jdem(out, size, "soft_mono_plain", scenes[key], steps, n, extra=extra,
                                       tag="_" + tag, keep_trajectory=True, timeout=timeout))
    res = {}
    for tag, key, _ in loops:
        runs = timed[tag]
        walls = [r["wall_s"] - r["jdem_split"].get("output", 0.0) for r in runs]
        res[tag] = dict(scene=os.path.relpath(scenes[key], out), wall_s=walls, cpu_s=[r["cpu_s"] for r in runs],
                        wall_s_median=statistics.median(walls),
                        cpu_s_median=statistics.median(r["cpu_s"] for r in runs),
                        bonds=runs[-1]["bonds_start"], trajectory=runs[-1]["trajectory"])
        log("feature check %s: %.3f s" % (tag, res[tag]["wall_s_median"]))
    spec = res["specialised"]
    fc = dict(scene=os.path.relpath(scenes["plain"], out), size=size, N=n, steps=steps, repeats=repeats,
              description="soft_mono with restitution 1, rolling friction 0 and no bonds: the loop specialised "
                          "for friction only, against the same scene with damping, rolling and mu_R evaluated "
                          "at zero coefficients (--all-laws) and zero-stiffness bonds between all touching pairs "
                          "(general), and against --all-laws without the bonds (general_contact_laws)",
              specialised=spec, general=res["general"], general_contact_laws=res["general_contact_laws"])
    for tag in ("general", "general_contact_laws"):
        sfx = "" if tag == "general" else "_contact_laws"
        fc["speed_ratio_wall" + sfx] = res[tag]["wall_s_median"] / spec["wall_s_median"]
        fc["speed_ratio_cpu" + sfx] = res[tag]["cpu_s_median"] / spec["cpu_s_median"]
        fc["identical_trajectory" + sfx] = bool(same_final_state(spec["trajectory"], res[tag]["trajectory"]))
    with open(path, "w") as f:
        json.dump(fc, f, indent=1)
