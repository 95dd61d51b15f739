"""fill_ch5.py — what scripts/mixing/report_ch5.py measures in one finished Chapter 5 fill, from
either engine's trajectory (docs/mixing.md §11):

* phi_v at the 27 points of Table 5-2 in the last frame, and its middle clip (points 10-18);
* the breakage (breakage.py): the bonds formed and broken per mode, the fragments at the end and
  by size at the seed's snapshot times, and the map of where the bonds broke;
* the free surface and the packing near the walls (structure.py);
* the energy balance with the bonds' energies and the inflow booked (energy.py);
* the bond-steps (intact bonds x steps, from observables/bonds), for the bonds' speed;
* the snapshot sheet: front and side views at t = 1, 3, 9 s and the end, the big spheres, the
  small ones in whole blocks, in fragments and alone in different colours; and the final
  middle clip (Ch. 6's Figs 6-1 and 6-2 show it); for Model 1 of Groups 1 and 3, the layer
  against the front wall beside the middle clip (the seed's Fig. 5-23, voids near the walls).
"""
import os

import h5py
import numpy as np

from scripts.mixing import breakage, deposit, energy, params, plots, stats, structure
from scripts.mixing_views import frame_index, scene_geometry

SNAPSHOTS = (1.0, 3.0, 9.0)   # [s] the seed's snapshot times (Figs 5-5 to 5-22), then the end
# the seed's Fig. 5-23 (voids near the walls) shows Group 3 Model 1; its Group 1 beside it
WALL_PICTURE_CASES = ("group1_model1", "group3_model1")
WALL_LAYER = 0.015   # [m] a small radius off the front wall: the plane that cuts the layer against it
BLOCK = 32                    # spheres in a whole 2 x 2 x 8 block (spec §4.1)
# fragment sizes (spheres) counted over time: single spheres, pieces, half blocks, whole blocks
FRAGMENT_BINS = ((1, 1), (2, 7), (8, 15), (16, 31), (BLOCK, BLOCK))
# the sheet's colours: the seed's red big and blue small spheres; the pieces of broken blocks apart
CATEGORIES = (("big sphere", plots.BIG_COLOUR), ("whole block", plots.SMALL_COLOUR),
              ("fragment of 2-31", "#2ca02c"), ("single small sphere", "#ff9f1c"))


def fragment_histogram(sizes):
    """The number of fragments in each FRAGMENT_BINS range of sizes."""
    return [int(np.count_nonzero((sizes >= a) & (sizes <= b))) for a, b in FRAGMENT_BINS]


def bond_steps(path):
    """Intact bonds x steps over the run, from observables/bonds (held between samples)."""
    with h5py.File(path, "r") as f:
        if "observables/bonds/value" not in f:
            return 0.0
        value, step = f["observables/bonds/value"][()], f["observables/bonds/step"][()]
    return float(np.sum(value[:-1] * np.diff(step)))


def breakage_result(rec, end):
    sizes = breakage.fragment_sizes(rec, end)
    whole = dict(breakage.broken_fraction(rec, end), fragments=int(len(sizes)),
                 whole_blocks=int(np.count_nonzero(sizes == BLOCK)),
                 singles=int(np.count_nonzero(sizes == 1)))
    steps = [round(t / rec["dt"]) for t in SNAPSHOTS] + [end]
    over_time = [dict(b, fragments=fragment_histogram(breakage.fragment_sizes(rec, b["step"])))
                 for b in breakage.over_time(rec, steps)]
    return whole, over_time


def bonded_scene(path):
    """Whether the trajectory's scene asks for bonds (its own or its inlet section's): a bonded
    fill that formed none is then reported so (0 formed), not taken for an unbonded one."""
    with h5py.File(path, "r") as f:
        scene = deposit.scene_of(f)
    return bool(scene.get("bonds")) or any((i.get("section") or {}).get("bonds") for i in scene.get("inlets") or [])


def result(path):
    """The fill's measures (summary.json's entry); "_breaks" and "_rec" are for the pictures."""
    dep = deposit.read_frame(path)
    box, _, _ = scene_geometry(path)
    phi = [float(p["phi_v"]) for p in params.at_points(dep, params.POINTS_TABLE_5_2)]
    out = {"particles": int(len(dep.radius)), "time": dep.time, "phi_v": phi,
           "middle_clip": stats.summary(phi[params.MIDDLE_CLIP]),
           "surface": structure.free_surface(dep, *box), "packing": structure.packing(dep, *box),
           "energy": energy.balance(path), "bond_steps": bond_steps(path),
           "built_by": deposit.built_by(path)}
    try:
        rec = breakage.read_bonds(path)
    except breakage.BreakageError:
        return out   # a trajectory without a bond table
    if not len(rec["bonds"]) and not bonded_scene(path):
        return out   # Group 1: an empty bond table (both engines write one), drawn as unbonded
    end = int(max(rec["formed"].max(initial=0), rec["broken_step"].max(initial=0), dep.step))
    out["breakage"], out["breakage_over_time"] = breakage_result(rec, end)
    out["_breaks"], out["_rec"] = (rec["broken_at"], rec["mode"]), rec
    return out


def colours(dep, rec):
    """CATEGORIES' colour of each particle of the frame `dep` (rec: None for an unbonded fill)."""
    big = params.big_mask(dep.radius)
    size = breakage.fragment_of(rec, dep.step, dep.id) if rec else np.zeros(len(dep.id), np.int64)
    c = np.where(size >= BLOCK, CATEGORIES[1][1],
                 np.where(size >= 2, CATEGORIES[2][1], CATEGORIES[3][1] if rec else CATEGORIES[1][1]))
    return np.where(big, CATEGORIES[0][1], c)


def write_pictures(entry, name, path, directory):
    """The break map (bonded fills), the snapshot sheet and the final middle clip (the spheres cut
    by y = 0.5 m) as DIR/ENGINE_CASE_{breaks,views,clip}.png; sets entry["break_map"],
    entry["views"] and entry["clip"] to their names."""
    rec = entry.pop("_rec", None)
    position, mode = entry.pop("_breaks", (np.zeros((0, 3)), np.zeros(0)))
    box, cylinders, _ = scene_geometry(path)
    stem = os.path.join(directory, name.replace("/", "_"))
    if len(mode):
        plots.break_map(position, mode, stem + "_breaks.png", box, cylinders,
                        title=f"{name}: bond breaks")
        entry["break_map"] = os.path.basename(stem + "_breaks.png")
    frames = sorted({frame_index(path, t) % frame_count(path) for t in SNAPSHOTS + ("final",)})
    deps = [deposit.read_frame(path, k) for k in frames]
    legend = CATEGORIES if rec else (CATEGORIES[0], ("small sphere", plots.SMALL_COLOUR))
    plots.snapshot_sheet([(d, colours(d, rec)) for d in deps], stem + "_views.png", box, cylinders,
                         legend, title=name)
    entry["views"] = os.path.basename(stem + "_views.png")
    plots.deposit_view(deps[-1], stem + "_clip.png", "front", box, cylinders, clip=0.0,
                       colours=colours(deps[-1], rec),
                       title=f"{name}: middle clip y = 0.5 m, t = {deps[-1].time:g} s")
    entry["clip"] = os.path.basename(stem + "_clip.png")
    if name.endswith(WALL_PICTURE_CASES):
        plots.slab_sheet(deps[-1], stem + "_wall.png",
                         [("the layer against the front wall (cut by y = %.3f m)" % (box[0][1] + WALL_LAYER),
                           box[0][1] + WALL_LAYER, 0.0),
                          ("the middle clip, y = 0.5 m", None, 0.0)], box, cylinders,
                         colours(deps[-1], rec), title=f"{name}: the voids near the walls, t = {deps[-1].time:g} s")
        entry["wall"] = os.path.basename(stem + "_wall.png")


def frame_count(path):
    with h5py.File(path, "r") as f:
        return int(f["particles/all/position/value"].shape[0])
