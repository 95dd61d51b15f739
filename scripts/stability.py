#!/usr/bin/python3
"""stability.py — the stability suite (reference_runs/stability/, `make stability`).

    scripts/stability.py [--out out/stability] [--engines jdem,liggghts] [--cases PATTERN,...]
                         [--factors 2,5,10] [--jdem build/jdem]

Every case of every scene in reference_runs/stability/ runs in each engine at its own dt
(factor 1), then at 2x, 5x and 10x the guard's largest safe dt: once without --force (the guard
must refuse: exit status 2 / LIGGGHTS error) and once with it (the run must stay finite or be
stopped by the watchdog; no non-finite number may appear in the file).  Writes
OUT/report.md, OUT/summary.json (one record per scene x engine x dt factor, the fields of the
issue) and prints one line per check, "PASS name" or "FAIL name: detail"; exits 1 if any check
failed.  PATTERN selects cases as SCENE/CASE with shell wildcards (fnmatch).

Quantities (docs/model.md §8 and the report's notes):
  energy_rel_error   max over samples |E(t) - E(0)| / max over samples of the energy in play,
                     E = KE + RE + elastic + gravitational + damping + friction - wall work, the
                     energy in play KE + RE + elastic + damping + friction + |wall work| (with
                     bonds, elastic includes the bonds' stored energy and damping their damping
                     and breakage energy)
  max_overlap_over_radius  largest overlap over the smaller radius (pairs) or the radius
                     (walls) in the frames
  energy returned    the most the contacts ever gave back beyond what they had received, over the
                     energy in play; received(t) = wall work - change of KE + RE + gravitational
                     energy, from the motion alone (asserted within the energy tolerance: an
                     elastic contact gives back all it received, to the integration error)
  spring energy created  -min of the cumulative damping + friction dissipation as booked: stored
                     energy that appeared without work (reported, not asserted; docs/model.md §8)
  tensile force      one-contact scenes: the largest attractive normal force over the peak
                     normal force
"""
import argparse
import fnmatch
import json
import math
import os
import re
import sys

import h5py
import numpy as np
import yaml

from scripts.bond_checks import beam_reference, mean_between_extrema
from scripts import engines

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENES = os.path.join(ROOT, "reference_runs", "stability")

ENERGY_TOL = 1e-3      # the 0.1 %
NONPHYSICAL_TOL = 1e-9  # attractive force over the peak force: round-off only


# ------------------------------------------------------------------------------------------
# running


def run_jdem(jdem, scene, case, out, force=False):
    cmd = [jdem, "run", scene, "-o", out] + engines.case_args(case) + (["--force"] if force else [])
    p, seconds = engines.timed(cmd)
    return p.returncode, p.stderr, seconds


def run_liggghts(scene, case, out, force=False):
    p, seconds = engines.timed(engines.script("liggghts_run", scene, "-o", out, *engines.case_args(case),
                                              *(["--force"] if force else [])))
    return p.returncode, p.stderr, seconds


def resolve(jdem, scene, case):
    return yaml.load(engines.resolve(scene, case, binary=jdem, check=True).stdout, Loader=yaml.CSafeLoader)


def guard_summary(stderr):
    """steps per contact and the largest safe dt from jdem's summary line."""
    m = re.search(r"\(([0-9.]+) steps per contact\)", stderr)
    s = re.search(r"largest safe dt = (\S+) s", stderr)
    return (float(m.group(1)) if m else float("inf")), (float(s.group(1)) if s else None)


def scaled_scene(doc, dt, path):
    """The resolved case at time step dt over the same duration (frames as often in time)."""
    d = dict(doc)
    t = dict(d["time"])
    duration = t["dt"] * t["steps"]
    t["dt"] = dt
    t["steps"] = max(1, int(math.ceil(duration / dt - 1e-9)))
    d["time"] = t
    o = dict(d.get("output") or {})
    f = doc["time"]["dt"] / dt
    for k in ("every", "observables_every"):
        if k in o:
            o[k] = max(1, int(o[k] * f))
    d["output"] = o
    with open(path, "w") as fh:
        yaml.safe_dump(d, fh, sort_keys=False)
    return path


# ------------------------------------------------------------------------------------------
# analysis


def all_finite(path):
    bad = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and not np.all(np.isfinite(obj[()])):
            bad.append(name)
    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return not bad


def energy_series(f):
    """The observables, the total energy and the energy in play.  Bonds (docs/model.md §9.3) store
    energy as bond_elastic_energy and dissipate it as bond_damping_dissipation and
    bond_breakage_energy; the folds below add them as elastic energy and as damping."""
    o = {k: f["observables"][k]["value"][()] for k in f["observables"]}
    zero = np.zeros_like(o["kinetic_energy"])
    elastic = o["elastic_energy"] + o.get("bond_elastic_energy", zero)
    damping = (o["damping_dissipation"] + o.get("bond_damping_dissipation", zero)
               + o.get("bond_breakage_energy", zero))
    total = (o["kinetic_energy"] + o["rotational_energy"] + elastic + o["gravitational_energy"]
             + damping + o["friction_dissipation"] - o["wall_work"])
    scale = (o["kinetic_energy"] + o["rotational_energy"] + elastic + damping
             + o["friction_dissipation"] + np.abs(o["wall_work"]))
    return o, total, scale


def plane_of(w, t):
    c = np.array(w["corners"], float) + np.array(w.get("velocity", [0, 0, 0]), float) * t
    n = np.cross(c[1] - c[0], c[2] - c[0])
    return c[0], n / np.linalg.norm(n)


def analyse(path, scene):
    """Quantities of one trajectory (a finished .h5 or a stopped .h5.part)."""
    r = {"finite": all_finite(path)}
    with h5py.File(path, "r") as f:
        o, total, scale = energy_series(f)
        in_play = float(np.nanmax(scale)) if len(scale) else 0.0
        r["energy_rel_error"] = float(np.nanmax(np.abs(total - total[0])) / in_play) if in_play > 0 else 0.0
        # energy the contacts received from the bodies (and from moving walls) so far: what the
        # contact forces took out of the motion, from the motion alone
        mech = o["kinetic_energy"] + o["rotational_energy"] + o["gravitational_energy"]
        received = o["wall_work"] - (mech - mech[0])
        r["energy_returned"] = max(0.0, -float(np.nanmin(received))) / in_play if in_play > 0 else 0.0
        # the cumulative dissipation as booked (received - stored): negative while the tangential
        # spring's stiffness K_t = K_n(delta) grows at fixed xi (docs/model.md §8)
        diss = o["damping_dissipation"] + o["friction_dissipation"]
        r["spring_energy_created"] = max(0.0, -float(np.nanmin(diss))) / in_play if in_play > 0 else 0.0
        part = f["particles/all"]
        x = part["position/value"][()]
        vel = part["velocity/value"][()]
        times = part["position/time"][()]
        F = part["force/value"][()]
        R = part["radius"][()]
        m = part["mass"][()]
        ids = part["id"][()]
    g = np.array(scene.get("gravity", [0, 0, 0]), float)
    n = len(R)
    worst = 0.0
    if n > 1:
        for k in range(len(x)):
            d = np.linalg.norm(x[k][:, None, :] - x[k][None, :, :], axis=2)
            ov = (R[:, None] + R[None, :] - d) / np.minimum(R[:, None], R[None, :])
            np.fill_diagonal(ov, -np.inf)
            worst = max(worst, float(np.nanmax(ov)))
    for w in scene.get("walls") or []:
        if w["type"] != "plane":
            continue
        for k in range(len(x)):
            p0, nv = plane_of(w, times[k])
            dist = (x[k] - p0) @ nv
            worst = max(worst, float(np.nanmax((R - dist) / R)))
    r["max_overlap_over_radius"] = worst
    # attractive normal force of the one contact of a one- or two-particle scene
    tensile = 0.0
    walls = scene.get("walls") or []
    if n == 1 and len(walls) == 1:
        _, nv = plane_of(walls[0], 0.0)
        fn = (F[:, 0, :] - m[0] * g) @ nv
        touching = (x[:, 0, :] - plane_of(walls[0], 0.0)[0]) @ nv < R[0]
        if np.any(touching) and np.nanmax(np.abs(fn)) > 0:
            tensile = max(0.0, -float(np.nanmin(fn[touching]))) / float(np.nanmax(np.abs(fn)))
    elif n == 2 and not walls:
        nv = x[:, 1, :] - x[:, 0, :]
        nv /= np.linalg.norm(nv, axis=1)[:, None]
        fn = np.einsum("ij,ij->i", F[:, 1, :] - m[1] * g, nv)
        if np.nanmax(np.abs(fn)) > 0:
            tensile = max(0.0, -float(np.nanmin(fn))) / float(np.nanmax(np.abs(fn)))
    r["tensile_force"] = tensile
    r["nonphysical"] = max(r["energy_returned"], tensile)
    r["final_positions"] = x[-1]
    r["positions"] = x
    r["velocities"] = vel
    r["times"] = times
    r["radius"] = R
    r["ids"] = ids
    return r


def extras(scene_name, doc, a):
    """Scene-specific physical checks: (name, value, limit or None, text)."""
    out = []
    if scene_name == "size_ratio_pile":
        # creep of the small spheres after settling (second half of the run)
        x, t = a["positions"], a["times"]
        half = np.searchsorted(t, t[-1] / 2)
        creep = float(np.max(np.abs(x[-1, :2, 0] - x[half, :2, 0]))) / float(a["radius"][0])
        out.append(("small_sphere_creep_over_R", creep, 1e-3,
                    "horizontal creep of the small spheres over the second half of the run / R_small"))
    if scene_name == "column":
        # bottom overlap, averaged over the last quarter of the run, against the static Hertz
        # value under 100 weights (exact Hertz wall rule)
        mat = doc["materials"]["sphere"]
        R = float(a["radius"][0])
        mass = 4.0 / 3.0 * math.pi * R ** 3 * mat["density"]
        F = len(a["radius"]) * mass * 9.81
        kw = 4.0 / 3.0 * mat["youngs_modulus"] / (1 - mat["poisson_ratio"] ** 2) * math.sqrt(R)
        want = (F / kw) ** (2 / 3)
        x, t = a["positions"], a["times"]
        last = x[np.searchsorted(t, 0.75 * t[-1]):, :, 2]
        got = R - float(np.mean(np.min(last, axis=1)))
        out.append(("bottom_overlap_vs_static_hertz", abs(got - want) / want, 0.02,
                    "bottom wall overlap %.4g m (mean of the last quarter) vs static Hertz %.4g m "
                    "(relative difference)" % (got, want)))
    if scene_name == "rolling":
        # rigid-body closed form: a rolling moment eta R m g (cap eta r_roll F_n, r_roll = R on a
        # wall) decelerates a sphere rolling without slip at eta g / 1.4 (I = 0.4 m R^2) while the
        # friction it needs, eta m g / 1.4, is within mu m g; beyond, the sphere slides and
        # friction decelerates it at mu g
        pair = [x for x in doc["interactions"] if sorted(x["materials"]) == ["sphere", "wall"]][0]
        eta, mu = pair["rolling_friction"], pair["friction"]
        v0 = doc["particles"][0]["velocity"][0]
        t = float(a["times"][-1])
        want = v0 - (eta / 1.4 if eta <= 1.4 * mu else mu) * 9.81 * t
        got = float(a["velocities"][-1, 0, 0])
        out.append(("velocity_change_vs_closed_form", abs((got - v0) - (want - v0)) / abs(want - v0), 2e-3,
                    "velocity at %.3g s: %.6g m/s vs rigid-body %.6g m/s (%s; relative error of the "
                    "change)" % (t, got, want, "rolling" if eta <= 1.4 * mu else "sliding")))
    loaded = [p for p in doc["particles"] if any(c != 0.0 for c in p.get("force", [0.0, 0.0, 0.0]))]
    if scene_name == "bonded_beam" and loaded:
        # the tip oscillates about its static deflection (the load acts from step 0): its mean
        # over the last two periods against the discrete chain's exact static deflection
        # (bond_checks.beam_reference, the reference of `make bonds`' beam_tip_deflection_discrete)
        tip = loaded[0]
        bond = doc["bond_types"][doc["bonds"][0]["type"]]
        r_bond = bond["radius_multiplier"] * tip["radius"]
        spacing = float(np.linalg.norm(np.subtract(doc["particles"][1]["position"],
                                                   doc["particles"][0]["position"])))
        P = abs(tip["force"][2])
        _, want = beam_reference(len(doc["bonds"]), P, bond["normal_stiffness"], bond["shear_stiffness"],
                                 r_bond, spacing)
        z = a["positions"][:, int(np.nonzero(a["ids"] == tip["id"])[0][0]), 2]
        got = -mean_between_extrema(z - tip["position"][2])
        out.append(("tip_deflection_vs_discrete_chain", abs(got - want) / want, 0.005,
                    "static tip deflection %.5g m (mean of the last two periods) vs the discrete "
                    "chain's %.5g m (relative difference)" % (got, want)))
    if scene_name == "dense_bed":
        piston = [w for w in doc["walls"] if w["name"] == "piston"][0]
        p0, nv = plane_of(piston, float(a["times"][-1]))
        x, R = a["final_positions"], a["radius"]
        delta = np.clip(R - (x - p0) @ nv, 0.0, None)
        mat = doc["materials"]["sphere"]
        kw = 4.0 / 3.0 * mat["youngs_modulus"] / (1 - mat["poisson_ratio"] ** 2) * np.sqrt(R)
        c = np.array(piston["corners"], float)
        area = np.linalg.norm(np.cross(c[1] - c[0], c[3] - c[0]))
        sigma = float(np.sum(kw * delta ** 1.5) / area)
        out.append(("piston_stress_MPa", sigma / 1e6, None,
                    "piston stress at the end, from the piston overlaps (exact Hertz wall)"))
        out.append(("reached_10MPa", 0.0 if sigma >= 10e6 else 1.0, 0.5, "the piston stress reached 10 MPa"))
    return out


# ------------------------------------------------------------------------------------------


class Checks:
    def __init__(self):
        self.failed = 0

    def check(self, name, ok, detail=""):
        print(("PASS %s" % name) if ok else ("FAIL %s: %s" % (name, detail)), flush=True)
        self.failed += 0 if ok else 1


def cases_of(jdem, patterns):
    out = []
    for fn in sorted(os.listdir(SCENES)):
        if not fn.endswith(".yaml"):
            continue
        path = os.path.join(SCENES, fn)
        for c in engines.cases(path, binary=jdem):
            key = "%s/%s" % (fn[:-5], c)
            if not patterns or any(fnmatch.fnmatch(key, p) for p in patterns):
                out.append((fn[:-5], path, c))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "stability"))
    ap.add_argument("--engines", default="jdem,liggghts")
    ap.add_argument("--cases", default="", help="SCENE/CASE patterns, comma separated (default: all)")
    ap.add_argument("--factors", default="2,5,10")
    ap.add_argument("--jdem", default=os.path.join(ROOT, "build", "jdem"))
    a = ap.parse_args()
    engines = [e for e in a.engines.split(",") if e]
    factors = [float(f) for f in a.factors.split(",") if f]
    patterns = [p for p in a.cases.split(",") if p]
    os.makedirs(a.out, exist_ok=True)
    c = Checks()
    records, rows, extra_rows = [], [], []
    for scene_name, path, case in cases_of(a.jdem, patterns):
        key = "%s/%s" % (scene_name, case)
        d = os.path.join(a.out, scene_name)
        os.makedirs(d, exist_ok=True)
        doc = resolve(a.jdem, path, case)
        resolved = os.path.join(d, case + ".resolved.yaml")
        with open(resolved, "w") as fh:
            yaml.safe_dump(doc, fh, sort_keys=False)
        # the guard's verdict (steps per contact, largest safe dt) from jdem's summary line
        _, err, _ = run_jdem(a.jdem, resolved, None, os.path.join(d, case + ".probe.h5"), force=True)
        spc, safe = guard_summary(err)
        if os.path.exists(os.path.join(d, case + ".probe.h5")):
            os.remove(os.path.join(d, case + ".probe.h5"))
        for engine in engines:
            for factor in [1.0] + factors:
                tag = "f%g" % factor
                out = os.path.join(d, "%s.%s.%s.h5" % (case, tag, engine))
                for stale in (out, out + ".part"):
                    if os.path.exists(stale):
                        os.remove(stale)
                runner = (lambda s, o, force: run_jdem(a.jdem, s, None, o, force)) if engine == "jdem" else \
                    (lambda s, o, force: run_liggghts(s, None, o, force))
                if factor == 1.0:
                    scene_file, dt, refused = resolved, doc["time"]["dt"], False
                else:
                    dt = factor * safe
                    scene_file = scaled_scene(doc, dt, os.path.join(d, "%s.%s.yaml" % (case, tag)))
                    rc, err, _ = runner(scene_file, out, False)
                    refused = rc != 0 and "is unsafe" in err and not os.path.exists(out) \
                        and not os.path.exists(out + ".part")
                    c.check("%s/%s/%s/refused" % (key, engine, tag), refused,
                            "exit %d, stderr %s" % (rc, err.strip()[-300:]))
                rc, err, wall = runner(scene_file, out, factor != 1.0)
                stopped = rc != 0 and "watchdog:" in err
                traj = out if os.path.exists(out) else (out + ".part" if os.path.exists(out + ".part") else None)
                rec = {"scene": key, "engine": engine, "dt": dt, "dt_factor": factor,
                       "steps_per_contact": spc * doc["time"]["dt"] / dt, "energy_rel_error": None,
                       "max_overlap_over_radius": None, "finite": False, "refused": refused,
                       "stopped_by_watchdog": stopped, "wall_s": round(wall, 3)}
                an = analyse(traj, doc) if traj else None
                if an:
                    rec.update(energy_rel_error=an["energy_rel_error"],
                               max_overlap_over_radius=an["max_overlap_over_radius"], finite=an["finite"])
                records.append(rec)
                name = "%s/%s/%s" % (key, engine, tag)
                if factor == 1.0:
                    ok = rc == 0 and an is not None
                    c.check(name + "/completed", ok, "exit %d: %s" % (rc, err.strip()[-400:]))
                    if not ok:
                        continue
                    c.check(name + "/finite", an["finite"], "non-finite values in %s" % traj)
                    c.check(name + "/energy_balance", an["energy_rel_error"] <= ENERGY_TOL,
                            "relative energy error %.3g > %g" % (an["energy_rel_error"], ENERGY_TOL))
                    c.check(name + "/no_energy_returned", an["energy_returned"] <= ENERGY_TOL,
                            "the contacts returned %.3g of the energy in play more than they received"
                            % an["energy_returned"])
                    c.check(name + "/no_tensile_force", an["tensile_force"] <= NONPHYSICAL_TOL,
                            "attractive normal force %.3g of the peak" % an["tensile_force"])
                    rows.append((key, engine, rec, an))
                    for ename, val, lim, text in extras(scene_name, doc, an):
                        extra_rows.append((key, engine, ename, val, lim, text))
                        if lim is not None:
                            c.check("%s/%s" % (name, ename), val <= lim, "%s = %.4g > %g" % (text, val, lim))
                else:
                    c.check(name + "/finite_or_stopped", an is not None and (an["finite"] or stopped)
                            and (rc == 0 or stopped),
                            "exit %d, file %s: %s" % (rc, traj, err.strip()[-300:]))
                    c.check(name + "/no_nan_in_file", an is not None and an["finite"],
                            "non-finite values in %s" % traj)
    with open(os.path.join(a.out, "summary.json"), "w") as fh:
        json.dump(records, fh, indent=1)
    write_report(a.out, rows, extra_rows, records, factors)
    print("report: %s" % os.path.join(a.out, "report.md"))
    sys.exit(1 if c.failed else 0)


def fmt(x, spec=".3g"):
    return "—" if x is None else format(x, spec)


def write_report(out, rows, extra_rows, records, factors):
    L = ["# Stability suite\n\n",
         "Written by `make stability` (`scripts/stability.py`); scenes in `reference_runs/stability/` "
         "(generated by `scripts/stability_scenes.py`).  Every case at its own dt (0.5 x the guard's "
         "largest safe dt), in both engines.  Energy error: max |E(t) - E(0)| over the largest energy "
         "in play (KE + RE + elastic + dissipated + |wall work|); required <= 0.1 %.  Non-physical: the "
         "larger of the energy the contacts gave back beyond what they had received (from the motion "
         "alone, over the energy in play; required <= 0.1 %, the integration error) and, for one-contact "
         "scenes, the largest attractive normal force over the peak force (required 0).  Spring energy "
         "created: stored tangential-spring energy that appeared without work while K_t = K_n(delta) "
         "grew at fixed xi (the literal law; docs/model.md §8), over the energy in play; reported.  Wall times are single runs on a shared machine: indicative only.\n\n",
         "| scene/case | engine | dt [s] | steps/contact | energy error | max overlap/R | non-physical | spring energy created | wall [s] |\n",
         "|---|---|---|---|---|---|---|---|---|\n"]
    for key, engine, rec, an in rows:
        L.append("| %s | %s | %s | %.1f | %s | %s | %s | %s | %.2f |\n" % (
            key, engine, fmt(rec["dt"]), rec["steps_per_contact"], fmt(rec["energy_rel_error"], ".2e"),
            fmt(rec["max_overlap_over_radius"], ".3g"), fmt(an["nonphysical"], ".1e"),
            fmt(an["spring_energy_created"], ".1e"), rec["wall_s"]))
    if extra_rows:
        L.append("\n## Scene-specific checks\n\n| scene/case | engine | quantity | value | limit | meaning |\n"
                 "|---|---|---|---|---|---|\n")
        for key, engine, name, val, lim, text in extra_rows:
            L.append("| %s | %s | %s | %.4g | %s | %s |\n" % (key, engine, name, val, "—" if lim is None else "%g" % lim, text))
    L.append("\n## At 2x, 5x and 10x the guard's largest safe dt\n\n"
             "Refused: the guard stopped the run without --force (jdem exit 2; LIGGGHTS error from fix "
             "jdem/guard).  With --force / `force`: completed, or stopped by the watchdog (its message, a "
             "closed `.part` file); finite: no NaN or inf anywhere in the file.\n\n"
             "| scene/case | engine | factor | refused | forced run | finite | energy error | max overlap/R |\n"
             "|---|---|---|---|---|---|---|---|\n")
    for r in records:
        if r["dt_factor"] == 1.0:
            continue
        L.append("| %s | %s | %g | %s | %s | %s | %s | %s |\n" % (
            r["scene"], r["engine"], r["dt_factor"], "yes" if r["refused"] else "**no**",
            "stopped by watchdog" if r["stopped_by_watchdog"] else "completed",
            "yes" if r["finite"] else "**no**", fmt(r["energy_rel_error"], ".2e"),
            fmt(r["max_overlap_over_radius"], ".3g")))
    with open(os.path.join(out, "report.md"), "w") as fh:
        fh.write("".join(L))


if __name__ == "__main__":
    main()
