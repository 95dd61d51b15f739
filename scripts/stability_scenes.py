#!/usr/bin/python3
"""stability_scenes.py — write the scenes of reference_runs/stability/.

    scripts/stability_scenes.py [--jdem build/jdem] [--out reference_runs/stability]

Each scene is one YAML file with a one-axis sweep (one case per extreme).  The time step of
every case is 0.5 x the largest safe dt of the stepper's guard (kernel/jdem_guard.h, asked from
`jdem run` on the case), rounded down to two significant digits, and the run lasts long enough
for every contact to end (impacts) or to settle and hold (static scenes).  The files are
generated: edit this script, not them.
"""
import argparse
import copy
import math
import os
import re
import tempfile

import yaml

from scripts import engines

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

GLASS = {"youngs_modulus": 4.8e10, "poisson_ratio": 0.2, "density": 2800.0}


def plane(name, z, half, up=True, mat="wall", velocity=None):
    """Horizontal square plane at height z, active side +z (up) or -z."""
    c = [[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]]
    w = {"name": name, "type": "plane", "corners": c if up else c[::-1], "material": mat}
    if velocity:
        w["velocity"] = velocity
    return w


def side_plane(name, axis, at, half, zmax, inward, mat="wall"):
    """Vertical plane x = at (axis 0) or y = at (axis 1), active side towards +inward."""
    o = 1 - axis
    pts = []
    for s, z in ((-half, 0.0), (half, 0.0), (half, zmax), (-half, zmax)):
        p = [0.0, 0.0, z]
        p[axis], p[o] = at, s
        pts.append(p)
    # (P2-P1) x (P3-P1) must point along +inward on `axis`
    e1 = [pts[1][k] - pts[0][k] for k in range(3)]
    e2 = [pts[2][k] - pts[0][k] for k in range(3)]
    n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
    if n[axis] * inward < 0:
        pts = pts[::-1]
    return {"name": name, "type": "plane", "corners": pts, "material": mat}


def safe_dt(jdem, doc):
    """The guard's largest safe dt for a one-case scene document."""
    d = tempfile.mkdtemp(prefix="jdem_stab_")
    path = os.path.join(d, "s.yaml")
    doc = copy.deepcopy(doc)
    doc["time"]["dt"] = 1e-30
    doc["time"]["steps"] = 1
    doc["time"].pop("end_time", None)
    with open(path, "w") as f:
        yaml.safe_dump(doc, f)
    p = engines.jdem("run", path, "-o", os.path.join(d, "o.h5"), binary=jdem)
    m = re.search(r"largest safe dt = (\S+) s", p.stderr)
    if p.returncode != 0 or not m:
        raise SystemExit("stability_scenes: %s" % p.stderr)
    return float(m.group(1))


def round_down(x, digits=2):
    e = math.floor(math.log10(x)) - digits + 1
    return float("%.*g" % (digits, math.floor(x / 10 ** e) * 10 ** e))


def set_path(doc, path, value):
    keys = path.split(".")
    node = doc
    for k in keys[:-1]:
        node = node[int(k)] if isinstance(node, list) else node[k]
    last = keys[-1]
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value


def finish(jdem, base, cases, duration):
    """Give each case (name -> overrides) its dt and steps; duration(case_doc) [s]."""
    out = {}
    for name, ov in cases.items():
        doc = copy.deepcopy(base)
        for k, v in ov.items():
            set_path(doc, k, v)
        dt = round_down(0.5 * safe_dt(jdem, doc))
        steps = int(math.ceil(duration(doc) / dt))
        every = max(1, steps // 400)
        out[name] = dict(ov, **{"time.dt": dt, "time.steps": steps, "output.every": every,
                                "output.observables_every": max(1, every // 4)})
    return out


def hertz_contact_time(m_eff, k_n, v):
    tau = 2.0 * 1.25 ** 0.4 * 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)
    return tau * (m_eff / k_n) ** 0.4 * v ** -0.2


def k_wall(E, nu, R):
    return 4.0 / 3.0 * E / (1.0 - nu * nu) * math.sqrt(R)


def k_p(E, nu, R):
    return 2.0 * E / (2.0 * (1.0 + nu)) * math.sqrt(2.0 * R) / (3.0 * (1.0 - nu))


def mass(R, rho):
    return 4.0 / 3.0 * math.pi * R ** 3 * rho


def wall_impact_duration(doc):
    """Approach over the initial gap plus 1.5 contact times (undamped Hertz at the normal speed)."""
    p = doc["particles"][0]
    m = doc["materials"]["sphere"]
    R = p["radius"]
    vn = abs(p["velocity"][2])
    gap = p["position"][2] - R
    tc = hertz_contact_time(mass(R, m["density"]), k_wall(m["youngs_modulus"], m["poisson_ratio"], R), vn)
    return gap / vn + 1.5 * tc


def base_doc(name, description, materials, particles, walls=None, gravity=None, interactions=None,
             time=None, coordination=None):
    doc = {"jdem_scene": 1, "name": name, "description": description,
           "time": dict({"dt": 1.0, "steps": 1}, **(time or {})),
           "output": {"every": 1, "observables_every": 1},
           "materials": materials}
    if coordination:
        doc["time"]["coordination_number"] = coordination
    if gravity:
        doc["gravity"] = gravity
    if interactions:
        doc["interactions"] = interactions
    doc["particles"] = particles
    if walls:
        doc["walls"] = walls
    return doc


def wall_impact_base(name, description, R, v, material, e=0.9, mu=0.3, eta=0.0, gap=1e-3):
    return base_doc(
        name, description,
        {"sphere": dict(material), "wall": {}},
        [{"id": 1, "material": "sphere", "radius": R, "position": [0.0, 0.0, R * (1 + gap)],
          "velocity": list(v)}],
        walls=[plane("floor", 0.0, 1000.0 * R)],
        interactions=[{"materials": ["sphere", "wall"], "restitution": e, "friction": mu,
                       "rolling_friction": eta}])


def scale_scene(jdem):
    base = wall_impact_base("scale", "Stiffness and scale: a sphere hits a plane at 1 m/s (30 deg "
                            "off normal); E from 1 MPa to 1 TPa, R from 10 um to 1 m, and Chung & "
                            "Ooi test 5's 10 um steel and polyethylene at V_n = 5 m/s, V_t = 1.5 m/s.",
                            1.0, (0.5, 0.0, -0.866), {"youngs_modulus": 1e9, "poisson_ratio": 0.3,
                                                       "density": 2500.0})
    cases = {}
    for E, en in ((1e6, "E1e6"), (1e9, "E1e9"), (1e12, "E1e12")):
        for R, rn in ((1e-5, "R10um"), (1e-3, "R1mm"), (1.0, "R1m")):
            cases["%s_%s" % (en, rn)] = {"materials.sphere.youngs_modulus": E,
                                         "particles.0.radius": R,
                                         "particles.0.position": [0.0, 0.0, R * 1.001],
                                         "walls.0.corners": plane("floor", 0.0, 1000 * R)["corners"]}
    for n, E, nu, rho in (("co5_steel", 2.08e11, 0.3, 7850.0), ("co5_polyethylene", 1.0e9, 0.4, 1400.0)):
        cases[n] = {"materials.sphere.youngs_modulus": E, "materials.sphere.poisson_ratio": nu,
                    "materials.sphere.density": rho, "particles.0.radius": 1e-5,
                    "particles.0.position": [0.0, 0.0, 1.001e-5], "particles.0.velocity": [1.5, 0.0, -5.0],
                    "walls.0.corners": plane("floor", 0.0, 1e-2)["corners"]}
    return base, finish(jdem, base, cases, wall_impact_duration)


def impact_speed_scene(jdem):
    R = 0.005
    base = base_doc("impact_speed", "Two glass spheres (R = 5 mm), head-on with spin, e = 0.5, "
                    "mu = 0.3, at relative speeds 1 to 100 m/s.",
                    {"glass": dict(GLASS, restitution=0.5, friction=0.3)},
                    [{"id": 1, "material": "glass", "radius": R, "position": [-R * 1.0005, 0.0, 0.0],
                      "velocity": [0.5, 0.0, 0.0], "angular_velocity": [0.0, 0.0, 200.0]},
                     {"id": 2, "material": "glass", "radius": R, "position": [R * 1.0005, 0.0, 0.0],
                      "velocity": [-0.5, 0.0, 0.0], "angular_velocity": [0.0, 0.0, 0.0]}])
    cases = {}
    for v in (1, 10, 50, 100):
        cases["v%03d" % v] = {"particles.0.velocity": [v / 2.0, 0.0, 0.0],
                              "particles.1.velocity": [-v / 2.0, 0.0, 0.0]}

    def duration(doc):
        v = 2 * doc["particles"][0]["velocity"][0]
        m = mass(R, GLASS["density"])
        k = k_p(GLASS["youngs_modulus"], GLASS["poisson_ratio"], R)
        return 0.001 * R / v + 1.5 * hertz_contact_time(m / 2, k, v)
    return base, finish(jdem, base, cases, duration)


def grazing_scene(jdem):
    R = 0.005
    base = wall_impact_base("grazing", "Grazing impacts of a glass sphere (R = 5 mm) on a plane at "
                            "10 m/s, incident angle 85 to 89.9 deg from the normal; e = 0.9, mu = 0.3.",
                            R, (0.0, 0.0, -1.0), GLASS, gap=1e-4)
    cases = {}
    for ang in (85.0, 88.0, 89.0, 89.9):
        a = math.radians(ang)
        cases["a%s" % ("%g" % ang).replace(".", "p")] = {
            "particles.0.velocity": [10.0 * math.sin(a), 0.0, -10.0 * math.cos(a)]}
    return base, finish(jdem, base, cases, wall_impact_duration)


def restitution_scene(jdem):
    R = 0.005
    base = wall_impact_base("restitution", "A glass sphere (R = 5 mm) hits a plane at V_n = 5 m/s, "
                            "V_t = 1 m/s; restitution 0.01 (over-damped: Luding's end rule keeps F_n "
                            ">= 0) to 1; mu = 0.3.", R, (1.0, 0.0, -5.0), GLASS)
    cases = {("e%g" % e).replace(".", "p"): {"interactions.0.restitution": e}
             for e in (0.01, 0.1, 0.5, 0.9, 1.0)}
    return base, finish(jdem, base, cases, wall_impact_duration)


def friction_scene(jdem):
    R = 0.005
    base = wall_impact_base("friction", "A spinning glass sphere (R = 5 mm) hits a plane at 5 m/s, "
                            "45 deg; e = 0.8; friction 0 to 10.", R, (3.5355, 0.0, -3.5355), GLASS, e=0.8)
    base["particles"][0]["angular_velocity"] = [0.0, -500.0, 0.0]
    cases = {("mu%g" % mu).replace(".", "p"): {"interactions.0.friction": mu} for mu in (0.0, 0.1, 1.0, 10.0)}
    return base, (finish(jdem, base, cases, wall_impact_duration) if jdem else None)


def mindlin(base, name, description):
    """The same scene with Mindlin's tangential stiffness, which the guard bounds (stiffer than
    K_n: docs/model.md §4.5)."""
    base = copy.deepcopy(base)
    base["name"] = name
    base["description"] = description
    base["model"] = {"tangential_stiffness": "mindlin"}
    return base


def mindlin_friction_scene(jdem):
    base, _ = friction_scene(None)
    base = mindlin(base, "friction_mindlin", base["description"] + "  Mindlin's K_t = 8 G* sqrt(R* delta).")
    cases = {("mu%g" % mu).replace(".", "p"): {"interactions.0.friction": mu} for mu in (0.1, 1.0, 10.0)}
    return base, finish(jdem, base, cases, wall_impact_duration)


def rolling_scene(jdem):
    R = 0.005
    v = 0.5
    base = wall_impact_base("rolling", "A glass sphere (R = 5 mm) rolls on a plane under gravity at "
                            "0.5 m/s, rolling without slip at the start; rolling coefficient 0.01 to "
                            "1; mu = 0.5, e = 0.5.", R, (v, 0.0, 0.0), GLASS, e=0.5, mu=0.5, gap=0.0)
    base["particles"][0]["angular_velocity"] = [0.0, v / R, 0.0]
    base["gravity"] = [0.0, 0.0, -9.81]
    base["time"]["max_impact_speed"] = 1.0
    cases = {("eta%g" % eta).replace(".", "p"): {"interactions.0.rolling_friction": eta}
             for eta in (0.01, 0.1, 0.5, 1.0)}
    return base, finish(jdem, base, cases, lambda doc: 0.05)


def pile_scene(jdem):
    Rs, Rb, d = 0.001, 0.05, 0.008
    h = Rs + math.sqrt((Rb + Rs) ** 2 - d * d) + 1e-7
    base = base_doc("size_ratio_pile", "Size ratio 1:50, static: a glass sphere R = 50 mm rests on "
                    "two R = 1 mm spheres on a floor (contact normals 9 deg off vertical, so only "
                    "friction keeps the small spheres from being squeezed out; mu = 0.5).  "
                    "Velocity-Verlet asynchrony at large size ratios (anchors.md, Vyas et al. "
                    "2025) would show as a creep of the small spheres.",
                    {"glass": dict(GLASS, restitution=0.3, friction=0.5), "wall": {}},
                    [{"id": 1, "material": "glass", "radius": Rs, "position": [-d, 0.0, Rs]},
                     {"id": 2, "material": "glass", "radius": Rs, "position": [d, 0.0, Rs]},
                     {"id": 3, "material": "glass", "radius": Rb, "position": [0.0, 0.0, h]}],
                    walls=[plane("floor", 0.0, 0.1)], gravity=[0.0, 0.0, -9.81],
                    interactions=[{"materials": ["glass", "wall"], "restitution": 0.3, "friction": 0.5}],
                    time={"max_impact_speed": 0.05})
    return base, finish(jdem, base, {"ratio50": {}}, lambda doc: 0.03)


def column_scene(jdem):
    R, n = 0.005, 100
    mat = {"youngs_modulus": 1e8, "poisson_ratio": 0.3, "density": 2500.0, "restitution": 0.1,
           "friction": 0.5}
    base = base_doc("column", "100 spheres (R = 5 mm, E = 100 MPa) stacked touching on a floor "
                    "under gravity; the column compresses and settles (the bottom contact carries "
                    "100 weights); e = 0.1.",
                    {"sphere": mat, "wall": {}},
                    [{"id": i + 1, "material": "sphere", "radius": R,
                      "position": [0.0, 0.0, R + 2 * R * i]} for i in range(n)],
                    walls=[plane("floor", 0.0, 0.05)], gravity=[0.0, 0.0, -9.81],
                    interactions=[{"materials": ["sphere", "wall"], "restitution": 0.1, "friction": 0.5}],
                    time={"max_impact_speed": 0.2}, coordination=2)
    return base, finish(jdem, base, {"n100": {}}, lambda doc: 2.0)


def bed_scene(jdem, tangential="jiang2021"):
    R, n, E, nu, rho = 0.001, 5, 7.0e10, 0.25, 2500.0
    L = 2 * R * n
    sigma = 10e6
    F = sigma * L * L / (n * n)                     # force per column of the lattice
    kp, kw = k_p(E, nu, R), k_wall(E, nu, R)
    squeeze = (n - 1) * (F / kp) ** (2 / 3) + 2 * (F / kw) ** (2 / 3)
    T = 1e-3
    v = 1.1 * squeeze / T                           # 10 % beyond 10 MPa at the end
    m = mass(R, rho)
    # the impact speed whose Hertz peak overlap equals the pair overlap at 10 MPa: the guard then
    # sees the stiffness of the loaded contacts (1/2 m_eff v^2 = 2/5 k_p delta^2.5)
    delta = (F / kp) ** (2 / 3)
    v_eq = math.sqrt(0.8 * kp * delta ** 2.5 / (m / 2))
    mat = {"youngs_modulus": E, "poisson_ratio": nu, "density": rho, "restitution": 0.5, "friction": 0.3}
    walls = [plane("floor", 0.0, L / 2), plane("piston", L, L / 2, up=False, velocity=[0.0, 0.0, -v]),
             side_plane("xlo", 0, -L / 2, L / 2, 2 * L, +1), side_plane("xhi", 0, L / 2, L / 2, 2 * L, -1),
             side_plane("ylo", 1, -L / 2, L / 2, 2 * L, +1), side_plane("yhi", 1, L / 2, L / 2, 2 * L, -1)]
    base = base_doc("dense_bed", "A 5 x 5 x 5 simple-cubic bed of glass-like spheres (R = 1 mm, E = "
                    "70 GPa) in a box, compressed by a piston moving at constant speed to 11 MPa "
                    "(10 %% beyond 10 MPa) in 1 ms.  max_impact_speed %.3g m/s is the impact whose "
                    "peak overlap equals the overlap of a contact at 10 MPa, so that the guard "
                    "judges the loaded stiffness." % v_eq,
                    {"sphere": mat, "wall": {}},
                    [{"id": 1 + i + n * (j + n * k), "material": "sphere", "radius": R,
                      "position": [-L / 2 + R + 2 * R * i, -L / 2 + R + 2 * R * j, R + 2 * R * k]}
                     for k in range(n) for j in range(n) for i in range(n)],
                    walls=walls,
                    interactions=[{"materials": ["sphere", "wall"], "restitution": 0.5, "friction": 0.3}],
                    time={"max_impact_speed": float("%.3g" % v_eq)}, coordination=6)
    if tangential == "mindlin":
        base = mindlin(base, "dense_bed_mindlin", base["description"] + "  Mindlin's K_t = 8 G* "
                       "sqrt(R* delta) (3(1 - nu)/(2 - nu) = 1.29 K_n): the guard bounds the stiffer "
                       "tangential spring.")
    return base, finish(jdem, base, {"sc125": {}}, lambda doc: T)


def beam_scene(jdem):
    """A cantilever of 11 bonded glass-like spheres, clamped at sphere 1 (`fixed`)."""
    R, n, E, nu, rho = 0.001, 10, 7.0e10, 0.3, 2600.0
    gap = 2.0e-7                                    # surface gap: the bonds alone carry the beam
    L = 2 * R + gap
    # the stiff end of realistic parallel bonds: Potyondy & Cundall's kn = E_c / (R_a + R_b)
    # with a cement as stiff as the grains (E_c = E = 70 GPa), kt = kn / (2 (1 + nu))
    kn = E / (2 * R)
    kt = float("%.4g" % (kn / (2 * (1 + nu))))
    I = math.pi * R ** 4 / 4
    EI, ell = kn * I * L, n * L                     # the chain's bending stiffness (docs/model.md §9.6)
    P = 3 * EI * 0.01 * ell / ell ** 3              # tip load of a static deflection of 1 % of l
    mu_l = mass(R, rho) / L
    period = 2 * math.pi / (1.8751 ** 2 * math.sqrt(EI / (mu_l * ell ** 4)))   # fundamental mode
    cement = {"normal_stiffness": kn, "shear_stiffness": kt, "tensile_strength": float("inf"),
              "shear_strength": float("inf"), "radius_multiplier": 1.0, "damping": 0.0}
    base = base_doc("bonded_beam", "A stiff bonded beam: 11 spheres (R = 1 mm, E = 70 GPa) in a "
                    "straight chain (surface gap 0.2 um), neighbours joined by parallel bonds at "
                    "the stiff end of realistic values (kn = E / 2R = %.3g N/m^3, kt = kn / 2(1 + "
                    "nu)), clamped at sphere 1 (fixed).  tip_impact: the tip sphere is struck "
                    "(transverse 1 m/s), undamped bonds; tip_load: a tip load of %.4g N (static "
                    "deflection 1 %% of the length) applied at once, bond damping 1; 4 fundamental "
                    "periods (%.3g s each)." % (kn, P, period),
                    {"glass": {"youngs_modulus": E, "poisson_ratio": nu, "density": rho,
                               "restitution": 0.5, "friction": 0.3}},
                    [dict({"id": k + 1, "material": "glass", "radius": R, "position": [k * L, 0.0, 0.0]},
                          **({"fixed": True} if k == 0 else {})) for k in range(n + 1)],
                    time={"max_impact_speed": 1.0})
    base["bond_types"] = {"cement": cement}
    base["bonds"] = [{"ids": [k, k + 1], "type": "cement"} for k in range(1, n + 1)]
    tip = "particles.%d" % n
    cases = {"tip_impact": {tip + ".velocity": [0.0, 0.0, -1.0]},
             "tip_load": {tip + ".force": [0.0, 0.0, -P], "bond_types.cement.damping": 1.0}}
    return base, finish(jdem, base, cases, lambda doc: 4 * period)


SCENES = [scale_scene, impact_speed_scene, grazing_scene, restitution_scene, friction_scene,
          rolling_scene, pile_scene, column_scene, bed_scene, beam_scene, mindlin_friction_scene,
          lambda jdem: bed_scene(jdem, "mindlin")]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jdem", default=os.path.join(ROOT, "build", "jdem"))
    ap.add_argument("--out", default=os.path.join(ROOT, "reference_runs", "stability"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for make in SCENES:
        base, cases = make(a.jdem)
        doc = copy.deepcopy(base)
        doc["sweep"] = [{"axis": "case", "values": cases}]
        path = os.path.join(a.out, base["name"] + ".yaml")
        with open(path, "w") as f:
            f.write("# Generated by scripts/stability_scenes.py -- edit the script, not this file.\n")
            f.write("# dt of each case: 0.5 x the guard's largest safe dt, two significant digits.\n")
            yaml.safe_dump(doc, f, sort_keys=False, default_flow_style=None, width=100)
        print(path, len(cases), "cases")


if __name__ == "__main__":
    main()
