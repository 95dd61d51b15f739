#!/usr/bin/python3
"""ParaView opens jdem's trajectories as they are (issue: the sidecar showed 0 points in the
default reader).  For each engine (build/jdem, build/liggghts-jdem through
scripts/liggghts_run.py), a shortened copy of the 216-sphere lattice_floor scene is run and its
sidecar opened by Debian's ParaView (`xvfb-run -a pvbatch tests/paraview/pv_probe.py`) with the
default reader.  Checks, against the .h5 read with h5py: the reader is Xdmf3ReaderS, the number
of time steps is the number of frames, the middle and the last frame have one point and one
vertex cell per particle and every particle array; and the PNG of the last frame (spheres scaled
by radius, white background) has non-background pixels where the particles are.
Needs `make paraview-deps`.  One line per check: "PASS name" / "FAIL name: detail".
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import matplotlib.image as mpimg
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "tests", "engine", "scenes", "lattice_floor.yaml")
PROBE = os.path.join(ROOT, "tests", "paraview", "pv_probe.py")
ARRAYS = sorted(["radius", "id", "species", "velocity", "angular_velocity", "force", "torque"])
failed = 0


def check(name, ok, detail=""):
    global failed
    print(f"PASS {name}" if ok else f"FAIL {name}: {detail}")
    sys.stdout.flush()
    failed += not ok
    return ok


def short_scene(tmp):
    text = open(SCENE).read().replace("steps: 40000", "steps: 4000").replace(
        "every: 10000", "every: 1000")
    path = os.path.join(tmp, "lattice_floor.yaml")
    open(path, "w").write(text)
    return path


def run_engine(engine, scene, out):
    if engine == "jdem":
        cmd = [os.path.join(ROOT, "build", "jdem"), "run", "--quiet", scene, "-o", out]
    else:
        cmd = ["/usr/bin/python3", os.path.join(ROOT, "scripts", "liggghts_run.py"), scene, "-o", out]
    return subprocess.run(cmd, capture_output=True, text=True)


def probe(xdmf, png):
    """pvbatch's report, or None.  pvbatch 5.11 under xvfb-run now and then dies before it has
    read anything (a display start-up failure, seen about once in ten runs): one retry, said."""
    for attempt in range(2):
        r = subprocess.run(["xvfb-run", "-a", "pvbatch", PROBE, xdmf, png], capture_output=True,
                           text=True)
        lines = [l for l in r.stdout.splitlines() if l.startswith("{")]
        if lines:
            return json.loads(lines[-1]), r
        print(f"(pvbatch gave no report, exit {r.returncode}: {r.stderr.strip()[-200:]!r})")
    return None, r


def main():
    if not shutil.which("pvbatch") or not shutil.which("xvfb-run"):
        check("paraview installed", False, "pvbatch or xvfb-run missing: run make paraview-deps")
        return 1
    tmp = tempfile.mkdtemp(prefix="jdem_paraview_")
    scene = short_scene(tmp)
    for engine in ("jdem", "liggghts-jdem"):
        out = os.path.join(tmp, engine, "lattice.h5")
        os.makedirs(os.path.dirname(out))
        r = run_engine(engine, scene, out)
        if not check(f"{engine} run", r.returncode == 0, r.stderr[-400:]):
            continue
        with h5py.File(out, "r") as f:
            n = f["particles/all/id"].shape[0]
            nframes = f["particles/all/position/step"].shape[0]
        png = os.path.join(tmp, engine, "last.png")
        info, pr = probe(out[:-3] + ".xdmf", png)
        if not check(f"{engine} pvbatch report", info is not None, pr.stderr[-400:]):
            continue
        check(f"{engine} default reader", info["reader"] == "Xdmf3ReaderS", info["reader"])
        check(f"{engine} time steps = frames ({nframes})", info["times"] == nframes,
              str(info["times"]))
        for label in ("middle", "last"):
            fr = info["frames"][label]
            check(f"{engine} {label} frame: {n} points", fr["points"] == n, str(fr["points"]))
            check(f"{engine} {label} frame: {n} vertex cells", fr["cells"] == n, str(fr["cells"]))
            check(f"{engine} {label} frame: every particle array", fr["arrays"] == ARRAYS,
                  str(fr["arrays"]))
        img = mpimg.imread(png)[:, :, :3]
        content = np.any(img < 0.9, axis=2)
        frac = content.mean()
        # ResetCamera frames the particles' bounds: the middle third of the image is theirs
        h, w = content.shape
        centre = content[h // 3: 2 * h // 3, w // 3: 2 * w // 3].mean()
        check(f"{engine} PNG has spheres (non-background {frac:.3f}, centre {centre:.3f})",
              0.01 < frac < 0.9 and centre > 0.05, f"{frac:.4f} {centre:.4f}")
    if not failed:
        shutil.rmtree(tmp, ignore_errors=True)
    else:
        print(f"(files kept in {tmp})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
