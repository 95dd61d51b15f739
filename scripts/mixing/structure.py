"""structure.py — the shape and packing of a settled deposit, for Jiang (2021) Ch. 5's claim that
strong bonds "leave an inclined free surface and more voids near the walls" (spec §3.8).  The
seed shows this in pictures only; these measures are ours [RECON].

free_surface: the deposit's top as a height map, the top (z + R) of the bed in each
SURFACE_CELL x SURFACE_CELL column of the box: the highest particle that the column's particles
reach from the bottom up without a vertical gap of more than BED_GAP between one particle's top
and the next one's bottom (spheres resting on an obstacle above the bed are not its surface),
and the plane z = a + b x + c y fitted to it by
least squares; its inclination atan(sqrt(b^2 + c^2)) in degrees and the slope along x (the
feed direction), from the columns inside the walls by more than WALL_BAND (a heap against a
wall is not the free surface).
packing: the solid fraction near the side walls (within WALL_BAND of x = lo/hi or y = lo/hi) and
in the interior (farther than INTERIOR from each), in the layer from FLOOR_BAND above the floor
to SURFACE_BAND under the lowest column of the height map, measured at a fixed, seeded set of
random points: the fraction that lies inside a sphere.
"""
import numpy as np

SURFACE_CELL = 0.05   # [m] height-map column width (> the big diameter, 0.06 m, no empty columns)
WALL_BAND = 0.06      # [m] two small diameters, one big one
INTERIOR = 0.15       # [m]
FLOOR_BAND = 0.06     # [m]
SURFACE_BAND = 0.06   # [m]
BED_GAP = 0.06        # [m] a big diameter: more than any gap inside a settled bed
SAMPLES = 200000      # random points per region: the fraction's standard error ~ 1e-3
SEED = 20211


def bed_top(bottom, top):
    """The top [m] of the stack of a column's particles (bottoms and tops [m]) reached from the
    lowest without a gap of more than BED_GAP."""
    order = np.argsort(bottom, kind="stable")
    bottom, top = bottom[order], np.maximum.accumulate(top[order])
    gaps = np.nonzero(bottom[1:] - top[:-1] > BED_GAP)[0]
    return float(top[gaps[0]] if len(gaps) else top[-1])


def height_map(dep, lo, hi, cell=SURFACE_CELL):
    """(x, y, h) of the columns' centres [m] and the bed's heights [m] (bed_top), the columns
    without particles out."""
    nx, ny = (int(round((hi[k] - lo[k]) / cell)) for k in (0, 1))
    i = np.clip(((dep.position[:, 0] - lo[0]) / cell).astype(int), 0, nx - 1)
    j = np.clip(((dep.position[:, 1] - lo[1]) / cell).astype(int), 0, ny - 1)
    column = i * ny + j
    z, r = dep.position[:, 2], dep.radius
    h = np.full(nx * ny, -np.inf)
    order = np.argsort(column, kind="stable")
    starts = np.searchsorted(column[order], np.arange(nx * ny + 1))
    for c in range(nx * ny):
        members = order[starts[c]:starts[c + 1]]
        if len(members):
            h[c] = bed_top(z[members] - r[members], z[members] + r[members])
    cx, cy = np.meshgrid(lo[0] + cell * (np.arange(nx) + 0.5), lo[1] + cell * (np.arange(ny) + 0.5),
                         indexing="ij")
    ok = np.isfinite(h)
    return cx.ravel()[ok], cy.ravel()[ok], h[ok]


def free_surface(dep, lo, hi):
    """{"inclination", "slope_x" (deg), "mean", "lowest", "highest" (m), "columns"} of the plane
    fitted to the height map inside the walls' bands."""
    x, y, h = height_map(dep, lo, hi)
    inner = ((x > lo[0] + WALL_BAND) & (x < hi[0] - WALL_BAND) & (y > lo[1] + WALL_BAND) &
             (y < hi[1] - WALL_BAND))
    x, y, h = x[inner], y[inner], h[inner]
    (a, b, c), *_ = np.linalg.lstsq(np.column_stack([np.ones_like(x), x, y]), h, rcond=None)
    return {"inclination": float(np.degrees(np.arctan(np.hypot(b, c)))),
            "slope_x": float(np.degrees(np.arctan(b))), "mean": float(np.mean(h)),
            "lowest": float(np.min(h)), "highest": float(np.max(h)), "columns": int(len(h))}


def covered(dep, points):
    """Boolean mask of the points that lie inside a sphere (one k-d tree per radius)."""
    from scipy.spatial import cKDTree
    inside = np.zeros(len(points), bool)
    for r in np.unique(dep.radius):
        centres = dep.position[dep.radius == r]
        d, _ = cKDTree(centres).query(points, distance_upper_bound=r)
        inside |= d < r
    return inside


def packing(dep, lo, hi):
    """{"wall", "interior" (solid fractions), "top" (m): the layer's top, "samples"}: the layer from
    FLOOR_BAND over the floor to SURFACE_BAND under the lowest column of the height map."""
    top = float(np.min(height_map(dep, lo, hi)[2])) - SURFACE_BAND
    rng = np.random.default_rng(SEED)
    z0 = lo[2] + FLOOR_BAND
    if top <= z0:
        return {"wall": float("nan"), "interior": float("nan"), "top": top, "samples": 0}
    out = {"top": top, "samples": SAMPLES}
    for name, want in (("wall", lambda d: d < WALL_BAND), ("interior", lambda d: d > INTERIOR)):
        points = np.zeros((0, 3))
        while len(points) < SAMPLES:   # rejection sampling of the region's plan
            p = rng.uniform([lo[0], lo[1], z0], [hi[0], hi[1], top], size=(SAMPLES, 3))
            to_wall = np.minimum.reduce([p[:, 0] - lo[0], hi[0] - p[:, 0], p[:, 1] - lo[1], hi[1] - p[:, 1]])
            points = np.vstack([points, p[want(to_wall)]])
        out[name] = float(np.mean(covered(dep, points[:SAMPLES])))
    return out
