#!/usr/bin/python3
"""The break-by-break comparison of the Chapter 5 cross-engine horizon
(scripts/mixing/horizon_ch5.py, break_agreement) on two hand-made bond records whose answer is
known by construction; the trajectory half is horizon_ch4's, tested by test_horizon.py.

Four bonds, two formed at step 0 and two at step 100.  Run A breaks them at steps 500 (pair
1-2, shear; pair 3-4, tension), 700 (5-6, shear) and 900 (7-8, tension); run B lists the same
breaks with some pairs the other way round (8-7, 2-1) and in another order, except that its last
break comes one step later, at 901.  Expected: the same bonds; the first break step 500, pair
1-2 (the lower pair of the two at that step), shear, in both; 3 breaks in the same order, then
(900, 7-8) against (901, 7-8); up to a horizon at step 800, 3 breaks each and the same; at step
1000 all 4 broken in each, half in tension.  A formed step moved makes the bonds differ.  The
scene editor replaces the one line it is given and refuses a key that occurs twice.  The first
wall contact lies between the last sample without one and the first with one; the free-fall
claim holds for a Group 2 case whose first break follows the last free sample, fails for one
whose break precedes it, and leaves Group 3 alone.
"""
import copy
import os
import tempfile

import h5py
import numpy as np

from tests.mixing.common import check, close, finish
from scripts.mixing import horizon_ch5

DT = 1.0e-4
BONDS = np.array([[1, 2], [3, 4], [5, 6], [7, 8]])
FORMED = np.array([0, 0, 100, 100])


def record(broken, steps, modes, bonds=BONDS, formed=FORMED):
    return {"bonds": bonds, "formed": formed, "broken": np.array(broken), "broken_step": np.array(steps),
            "mode": np.array(modes), "broken_at": np.zeros((len(steps), 3)), "dt": DT}


a = record([[1, 2], [3, 4], [5, 6], [7, 8]], [500, 500, 700, 900], [2, 1, 2, 1])
b = record([[8, 7], [5, 6], [3, 4], [2, 1]], [901, 700, 500, 500], [1, 2, 1, 2],
           bonds=BONDS[::-1, ::-1], formed=FORMED[::-1])
r = horizon_ch5.break_agreement(a, b, 800, 1000)

check("ch5_horizon_same_bonds", r["same_bonds"] and r["bonds"] == [4, 4], str(r["bonds"]))
for e in horizon_ch5.ENGINES:
    f = r["first"][e]
    check(f"ch5_horizon_first_break_{e}", f["step"] == 500 and f["pair"] == [1, 2] and f["mode"] == "shear",
          str(f))
    close(f"ch5_horizon_first_break_time_{e}", f["time"], 500 * DT, 1e-12)
check("ch5_horizon_common_prefix", r["common_prefix"] == 3, str(r["common_prefix"]))
d = r["first_difference"]
check("ch5_horizon_first_difference",
      (d["jdem"]["step"], d["jdem"]["pair"]) == (900, [7, 8]) and
      (d["liggghts-jdem"]["step"], d["liggghts-jdem"]["pair"]) == (901, [7, 8]) and
      d["jdem"]["mode"] == d["liggghts-jdem"]["mode"] == "tension", str(d))
h = r["by_horizon"]
check("ch5_horizon_breaks_by_horizon", h["breaks"] == [3, 3] and h["same"] and h["step"] == 800, str(h))
for e in horizon_ch5.ENGINES:
    t = r["totals"][e]
    check(f"ch5_horizon_totals_{e}", t["broken"] == 4 and t["formed"] == 4, str(t))
    close(f"ch5_horizon_tension_{e}", t["tension"], 0.5, 1e-15)

moved = copy.deepcopy(b)
moved["formed"] = FORMED[::-1] + np.array([0, 0, 0, 1])
check("ch5_horizon_bonds_differ", not horizon_ch5.break_agreement(a, moved, 800, 1000)["same_bonds"],
      "a bond formed one step later went unnoticed")
check("ch5_horizon_no_horizon", horizon_ch5.break_agreement(a, b, None, 1000)["by_horizon"] is None,
      "a run that never agreed got breaks up to a horizon")

text = "time:\n  dt: 0.0001\n  steps: 270000\noutput:\n  every: 10000\n  observables_every: 1000\n"
got = horizon_ch5.set_key(text, "steps", "20000")
check("ch5_horizon_set_key", got == text.replace("270000", "20000"), got)
try:
    horizon_ch5.set_key(text + "  steps: 5\n", "steps", "1")
    check("ch5_horizon_set_key_twice", False, "a key on two lines was edited")
except SystemExit as e:
    check("ch5_horizon_set_key_twice", "not exactly one '  steps:' line" in str(e), str(e))

# first_wall_contact: wall contacts sampled every 200 steps, none until the sample at 6200
with tempfile.TemporaryDirectory() as tmp:
    path = os.path.join(tmp, "obs.h5")
    with h5py.File(path, "w") as f:
        f["observables/wall_contacts/step"] = np.arange(0, 8001, 200)
        f["observables/wall_contacts/value"] = np.where(np.arange(0, 8001, 200) >= 6200, 16.0, 0.0)
    w = horizon_ch5.first_wall_contact(path)
    check("ch5_horizon_first_wall_contact", w == {"last_free": 6000, "seen": 6200}, str(w))

# free_fall_claims: a Group 2 case whose first break (step 6172) follows the last free sample
# (6000) holds, one whose break (5900) precedes it does not; a Group 3 case is not judged
def case(name, brk):
    b = {"first": {e: horizon_ch5.describe((brk, 71, 72, 2), DT) for e in horizon_ch5.ENGINES}}
    return {"case": name, "breaks": b,
            "first_wall_contact": {e: {"last_free": 6000, "seen": 6200} for e in horizon_ch5.ENGINES}}
lines = horizon_ch5.free_fall_claims([case("group2_model1", 6172), case("group2_model2", 5900),
                                      case("group3_model1", 5900)])
check("ch5_free_fall_claims", len(lines) == 4 and all("group2_model1" in l and l.endswith("**held**")
                                                    for l in lines[:2])
      and all("group2_model2" in l and l.endswith("**not held**") for l in lines[2:]), "\n".join(lines))

finish()
