#!/usr/bin/python3
"""Engine test 4: energy balance of damped, frictional, rolling-resisted oblique impacts:
KE + RE + elastic + gravitational + damping + friction - wall_work must stay constant within
1e-3 of the initial total, for a spinning sphere on a floor that slides along x, and for two
spinning spheres (mu_r = 0.5).

Run:  /usr/bin/python3 tests/engine/test_energy_balance.py   (JDEM=path/to/jdem to override)
"""
from tests.engine.engine_common import Checks, energy_total, load, np, run

c = Checks()
for name, wall in (("oblique_wall", True), ("oblique_pair", False)):
    _, out = run(name)
    obs = load(out)["obs"]
    tot = energy_total(obs)
    drift = np.max(np.abs(tot - tot[0])) / abs(tot[0])
    c.check(f"{name}_energy_balance", drift <= 1e-3, f"max |E - E0|/E0 = {drift:.3g}")
    touched = np.max(obs["wall_contacts" if wall else "contacts"]) > 0
    c.check(f"{name}_contact_happened", touched, "no contact during the run")
    c.check(f"{name}_damping_dissipated", obs["damping_dissipation"][-1] > 1e-3 * abs(tot[0]),
            f"damping dissipation {obs['damping_dissipation'][-1]:.3g} J")
    c.check(f"{name}_friction_dissipated", obs["friction_dissipation"][-1] > 1e-4 * abs(tot[0]),
            f"friction dissipation {obs['friction_dissipation'][-1]:.3g} J")
    if wall:
        c.check(f"{name}_wall_did_work", abs(obs["wall_work"][-1]) > 1e-5 * abs(tot[0]),
                f"wall_work {obs['wall_work'][-1]:.3g} J")
# Independent reference: damped frictionless head-on impact, e = 0.5 -> e_out = 0.582 (spec
# table, 3 digits: +-0.0005 in e_out is +-6e-4 of the initial kinetic energy).
_, out = run("damped_headon")
obs = load(out)["obs"]
ke0 = obs["kinetic_energy"][0]
expected = (1.0 - 0.582 ** 2) * ke0
damp = obs["damping_dissipation"][-1]
c.check("damped_headon_damping_vs_spec_restitution", abs(damp - expected) <= 6e-4 * ke0,
        f"damping dissipation {damp:.6g} J, expected {expected:.6g} J")
c.check("damped_headon_no_friction", abs(obs["friction_dissipation"][-1]) <= 1e-12 * ke0,
        f"friction dissipation {obs['friction_dissipation'][-1]:.3g} J")
c.check("damped_headon_dissipation_never_decreases",
        bool(np.all(np.diff(obs["damping_dissipation"]) >= -1e-15 * ke0)), "damping decreased")
c.exit()
