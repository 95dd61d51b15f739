#!/usr/bin/python3
"""h5md_check.py — check an HDF5 file against the MUST rules of H5MD 1.1 (and of its units
module 1.0 when the file uses it).

    scripts/h5md_check.py FILE.h5 [FILE.h5 ...]

Prints one line per rule and file, "PASS file: rule" or "FAIL file: rule: detail", and exits 1
if any rule failed.  The rules, from the specification's text:
  h5md group     /h5md exists; attribute version, integer [2], equal to [1, 1]; groups author
                 (string attribute name) and creator (string attributes name and version).
  modules        every group under /h5md/modules has an integer [2] version attribute; `unit`
                 attributes only with the units module, which has a string attribute system
                 and whose unit attributes are ASCII strings.
  particles      every group under /particles has a box group with an integer scalar
                 dimension and a string [dimension] boundary of "periodic" or "none" (edges,
                 [dimension] or [dimension][dimension] floats, required when any is periodic);
                 position, velocity, force, ...: H5MD elements (below), position's last axis =
                 dimension; id and species of integer type.
  particle count a time-dependent id (a particle set that changes) is integer [var][N] with
                 HDF5 fill value -1, holds -1 for each empty slot and no id twice in a frame,
                 and every time-dependent element of the group has N slots on the same
                 frames.
  elements       a time-dependent element is a group with step (integer, [var] or scalar),
                 value ([var][...]) and, when given, time (float, the shape of step); a [var]
                 step has one entry per row of value and increases strictly.
  observables    every observable (also in subgroups) is an H5MD element.
  connectivity   every element is a tuple list: an integer dataset [N][k] (or a time-dependent
                 group whose value is [var][N][k]) with a particles_group attribute that is an
                 object reference to a group under /particles.
"""
import sys

import h5py
import numpy as np

TD_SKIP = {"box"}


class Report:
    def __init__(self, path):
        self.path, self.failed = path, 0

    def rule(self, name, problems):
        if problems:
            self.failed += 1
            print(f"FAIL {self.path}: {name}: {'; '.join(problems[:5])}"
                  + (f" (+{len(problems) - 5} more)" if len(problems) > 5 else ""))
        else:
            print(f"PASS {self.path}: {name}")


def is_str(v):
    return isinstance(v, (str, bytes)) or (isinstance(v, np.ndarray) and v.dtype.kind in "SUO")


def int_kind(obj):
    return obj.dtype.kind in "iu"


def check_h5md(f):
    p = []
    g = f.get("h5md")
    if not isinstance(g, h5py.Group):
        return ["no /h5md group"]
    v = g.attrs.get("version")
    if v is None or np.shape(v) != (2,) or np.asarray(v).dtype.kind not in "iu":
        p.append(f"/h5md@version must be integer [2], is {v!r}")
    elif list(v) != [1, 1]:
        p.append(f"/h5md@version is {list(v)}, this checker knows 1.1")
    for sub, attrs in (("author", ("name",)), ("creator", ("name", "version"))):
        s = g.get(sub)
        if not isinstance(s, h5py.Group):
            p.append(f"no /h5md/{sub} group")
            continue
        for a in attrs:
            if not is_str(s.attrs.get(a)):
                p.append(f"/h5md/{sub}@{a} must be a string")
    return p


def unit_attrs(f):
    found = []

    def visit(name, obj):
        if "unit" in obj.attrs:
            found.append((name, obj))
    f.visititems(visit)
    return found


def check_modules(f):
    p = []
    mods = f.get("h5md/modules")
    if mods is None:
        units = unit_attrs(f)
        if units:
            p.append(f"{len(units)} unit attributes (e.g. /{units[0][0]}@unit) without the units "
                     "module that defines them (/h5md/modules/units)")
        return p
    for name, m in mods.items():
        v = m.attrs.get("version")
        if v is None or np.shape(v) != (2,) or np.asarray(v).dtype.kind not in "iu":
            p.append(f"/h5md/modules/{name}@version must be integer [2]")
    if "units" in mods:
        if not is_str(mods["units"].attrs.get("system")):
            p.append("/h5md/modules/units@system must be a string")

        for name, obj in unit_attrs(f):
            t = h5py.h5a.open(obj.id, b"unit").get_type()
            if not isinstance(t, h5py.h5t.TypeStringID):
                p.append(f"/{name}@unit is not a string")
            elif t.get_cset() != h5py.h5t.CSET_ASCII:
                p.append(f"/{name}@unit is not an ASCII string")
    return p


def element_problems(obj, where):
    """H5MD element: a dataset (time-independent) or a time-dependent group."""
    if isinstance(obj, h5py.Dataset):
        return []
    p = []
    if "value" not in obj or "step" not in obj:
        return [f"{where}: a time-dependent group needs step and value"]
    value, step = obj["value"], obj["step"]
    if not int_kind(step):
        p.append(f"{where}/step is not integer")
    if step.shape not in ((), (step.shape[0],) if step.shape else ()):
        p.append(f"{where}/step must be [var] or scalar")
    if "time" in obj:
        t = obj["time"]
        if t.dtype.kind != "f":
            p.append(f"{where}/time is not float")
        if t.shape != step.shape:
            p.append(f"{where}/time shape {t.shape} != step shape {step.shape}")
    if len(value.shape) < 1:
        p.append(f"{where}/value must have a leading [var] axis")
    elif step.shape:
        if step.shape[0] != value.shape[0]:
            p.append(f"{where}: {step.shape[0]} steps for {value.shape[0]} values")
        s = step[()]
        if len(s) > 1 and not np.all(np.diff(s) > 0):
            p.append(f"{where}/step does not increase strictly")
    return p


def check_particles(f):
    p = []
    parts = f.get("particles")
    if parts is None:
        return p
    for gname, grp in parts.items():
        w = f"/particles/{gname}"
        box = grp.get("box")
        if not isinstance(box, h5py.Group):
            p.append(f"{w}: no box group")
            continue
        dim = box.attrs.get("dimension")
        if dim is None or np.shape(dim) != () or np.asarray(dim).dtype.kind not in "iu":
            p.append(f"{w}/box@dimension must be an integer scalar")
            continue
        dim = int(dim)
        b = box.attrs.get("boundary")
        vals = [x.decode() if isinstance(x, bytes) else str(x) for x in np.atleast_1d(b)] \
            if b is not None else []
        if len(vals) != dim or any(x not in ("periodic", "none") for x in vals):
            p.append(f"{w}/box@boundary must be {dim} of 'periodic'/'none', is {vals}")
        if "periodic" in vals and "edges" not in box:
            p.append(f"{w}/box: periodic boundaries need edges")
        for name, obj in grp.items():
            if name in TD_SKIP:
                continue
            p += element_problems(obj, f"{w}/{name}")
            if name == "position":
                val = obj["value"] if isinstance(obj, h5py.Group) else obj
                if val.shape[-1] != dim:
                    p.append(f"{w}/position: last axis {val.shape[-1]} != dimension {dim}")
            if name in ("id", "species"):
                val = obj["value"] if isinstance(obj, h5py.Group) else obj
                if not int_kind(val):
                    p.append(f"{w}/{name} is not of integer type")
    return p


def check_observables(f):
    p = []
    obs = f.get("observables")
    if obs is None:
        return p

    def walk(g, where):
        for name, obj in g.items():
            w = f"{where}/{name}"
            if isinstance(obj, h5py.Group) and "value" not in obj:
                walk(obj, w)  # a subgroup of observables
            else:
                p.extend(element_problems(obj, w))
    walk(obs, "/observables")
    return p


def check_connectivity(f):
    p = []
    con = f.get("connectivity")
    if con is None:
        return p
    for name, obj in con.items():
        w = f"/connectivity/{name}"
        data = obj
        if isinstance(obj, h5py.Group):
            if "value" not in obj:
                p.append(f"{w}: neither a tuple list dataset nor a time-dependent group")
                continue
            p += element_problems(obj, w)
            data = obj["value"]
            shape = data.shape[1:]
        else:
            shape = data.shape
        if len(shape) != 2 or not int_kind(data):
            p.append(f"{w}: a tuple list is an integer [N][k] dataset, is {data.dtype}{shape}")
        ref = obj.attrs.get("particles_group")
        if not isinstance(ref, h5py.Reference):
            p.append(f"{w}@particles_group must be an object reference, is {type(ref).__name__}")
            continue
        target = f[ref]
        if not isinstance(target, h5py.Group) or not target.name.startswith("/particles/"):
            p.append(f"{w}@particles_group points at {target.name}, not a particles group")
    return p


def check_particle_count(f):
    """H5MD 1.1, particles group: with a varying number of particles, id is time-dependent and
    -1 (its fill value) marks the slots that hold no particle."""
    p = []
    for gname, grp in (f.get("particles") or {}).items():
        ids = grp.get("id")
        if not isinstance(ids, h5py.Group) or "value" not in ids:
            continue
        w = f"/particles/{gname}/id"
        val = ids["value"]
        if len(val.shape) != 2 or not int_kind(val):
            p.append(f"{w}/value must be integer [var][N], is {val.dtype}{val.shape}")
            continue
        buf = np.zeros(1, dtype=val.dtype)
        val.id.get_create_plist().get_fill_value(buf)
        fill = int(buf[0])
        if fill != -1:
            p.append(f"{w}/value has fill value {fill}, not -1")
        a = val[()]
        if np.any(a < -1):
            p.append(f"{w}/value holds ids below -1 ({int(a.min())})")
        for k, row in enumerate(a):
            live = row[row >= 0]
            if len(np.unique(live)) != len(live):
                p.append(f"{w}/value frame {k} holds an id twice")
                break
        steps = ids["step"][()] if "step" in ids else None
        for name, obj in grp.items():
            if name in TD_SKIP or name == "id" or not isinstance(obj, h5py.Group):
                continue
            v = obj["value"]
            if len(v.shape) < 2 or v.shape[1] != val.shape[1]:
                p.append(f"/particles/{gname}/{name}/value has {v.shape[1:2]} slots, id {val.shape[1]}")
            if steps is not None and "step" in obj and not np.array_equal(obj["step"][()], steps):
                p.append(f"/particles/{gname}/{name}: frames other than id's")
    return p


RULES = [("h5md group", check_h5md), ("modules", check_modules), ("particles", check_particles),
         ("particle count", check_particle_count),
         ("observables", check_observables), ("connectivity", check_connectivity)]


def check_file(path):
    r = Report(path)
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        r.rule("HDF5 file", [str(e)])
        return r.failed
    with f:
        for name, fn in RULES:
            r.rule(name, fn(f))
    return r.failed


def main(argv):
    if not argv:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    return 1 if sum(check_file(p) for p in argv) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
