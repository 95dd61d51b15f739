"""bench_config.py — the definitions of the performance benchmark (scripts/bench.py): its beds'
sizes, materials and variants, the engines it times, and the small helpers every part shares
(the scene templates of reference_runs/bench/, the open box's walls, the stepper's safe dt)."""
import math
import os
import string
import sys
import time

from scripts.engines import ROOT, guard_dt

TEMPLATES = os.path.join(ROOT, "reference_runs", "bench")

E_SOFT, E_STIFF = 1.0e7, 7.0e10
R_SMALL, R_LARGE = 1.0e-3, 2.0e-3
LAYERS = 20                       # lattice layers before settling
TOUCH = 5e-7                      # contact overlap of the bench beds, fraction of the smallest radius
ETA_ROLL = 0.1                    # rolling-friction coefficient of the "roll" variants
SIZES = {"5k": 5000, "20k": 20000, "80k": 80000, "320k": 320000, "1M": 1000000}
# The large beds are k x k lateral copies of the settled, relaxed 20k bed (bench_tiling.py):
# settling 1M spheres would take ~1.5 h.  N: 81 920, 327 680 and 1 003 520.
TILES = {"80k": ("20k", 2), "320k": ("20k", 4), "1M": ("20k", 7)}
STEPS = {"5k": 2000, "20k": 500, "80k": 200, "320k": 100, "1M": 50}
SETTLE_TIME = {"mono": 0.12, "bi": 0.15}
VARIANTS = [(stiff, disp, roll) for stiff in ("soft", "stiff") for disp in ("mono", "bi")
            for roll in ("", "_roll")]
# The bonded beds: the same beds with a parallel bond between every touching pair, formed at
# step 0 (no rolling resistance; stock LIGGGHTS has no parallel bonds: jdem and liggghts-jdem only)
BONDED_VARIANTS = ["%s_%s_bonded" % (stiff, disp) for stiff in ("soft", "stiff") for disp in ("mono", "bi")]
VARIANT_NAMES = ["%s_%s%s" % v for v in VARIANTS] + BONDED_VARIANTS
ENGINES = ("jdem", "liggghts-jdem", "liggghts")
# Bonds of the bonded variants: axial stiffness per area kn = E / (2 R_small) (a bond as stiff as
# a column of the grains' material between the two centres), kt = kn / (2 (1 + nu)) (the shear
# modulus' ratio), strengths 1e9 Pa: ~1e5 x the stresses a 4 cm bed's weight puts on a bond, so
# the bed stays intact while the failure test is still evaluated every step.  The bond rule
# bonds pairs whose surfaces are at most BOND_MAX_GAP x the smaller radius apart: the relaxed
# beds' contacts all overlap (by TOUCH), so these are exactly the pairs in contact at step 0.
BOND_STRENGTH = 1.0e9
BOND_MAX_GAP = 1.0e-9
# A single engine run that takes longer than this is reported as failed (and the bench goes on)
RUN_TIMEOUT_S = 3600.0
PROFILE_MAX_SIZE = "20k"          # the callgrind profile runs on the smallest size, if not above this
FLATNESS_TARGET = 1.25            # jdem's cost per particle-step within 1.25x from 5k to 1M (flat in N)


def is_bonded(variant):
    return variant.endswith("_bonded")


def variant_dispersity(variant):
    return variant.split("_")[1]


def log(msg):
    sys.stderr.write("[bench %s] %s\n" % (time.strftime("%H:%M:%S"), msg))
    sys.stderr.flush()


def num(x):
    return repr(float(x))


def walls_yaml(side, height):
    L, H = num(side), num(height)
    rows = [("floor", "[[0, 0, 0], [%s, 0, 0], [%s, %s, 0], [0, %s, 0]]" % (L, L, L, L)),
            ("x_low", "[[0, 0, 0], [0, %s, 0], [0, %s, %s], [0, 0, %s]]" % (L, L, H, H)),
            ("x_high", "[[%s, 0, 0], [%s, 0, %s], [%s, %s, %s], [%s, %s, 0]]" % (L, L, H, L, L, H, L, L)),
            ("y_low", "[[0, 0, 0], [0, 0, %s], [%s, 0, %s], [%s, 0, 0]]" % (H, L, H, L)),
            ("y_high", "[[0, %s, 0], [%s, %s, 0], [%s, %s, %s], [0, %s, %s]]" % (L, L, L, L, L, H, L, H))]
    return "\n".join("  - {name: %s, type: plane, corners: %s, material: wall}" % r for r in rows)


def fill(template, **kw):
    with open(os.path.join(TEMPLATES, template)) as f:
        return string.Template(f.read()).substitute(**{k: str(v) for k, v in kw.items()})


def safe_dt(scene_path):
    """guard_dt() rounded down to two significant digits."""
    v = guard_dt(scene_path)
    e = math.floor(math.log10(v)) - 1
    return math.floor(v / 10.0 ** e) * 10.0 ** e
