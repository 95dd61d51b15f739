"""cube_scene.py — the scene of one compression cube cut from a deposit (spec §2.4), for the
Chapter 4 and Chapter 5 generators (reference_runs/mixing/ch{4,5}/generate.py).

A 0.2 m cube centred at a measurement point keeps the deposit's particles whose centres lie
inside it, and the bonds intact between them (particles_from, docs/scenes.md); five fixed walls
and a servo top wall stand at the outline of the kept particles, so that none starts inside a
wall [RECON].  The kept particles are `settled`: their contact overlaps are allowed at the start.
"""
import os

from scripts.mixing import deposit

CUBE = 0.2                # [TEXT] spec §2.4: side [m]
SEED_DT = 1.0e-4          # [TEXT] Tables 4-1 and 5-1 [s]
END_TIME = 10.0           # [s] the servo holds long before (docs/mixing.md §5)


def servo(target):
    """The servo top wall: `target` [Pa] +- 1 %; Ch. 4's 1000 +- 10 Pa is the seed's [TEXT], the
    gain, speed limit and hold are [RECON] (docs/mixing.md §5)."""
    return {"target": target, "gain": 1.0e-4, "tolerance": 0.01 * target, "max_speed": 0.02,
            "hold": 0.05}


def outline(cut):
    """The box that touches the kept particles (min(x - R)..max(x + R))."""
    r = cut.radius[:, None]
    return ((cut.position - r).min(axis=0).round(12).tolist(),
            (cut.position + r).max(axis=0).round(12).tolist())


def cube_walls(lo, hi, target):
    """Five fixed walls and the servo top, corners counter-clockwise seen from inside."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    quad = {
        "floor": [[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0]],
        "left": [[x0, y0, z0], [x0, y1, z0], [x0, y1, z1], [x0, y0, z1]],
        "right": [[x1, y0, z0], [x1, y0, z1], [x1, y1, z1], [x1, y1, z0]],
        "front": [[x0, y0, z0], [x0, y0, z1], [x1, y0, z1], [x1, y0, z0]],
        "back": [[x0, y1, z0], [x1, y1, z0], [x1, y1, z1], [x0, y1, z1]],
        "top": [[x0, y0, z1], [x0, y1, z1], [x1, y1, z1], [x1, y0, z1]],
    }
    walls = [{"name": n, "type": "plane", "corners": c, "material": "wall"} for n, c in quad.items()]
    walls[-1]["servo"] = servo(target)
    return walls


def cube_doc(case_doc, dep, deposit_path, centre, target, set_dt):
    """The case's scene (materials, bonds, model) turned into the cube at `centre` of the deposit
    `dep` (deposit.read_frame of deposit_path): no inlet, the cube's walls, the kept particles,
    10 s at the seed's dt rescaled by set_dt(doc, dt) to the case's."""
    lo, hi = (centre - CUBE / 2).round(12).tolist(), (centre + CUBE / 2).round(12).tolist()
    cut = deposit.keep_box(dep, lo, hi, source=deposit_path)
    doc = dict(case_doc)
    doc.pop("inlets", None)
    doc.pop("sweep", None)
    doc["walls"] = cube_walls(*outline(cut), target)
    doc["particles_from"] = [{"file": os.path.abspath(deposit_path), "frame": -1,
                              "region": {"lo": lo, "hi": hi}}]
    dt = doc["time"]["dt"]
    doc["time"] = {"dt": SEED_DT, "end_time": END_TIME,
                   "max_impact_speed": doc["time"]["max_impact_speed"]}
    doc["output"] = {"every": 1000, "observables_every": 100}   # 0.1 s, 0.01 s
    set_dt(doc, dt)
    return doc
