#!/usr/bin/python3
"""compare_trajectories.py — compare two jdem H5MD trajectories (e.g. build/jdem vs
build/liggghts-jdem) frame by frame.

    scripts/compare_trajectories.py A.h5 B.h5 [--tol 1e-10] [--rows 12]

Particles are matched by id and frames by step (only steps present in both are compared; the
frames of each file are listed if they differ).  For every common frame the largest difference
of each field is scaled by the scene's scale of that field:

    position          max radius R
    velocity          largest initial speed, else sqrt(|g| R), else 1 m/s
    angular_velocity  velocity scale / R
    force             largest |force| over both runs (else 1 N)
    torque            largest |torque| over both runs, else force scale x R

The observables present in both files are compared too (energies relative to the largest
kinetic + rotational + elastic energy of A, contact counts absolutely; --no-observables skips
them).  Prints a compact table (a sample of frames and the worst frame) and exits 1 when any
scaled difference exceeds the tolerance (2 on unusable input).
"""
import argparse
import sys

import h5py
import numpy as np
import yaml

FIELDS = ("position", "velocity", "angular_velocity", "force", "torque")
SHORT = {"position": "x", "velocity": "v", "angular_velocity": "w", "force": "f", "torque": "t"}


def load(path):
    f = h5py.File(path, "r")
    p = f["particles/all"]
    out = {"file": f, "id": p["id"][()], "radius": p["radius"][()], "fields": {}}
    for k in FIELDS:
        if k in p:
            out["fields"][k] = (p[k]["step"][()], p[k]["value"])
    g = None
    if "parameters" in f and "scene" in f["parameters"]:
        try:
            txt = f["parameters/scene"][()]
            if isinstance(txt, bytes):
                txt = txt.decode()
            g = yaml.safe_load(str(txt)).get("gravity")
        except Exception:  # the scene text is optional metadata
            g = None
    out["gravity"] = np.array(g if g else [0.0, 0.0, 0.0], dtype=float)
    try:
        out["creator"] = f["h5md/creator"].attrs["name"]
        if isinstance(out["creator"], bytes):
            out["creator"] = out["creator"].decode()
    except Exception:
        out["creator"] = "?"
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--tol", type=float, default=1e-10)
    ap.add_argument("--rows", type=int, default=12, help="frames shown in the table (plus the worst)")
    ap.add_argument("--no-observables", action="store_true", help="compare the per-particle fields only")
    args = ap.parse_args()
    try:
        A, B = load(args.a), load(args.b)
    except (OSError, KeyError) as e:
        print("FAIL cannot read the trajectories: %s" % e)
        return 2

    ida, idb = A["id"], B["id"]
    if sorted(ida.tolist()) != sorted(idb.tolist()):
        print("FAIL the particle ids differ (%d vs %d particles)" % (len(ida), len(idb)))
        return 2
    ia = np.argsort(ida)
    ib = np.argsort(idb)
    fields = [k for k in FIELDS if k in A["fields"] and k in B["fields"]]
    if "position" not in fields:
        print("FAIL no common position data")
        return 2
    sa, sb = A["fields"]["position"][0], B["fields"]["position"][0]
    common = np.intersect1d(sa, sb)
    if len(common) == 0:
        print("FAIL no common steps")
        return 2
    if len(common) != len(sa) or len(common) != len(sb):
        print("note: %d frames in A, %d in B, %d common steps" % (len(sa), len(sb), len(common)))

    def frames(X, k):
        steps, val = X["fields"][k]
        idx = {int(s): n for n, s in enumerate(steps)}
        return [idx[int(s)] for s in common], val

    R = float(max(A["radius"].max(), 1e-300))
    # scales
    fa0, va = frames(A, "velocity") if "velocity" in fields else (None, None)
    vscale = float(np.max(np.linalg.norm(va[fa0[0]], axis=1))) if va is not None else 0.0
    if vscale == 0.0:
        gabs = float(np.linalg.norm(A["gravity"]))
        vscale = np.sqrt(gabs * R) if gabs > 0 else 1.0
    scale = {"position": R, "velocity": vscale, "angular_velocity": vscale / R}
    for k in ("force", "torque"):
        if k in fields:
            m = 0.0
            for X in (A, B):
                val = X["fields"][k][1][()]
                if val.size:
                    m = max(m, float(np.max(np.linalg.norm(val, axis=2))))
            scale[k] = m
    if scale.get("force", 0.0) == 0.0:
        scale["force"] = 1.0
    if scale.get("torque", 0.0) == 0.0:
        scale["torque"] = scale["force"] * R

    # per-frame scaled differences
    table = np.zeros((len(common), len(fields)))
    for c, k in enumerate(fields):
        fa, va = frames(A, k)
        fb, vb = frames(B, k)
        va_all, vb_all = va[()], vb[()]
        for n in range(len(common)):
            xa = va_all[fa[n]][ia]
            xb = vb_all[fb[n]][ib]
            table[n, c] = float(np.max(np.abs(xa - xb))) / scale[k] if xa.size else 0.0

    print("A: %s (%s)\nB: %s (%s)" % (args.a, A["creator"], args.b, B["creator"]))
    print("scales: " + ", ".join("%s %.3e" % (SHORT[k], scale[k]) for k in fields))
    head = "%10s" % "step" + "".join("%11s" % ("d" + SHORT[k]) for k in fields)
    print(head)
    rows = sorted(set(np.linspace(0, len(common) - 1, min(args.rows, len(common))).astype(int).tolist()))
    worst = int(np.argmax(table.max(axis=1)))
    for n in rows:
        print("%10d" % common[n] + "".join("%11.2e" % v for v in table[n]))
    print("worst frame: step %d:" % common[worst] + "".join(
        " d%s %.2e" % (SHORT[k], table[worst, c]) for c, k in enumerate(fields)))
    overall = float(table.max())

    # observables present in both files, at common steps: energies relative to the largest
    # kinetic + rotational + elastic energy of A, counts absolute
    obs_worst = 0.0
    if not args.no_observables and "observables" in A["file"] and "observables" in B["file"]:
        oa, ob = A["file"]["observables"], B["file"]["observables"]
        names = sorted(set(oa.keys()) & set(ob.keys()))
        escale = 0.0
        tot = None
        for k in ("kinetic_energy", "rotational_energy", "elastic_energy"):
            if k in oa:
                val = oa[k]["value"][()]
                tot = val if tot is None else tot[: len(val)] + val[: len(tot)]
        if tot is not None and len(tot):
            escale = float(np.max(np.abs(tot)))
        escale = escale if escale > 0 else 1.0
        parts = []
        for k in names:
            sa_, sb_ = oa[k]["step"][()], ob[k]["step"][()]
            cs, ka, kb = np.intersect1d(sa_, sb_, return_indices=True)
            if not len(cs):
                continue
            d = np.abs(oa[k]["value"][()][ka] - ob[k]["value"][()][kb])
            sc = 1.0 if k.endswith("contacts") else escale
            w = float(d.max()) / sc
            obs_worst = max(obs_worst, w)
            parts.append("%s %.1e" % (k, w))
        if parts:
            print("observables (energies / %.3e J, counts absolute): %s" % (escale, ", ".join(parts)))
    overall = max(overall, obs_worst)
    ok = overall <= args.tol
    print("%s max scaled difference %.3e over %d frames (tolerance %.1e)" % (
        "PASS" if ok else "FAIL", overall, len(common), args.tol))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
