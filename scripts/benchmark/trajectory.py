"""Reading an H5MD trajectory and the impact kinematics of sphere 1 in the sign conventions."""
import math

import h5py
import numpy as np
import yaml

# ------------------------------------------------------------------------------------------------
# Sign conventions (fixed axes, measured once from the initial state of each run):
#   sphere 1 is particle id 1; the target is particle id 2 or, without a second particle, wall 0.
#   n  unit normal from sphere 1 towards the target (fixed for the whole impact);
#   t  unit tangent: direction of sphere 1's initial contact-point velocity in the tangent plane
#      (the scenes put it along +x);
#   b  = n x t, the spin axis: w = omega_1 . b, so that a spin w > 0 moves sphere 1's contact point
#      (lever R1 n) along +t: (w b) x (R1 n) = w R1 t.
#   V_cn  = (v1 - v2) . n       approach speed (> 0 before);  V'_cn = -(v1' - v2') . n  (> 0 after)
#   V_ct  = v1 . t              tangential velocity of sphere 1's centre
#   V_st  = [(v1 + omega1 x R1 n) - (v2 + omega2 x (-R2 n))] . t
#         = V_ct + (omega1 x r)_t for a resting target: slip of sphere 1's surface over the target
#   e_n = V'_cn/V_cn,  e_t = V'_ct/V_ct,  beta = -V'_st/V_st,  tan(recoil) = V'_st/V'_cn.
# ------------------------------------------------------------------------------------------------


class Run:
    """The parts of one H5MD trajectory the analysis needs."""

    def __init__(self, path):
        with h5py.File(path, "r") as f:
            part = f["particles/all"]
            self.time = part["position/time"][()]
            self.x = part["position/value"][()]
            self.v = part["velocity/value"][()]
            self.w = part["angular_velocity/value"][()]
            self.force = part["force/value"][()]
            self.mass = part["mass"][()]
            self.radius = part["radius"][()]
            self.obs = {k: f["observables"][k]["value"][()] for k in f["observables"]}
            text = f["parameters/scene"][()]
            self.scene = yaml.load(text.decode() if isinstance(text, bytes) else text, Loader=yaml.CSafeLoader)
        self.two_spheres = len(self.mass) == 2


def num(value):
    return float(value)


def pair_coefficient(run, key):
    """Restitution or friction between sphere 1 and its target: their interaction entry if the
    scene has one, else sphere 1's material value (pairs without an entry must agree)."""
    material = run.scene["particles"][0]["material"]
    target = (run.scene["particles"][1] if run.two_spheres else run.scene["walls"][0])["material"]
    for entry in run.scene.get("interactions") or []:
        if sorted(entry["materials"]) == sorted([material, target]) and key in entry:
            return num(entry[key])
    return num(run.scene["materials"][material][key])


def wall_plane(run):
    """Point and unit normal (active side) of wall 0."""
    p = np.array(run.scene["walls"][0]["corners"], dtype=float)
    normal = np.cross(p[1] - p[0], p[2] - p[0])
    return p[0], normal / np.linalg.norm(normal)


def overlap(run):
    """Overlap of sphere 1 with the target at every frame [m]."""
    if run.two_spheres:
        dist = np.linalg.norm(run.x[:, 1] - run.x[:, 0], axis=1)
        return run.radius[0] + run.radius[1] - dist
    point, normal = wall_plane(run)
    return run.radius[0] - (run.x[:, 0] - point) @ normal


def axes(run):
    """The fixed axes n, t, b of the sign conventions."""
    if run.two_spheres:
        d = run.x[0, 1] - run.x[0, 0]
        n = d / np.linalg.norm(d)
    else:
        n = -wall_plane(run)[1]
    surface = run.v[0, 0] + np.cross(run.w[0, 0], run.radius[0] * n)
    t = surface - (surface @ n) * n
    if np.linalg.norm(t) < 1e-12 * (np.linalg.norm(surface) + 1e-300):
        t = np.cross(n, [0.0, 1.0, 0.0]) if abs(n[1]) < 0.9 else np.cross(n, [1.0, 0.0, 0.0])
    t = t / np.linalg.norm(t)
    return n, t, np.cross(n, t)


def impact_state(run, frame, n, t, b):
    """V_cn (approach speed), V_ct, w and V_st of sphere 1 at one frame (see the conventions)."""
    v1, w1, r1 = run.v[frame, 0], run.w[frame, 0], run.radius[0]
    surface1 = v1 + np.cross(w1, r1 * n)
    if run.two_spheres:
        v2, w2, r2 = run.v[frame, 1], run.w[frame, 1], run.radius[1]
        surface2 = v2 + np.cross(w2, -r2 * n)
    else:
        v2 = surface2 = np.zeros(3)
    return {"V_cn": (v1 - v2) @ n, "V_ct": v1 @ t, "w": w1 @ b, "V_st": (surface1 - surface2) @ t}


def pre_post(run):
    """Impact state before (frame 0) and after (last frame); post V_cn is the separation speed."""
    n, t, b = axes(run)
    pre = impact_state(run, 0, n, t, b)
    post = impact_state(run, -1, n, t, b)
    post["V_cn"] = -post["V_cn"]
    return pre, post


def contact_interval(run, force_n):
    """Onset and end of F_n > 0 [s].  F_n^(2/3) is proportional to the overlap for Hertz, so it is
    linear in time near both ends; each end is where the line through the first (last) two
    positive samples reaches zero (the force itself is clamped at zero outside the contact)."""
    on = np.nonzero(force_n > 0.0)[0]
    first, last = on[0], on[-1]
    s = np.clip(force_n, 0.0, None) ** (2.0 / 3.0)
    t = run.time

    def zero_of_line(i0, i1):
        return t[i0] - s[i0] * (t[i1] - t[i0]) / (s[i1] - s[i0])

    return zero_of_line(first, first + 1), zero_of_line(last, last - 1)


def normal_force(run):
    n, _, _ = axes(run)
    return -run.force[:, 0] @ n


def oblique_quantities(pre, post, mu, radius):
    """The measured quantities of Tests 4-8 from pre/post states (see the conventions)."""
    v_st = post["V_st"]
    return {"e_t": post["V_ct"] / pre["V_ct"] if pre["V_ct"] != 0 else float("nan"),
            "w_post": post["w"], "V_ct_post": post["V_ct"],
            "rebound_angle_deg": math.degrees(math.atan2(v_st, post["V_cn"])),
            "tan_recoil": v_st / post["V_cn"], "beta": -v_st / pre["V_st"],
            "psi2": v_st / (mu * post["V_cn"]), "spin_norm": radius * post["w"] / (mu * pre["V_cn"])}
