"""energy.py — the energy balance of a fill with an inlet, from either engine's observables
(docs/output.md): every booked term, the bonds' stored, damped and breakage energy included,
against the energy the inlet brought in (observables/inlet_energy, kinetic and gravitational at
insertion), the way scripts/stability.py folds the bonds' terms.

    residual(t) = KE + RE + elastic + gravitational + damping + friction + bond elastic
                  + bond damping + bond breakage + lost - wall_work - inflow

(lost: observables/lost_energy, what the spheres deleted outside the scene's domain took;
docs/scenes.md "Domain").

The residual is reported over the energy in play, the largest over the samples of KE + RE +
elastic + the dissipated energies + |wall_work| (stability.py's measure: the gravitational
energy is a reference-dependent offset), and over the inflow.
"""
import h5py
import numpy as np

from scripts.mixing.deposit import scene_of

STORED = ("kinetic_energy", "rotational_energy", "elastic_energy", "bond_elastic_energy")
DISSIPATED = ("damping_dissipation", "friction_dissipation", "bond_damping_dissipation",
              "bond_breakage_energy")


def balance(path):
    """{"in_play", "inflow", "residual_in_play", "residual_inflow", "breakage", "damping",
    "friction", "samples"} [J and fractions] of the trajectory at path; None without an inlet
    or the energy observables, or for a run without the energy accounts (its scene's
    output.energy: false; it still writes the kinetic, gravitational and inlet energies, but
    books no dissipation)."""
    with h5py.File(path, "r") as f:
        if not (scene_of(f).get("output") or {}).get("energy", True):
            return None
        o = {k: f["observables/%s/value" % k][()] for k in
             STORED + DISSIPATED + ("gravitational_energy", "wall_work", "inlet_energy",
                                           "lost_energy")
             if "observables/%s/value" % k in f}
    if "inlet_energy" not in o or "kinetic_energy" not in o:
        return None
    zero = np.zeros_like(o["kinetic_energy"])
    get = lambda k: o.get(k, zero)
    stored = sum(get(k) for k in STORED)
    dissipated = sum(get(k) for k in DISSIPATED)
    residual = (stored + dissipated + get("gravitational_energy") + get("lost_energy")
                - get("wall_work") - o["inlet_energy"])
    in_play = float(np.max(stored + dissipated + np.abs(get("wall_work"))))
    worst = float(np.max(np.abs(residual)))
    return {"in_play": in_play, "inflow": float(np.max(np.abs(o["inlet_energy"]))),
            "residual_in_play": worst / in_play if in_play > 0 else float("nan"),
            "residual_inflow": worst / float(np.max(np.abs(o["inlet_energy"]))),
            "breakage": float(get("bond_breakage_energy")[-1]),
            "damping": float(get("damping_dissipation")[-1] + get("bond_damping_dissipation")[-1]),
            "friction": float(get("friction_dissipation")[-1]), "samples": int(len(residual)),
            "lost": float(get("lost_energy")[-1])}
