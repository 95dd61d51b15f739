"""Volume of a particle (radius R) inside a measuring sphere (radius r), centres d apart.

The seed's eqs (39)-(40) build the lens from two caps through arcsin/arccos and fail when the
measuring centre lies deep inside the particle; the closed form below (spec §2.2) is the same
lens for every overlap, and the two "inside" cases are handled first.
"""
import math

import numpy as np


def lens_volume(d, R, r):
    """Volume [m^3] of the intersection of two spheres of radii R and r whose centres are d apart
    (arrays broadcast)."""
    d, R, r = np.broadcast_arrays(np.asarray(d, dtype=float), np.asarray(R, dtype=float),
                                  np.asarray(r, dtype=float))
    out = np.zeros(d.shape)
    inner = d <= np.abs(r - R)
    small = np.minimum(R, r)
    out[inner] = 4.0 / 3.0 * math.pi * small[inner] ** 3
    part = (~inner) & (d < R + r)
    dp, Rp, rp = d[part], R[part], r[part]
    out[part] = (math.pi * (Rp + rp - dp) ** 2
                 * (dp ** 2 + 2 * dp * rp - 3 * rp ** 2 + 2 * dp * Rp + 6 * rp * Rp - 3 * Rp ** 2)
                 / (12.0 * dp))
    return out
