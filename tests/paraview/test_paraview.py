#!/usr/bin/python3
"""ParaView opens jdem's trajectories as they are, walls, bonds and growing particle sets
included.  Each case is run by its engine and its sidecar opened by Debian's ParaView
(`xvfb-run -a pvbatch tests/paraview/pv_probe.py`) with the default reader:
  pour    reference_runs/pour (576 spheres, a box and a bar), shortened     both engines
  block   the bonded block drop (tests/liggghts/bond_scenes/block_drop.yaml) both engines
  co1     Chung-Ooi test 1 (tests/engine/scenes/chung_ooi_1.yaml)           both engines
  inlet   the conveyor fill (tests/inlet/fill_small.yaml), a growing set    build/jdem
  insert  fix insert/pack (tests/paraview/insert_pack.in), a growing set    liggghts-jdem
  tray    five spheres in an STL tray (floor and four sides, 10 triangles) both engines
Checks, each against the .h5 read with h5py: scripts/h5md_check.py passes; the reader is
Xdmf3ReaderS; time steps = frames; at the middle and the last frame the particle points and
vertex cells = the live particles (ids >= 0) and every particle array is there; the bond line
cells = the bonds formed by then and not broken by then (from /jdem/bonds, /jdem/broken_bonds);
the wall cells = 1 per plane + 32 per cylinder + 1 per mesh triangle (/jdem/walls/type and
/jdem/walls/mesh/wall); a growing set grows.  The
PNG of the last frame (spheres blue, walls grey, bonds red, white background) has spheres, grey
pixels over at least a tenth of the walls' extent and red ones in the bonds' extent.
And the seed's Fig. 5-4 from both engines' sidecars holds the Ch. 5 section's spheres and
bonds (scripts/mixing/section_ch5.py).  Needs `make paraview-deps`.  One line per check: "PASS name" / "FAIL name: detail".

    test_paraview.py [--pngs DIR]   (DIR: keep each PNG as DIR/{j,l}_CASE.png; the pour runs
                                      its full length then)
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import matplotlib.image as mpimg
from tests.mesh.stl_files import write_binary_stl
import numpy as np

from scripts import engines

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PROBE = os.path.join(ROOT, "tests", "paraview", "pv_probe.py")
ARRAYS = sorted(["radius", "id", "species", "velocity", "angular_velocity", "force", "torque"])
CYLINDER_FACETS = 32  # io/h5md.h JD_H5MD_CYLINDER_FACETS
CASES = [("pour", "reference_runs/pour/scene.yaml", ("jdem", "liggghts-jdem")),
         ("block", "tests/liggghts/bond_scenes/block_drop.yaml", ("jdem", "liggghts-jdem")),
         ("co1", "tests/engine/scenes/chung_ooi_1.yaml", ("jdem", "liggghts-jdem")),
         ("inlet", "tests/inlet/fill_small.yaml", ("jdem",)),
         ("insert", "tests/paraview/insert_pack.in", ("liggghts-jdem",)),
         ("tray", None, ("jdem", "liggghts-jdem"))]
failed = 0


def check(name, ok, detail=""):
    global failed
    print(f"PASS {name}" if ok else f"FAIL {name}: {detail}")
    sys.stdout.flush()
    failed += not ok
    return ok


def short_pour(tmp):
    """The pour to 0.1 s (the spheres reach the bar), frames every 1000 steps."""
    text = open(os.path.join(ROOT, "reference_runs", "pour", "scene.yaml")).read()
    text = text.replace("end_time: 0.6", "end_time: 0.1").replace("every: 2000", "every: 1000")
    path = os.path.join(tmp, "pour.yaml")
    open(path, "w").write(text)
    return path


def tray_triangles(L=0.04, H=0.02):
    """An open box [0, L]^2 x [0, H] as an STL mesh: each triangle counter-clockwise seen from
    inside (its right-hand normal points at the particles), as the box walls of the pour."""
    o, x, y, xy = (0.0, 0.0, 0.0), (L, 0.0, 0.0), (0.0, L, 0.0), (L, L, 0.0)
    up = lambda p: (p[0], p[1], H)
    return [(o, x, xy), (o, xy, y),                                  # floor, normal +z
            (o, y, up(y)), (o, up(y), up(o)),                        # x = 0, normal +x
            (x, up(x), up(xy)), (x, up(xy), xy),                     # x = L, normal -x
            (o, up(o), up(x)), (o, up(x), x),                        # y = 0, normal +y
            (y, xy, up(xy)), (y, up(xy), up(y))]                     # y = L, normal -y


def tray_scene(tmp):
    """Five spheres dropped into the meshed tray (binary STL, float32 corners)."""
    write_binary_stl(os.path.join(tmp, "tray.stl"), tray_triangles())
    drops = "\n".join("  - {material: glass, radius: 0.003, position: [%r, %r, %r]}" % (
        0.02 + 0.01 * np.cos(2 * np.pi * k / 5), 0.02 + 0.01 * np.sin(2 * np.pi * k / 5), 0.008 + 0.001 * k)
        for k in range(5))
    path = os.path.join(tmp, "tray.yaml")
    with open(path, "w") as f:
        f.write("jdem_scene: 1\nname: paraview_tray\ntime: {dt: 1.0e-5, steps: 3000}\n"
                "output: {every: 500}\ngravity: [0, 0, -9.81]\nmaterials:\n"
                "  glass: {youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500, restitution: 0.5,"
                " friction: 0.3}\n  plate: {restitution: 0.5, friction: 0.3}\n"
                "particles:\n%s\nwalls:\n  - {name: tray, type: mesh, file: tray.stl, material: plate}\n"
                % drops)
    return path


def run_case(engine, scene, out):
    if scene.endswith(".in"):  # a LIGGGHTS deck of its own; LIGGGHTS writes its log in cwd
        cmd = [engines.LIGGGHTS_JDEM, "-in", scene, "-var", "out", out, "-log", "none"]
    elif engine == "jdem":
        cmd = [engines.JDEM, "run", "--quiet", scene, "-o", out]
    else:
        cmd = engines.script("liggghts_run", scene, "-o", out)
    return engines.run(cmd, cwd=os.path.dirname(out))


def probe(xdmf, png):
    """pvbatch's report, or None.  pvbatch 5.11 under xvfb-run now and then dies before it has
    read anything (its X connection fails at start-up, more often on a loaded machine): up to
    three tries, each said."""
    for attempt in range(3):
        r = subprocess.run(["xvfb-run", "-a", "pvbatch", PROBE, xdmf, png], capture_output=True,
                           text=True)
        lines = [l for l in r.stdout.splitlines() if l.startswith("{")]
        if lines:
            return json.loads(lines[-1]), r
        print(f"(pvbatch gave no report, exit {r.returncode}: {r.stderr.strip()[-200:]!r})")
    return None, r


def expected(path):
    """What the reader must show, from the .h5: live particles and intact bonds per frame."""
    with h5py.File(path, "r") as f:
        steps = f["particles/all/position/step"][()]
        ids = f["particles/all/id"]
        if isinstance(ids, h5py.Group):
            live = (ids["value"][()] >= 0).sum(axis=1)
        else:
            live = np.full(len(steps), ids.shape[0])
        bonds = np.zeros(len(steps), dtype=int)
        if "jdem/bonds" in f:
            pairs = [tuple(p) for p in f["jdem/bonds/ids"][()]]
            formed = f["jdem/bonds/formed_step"][()]
            broke = {}
            if "jdem/broken_bonds" in f:
                for p, s in zip(f["jdem/broken_bonds/ids"][()], f["jdem/broken_bonds/step"][()]):
                    broke.setdefault(tuple(p), int(s))
            for k, s in enumerate(steps):
                bonds[k] = sum(1 for p, fs in zip(pairs, formed)
                               if fs <= s and broke.get(p, np.iinfo(np.int64).max) > s)
        types = f["jdem/walls/type"][()] if "jdem/walls" in f else np.zeros(0)
        quad_wall = f["jdem/walls/mesh/wall"][()] if "jdem/walls" in f else np.zeros(0)
        walls = int(sum(CYLINDER_FACETS if t == 1 else int(np.sum(quad_wall == k)) if t == 2 else 1
                        for k, t in enumerate(types)))
    return steps, live, bonds, walls


def frame_checks(tag, info, steps, live, bonds, walls):
    for label, k in (("middle", len(steps) // 2), ("last", len(steps) - 1)):
        fr = info["frames"][label]
        p = fr["particles"]
        check(f"{tag} {label} frame: {live[k]} particle points", p["points"] == live[k],
              str(p["points"]))
        check(f"{tag} {label} frame: {live[k]} vertex cells", p["cells"] == live[k], str(p["cells"]))
        if live[k]:
            check(f"{tag} {label} frame: every particle array", p["arrays"] == ARRAYS,
                  str(p["arrays"]))
        check(f"{tag} {label} frame: {bonds[k]} bond lines", fr["bonds"]["cells"] == bonds[k],
              str(fr["bonds"]["cells"]))
        check(f"{tag} {label} frame: {walls} wall quadrilaterals", fr["walls"]["cells"] == walls,
              str(fr["walls"]["cells"]))


def colour_fraction(img, box, kind):
    if box is None:
        return 0.0
    x0, y0, x1, y1 = box
    px = img[y0:y1, x0:x1]
    if px.size == 0:
        return 0.0
    r, g, b = px[..., 0], px[..., 1], px[..., 2]
    hi, lo = np.maximum(np.maximum(r, g), b), np.minimum(np.minimum(r, g), b)
    if kind == "grey":
        sel = (hi - lo < 0.08) & (hi < 0.9) & (hi > 0.2)
    else:  # red
        sel = (r - np.maximum(g, b) > 0.3)
    return float(sel.mean())


def png_checks(tag, png, info, bonds, walls):
    img = mpimg.imread(png)[:, :, :3]
    blue = (img[..., 2] - img[..., 0] > 0.2).mean()
    check(f"{tag} PNG has spheres (blue fraction {blue:.3f})", blue > 0.001, f"{blue:.4f}")
    if walls:
        frac = colour_fraction(img, info["boxes"]["walls"], "grey")
        check(f"{tag} PNG shows the walls (grey over {frac:.2f} of their extent)", frac > 0.1,
              f"{frac:.3f} in {info['boxes']['walls']}")
    if bonds[-1]:
        frac = colour_fraction(img, info["boxes"]["bonds"], "red")
        check(f"{tag} PNG shows the bonds (red over {frac:.2f} of their extent)", frac > 0.02,
              f"{frac:.3f} in {info['boxes']['bonds']}")


def one(case, scene, engine, tmp, pngs):
    tag = f"{engine} {case}"
    out = os.path.join(tmp, engine, case, f"{case}.h5")
    os.makedirs(os.path.dirname(out))
    r = run_case(engine, scene, out)
    if not check(f"{tag} run", r.returncode == 0, (r.stderr or r.stdout)[-400:]):
        return
    c = engines.run(engines.script("h5md_check", out))
    check(f"{tag} H5MD conformance", c.returncode == 0,
          "; ".join(l for l in c.stdout.splitlines() if l.startswith("FAIL"))[-400:])
    steps, live, bonds, walls = expected(out)
    if case in ("inlet", "insert"):
        check(f"{tag} the particle set grows ({live[0]} -> {live[-1]})",
              live[-1] > live[0] and np.all(np.diff(live) >= 0), str(list(live)))
    png = os.path.join(tmp, engine, case, "last.png")
    info, pr = probe(out[:-3] + ".xdmf", png)
    if not check(f"{tag} pvbatch report", info is not None, pr.stderr[-400:]):
        return
    check(f"{tag} default reader", info["reader"] == "Xdmf3ReaderS", info["reader"])
    check(f"{tag} time steps = frames ({len(steps)})", info["times"] == len(steps),
          str(info["times"]))
    frame_checks(tag, info, steps, live, bonds, walls)
    png_checks(tag, png, info, bonds, walls)
    if pngs:
        shutil.copy(png, os.path.join(pngs, f"{engine[0]}_{case}.png"))


def refuses_without_grow(tmp):
    """dump h5md/jdem grow no: a changing atom count stops the run with the message that names
    the keyword, and no trajectory is published."""
    out = os.path.join(tmp, "grow_no", "g.h5")
    os.makedirs(os.path.dirname(out))
    r = engines.run([engines.LIGGGHTS_JDEM, "-in", os.path.join(ROOT, "tests", "paraview", "insert_pack.in"),
                     "-var", "out", out, "-var", "dumpkw", "grow no", "-log", "none"], cwd=os.path.dirname(out))
    want = ("ERROR: dump h5md/jdem: the number of atoms changed (0 -> 12); give the dump "
            "'grow yes' for a particle set that changes")
    check("liggghts-jdem grow no: a growing set is refused by name",
          r.returncode != 0 and want in r.stdout + r.stderr and not os.path.exists(out),
          (r.stdout + r.stderr)[-300:])


def ch5_section(tmp):
    """The seed's Fig. 5-4 (scripts/mixing/section_ch5.py): ParaView draws the first section of
    the Ch. 5 stream from each engine's sidecar with its 4 big and 512 small spheres and 16 x 60
    bonds (a 2 x 2 x 8 block: 4 x 7 bonds along its axis, 4 x 8 across); the script stops with
    the counts when they differ."""
    out = os.path.join(tmp, "section")
    r = subprocess.run([sys.executable, "-m", "scripts.mixing.section_ch5", "--out", out, "--results", out],
                       cwd=ROOT, capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=ROOT))
    check("ch5 section: ParaView draws 4 big, 512 small spheres and 960 bonds in both engines",
          r.returncode == 0 and "4 big and 512 small spheres, 16 blocks of 2 x 2 x 8 and 960 bonds" in r.stdout
          and os.path.exists(os.path.join(out, "fig5-4.png")), (r.stdout + r.stderr)[-500:])


def main(argv):
    pngs = os.path.abspath(argv[argv.index("--pngs") + 1]) if "--pngs" in argv else None
    if not shutil.which("pvbatch") or not shutil.which("xvfb-run"):
        check("paraview installed", False, "pvbatch or xvfb-run missing: run make paraview-deps")
        return 1
    tmp = tempfile.mkdtemp(prefix="jdem_paraview_")
    for case, scene, case_engines in CASES:
        path = tray_scene(tmp) if case == "tray" else os.path.join(ROOT, scene)
        if case == "pour" and not pngs:
            path = short_pour(tmp)
        for engine in case_engines:
            one(case, path, engine, tmp, pngs)
    refuses_without_grow(tmp)
    ch5_section(tmp)
    if not failed:
        shutil.rmtree(tmp, ignore_errors=True)
    else:
        print(f"(files kept in {tmp})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
