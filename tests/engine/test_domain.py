#!/usr/bin/python3
"""Engine test: the scene's domain (kernel/jdem_domain.h, stepper/domain.c).

tests/engine/scenes/domain_exit.yaml: four spheres fly out of the domain while a lattice settles
on a floor.  Each flier moves more than half the skin a step, so its own motion triggers a
neighbour build at every step, and it must be deleted exactly at the first step its centre is
outside [lo, hi) of ballistic motion.  References:
  - the deletion steps: the closed form of the fliers' motion (C, D along -y; B, held, along +z;
    A along +x);
  - the lost energy: a free flier keeps 1/2 m v.v + 1/2 I w.w - m g.x of its start exactly (the
    velocity Verlet step conserves it under a constant force); the held flier B moves at its
    initial velocity, so its energy is that at its deletion position;
  - the energy balance with the lost energy booked;
  - the bed: the same scene without `domain:` (no deletion; the fliers never touch the bed)
    must give the same bed trajectory.

Run:  /usr/bin/python3 tests/engine/test_domain.py        (JDEM=path/to/jdem to override)
"""
import os
import re
import tempfile

from tests.engine.engine_common import Checks, energy_total, engines, load, np, run, scene

G = np.array([0.0, 0.0, -9.81])
DT = 1.0e-6
LO, HI = np.array([-0.001, -0.001, -0.001]), np.array([0.05, 0.03, 0.03])
# id: (x0, v0, w0, held)
FLIERS = {1001: ([0.02005, 0.02, 0.02], [150.0, 0, 0], [0, 0, 100.0], False),
          1002: ([0.02, 0.02, 0.0152], [0, 0, 120.0], [0, 0, 0], True),
          1003: ([0.02, 0.005, 0.02], [0, -130.0, 0], [0, 0, 0], False),
          1004: ([0.022, 0.005, 0.02], [0, -130.0, 0], [0, 0, 0], False)}


def position(x0, v0, held, k):
    t = k * DT
    return x0 + v0 * t + (0.0 if held else 0.5) * G * t * t


def exit_step(x0, v0, held):
    k = 0
    while np.all(position(x0, v0, held, k) >= LO) and np.all(position(x0, v0, held, k) < HI):
        k += 1
    return k


c = Checks()
_, out = run("domain_exit")
t = load(out)
obs, step = t["obs"], None
with __import__("h5py").File(out, "r") as f:
    step = f["observables/lost_particles/step"][()]
    frame_ids = f["particles/all/id/value"][()]
    frame_steps = f["particles/all/id/step"][()]
ids = t["id"] if t["id"].ndim == 1 else frame_ids[0]
row = {int(i): k for k, i in enumerate(ids)}

want_energy, events = 0.0, {}
for pid, (x0, v0, w0, held) in FLIERS.items():
    x0, v0, w0 = np.array(x0), np.array(v0, float), np.array(w0, float)
    k = exit_step(x0, v0, held)
    events.setdefault(k, []).append(pid)
    r = t["radius"][row[pid]]
    m = t["mass"][row[pid]]
    inertia = 0.4 * m * r * r
    x = position(x0, v0, held, k) if held else x0  # a free flier's energy is that of its start
    want_energy += 0.5 * m * v0 @ v0 + 0.5 * inertia * w0 @ w0 - m * G @ x
lost = obs["lost_particles"]
expected = np.zeros_like(lost)
for k, pids in events.items():
    expected[step >= k] += len(pids)
c.check("domain_deletion_steps_match_ballistic_exit", np.array_equal(lost, expected),
        f"deletions at steps {[int(s) for s in step[1:][np.diff(lost) > 0]]}, expected "
        f"{sorted(events)}")
c.close_to("domain_lost_energy_closed_form", obs["lost_energy"][-1], want_energy, 1e-10)
# the rows of the deleted particles are empty (id -1) from the first frame after their step
for pid in FLIERS:
    k = exit_step(*(np.array(v, float) for v in FLIERS[pid][:2]), FLIERS[pid][3])
    gone = frame_ids[:, row[pid]] == -1
    c.check(f"domain_row_{pid}_empty_after_deletion", np.array_equal(gone, frame_steps >= k),
            f"rows empty at frames {frame_steps[gone].tolist()}, deleted at step {k}")
# E (id 1005), held at rest, keeps its load when the deletions move its scene index
e_row = row[1005]
e_moved = np.max(np.abs(t["position"][:, e_row] - t["position"][0, e_row]))
c.check("domain_held_particle_keeps_its_load", e_moved == 0.0 and frame_ids[-1, e_row] == 1005,
        f"the held sphere moved by {e_moved:.3g} m")
c.check("domain_bond_went_with_its_particles", obs["bonds"][0] == 1 and obs["bonds"][-1] == 0,
        f"bonds {obs['bonds'][0]:g} at the start, {obs['bonds'][-1]:g} at the end")
total = energy_total(obs) + obs["bond_elastic_energy"] + obs["bond_damping_dissipation"] \
    + obs["bond_breakage_energy"] + obs["lost_energy"]
drift = np.max(np.abs(total - total[0])) / abs(total[0])
c.check("domain_energy_balance_with_lost_energy", drift <= 1e-6, f"max |E - E0|/E0 = {drift:.3g}")


def run_text(text, name):
    """Run a scene given as text: (exit status and stderr, trajectory path)."""
    path = os.path.join(tempfile.mkdtemp(prefix="jdem_domain_"), name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    out_path = os.path.join(os.path.dirname(path), name + ".h5")
    p = engines.jdem("run", path, "-o", out_path, "--quiet")
    return p, out_path


def same_bed_as_open(label, t, ids, lost_run_obs, text):
    """The scene TEXT without its domain: nothing is deleted, and the bed (the lattice, which
    the fliers never touch) is the same as in the run with deletions, T."""
    open_text = re.sub(r"(?m)^domain:\n(  .*\n)+", "", text)
    assert open_text != text
    p, out2 = run_text(open_text, label + "_open")
    c.check(f"{label}_open_run_ran", p.returncode == 0, p.stderr.strip())
    if p.returncode != 0:
        return
    u = load(out2)
    bed = [k for k, i in enumerate(ids) if int(i) not in FLIERS]
    ids2 = u["id"] if u["id"].ndim == 1 else ids
    order2 = {int(i): k for k, i in enumerate(ids2)}
    bed2 = [order2[int(ids[k])] for k in bed]
    d = np.nanmax(np.abs(t["position"][-1][bed] - u["position"][-1][bed2]))
    c.check(f"{label}_bed_same_as_without_domain", d <= 1e-12, f"max difference {d:.3g} m")
    moved = np.max(np.abs(u["position"][-1][bed2] - u["position"][0][bed2]))
    c.check(f"{label}_bed_moved", moved > 1e-5, f"largest bed displacement {moved:.3g} m")
    c.check(f"{label}_bed_hit_the_floor", np.max(lost_run_obs["wall_contacts"]) > 10,
            f"at most {np.max(lost_run_obs['wall_contacts']):g} wall contacts")


text = open(scene("domain_exit")).read()
same_bed_as_open("domain", t, ids, obs, text)

# The same with MEPA's normal law, whose contact record is the whole state (its plastic overlap
# last) beside a rolling record with the energy accounts: the deletions renumber the particles
# and re-sort every list of candidates (stepper/reorder.c), which must keep each record's width
# (the sanitized build of this suite checks the copies' bounds).
mepa_text = text.replace("rolling_friction: 0.05}", "rolling_friction: 0.05, loading_stiffness: 2.0e6, "
                         "unloading_stiffness: 4.0e6, cohesive_stiffness: 1.0e6}")
mepa_text = mepa_text.replace("\nmaterials:\n", "\nmodel: {normal_law: mepa}\nmaterials:\n", 1)
assert mepa_text.count("unloading_stiffness") == 2 and "normal_law" in mepa_text
p, mepa_out = run_text(mepa_text, "domain_exit_mepa")
c.check("mepa_domain_run_ran", p.returncode == 0, p.stderr.strip())
if p.returncode == 0:
    m = load(mepa_out)
    with __import__("h5py").File(mepa_out, "r") as f:
        mepa_step = f["observables/lost_particles/step"][()]
    c.check("mepa_domain_deletion_steps_match_ballistic_exit",
            np.array_equal(mepa_step, step) and np.array_equal(m["obs"]["lost_particles"], expected),
            f"deletions at steps {[int(s) for s in mepa_step[1:][np.diff(m['obs']['lost_particles']) > 0]]}")
    same_bed_as_open("mepa_domain", m, ids, m["obs"], mepa_text)
c.exit()
