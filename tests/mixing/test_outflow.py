#!/usr/bin/python3
"""scripts/mixing/outflow.py on a synthetic trajectory: four particles falling at 2 m/s in the
band under a cylinder at +-10 and +-30 degrees from the vertical in each of 3 frames (spread:
the sample std of the 12 pooled angles, sqrt(6000/11) = 23.35 deg; mean 0), and three that must be left out: one above the
band, one resting in it, one beyond it in x; an empty slot (id -1) is skipped."""
import math
import os
import tempfile

import h5py
import numpy as np

from tests.mixing.common import check, close, finish
from scripts.mixing import outflow

CX, CZ, RC = 0.3, 1.5, 0.05
angles = np.radians([10.0, -10.0, 30.0, -30.0])
pos = [[CX + 0.05 * k, 0.5, CZ - 4 * RC] for k in range(4)] + \
      [[CX, 0.5, CZ + 0.2], [CX, 0.5, CZ - 3 * RC], [CX + 0.4, 0.5, CZ - 3 * RC], [CX, 0.5, CZ - 3 * RC]]
vel = [[2 * math.sin(a), 0.0, -2 * math.cos(a)] for a in angles] + \
      [[0.0, 0.0, -2.0], [0.0, 0.0, 0.0], [0.0, 0.0, -2.0], [0.0, 0.0, -2.0]]
frames = 3
ids = np.tile(np.array([1, 2, 3, 4, 5, 6, 7, -1]), (frames, 1))
path = os.path.join(tempfile.mkdtemp(), "outflow.h5")
with h5py.File(path, "w") as f:
    p = f.create_group("particles/all")
    p["id/value"] = ids
    p["position/value"] = np.tile(np.array(pos)[None], (frames, 1, 1))
    p["velocity/value"] = np.tile(np.array(vel)[None], (frames, 1, 1))
got = outflow.spread(path, [(CX, CZ, RC)])[0]
check("outflow_band_members", got["n"] == 4 * frames, f"{got}")
close("outflow_mean", got["mean"], 0.0, 1e-12)
want = float(np.std(np.tile([10.0, -10.0, 30.0, -30.0], frames), ddof=1))
close("outflow_spread", got["std"], want, 1e-9)
close("outflow_spread_value", want, math.sqrt(2000 * frames / (4 * frames - 1)), 1e-9)
finish()
