#!/usr/bin/python3
"""particles_from (docs/scenes.md): a run that starts from a frame of another run's trajectory.

A source run (scenes/deposit_source.yaml, two particle materials) is written first; the scenes
of this test are made from its last frame.  Checks:
  - round trip: the resolved scene holds exactly the source frame's particles whose centre lies
    in the region (selected here with numpy), at the source position plus the translation, with
    the source velocities, ids, radii and material names, bit for bit; the new run's first frame
    holds that state bit for bit; materials are matched by name in a scene that lists them in
    another order;
  - empty slots: a trajectory whose id is a time series with -1 for empty slots (a changing
    particle set) gives only the occupied slots of the frame;
  - ids: renumber gives the kept particles consecutive ids after the scene's own particles;
  - bonds: from a bonded block that broke on a plate (tests/liggghts/bond_scenes/block_drop.yaml),
    the resolved scene's bonds are exactly those intact at the frame between two kept particles,
    as scripts/mixing/breakage.py computes them from the bond and break tables (formed by the
    frame's step, not broken by then), with their type by name; bonds: none keeps none; a bond
    type the scene lacks, and a bonded deposit fed to an inlet section (which does not carry
    bonds), are refused with their exact messages;
  - the other engine: the LIGGGHTS deck made from the resolved scene (scene_to_liggghts.py) runs
    the same particles, and its trajectory matches build/jdem's (compare_trajectories.py); a
    scene started from liggghts-jdem's trajectory gets its last frame bit for bit;
  - a relative file: resolved against the scene file's folder, not the working directory, so a
    scene and its deposit moved together keep their particles (the same as with the absolute
    path), and a missing one is named by the path tried;
  - bad input: the exact message of each (a missing file, a frame that does not exist, a file
    that is not HDF5, an HDF5 file that is not H5MD, an H5MD file without particles, an empty region, a region outside the
    deposit with the wording of scripts/mixing/deposit.py, a region that keeps nothing, a
    material the scene lacks), each with exit status 2.
"""
import os
import shutil
import tempfile

import h5py
import numpy as np
import yaml

from tests.engine.engine_common import JDEM, Checks, scene

from scripts import engines
from scripts.mixing import deposit  # the generators' reader and cutter: the reference wording

LIG = engines.LIGGGHTS_JDEM
MATERIALS = """materials:
  steel: {youngs_modulus: 2.0e8, poisson_ratio: 0.3, density: 7800, restitution: 0.7, friction: 0.4}
  wall: {restitution: 0.6, friction: 0.5}
  glass: {youngs_modulus: 1.0e8, poisson_ratio: 0.25, density: 2500, restitution: 0.7, friction: 0.4}
interactions:
  - {materials: [glass, wall], restitution: 0.6, friction: 0.5}
  - {materials: [steel, wall], restitution: 0.6, friction: 0.5}
"""
FLOOR = """walls:
  - {name: floor, type: plane, corners: [[-0.05,-0.05,0],[0.15,-0.05,0],[0.15,0.05,0],[-0.05,0.05,0]], material: wall}
"""
LO, HI, SHIFT = [-0.01, -0.01, 0.0], [0.01, 0.0, 0.018], [0.1, 0.0, 0.0]


def write_scene(work, name, entry, extra="", materials=MATERIALS):
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write("jdem_scene: 1\nname: %s\ntime: {dt: 2.0e-6, steps: 1000}\noutput: {every: 500}\n"
                "gravity: [0, 0, -9.81]\n%s%s%sparticles_from:\n  - %s\n" %
                (name, materials, FLOOR, extra, entry))
    return path


def resolve(path):
    p = engines.resolve(path, binary=JDEM)
    return p.returncode, p.stdout, p.stderr.strip()


def resolved_particles(text):
    return yaml.load(text, Loader=yaml.CSafeLoader)["particles"]


def source_frame(src):
    """The last frame of the source: ids, material names, radii, positions, velocities."""
    with h5py.File(src, "r") as f:
        names = list(yaml.load(f["parameters/scene"][()].decode(), Loader=yaml.CSafeLoader)["materials"])
        p = f["particles/all"]
        return (p["id"][()], [names[s] for s in p["species"][()]], p["radius"][()],
                p["position/value"][-1], p["velocity/value"][-1], p["angular_velocity/value"][-1])


def check_round_trip(c, work, src):
    entry = "{file: %s, region: {lo: %s, hi: %s}, translate: %s, velocities: keep}" % (src, LO, HI, SHIFT)
    path = write_scene(work, "round_trip", entry)
    rc, out, err = resolve(path)
    if not c.check("deposit_resolve", rc == 0, err):
        return None
    got = resolved_particles(out)
    ids, mats, radius, pos, vel, omega = source_frame(src)
    keep = np.all((pos >= LO) & (pos < HI), axis=1)
    c.check("deposit_region_keeps_some_not_all", 0 < keep.sum() < len(ids), "kept %d of %d" % (keep.sum(), len(ids)))
    c.check("deposit_particle_set", [p["id"] for p in got] == ids[keep].tolist(),
            "ids %s, want %s" % ([p["id"] for p in got], ids[keep].tolist()))
    want_pos = pos[keep] + np.array(SHIFT)
    same = (len(got) == keep.sum() and
            np.array_equal(np.array([p["position"] for p in got]), want_pos) and
            np.array_equal(np.array([p["velocity"] for p in got]), vel[keep]) and
            np.array_equal(np.array([p["angular_velocity"] for p in got]), omega[keep]) and
            np.array_equal(np.array([p["radius"] for p in got]), radius[keep]))
    c.check("deposit_state_bitwise", same, "positions, velocities or radii differ from the source frame")
    c.check("deposit_materials_by_name", [p["material"] for p in got] == [m for m, k in zip(mats, keep) if k],
            "materials differ")
    out_h5 = os.path.join(work, "round_trip.jdem.h5")
    p = engines.jdem("run", path, "-o", out_h5, "--quiet", binary=JDEM)
    if c.check("deposit_run", p.returncode == 0, p.stderr.strip()):
        with h5py.File(out_h5, "r") as f:
            a = f["particles/all"]
            first = (np.array_equal(a["id"][()], ids[keep]) and
                     np.array_equal(a["position/value"][0], want_pos) and
                     np.array_equal(a["velocity/value"][0], vel[keep]))
        c.check("deposit_first_frame_bitwise", first, "the run's frame 0 differs from the resolved state")
    return path, out_h5


def check_dilation(c, work, src):
    """dilate: s scales the kept positions about the region's centre, then translate adds:
    c + s (x - c) + shift, in that order of double operations (numpy's are the same)."""
    s, shift = 1.25, [0.1, 0.0, 0.01]   # lifted: the spread bed's bottom layer would cut the floor
    entry = "{file: %s, region: {lo: %s, hi: %s}, dilate: %r, translate: %s}" % (src, LO, HI, s, shift)
    rc, out, err = resolve(write_scene(work, "dilated", entry))
    if not c.check("deposit_dilated_resolve", rc == 0, err):
        return
    got = np.array([p["position"] for p in resolved_particles(out)])
    _, _, _, pos, _, _ = source_frame(src)
    kept = pos[np.all((pos >= LO) & (pos < HI), axis=1)]
    centre = 0.5 * (np.array(LO) + np.array(HI))
    want = (centre + s * (kept - centre)) + np.array(shift)
    c.check("deposit_dilated_positions_bitwise", got.shape == want.shape and np.array_equal(got, want),
            "positions differ from c + s (x - c) + shift")


def check_renumber(c, work, src):
    extra = "particles:\n  - {id: 7, material: glass, radius: 0.002, position: [0.13, 0.03, 0.01]}\n"
    entry = "{file: %s, region: {lo: %s, hi: %s}, translate: %s, ids: renumber}" % (src, LO, HI, SHIFT)
    rc, out, err = resolve(write_scene(work, "renumber", entry, extra))
    if c.check("deposit_renumber_resolve", rc == 0, err):
        got = [p["id"] for p in resolved_particles(out)]
        c.check("deposit_renumber_ids", got == list(range(7, 7 + len(got))), "ids %s" % got)
        c.check("deposit_velocities_zero", all(p["velocity"] == [0.0, 0.0, 0.0] for p in resolved_particles(out)),
                "velocities: zero (the default) left a velocity")


def check_empty_slots(c, work, src):
    """A changing particle set: /particles/all/id as a time series [F][N] with -1 in empty
    slots; the empty slots of the chosen frame are skipped, the others kept."""
    grown = os.path.join(work, "grown.h5")
    with h5py.File(src, "r") as f, h5py.File(grown, "w") as g:
        for k in f:
            f.copy(k, g)
        ids = g["particles/all/id"][()]
        del g["particles/all/id"]
        series = np.tile(ids, (g["particles/all/position/value"].shape[0], 1))
        series[-1, ::3] = -1
        g["particles/all/id/value"] = series
        g["particles/all/id/step"] = g["particles/all/position/step"][()]
    rc, out, err = resolve(write_scene(work, "empty_slots", "{file: %s, translate: %s}" % (grown, SHIFT)))
    if c.check("deposit_empty_slots_resolve", rc == 0, err):
        got = [p["id"] for p in resolved_particles(out)]
        want = [int(i) for i in series[-1] if i != -1]
        c.check("deposit_empty_slots_skipped", got == want, "ids %s, want %s" % (got, want))


def check_liggghts(c, work, path, jdem_h5):
    if not os.access(LIG, os.X_OK):
        c.check("deposit_liggghts", False, "build/liggghts-jdem is missing (run make)")
        return
    lig_h5 = os.path.join(work, "round_trip.lig.h5")
    p = engines.liggghts_run(path, lig_h5)
    if not c.check("deposit_liggghts_run", p.returncode == 0, (p.stdout + p.stderr).strip()[-800:]):
        return
    with h5py.File(lig_h5, "r") as f, h5py.File(jdem_h5, "r") as g:
        same0 = (np.array_equal(f["particles/all/id"][()], g["particles/all/id"][()]) and
                 np.array_equal(f["particles/all/position/value"][0], g["particles/all/position/value"][0]))
    c.check("deposit_liggghts_same_particles", same0, "frame 0 of liggghts-jdem differs from build/jdem's")
    p = engines.run(engines.script("compare_trajectories", jdem_h5, lig_h5))
    lines = [l for l in (p.stdout + p.stderr).strip().splitlines() if l.strip()]
    c.check("deposit_liggghts_trajectory", p.returncode == 0, lines[-1] if lines else "")
    rc, out, err = resolve(write_scene(work, "from_liggghts", "{file: %s, velocities: keep}" % lig_h5))
    if c.check("deposit_from_liggghts_resolve", rc == 0, err):
        got = resolved_particles(out)
        ids, _, _, pos, vel, _ = source_frame(lig_h5)
        c.check("deposit_from_liggghts_bitwise", [p["id"] for p in got] == ids.tolist() and
                np.array_equal(np.array([p["position"] for p in got]), pos) and
                np.array_equal(np.array([p["velocity"] for p in got]), vel),
                "the particles differ from liggghts-jdem's last frame")


BONDED_SCENE = """jdem_scene: 1
name: %s
time: {dt: 1.0e-7, steps: 10}
gravity: [0, 0, -9.81]
materials:
  clay: {youngs_modulus: 1.0e9, poisson_ratio: 0.25, density: 2500, restitution: 0.5, friction: 0.5}
  plate: {restitution: 0.5, friction: 0.5}
%swalls:
  - {name: floor, type: plane, corners: [[-0.05,-0.05,0],[0.05,-0.05,0],[0.05,0.05,0],[-0.05,0.05,0]], material: plate}
particles_from:
  - %s
"""
CEMENT = ("bond_types:\n  %s: {normal_stiffness: 1.0e12, shear_stiffness: 5.0e11, tensile_strength: 1.5e6, "
          "shear_strength: 1.0e6, radius_multiplier: 1.0}\n")


def bonded_scene(work, name, entry, bond_type="cement"):
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write(BONDED_SCENE % (name, CEMENT % bond_type, entry))
    return path


INLET = """inlets:
  - {name: belt, section: {from_deposit: [%s]}, origin: [0.0, 0.0, 0.02], velocity: [1, 0, 0],
     plane: {point: [0.01, 0, 0], normal: [1, 0, 0]}, period: 0.1, stop: {sections: 1}}
"""


def check_inlet_refuses_bonds(c, work, src, intact):
    text = BONDED_SCENE.replace("particles_from:\n  - %s\n", "")
    for name, entry in (("inlet_bonded", "{file: %s}" % src), ("inlet_unbonded", "{file: %s, bonds: none}" % src)):
        path = os.path.join(work, name + ".yaml")
        with open(path, "w") as f:
            f.write(text % (name, CEMENT % "cement") + INLET % entry)
        rc, _, err = resolve(path)
        if name == "inlet_unbonded":
            c.check("deposit_bonds_inlet_none", rc == 0, err)
            continue
        want = ("key 'inlets.0.section.from_deposit.0': %s: %d bonds intact between the kept particles, "
                "which an inlet section does not carry over; valid: bonds: none (the section unbonded), "
                "or the section's blocks and bonds" % (src, intact))
        got = err.split(": ", 2)[-1]
        c.check("deposit_bonds_inlet_refused", rc == 2 and got == want, "rc %d, got %r, want %r" % (rc, got, want))


def check_bonds(c, work):
    """The bonds intact at the frame between kept particles come along (bonds: keep, the
    default), against breakage.py's reading of the source's tables."""
    from scripts.mixing import breakage
    src = os.path.join(work, "block_drop.h5")
    drop = os.path.join(engines.ROOT, "tests", "liggghts", "bond_scenes", "block_drop.yaml")
    p = engines.jdem("run", drop, "-o", src, "--quiet", binary=JDEM)
    if not c.check("deposit_bonds_source_run", p.returncode == 0, p.stderr.strip()):
        return
    rec = breakage.read_bonds(src)
    with h5py.File(src, "r") as f:
        step = int(f["particles/all/position/step"][-1])
        pos, ids = f["particles/all/position/value"][-1], f["particles/all/id"][()]
    lo, hi = pos.min(axis=0) - 1e-6, pos.max(axis=0) + 1e-6
    hi[0] = np.median(pos[:, 0])                       # about half of the block
    kept = set(ids[np.all((pos >= lo) & (pos < hi), axis=1)].tolist())
    intact = breakage.intact_at(rec, step)
    want = sorted(tuple(sorted(b)) for b in intact.tolist() if b[0] in kept and b[1] in kept)
    broken_kept = sum(1 for a, b in rec["broken"][rec["broken_step"] <= step].tolist() if a in kept and b in kept)
    c.check("deposit_bonds_source_broke", broken_kept > 0 and len(want) > 0,
            "%d intact and %d broken bonds among the kept particles: the check needs both" % (len(want), broken_kept))
    entry = "{file: %s, region: {lo: %s, hi: %s}}" % (src, lo.tolist(), hi.tolist())
    rc, out, err = resolve(bonded_scene(work, "bonds_keep", entry))
    if c.check("deposit_bonds_resolve", rc == 0, err):
        doc = yaml.load(out, Loader=yaml.CSafeLoader)
        got = sorted(tuple(sorted(b["ids"])) for b in doc.get("bonds", []))
        c.check("deposit_bonds_intact_kept", got == want,
                "%d bonds, want %d (first differences %s)" % (len(got), len(want), sorted(set(got) ^ set(want))[:4]))
        c.check("deposit_bonds_type_by_name", all(b["type"] == "cement" for b in doc.get("bonds", [])),
                "a bond type other than cement")
    rc, out, err = resolve(bonded_scene(work, "bonds_none", entry[:-1] + ", bonds: none}"))
    if c.check("deposit_bonds_none_resolve", rc == 0, err):
        c.check("deposit_bonds_none", not yaml.load(out, Loader=yaml.CSafeLoader).get("bonds"),
                "bonds: none kept bonds")
    rc, _, err = resolve(bonded_scene(work, "bonds_bad_type", entry, bond_type="glue"))
    want_msg = ("key 'particles_from.0.file': %s: the deposit's bond type 'cement' is not a bond type "
                "of this scene; valid: a bond type of that name under bond_types, or bonds: none" % src)
    got = err.split(": ", 2)[-1]
    c.check("deposit_bonds_bad_type", rc == 2 and got == want_msg, "rc %d, got %r, want %r" % (rc, got, want_msg))
    check_inlet_refuses_bonds(c, work, src, len(intact))


def bad_cases(work, src):
    """(name, entry, extra scene text, materials, expected message after 'FILE:LINE: ')."""
    dep = deposit.read_frame(src)
    text = os.path.join(work, "not_hdf5.h5")
    with open(text, "w") as f:
        f.write("not an HDF5 file\n")
    plain = os.path.join(work, "plain.h5")
    with h5py.File(plain, "w") as f:
        f["x"] = np.zeros(3)
    no_particles = os.path.join(work, "no_particles.h5")
    with h5py.File(no_particles, "w") as f:
        f.create_group("h5md")
    outside_hi = [0.01, 0.0, 0.3]
    try:
        deposit.keep_box(dep, LO, outside_hi)
        outside = "keep_box accepted the region"
    except deposit.DepositError as e:
        outside = str(e)
    ext_lo = dep.position.min(axis=0) - dep.radius.max()
    corner_hi = (ext_lo + dep.radius.max() / 2).tolist()
    valid = "valid: an H5MD trajectory written by jdem or liggghts-jdem"
    k = "key 'particles_from.0.%s': "
    missing = os.path.join(work, "missing.h5")
    return [
        ("missing_file", "{file: %s}" % missing, k % "file" + "%s: no such file; %s" % (missing, valid)),
        ("no_such_frame", "{file: %s, frame: 4}" % src,
         k % "frame" + "%s: frame 4 does not exist; valid: -4 to 3 (4 frames)" % src),
        ("not_hdf5", "{file: %s}" % text, k % "file" + "%s: not an HDF5 file; %s" % (text, valid)),
        ("not_h5md", "{file: %s}" % plain, k % "file" + "%s: no /h5md group (not an H5MD file); %s" % (plain, valid)),
        ("no_particles", "{file: %s}" % no_particles,
         k % "file" + "%s: no /particles/all/position; %s" % (no_particles, valid)),
        ("empty_region", "{file: %s, region: {lo: [0, 0, 0], hi: [0.01, 0, 0.01]}}" % src,
         k % "region" + "region [0.0, 0.0, 0.0]..[0.01, 0.0, 0.01]: empty; valid: lo < hi"),
        ("region_outside", "{file: %s, region: {lo: %s, hi: %s}}" % (src, LO, outside_hi), k % "region" + outside),
        ("region_keeps_nothing", "{file: %s, region: {lo: %s, hi: %s}}" % (src, ext_lo.tolist(), corner_hi),
         k % "region" + "region %s..%s keeps no particle of the deposit; valid: a region holding at "
         "least one particle centre" % (ext_lo.tolist(), corner_hi)),
        ("dilate_without_region", "{file: %s, dilate: 1.2}" % src,
         k % "dilate" + "a dilation needs a region (it scales the kept positions about the "
         "region's centre); valid: add region: {lo: [x, y, z], hi: [x, y, z]}"),
        ("dilate_too_large", "{file: %s, region: {lo: %s, hi: %s}, dilate: 2.5}" % (src, LO, HI),
         k % "dilate" + "2.5 is out of range; valid: a number in [1, 2]"),
        ("bad_velocities", "{file: %s, velocities: fast}" % src,
         k % "velocities" + "unknown value 'fast'; valid: zero, keep"),
    ]


def check_bad(c, work, src):
    for name, entry, want in bad_cases(work, src):
        path = write_scene(work, "bad_" + name, entry)
        rc, _, err = resolve(path)
        got = err.split(": ", 2)[-1] if err.startswith("jdem: ") else err
        c.check("deposit_bad_" + name, rc == 2 and got == want, "rc %d, got %r, want %r" % (rc, got, want))
    no_steel = MATERIALS.replace("  steel: {youngs_modulus: 2.0e8, poisson_ratio: 0.3, density: 7800, "
                                 "restitution: 0.7, friction: 0.4}\n", "").replace(
        "  - {materials: [steel, wall], restitution: 0.6, friction: 0.5}\n", "")
    rc, _, err = resolve(write_scene(work, "bad_material", "{file: %s}" % src, materials=no_steel))
    want = ("key 'particles_from.0.file': %s: the deposit's material 'steel' is not a particle material "
            "of this scene; valid: a material of that name with youngs_modulus, poisson_ratio and "
            "density in materials" % src)
    got = err.split(": ", 2)[-1]
    c.check("deposit_bad_material", rc == 2 and got == want, "rc %d, got %r, want %r" % (rc, got, want))


def check_relative_file(c, work, src):
    """file: ../deposit.h5 from work/moved/scenes/, resolved from the filesystem's root as the
    working directory, before and after the folder is renamed: the same particles as the
    absolute path gives."""
    rc, want, err = resolve(write_scene(work, "absolute", "{file: %s}" % src))
    before = os.path.join(work, "moved")
    os.makedirs(os.path.join(before, "scenes"))
    shutil.copyfile(src, os.path.join(before, "deposit.h5"))
    write_scene(os.path.join(before, "scenes"), "relative", "{file: ../deposit.h5}")
    write_scene(os.path.join(before, "scenes"), "relative_missing", "{file: ../missing.h5}")
    after = os.path.join(work, "moved_again")
    os.rename(before, after)
    got = engines.resolve(os.path.join(after, "scenes", "relative.yaml"), binary=JDEM, cwd="/")
    c.check("deposit_relative_to_scene", rc == 0 and got.returncode == 0 and
            resolved_particles(got.stdout) == resolved_particles(want),
            "rc %d/%d: %s %s" % (rc, got.returncode, err, got.stderr.strip()))
    missing = os.path.join(after, "scenes", "../missing.h5")
    p = engines.resolve(os.path.join(after, "scenes", "relative_missing.yaml"), binary=JDEM, cwd="/")
    got_msg = p.stderr.strip().split(": ", 2)[-1]
    want_msg = ("key 'particles_from.0.file': %s: no such file; valid: an H5MD trajectory written "
                "by jdem or liggghts-jdem" % missing)
    c.check("deposit_relative_missing", p.returncode == 2 and got_msg == want_msg,
            "rc %d, got %r, want %r" % (p.returncode, got_msg, want_msg))


def main():
    c = Checks()
    work = tempfile.mkdtemp(prefix="jdem_deposit_")
    src = os.path.join(work, "source.h5")
    p = engines.jdem("run", scene("deposit_source"), "-o", src, "--quiet", binary=JDEM)
    if not c.check("deposit_source_run", p.returncode == 0, p.stderr.strip()):
        c.exit()
    done = check_round_trip(c, work, src)
    check_renumber(c, work, src)
    check_dilation(c, work, src)
    check_empty_slots(c, work, src)
    check_relative_file(c, work, src)
    check_bad(c, work, src)
    check_bonds(c, work)
    if done:
        check_liggghts(c, work, *done)
    c.exit()


if __name__ == "__main__":
    main()
