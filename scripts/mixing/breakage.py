"""Breakage diagnostics of a bonded fill (Jiang (2021) Ch. 5; spec §4.3 [RECON]: the seed counts
nothing, these are ours): from a trajectory of either engine, the bonds formed and broken up to a
time, the broken fraction per failure mode, where the bonds broke, and the fragments, the
connected components of the intact bonds among the particles ever bonded (a whole 2 x 2 x 8
block is one fragment of 32 spheres, a sphere that lost every bond a fragment of 1).

The trajectory's records (docs/output.md): /connectivity/bonds [B][2] with /jdem/bonds/formed_step,
/connectivity/broken_bonds [K][2] with /jdem/broken_bonds/{step, mode, position}; mode 1 tension,
2 shear (kernel/jdem_bond.h, jd_bond_mode).
"""
import os

import numpy as np

MODES = {1: "tension", 2: "shear"}


class BreakageError(ValueError):
    """A trajectory without bond records; the message names the file."""


def read_bonds(path):
    """{"bonds": [B][2] ids, "formed": [B] steps, "broken": [K][2] ids, "broken_step": [K],
    "mode": [K], "broken_at": [K][3] m, "dt": s} of the trajectory at `path`."""
    import h5py
    if not os.path.exists(path):
        raise BreakageError(f"{path}: no such file; valid: an H5MD trajectory of a bonded run")
    with h5py.File(path, "r") as f:
        if "connectivity/bonds" not in f:
            raise BreakageError(f"{path}: no /connectivity/bonds; valid: the trajectory of a run "
                                f"with bonds")
        get = lambda k, shape: f[k][()] if k in f else np.zeros(shape)
        return {"bonds": f["connectivity/bonds"][()], "formed": f["jdem/bonds/formed_step"][()],
                "broken": get("connectivity/broken_bonds", (0, 2)).astype(np.int64),
                "broken_step": get("jdem/broken_bonds/step", (0,)).astype(np.int64),
                "mode": get("jdem/broken_bonds/mode", (0,)).astype(np.int64),
                "broken_at": get("jdem/broken_bonds/position", (0, 3)),
                "dt": float(f["parameters"].attrs["dt"])}


def intact_at(rec, step):
    """The bonds (pairs of ids) formed at or before `step` and not broken by then."""
    formed = rec["bonds"][rec["formed"] <= step]
    gone = {tuple(p) for p in rec["broken"][rec["broken_step"] <= step].tolist()}
    return np.array([p for p in formed.tolist() if tuple(p) not in gone], dtype=np.int64).reshape(-1, 2)


def components(rec, step):
    """(ids, label): the particles of the bonds formed by `step`, sorted by id, and the fragment
    each one belongs to, a connected component of the intact bonds (labels 0..n-1)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    ids = np.unique(rec["bonds"][rec["formed"] <= step]).astype(np.int64)
    if len(ids) == 0:
        return ids, np.zeros(0, dtype=np.int64)
    intact = intact_at(rec, step)
    rows, cols = np.searchsorted(ids, intact[:, 0]), np.searchsorted(ids, intact[:, 1])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(ids), len(ids)))
    return ids, connected_components(graph, directed=False)[1]


def fragment_sizes(rec, step):
    """The sizes of the fragments at `step`, largest first."""
    return np.sort(np.bincount(components(rec, step)[1]))[::-1]


def fragment_of(rec, step, ids):
    """The size of the fragment each particle of `ids` belongs to at `step`; 0 for a particle
    never bonded by then."""
    bonded, label = components(rec, step)
    out = np.zeros(len(ids), dtype=np.int64)
    if len(bonded):
        at = np.minimum(np.searchsorted(bonded, ids), len(bonded) - 1)
        hit = bonded[at] == ids
        out[hit] = np.bincount(label)[label[at[hit]]]
    return out


def broken_fraction(rec, step):
    """{"formed": B, "broken": K, "tension": fraction, "shear": fraction, "total": fraction} of
    the bonds formed by `step` (fractions of the formed ones)."""
    formed = int(np.count_nonzero(rec["formed"] <= step))
    done = rec["broken_step"] <= step
    out = {"formed": formed, "broken": int(np.count_nonzero(done))}
    for m, name in MODES.items():
        out[name] = np.count_nonzero(done & (rec["mode"] == m)) / formed if formed else float("nan")
    out["total"] = out["broken"] / formed if formed else float("nan")
    return out


def over_time(rec, steps):
    """broken_fraction at each of `steps`."""
    return [dict(broken_fraction(rec, int(s)), step=int(s), time=int(s) * rec["dt"]) for s in steps]
