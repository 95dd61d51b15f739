"""outflow.py — the angular spread of the flow leaving each obstacle (Jiang (2021) Ch. 5's claim
that broken weak blocks scatter the flow into "a wider range of reflection angles"; the seed
measures nothing, so this is ours [RECON]).

From every frame of a fill (either engine's trajectory): the particles in flight in a band
under each cylinder obstacle, centres within BAND_X of its axis in x and BAND_Z below it
(from 2 to 7 cylinder radii under the axis), falling faster than MIN_FALL_SPEED (so the heap
and particles resting on each other are out); each one's direction from the vertical,
theta = atan2(vx, -vz) in degrees (positive: to +x).  Pooled over the frames, the spread is the
standard deviation of theta; the mean says where the stream goes.
"""
import h5py
import numpy as np

BAND_X = 0.3           # [m] half-width of the band in x about the cylinder's axis
BAND_Z = (2.0, 7.0)    # the band's top and bottom under the axis, in cylinder radii
MIN_FALL_SPEED = 0.5   # [m/s]


def spread(path, cylinders):
    """[{"x", "z", "n", "mean", "std"}] (deg) per cylinder (x, z, radius) of the fill at path."""
    theta = [[] for _ in cylinders]
    with h5py.File(path, "r") as f:
        p = f["particles/all"]
        ids, x, v = p["id"], p["position/value"], p["velocity/value"]
        series = isinstance(ids, h5py.Group)
        for k in range(x.shape[0]):   # each frame read once, for every cylinder
            live = (ids["value"][k] if series else ids[()]) >= 0
            xk, vk = x[k][live], v[k][live]
            falling = -vk[:, 2] > MIN_FALL_SPEED
            for t, (cx, cz, rc) in zip(theta, cylinders):
                below = cz - xk[:, 2]
                band = (falling & (np.abs(xk[:, 0] - cx) < BAND_X) & (below > BAND_Z[0] * rc) &
                        (below < BAND_Z[1] * rc))
                t.append(np.degrees(np.arctan2(vk[band, 0], -vk[band, 2])))
    out = []
    for t, (cx, cz, _) in zip(theta, cylinders):
        t = np.concatenate(t) if t else np.zeros(0)
        out.append({"x": cx, "z": cz, "n": int(len(t)),
                    "mean": float(np.mean(t)) if len(t) else float("nan"),
                    "std": float(np.std(t, ddof=1)) if len(t) > 1 else float("nan")})
    return out
