#!/usr/bin/python3
"""Verify that a jdem trajectory file follows the H5MD 1.1 layout of io/h5md.h.

usage: check_h5md_layout.py FILE.h5 [--require velocity,force,...] [--no-sidecar]

Prints one line per check ("PASS ..." / "FAIL ...") and exits 1 if any check fails,
2 on usage errors.  Works on the output of both engines (standalone jdem and LIGGGHTS dump
h5md/jdem) and on a PATH.part left by an aborted run (the sidecar check is skipped then).
"""
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

TIME_DEP = ("position", "velocity", "angular_velocity", "force", "torque")
UNITS = {"position": "m", "velocity": "m s-1", "angular_velocity": "s-1", "force": "N",
         "torque": "N m"}


class Checker:
    def __init__(self):
        self.failed = 0

    def check(self, ok, what, detail=""):
        line = ("PASS " if ok else "FAIL ") + what
        if detail and not ok:
            line += ": " + detail
        print(line)
        if not ok:
            self.failed += 1
        return ok


def as_str(v):
    if isinstance(v, bytes):
        return v.decode("utf-8")
    if isinstance(v, np.ndarray) and v.shape == ():
        return as_str(v[()])
    return str(v) if v is not None else None


def dtype_is(ds, kind, size):
    return ds.dtype.kind == kind and ds.dtype.itemsize == size


def main(argv):
    args = [a for a in argv[1:]]
    require = ["position"]
    sidecar = True
    path = None
    i = 0
    while i < len(args):
        a = args[i]
        if a == "--require" and i + 1 < len(args):
            require += [g for g in args[i + 1].split(",") if g]
            i += 2
            continue
        if a == "--no-sidecar":
            sidecar = False
        elif a.startswith("-") or path is not None:
            print(__doc__.strip().splitlines()[2])
            return 2
        else:
            path = a
        i += 1
    if path is None:
        print(__doc__.strip().splitlines()[2])
        return 2
    for g in require:
        if g not in TIME_DEP:
            print(f"unknown group in --require: {g}")
            return 2

    c = Checker()
    try:
        f = h5py.File(path, "r")
    except Exception as e:  # noqa: BLE001 - report any open failure as a check
        c.check(False, f"open {path}", str(e))
        return 1
    c.check(True, f"open {path}")

    with f:
        # /h5md
        h5md = f.get("h5md")
        if c.check(isinstance(h5md, h5py.Group), "/h5md group"):
            ver = h5md.attrs.get("version")
            c.check(ver is not None and np.asarray(ver).dtype.kind in "iu"
                    and list(np.asarray(ver).ravel()) == [1, 1],
                    "/h5md version == [1, 1] (int)", f"got {ver!r}")
            a = h5md.get("author")
            c.check(isinstance(a, h5py.Group) and as_str(a.attrs.get("name")),
                    "/h5md/author name")
            cr = h5md.get("creator")
            c.check(isinstance(cr, h5py.Group) and as_str(cr.attrs.get("name"))
                    and as_str(cr.attrs.get("version")), "/h5md/creator name and version")

        par = f.get("parameters")
        if c.check(isinstance(par, h5py.Group), "/parameters group"):
            dt = par.attrs.get("dt")
            c.check(dt is not None and np.asarray(dt).dtype == np.float64,
                    "/parameters dt is float64", f"got {dt!r}")
            if "scene" in par:
                sc = par["scene"]
                c.check(h5py.check_string_dtype(sc.dtype) is not None and sc.shape == (),
                        "/parameters/scene is a scalar string")

        allg = f.get("particles/all")
        if not c.check(isinstance(allg, h5py.Group), "/particles/all group"):
            return 1

        box = allg.get("box")
        if c.check(isinstance(box, h5py.Group), "/particles/all/box group"):
            dim = box.attrs.get("dimension")
            c.check(dim is not None and int(np.asarray(dim)) == 3, "box dimension == 3",
                    f"got {dim!r}")
            bnd = box.attrs.get("boundary")
            ok = bnd is not None and np.asarray(bnd).shape == (3,)
            c.check(ok and all(as_str(b) in ("none", "periodic") for b in bnd),
                    "box boundary is 3 strings", f"got {bnd!r}")

        # time-independent
        n = None
        for name, kind, size in (("id", "i", 8), ("species", "i", 4), ("radius", "f", 8),
                                 ("mass", "f", 8)):
            ds = allg.get(name)
            if not c.check(isinstance(ds, h5py.Dataset), f"/particles/all/{name} dataset"):
                continue
            c.check(ds.ndim == 1, f"{name} is 1-D", f"shape {ds.shape}")
            if n is None:
                n = ds.shape[0] if ds.ndim == 1 else None
            c.check(ds.shape == (n,), f"{name} shape == [N={n}]", f"shape {ds.shape}")
            c.check(dtype_is(ds, kind, size), f"{name} dtype {kind}{size}", f"got {ds.dtype}")
        if n is not None and "id" in allg and allg["id"].shape == (n,) and n > 1:
            ids = allg["id"][()]
            c.check(bool(np.all(np.diff(ids) > 0)), "id sorted ascending and unique")

        # time-dependent
        nframes = None
        for g in TIME_DEP:
            grp = allg.get(g)
            if grp is None:
                c.check(g not in require, f"/particles/all/{g} present",
                        "required but missing")
                continue
            if not c.check(isinstance(grp, h5py.Group), f"/particles/all/{g} group"):
                continue
            for sub in ("step", "time", "value"):
                c.check(isinstance(grp.get(sub), h5py.Dataset), f"{g}/{sub} dataset")
            if not all(isinstance(grp.get(s), h5py.Dataset) for s in ("step", "time", "value")):
                continue
            st, tm, va = grp["step"], grp["time"], grp["value"]
            f_ = st.shape[0] if st.ndim == 1 else -1
            if nframes is None:
                nframes = f_
            c.check(st.ndim == 1 and dtype_is(st, "i", 8), f"{g}/step is int64 [F]",
                    f"{st.dtype} {st.shape}")
            c.check(tm.shape == (f_,) and dtype_is(tm, "f", 8), f"{g}/time is float64 [F]",
                    f"{tm.dtype} {tm.shape}")
            c.check(va.shape == (f_, n, 3) and dtype_is(va, "f", 8),
                    f"{g}/value is float64 [F={f_}][N={n}][3]", f"{va.dtype} {va.shape}")
            if g != "position":
                c.check(f_ == nframes, f"{g} has as many frames as position ({nframes})",
                        f"has {f_}")
            c.check(va.maxshape[0] is None and va.chunks is not None,
                    f"{g}/value chunked and extendible", f"maxshape {va.maxshape}")
            c.check(as_str(va.attrs.get("unit")) == UNITS[g], f"{g}/value unit '{UNITS[g]}'",
                    f"got {va.attrs.get('unit')!r}")
            c.check(as_str(tm.attrs.get("unit")) == "s", f"{g}/time unit 's'")
            if f_ > 1:
                c.check(bool(np.all(np.diff(st[()]) > 0)), f"{g}/step strictly increasing")
                c.check(bool(np.all(np.diff(tm[()]) >= 0)), f"{g}/time non-decreasing")
            if f_ > 0 and n:
                c.check(bool(np.all(np.isfinite(va[f_ - 1]))), f"{g}/value last frame finite")

        # observables
        obs = f.get("observables")
        if obs is not None:
            names = []
            obs.visititems(lambda k, o: names.append(k)
                           if isinstance(o, h5py.Group) and "value" in o else None)
            for k in names:
                o = obs[k]
                ok = all(isinstance(o.get(s), h5py.Dataset) for s in ("step", "time", "value"))
                if not c.check(ok, f"/observables/{k} has step, time, value"):
                    continue
                m = o["value"].shape
                c.check(o["value"].ndim == 1 and dtype_is(o["value"], "f", 8)
                        and o["step"].shape == m and dtype_is(o["step"], "i", 8)
                        and o["time"].shape == m and dtype_is(o["time"], "f", 8),
                        f"/observables/{k} shapes [{m[0] if m else '?'}] and dtypes",
                        f"value {o['value'].dtype}{o['value'].shape} step {o['step'].shape}"
                        f" time {o['time'].shape}")

    # XDMF sidecar
    if sidecar and not path.endswith(".part"):
        base, _ = os.path.splitext(path)
        xpath = base + ".xdmf"
        if c.check(os.path.exists(xpath), f"sidecar {xpath} exists"):
            try:
                root = ET.parse(xpath).getroot()
                grids = root.findall("./Domain/Grid/Grid")
                c.check(len(grids) == (nframes or 0), f"sidecar has {nframes} frame grids",
                        f"has {len(grids)}")
                refs = [d.text.strip() for d in root.iter("DataItem")
                        if d.get("Format") == "HDF" and d.text]
                h5name = os.path.basename(path)
                c.check(bool(refs) and all(r.split(":", 1)[0] == h5name for r in refs),
                        f"sidecar references '{h5name}' by basename")
            except ET.ParseError as e:
                c.check(False, "sidecar is well-formed XML", str(e))

    print(f"{'OK' if c.failed == 0 else 'FAILED'}: {c.failed} failed check(s) in {path}")
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
