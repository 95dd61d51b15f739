#!/usr/bin/python3
"""compare_trajectories.py — compare two jdem H5MD trajectories (e.g. build/jdem vs
build/liggghts-jdem) frame by frame.

    scripts/compare_trajectories.py A.h5 B.h5 [--tol TOL] [--rows 12]

The tolerance is the scene's `output.compare_tolerance` (stored in A's /parameters/scene; the
default there is 1e-10), unless --tol overrides it.

Particles are matched by id and frames by step (only steps present in both are compared; the
frames of each file are listed if they differ).  A growing particle set (an inlet's run: ids
per frame, -1 in the empty slots) is compared over the particles present, which must be the
same in both files at each common frame.  For every common frame the largest difference
of each field is scaled by the scene's scale of that field:

    position          max radius R
    velocity          largest initial speed, else sqrt(|g| R), else 1 m/s
    angular_velocity  velocity scale / R
    force             largest |force| over both runs (else 1 N)
    torque            largest |torque| over both runs, else force scale x R

The observables present in both files are compared too (energies relative to the largest
kinetic + rotational + elastic energy of A, counts of contacts, bonds and fragments absolutely,
the wall observables of a servo scene -- series in groups such as wall_force/NAME/x -- relative
to the largest magnitude of A's series of the same group (wall_force, servo_stress,
stress_tensor), servo_position/NAME relative to the position scale; --no-observables skips
them).  --until STEP compares the frames up to STEP only (e.g. up to the
first broken bond).  Prints a compact table (a sample of frames and the worst frame) and exits 1
when any scaled difference exceeds the tolerance (2 on unusable input).
"""
import argparse
import sys

import h5py
import numpy as np
import yaml

FIELDS = ("position", "velocity", "angular_velocity", "force", "torque")
COUNTS = ("contacts", "wall_contacts", "bonds", "fragments")  # observables compared absolutely
SHORT = {"position": "x", "velocity": "v", "angular_velocity": "w", "force": "f", "torque": "t"}


def load(path):
    f = h5py.File(path, "r")
    p = f["particles/all"]
    out = {"file": f, "radius": p["radius"][()], "fields": {}}
    if isinstance(p["id"], h5py.Group):   # a growing particle set: ids per frame, -1 empty
        out["id_steps"], out["id_frames"] = p["id/step"][()], p["id/value"][()]
    else:
        out["id_steps"], out["id_frames"] = None, p["id"][()]
    for k in FIELDS:
        if k in p:
            out["fields"][k] = (p[k]["step"][()], p[k]["value"])
    scene = {}
    if "parameters" in f and "scene" in f["parameters"]:
        try:
            txt = f["parameters/scene"][()]
            if isinstance(txt, bytes):
                txt = txt.decode()
            scene = yaml.load(str(txt), Loader=yaml.CSafeLoader) or {}
        except Exception:  # the scene text is optional metadata
            scene = {}
    out["gravity"] = np.array(scene.get("gravity") or [0.0, 0.0, 0.0], dtype=float)
    out["tolerance"] = (scene.get("output") or {}).get("compare_tolerance")
    try:
        out["creator"] = f["h5md/creator"].attrs["name"]
        if isinstance(out["creator"], bytes):
            out["creator"] = out["creator"].decode()
    except Exception:
        out["creator"] = "?"
    return out


class Unusable(Exception):
    """The two trajectories cannot be compared (message says why)."""


def ids_at(X, step):
    """The ids of X's slots at `step` (-1: an empty slot of a growing set)."""
    if X["id_steps"] is None:
        return X["id_frames"]
    at = np.flatnonzero(X["id_steps"] == step)
    if not len(at):
        raise Unusable("no ids at step %d" % step)
    return X["id_frames"][at[0]]


def live_order(X, step):
    """The slots of X's particles at `step`, ordered by id, and their ids."""
    ids = ids_at(X, step)
    slots = np.flatnonzero(ids >= 0)
    slots = slots[np.argsort(ids[slots], kind="stable")]
    return slots, ids[slots]


def frame_index(X, field, common):
    """Indices of the common steps in X's frames of one field, and the field's dataset."""
    steps, val = X["fields"][field]
    idx = {int(s): n for n, s in enumerate(steps)}
    return [idx[int(s)] for s in common], val


def scales(A, B, fields, common):
    """The scale of each field (see the module docstring)."""
    R = float(max(np.nanmax(A["radius"]), 1e-300))
    vscale = 0.0
    if "velocity" in fields:
        fa, va = frame_index(A, "velocity", common)
        slots, _ = live_order(A, common[0])
        vscale = float(np.max(np.linalg.norm(va[fa[0]][slots], axis=1), initial=0.0))
    if vscale == 0.0:
        gabs = float(np.linalg.norm(A["gravity"]))
        vscale = np.sqrt(gabs * R) if gabs > 0 else 1.0
    scale = {"position": R, "velocity": vscale, "angular_velocity": vscale / R}
    for k in ("force", "torque"):
        if k in fields:
            m = 0.0
            for X in (A, B):
                val = X["fields"][k][1][()]
                if val.size and np.isfinite(val).any():
                    m = max(m, float(np.nanmax(np.linalg.norm(val, axis=2))))
            scale[k] = m
    if scale.get("force", 0.0) == 0.0:
        scale["force"] = 1.0
    if scale.get("torque", 0.0) == 0.0:
        scale["torque"] = scale["force"] * R
    return scale


def field_differences(A, B, fields, common, scale):
    """table[frame, field]: the largest scaled difference of the field in that frame."""
    order = []
    for step in common:
        (ia, ida), (ib, idb) = live_order(A, step), live_order(B, step)
        if not np.array_equal(ida, idb):
            raise Unusable("the particle ids differ at step %d (%d vs %d particles)" % (
                step, len(ida), len(idb)))
        order.append((ia, ib))
    table = np.zeros((len(common), len(fields)))
    for c, k in enumerate(fields):
        fa, va = frame_index(A, k, common)
        fb, vb = frame_index(B, k, common)
        va_all, vb_all = va[()], vb[()]
        for n, (ia, ib) in enumerate(order):
            xa = va_all[fa[n]][ia]
            xb = vb_all[fb[n]][ib]
            table[n, c] = float(np.max(np.abs(xa - xb))) / scale[k] if xa.size else 0.0
    return table


def observable_differences(A, B, until=None, position_scale=1.0):
    """{name: largest difference} of the observables present in both files at common steps:
    energies relative to the largest kinetic + rotational + elastic energy of A, counts
    absolute; and that energy scale."""
    if "observables" not in A["file"] or "observables" not in B["file"]:
        return {}, 1.0
    oa, ob = A["file"]["observables"], B["file"]["observables"]
    tot = None
    for k in ("kinetic_energy", "rotational_energy", "elastic_energy"):
        if k in oa:
            val = oa[k]["value"][()]
            tot = val if tot is None else tot[: len(val)] + val[: len(tot)]
    escale = float(np.max(np.abs(tot))) if tot is not None and len(tot) else 0.0
    escale = escale if escale > 0 else 1.0
    diffs = {}
    for k in sorted(set(series_names(oa)) & set(series_names(ob))):
        cs, ka, kb = np.intersect1d(oa[k]["step"][()], ob[k]["step"][()], return_indices=True)
        if until is not None:
            keep = cs <= until
            cs, ka, kb = cs[keep], ka[keep], kb[keep]
        if not len(cs):
            continue
        d = np.abs(oa[k]["value"][()][ka] - ob[k]["value"][()][kb])
        diffs[k] = float(d.max()) / (1.0 if k in COUNTS else group_scale(oa, k, position_scale)
                                     if "/" in k else escale)
    return diffs, escale


def series_names(group):
    """The observable series (groups holding step and value) under GROUP, as relative paths."""
    names = []
    group.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Group)
                     and "value" in obj and "step" in obj else None)
    return names


def group_scale(obs, name, position_scale):
    """Scale of a wall observable series NAME: servo_position the position scale, the others
    the largest magnitude over A's series of the same top-level group (else 1)."""
    top = name.split("/")[0]
    if top == "servo_position":
        return position_scale
    peak = max((float(np.max(np.abs(obs[top][k]["value"][()])))
                for k in series_names(obs[top]) if len(obs[top][k]["value"])), default=0.0)
    return peak if peak > 0 else 1.0


def compare(path_a, path_b, observables=True, until=None):
    """Compare two trajectories.  Returns a dict with the loaded files (A, B), the compared
    fields, the common steps, the scales, the per-frame table, the observable differences and
    `worst`, the largest scaled difference of all.  Raises Unusable."""
    try:
        A, B = load(path_a), load(path_b)
    except (OSError, KeyError) as e:
        raise Unusable("cannot read the trajectories: %s" % e)
    if A["id_steps"] is None and B["id_steps"] is None and \
            sorted(A["id_frames"].tolist()) != sorted(B["id_frames"].tolist()):
        raise Unusable("the particle ids differ (%d vs %d particles)" % (len(A["id_frames"]),
                                                                         len(B["id_frames"])))
    fields = [k for k in FIELDS if k in A["fields"] and k in B["fields"]]
    if "position" not in fields:
        raise Unusable("no common position data")
    common = np.intersect1d(A["fields"]["position"][0], B["fields"]["position"][0])
    if until is not None:
        common = common[common <= until]
    if len(common) == 0:
        raise Unusable("no common steps")
    scale = scales(A, B, fields, common)
    table = field_differences(A, B, fields, common, scale)
    obs, escale = (observable_differences(A, B, until, scale["position"]) if observables
                   else ({}, 1.0))
    worst = max([float(table.max())] + list(obs.values()))
    return {"A": A, "B": B, "fields": fields, "common": common, "scale": scale, "table": table,
            "observables": obs, "energy_scale": escale, "worst": worst}


def report(c, path_a, path_b, rows):
    """Print the comparison as a compact table."""
    A, B, fields, common, table = c["A"], c["B"], c["fields"], c["common"], c["table"]
    na, nb = len(A["fields"]["position"][0]), len(B["fields"]["position"][0])
    if len(common) != na or len(common) != nb:
        print("note: %d frames in A, %d in B, %d common steps" % (na, nb, len(common)))
    print("A: %s (%s)\nB: %s (%s)" % (path_a, A["creator"], path_b, B["creator"]))
    print("scales: " + ", ".join("%s %.3e" % (SHORT[k], c["scale"][k]) for k in fields))
    print("%10s" % "step" + "".join("%11s" % ("d" + SHORT[k]) for k in fields))
    shown = sorted(set(np.linspace(0, len(common) - 1, min(rows, len(common))).astype(int).tolist()))
    for n in shown:
        print("%10d" % common[n] + "".join("%11.2e" % v for v in table[n]))
    worst = int(np.argmax(table.max(axis=1)))
    print("worst frame: step %d:" % common[worst] + "".join(
        " d%s %.2e" % (SHORT[k], table[worst, i]) for i, k in enumerate(fields)))
    if c["observables"]:
        print("observables (energies / %.3e J, counts absolute): %s" % (
            c["energy_scale"], ", ".join("%s %.1e" % kv for kv in c["observables"].items())))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--tol", type=float, default=None,
                    help="tolerance (default: the scene's output.compare_tolerance, else 1e-10)")
    ap.add_argument("--rows", type=int, default=12, help="frames shown in the table (plus the worst)")
    ap.add_argument("--no-observables", action="store_true", help="compare the per-particle fields only")
    ap.add_argument("--until", type=int, default=None,
                    help="compare the frames up to this step only (e.g. before the first broken bond)")
    args = ap.parse_args()
    try:
        c = compare(args.a, args.b, not args.no_observables, args.until)
    except Unusable as e:
        print("FAIL %s" % e)
        return 2
    report(c, args.a, args.b, args.rows)
    tol = args.tol if args.tol is not None else (c["A"]["tolerance"] or 1e-10)
    ok = c["worst"] <= tol
    print("%s max scaled difference %.3e over %d frames (tolerance %.1e)" % (
        "PASS" if ok else "FAIL", c["worst"], len(c["common"]), tol))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
