#!/usr/bin/python3
"""Engine test: the large bench beds by tiling (scripts/bench_tiling.py, make_tiled_bed in
scripts/bench_beds.py), on a bed whose tiling has a closed form.

The base bed is a simple-cubic lattice of n x n x nz spheres of radius R whose neighbours, and
the floor and the four side walls, all overlap by the bench's touch overlap t (spacing 2R - t).
Its k x k tiling must be the (k n) x (k n) x nz lattice of the same spacing: the seam gap is t
(two side-wall contacts of overlap t, less the target t), every position is the big lattice's,
and the contacts are the big lattice's (pairs (kn - 1) kn nz x 2 + (kn)^2 (nz - 1), walls
(kn)^2 + 4 kn nz), each overlapping by t.  The stepper's start-overlap rule is the reference for
the refusal: build/jdem accepts the tiled bed, and refuses the same tiles placed 1.5 t closer
(every seam pair then overlaps by 2.5 t > 1e-6 R = 2 t) exactly where start_overlap_violations
finds them.  The bonded variant's rule bonds exactly the pairs in contact (`jdem resolve`).

Run:  /usr/bin/python3 tests/engine/test_bench_tiling.py      (JDEM=path/to/jdem to override)
"""
import json
import os
import re
import tempfile

import yaml

from tests.engine.engine_common import JDEM, Checks, np

from scripts import bench_beds, bench_config, bench_scenes, bench_tiling, engines

R, n, nz, k = 1.0e-3, 4, 3, 3
t = bench_config.TOUCH * R
a = 2.0 * R - t


def lattice(nx, ny, nz):
    i, j, l = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    x = R - t + a * np.stack((i.ravel(), j.ravel(), l.ravel()), axis=1).astype(float)
    return x, np.full(len(x), R), np.arange(1, len(x) + 1), 2.0 * (R - t) + (nx - 1) * a


def sorted_rows(x):
    return x[np.lexsort((x[:, 2], x[:, 1], x[:, 0]))]


def save_bed(d, name, x, r, ids, side):
    path = os.path.join(d, name + ".npz")
    np.savez(path, id=ids, radius=r, x=x, info=json.dumps(dict(side=side, height=2.0 * nz * a)))
    return path


c = Checks()
out = tempfile.mkdtemp(prefix="jdem_tiling_")
x0, r0, id0, side0 = lattice(n, n, nz)
gap = bench_tiling.seam_gap(x0, r0, side0, t)
c.check("seam_gap_is_t", abs(gap - t) <= 1e-6 * t, f"gap {gap!r}, want {t!r}")

x, r, ids, side = bench_tiling.tile(x0, r0, id0, side0, k, gap)
N = (k * n) ** 2 * nz
xb, _, _, side_big = lattice(k * n, k * n, nz)
c.check("count", len(r) == N and len(ids) == N and len(set(ids.tolist())) == N and ids.min() > 0,
        f"{len(r)} spheres, {len(set(ids.tolist()))} distinct ids, want {N}")
c.check("side", abs(side - side_big) <= 1e-15, f"side {side!r}, want {side_big!r}")
dev = np.abs(sorted_rows(x) - sorted_rows(xb)).max()
c.check("positions_are_the_big_lattice", dev <= 1e-15, f"largest deviation {dev:.3g} m")

I, J, _, ov, WI, _, WO = bench_beds.find_contacts(x, r, side)
m = k * n
pairs = 2 * (m - 1) * m * nz + m * m * (nz - 1)
walls = m * m + 4 * m * nz
c.check("pair_contacts", len(I) == pairs, f"{len(I)} pairs, want {pairs}")
c.check("wall_contacts", len(WI) == walls, f"{len(WI)} wall contacts, want {walls}")
worst = max(np.abs(ov - t).max(), np.abs(WO - t).max())
c.check("every_overlap_is_t", worst <= 1e-6 * t, f"largest |overlap - t| {worst:.3g} m")
bad, badw = bench_tiling.start_overlap_violations(r, I, J, ov, WI, WO)
c.check("no_violation", not bad and not badw, f"{len(bad)} pairs, {len(badw)} walls")

# the stepper's own refusal rule: bench_scenes.make_scene runs build/jdem on the scene (its guard), which
# first checks the start overlaps
bed = save_bed(out, "tiled", x, r, ids, side)
dt = float("nan")
try:
    _, dt = bench_scenes.make_scene(out, "test", "soft_mono", bed, 1)
    c.check("stepper_accepts_tiled_bed", dt > 0, f"dt {dt}")
except RuntimeError as e:
    c.check("stepper_accepts_tiled_bed", False, str(e)[-400:])

xc, rc_, idc, sidec = bench_tiling.tile(x0, r0, id0, side0, k, gap - 1.5 * t)
I, J, _, ov, WI, _, WO = bench_beds.find_contacts(xc, rc_, sidec)
bad, badw = bench_tiling.start_overlap_violations(rc_, I, J, ov, WI, WO)
seam_pairs = 2 * (k - 1) * m * nz
c.check("closer_tiles_flagged", len(bad) == seam_pairs and not badw,
        f"{len(bad)} pairs and {len(badw)} walls flagged, want {seam_pairs} seam pairs")
bad_ids = {tuple(sorted((int(idc[i]), int(idc[j])))) for i, j, _ in bad}
try:
    bench_scenes.make_scene(out, "test", "soft_mono_close", save_bed(out, "close", xc, rc_, idc, sidec), 1)
    c.check("stepper_refuses_closer_tiles", False, "build/jdem accepted overlaps of 2.5 t")
except RuntimeError as e:
    msg = str(e)
    named = [tuple(sorted(map(int, p))) for p in
             re.findall(r"particles (\d+) and (\d+) overlap", msg)]
    c.check("stepper_refuses_closer_tiles", len(named) == 1 and named[0] in bad_ids,
            f"stepper's message names {named}; flagged {len(bad_ids)} pairs; message: {msg[-300:]}")

# bonded variant: the rule bonds exactly the pairs in contact, at a dt no longer than without bonds
sc, dt_b = bench_scenes.make_scene(out, "test", "soft_mono_bonded", bed, 1)
p = engines.resolve(sc, binary=JDEM)
res = yaml.load(p.stdout, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)) if p.returncode == 0 else {}
nb = len(res.get("bonds") or [])
c.check("bonded_every_contact", nb == pairs, f"{nb} bonds, want {pairs}; {p.stderr.strip()[-300:]}")
c.check("bonded_dt_from_guard", 0 < dt_b <= dt, f"bonded dt {dt_b}, unbonded {dt}")

# the bench's decks (scene dict built from the bed and jdem's step-0 bonds, bench_scenes.resolved_scene)
# against the reference path: scene_to_liggghts.py on the whole `jdem resolve` output
def deck_files(dd):
    return {f: open(os.path.join(dd, f), "rb").read() for f in sorted(os.listdir(dd))
            if f in ("in.bench", "particles.data") or f.startswith("bonds_")}


for variant in ("soft_mono", "soft_mono_bonded"):
    sc = bench_scenes.scene_path(out, "test", variant)
    decks = bench_scenes.make_decks(out, "test", variant, sc, bed, 1)
    for engine, deck in sorted(decks.items()):
        dd = os.path.dirname(deck)
        fast = deck_files(dd)
        for f in fast:
            os.remove(os.path.join(dd, f))
        resolved = os.path.join(dd, "resolved.yaml")
        p = engines.write_deck(resolved, deck, "--trajectory", os.path.join(dd, "out.h5"),
                               *(["--builtin"] if engine == "liggghts" else []))
        with open(deck) as f:
            text = bench_scenes.adapt_deck(f.read(), engine, 1)
        with open(deck, "w") as f:
            f.write(text)
        ref = deck_files(dd)
        c.check(f"deck_{variant}_{engine}", p.returncode == 0 and fast == ref and len(ref) == 2 + (
            variant.endswith("bonded")), f"files {sorted(fast)} vs {sorted(ref)}, differing: "
            f"{[f for f in ref if fast.get(f) != ref[f]]}; {p.stderr.strip()[-300:]}")
c.exit()
