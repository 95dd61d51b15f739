"""A deposit: one frame of the particle set of an H5MD trajectory, and the regions cut from it.

read_frame() is the only function that knows the layout of the engines' files
(io/h5md.h: /particles/all/{id,species,radius,mass} and /particles/all/position/value [F][N][3]).
A run with an inlet holds more rows than particles in a frame: a slot not yet filled has a
non-finite position or, where the id is a time series (/particles/all/id/value [F][N]), id -1;
read_frame keeps the live particles only.
"""
import math
import os
from dataclasses import dataclass

import numpy as np
import yaml


class DepositError(ValueError):
    """Bad input to the readers or the cutters; the message names the file or value."""


@dataclass
class Deposit:
    id: np.ndarray        # [N] int64
    species: np.ndarray   # [N] int32, index in the scene's material list
    radius: np.ndarray    # [N] m
    mass: np.ndarray      # [N] kg
    position: np.ndarray  # [N, 3] m
    step: int = 0
    time: float = 0.0     # s

    @property
    def density(self):
        """Particle density [kg/m^3] from its mass and radius."""
        return self.mass / (4.0 / 3.0 * math.pi * self.radius ** 3)

    def subset(self, keep):
        """The particles selected by the boolean or index array `keep`."""
        return Deposit(self.id[keep], self.species[keep], self.radius[keep], self.mass[keep],
                       self.position[keep], self.step, self.time)

    def translated(self, shift):
        return Deposit(self.id, self.species, self.radius, self.mass,
                       self.position + np.asarray(shift, dtype=float), self.step, self.time)


def read_frame(path, frame=-1):
    """Frame `frame` (Python index: -1 is the last) of the trajectory at `path`."""
    import h5py
    if not os.path.exists(path):
        raise DepositError(f"{path}: no such file; valid: an H5MD trajectory written by jdem or "
                           f"liggghts-jdem")
    with h5py.File(path, "r") as f:
        if "particles/all/position/value" not in f:
            raise DepositError(f"{path}: no /particles/all/position; valid: an H5MD trajectory "
                               f"written by jdem or liggghts-jdem")
        p = f["particles/all"]
        frames = p["position/value"].shape[0]
        if not -frames <= frame < frames:
            raise DepositError(f"{path}: frame {frame} does not exist; valid: {-frames} to "
                               f"{frames - 1} ({frames} frames)")
        ids = p["id/value"][frame] if isinstance(p["id"], h5py.Group) else p["id"][()]
        position = p["position/value"][frame]
        live = np.all(np.isfinite(position), axis=1) & (ids >= 0)
        return Deposit(ids[live], p["species"][()][live], p["radius"][()][live],
                       p["mass"][()][live], position[live], int(p["position/step"][frame]),
                       float(p["position/time"][frame]))


def scene_of(f):
    """The resolved scene a trajectory keeps (/parameters/scene, written by both engines) as a
    dict, {} without one; f: the open h5py.File."""
    if "parameters/scene" not in f:
        return {}
    text = f["parameters/scene"][()]
    return yaml.load(text.decode() if isinstance(text, bytes) else text, Loader=yaml.CSafeLoader) or {}


def built_by(path):
    """The binaries that computed the trajectory at `path`, earliest first: the creator versions
    ("0.1.0+<commit>") of the runs it continues (/h5md/creator "continues", written when a run
    resumes) and its own; "unknown" for a file without them."""
    import h5py
    with h5py.File(path, "r") as f:
        attrs = f["h5md/creator"].attrs if "h5md/creator" in f else {}
        text = [v.decode() if isinstance(v, bytes) else str(v)
                for v in (attrs.get("continues", ""), attrs.get("version", "unknown"))]
    versions = [v.strip() for v in ", ".join(t for t in text if t).split(",") if v.strip()]
    return list(dict.fromkeys(versions))  # in order, each once


def inside_box(dep, lo, hi):
    """Boolean mask of the particles whose centre lies in [lo, hi) (componentwise)."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    return np.all((dep.position >= lo) & (dep.position < hi), axis=1)


def keep_box(dep, lo, hi, source="deposit"):
    """The particles whose centre lies in the box [lo, hi); an error if the box reaches beyond
    the deposit's extent (the particles' outline, min(x - R)..max(x + R)) by more than the
    largest radius (the slack of a packing against a wall)."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    if np.any(hi <= lo):
        raise DepositError(f"region {lo.tolist()}..{hi.tolist()}: empty; valid: lo < hi")
    ext_lo = dep.position.min(axis=0) - dep.radius.max()
    ext_hi = dep.position.max(axis=0) + dep.radius.max()
    slack = dep.radius.max()
    if np.any(lo < ext_lo - slack) or np.any(hi > ext_hi + slack):
        raise DepositError(f"region {lo.tolist()}..{hi.tolist()} lies outside the {source} "
                           f"(extent {ext_lo.round(6).tolist()}..{ext_hi.round(6).tolist()}); "
                           f"valid: a region inside it")
    return dep.subset(inside_box(dep, lo, hi))


def deposit_height(dep):
    """Top of the deposit [m]: the highest particle top (z + R)."""
    return float(np.max(dep.position[:, 2] + dep.radius))
