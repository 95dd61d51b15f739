#!/usr/bin/python3
"""The break-by-break comparison of the Chapter 5 cross-engine horizon
(scripts/mixing/horizon_ch5.py) on hand-made bond records and observables whose answers are
known by construction; the trajectory half is horizon_ch4's, tested by test_horizon.py.

* break_agreement: four bonds, two formed at step 0 and two at step 100.  Run A breaks them at
  steps 500 (pair 1-2, shear; pair 3-4, tension), 700 (5-6, shear) and 900 (7-8, tension); run B
  lists the same breaks with some pairs the other way round (8-7, 2-1) and in another order,
  except that its last break comes one step later, at 901.  Expected: the same bonds; the first
  break step 500, pair 1-2 (the lower pair of the two at that step), shear, in both; 3 breaks in
  the same order, then (900, 7-8) against (901, 7-8); up to a horizon at step 700 (a break on it
  counts) 3 breaks each and the same, up to 900 not the same; at step 1000 all 4 broken in each,
  half in tension.  A formed step moved makes the bonds differ.
* the scene editor replaces the one line it is given and refuses a key that occurs twice; the
  stream's shift moves the inlet's origin by K micrometres in y and nothing else.
* first_wall_contact: the first sample with a wall contact, and whether the samples were every
  step.
* free_fall_claims: a Group 2 case whose first break follows the first wall contact holds, one
  whose break comes at the contact's step does not, one with breaks and no wall contact does
  not, one sampled every 200 steps is undecided; Group 3 is not judged.
* spread_rows: the engines' means, the std pooled over both engines' runs of a case and over a
  group's cases, and the bound 2 s sqrt(1/n + 1/n'), against hand computations.
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
ENGINES = horizon_ch5.ENGINES


def record(broken, steps, modes, bonds=BONDS, formed=FORMED):
    return {"bonds": bonds, "formed": formed, "broken": np.array(broken), "broken_step": np.array(steps),
            "mode": np.array(modes), "broken_at": np.zeros((len(steps), 3)), "dt": DT}


# ---- break_agreement ----
a = record([[1, 2], [3, 4], [5, 6], [7, 8]], [500, 500, 700, 900], [2, 1, 2, 1])
b = record([[8, 7], [5, 6], [3, 4], [2, 1]], [901, 700, 500, 500], [1, 2, 1, 2],
           bonds=BONDS[::-1, ::-1], formed=FORMED[::-1])
r = horizon_ch5.break_agreement(a, b, 700, 1000)

check("ch5_horizon_same_bonds", r["same_bonds"] and r["bonds"] == [4, 4], str(r["bonds"]))
for e in ENGINES:
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
check("ch5_horizon_breaks_by_horizon", h["breaks"] == [3, 3] and h["same"] and h["step"] == 700, str(h))
h = horizon_ch5.break_agreement(a, b, 900, 1000)["by_horizon"]
check("ch5_horizon_breaks_by_horizon_differ", h["breaks"] == [4, 3] and not h["same"], str(h))
for e in ENGINES:
    t = r["totals"][e]
    check(f"ch5_horizon_totals_{e}", t["broken"] == 4 and t["formed"] == 4, str(t))
    close(f"ch5_horizon_tension_{e}", t["tension"], 0.5, 1e-15)
moved = copy.deepcopy(b)
moved["formed"] = FORMED[::-1] + np.array([0, 0, 0, 1])
check("ch5_horizon_bonds_differ", not horizon_ch5.break_agreement(a, moved, 700, 1000)["same_bonds"],
      "a bond formed one step later went unnoticed")

# ---- the scene editor ----
text = ("time:\n  dt: 0.0001\n  steps: 270000\noutput:\n  every: 10000\n  observables_every: 1000\n"
        "inlets:\n- name: belt\n  origin: [-0.070499999999999993, 0.5, 1.8]\n  velocity: [1, 0, 0]\n")
got = horizon_ch5.set_key(text, "steps", "20000")
check("ch5_horizon_set_key", got == text.replace("270000", "20000"), got)
try:
    horizon_ch5.set_key(text + "  steps: 5\n", "steps", "1")
    check("ch5_horizon_set_key_twice", False, "a key on two lines was edited")
except SystemExit as e:
    check("ch5_horizon_set_key_twice", "not exactly one '  steps:' line" in str(e), str(e))
got = horizon_ch5.shift_stream(text, [-0.0705, 0.5, 1.8], 3)
check("ch5_horizon_shift_stream",
      got == text.replace("[-0.070499999999999993, 0.5, 1.8]", "[-0.0705, 0.500003, 1.8]"), got)

# ---- first_wall_contact ----
with tempfile.TemporaryDirectory() as tmp:
    def wall_contacts(steps, first):
        path = os.path.join(tmp, "obs%d_%d.h5" % (len(steps), first))
        with h5py.File(path, "w") as f:
            f["observables/wall_contacts/step"] = steps
            f["observables/wall_contacts/value"] = np.where(steps >= first, 16.0, 0.0)
        return horizon_ch5.first_wall_contact(path)
    w = wall_contacts(np.arange(0, 8001), 6150)
    check("ch5_first_wall_contact_every_step", w == {"step": 6150, "every_step": True}, str(w))
    w = wall_contacts(np.arange(0, 8001, 200), 6150)
    check("ch5_first_wall_contact_sparse", w == {"step": 6200, "every_step": False}, str(w))
    w = wall_contacts(np.arange(0, 8001), 9000)
    check("ch5_first_wall_contact_none", w == {"step": None, "every_step": True}, str(w))


# ---- free_fall_claims ----
def case(name, brk, wall, every_step=True):
    b = {"first": {e: None if brk is None else horizon_ch5.describe((brk, 71, 72, 2), DT) for e in ENGINES}}
    return {"case": name, "breaks": b,
            "first_wall_contact": {e: {"step": wall, "every_step": every_step} for e in ENGINES}}


lines = horizon_ch5.free_fall_claims([case("group2_model1", 6172, 6150), case("group2_model2", 6150, 6150),
                                      case("group2_model3", 5000, None), case("group2_model4", 6172, 6200, False),
                                      case("group2_model5", None, 6150), case("group3_model1", 100, 6150)])
want = [("group2_model1", "**held**"), ("group2_model2", "**not held**"), ("group2_model3", "**not held**"),
        ("group2_model4", "**undecided**"), ("group2_model5", "**held**")]
check("ch5_free_fall_claims",
      len(lines) == 2 * len(want) and all(c in line and line.endswith(v)
                                         for (c, v), pair in zip(want, zip(lines[::2], lines[1::2]))
                                         for line in pair), "\n".join(lines))


# ---- spread_rows ----
# jdem broke 5123 bonds (K = 0) and 5140, 5100 (K = 1, 2): mean 5121, squared deviations 4, 361,
# 441 (806); liggghts-jdem's lone run 5107: s = sqrt(806 / 2) = sqrt(403), the bound
# 2 s sqrt(1/3 + 1/1); 5107 is 14 below, inside; 5180 (59 above) is outside 46.36.  With
# liggghts-jdem's runs 5107, 5111, 5115 (mean 5111, squared deviations 32): s = sqrt(838 / 4),
# bound 2 s sqrt(2/3) = 23.63, difference -10, inside.
def spread_case(name, jdem, lig):
    return {"case": name, "breaks": {"totals": {"jdem": {"broken": jdem}, "liggghts-jdem": {"broken": lig}}}}


def reals(*counts):
    return [{"jitter": k + 1, "totals": {"broken": c}} for k, c in enumerate(counts)]


q = horizon_ch5.spread_rows([spread_case("group2_model1", 5123, 5107)],
                            {"group2_model1": {"jdem": reals(5140, 5100)}})
close("ch5_spread_mean", q[0]["mean"]["jdem"], 5121.0, 1e-12)
close("ch5_spread_std", q[0]["std"], 403 ** 0.5, 1e-12)
close("ch5_spread_bound", q[0]["bound"], 2 * 403 ** 0.5 * (4 / 3) ** 0.5, 1e-12)
check("ch5_spread_held", q[0]["held"] and q[0]["difference"] == -14 and q[0]["counts"]["jdem"] == [5123, 5140, 5100]
      and q[0]["jitters"]["jdem"] == [0, 1, 2] and q[0]["counts"]["liggghts-jdem"] == [5107], str(q))
q = horizon_ch5.spread_rows([spread_case("group2_model1", 5123, 5180)],
                            {"group2_model1": {"jdem": reals(5140, 5100)}})
check("ch5_spread_not_held", not q[0]["held"] and q[0]["difference"] == 59, str(q))
q = horizon_ch5.spread_rows([spread_case("group2_model1", 5123, 5107)],
                            {"group2_model1": {"jdem": reals(5140, 5100), "liggghts-jdem": reals(5115, 5111)}})
close("ch5_spread_both_engines_std", q[0]["std"], (838 / 4) ** 0.5, 1e-12)
close("ch5_spread_both_engines_bound", q[0]["bound"], 2 * (838 / 4) ** 0.5 * (2 / 3) ** 0.5, 1e-12)
check("ch5_spread_both_engines", q[0]["held"] and q[0]["difference"] == -10 and q[0]["dof"] == 4, str(q))
check("ch5_spread_no_realisations", horizon_ch5.spread_rows([spread_case("group2_model1", 5123, 5107)], {}) == [],
      "a case without realisations got a spread")
# pooled over a group: a second Group 2 case, jdem 6000, 6004, 6008 (squared deviations 32) and
# liggghts-jdem's lone 6015, pools with the first (806) to sqrt(838 / 4) = sqrt(209.5); its
# difference 11 is outside its own 2 x 4 x sqrt(4/3) = 9.24 but inside the pooled
# 2 sqrt(209.5) sqrt(4/3) = 33.4; a Group 3 case pools alone
q = horizon_ch5.spread_rows([spread_case("group2_model1", 5123, 5107), spread_case("group2_model2", 6000, 6015),
                             spread_case("group3_model2", 6000, 6015)],
                            {"group2_model1": {"jdem": reals(5140, 5100)},
                             "group2_model2": {"jdem": reals(6004, 6008)},
                             "group3_model2": {"jdem": reals(6004, 6008)}})
close("ch5_spread_pooled", q[0]["pooled_std"], 209.5 ** 0.5, 1e-12)
check("ch5_spread_pooled_same_group", q[1]["pooled_std"] == q[0]["pooled_std"] and q[0]["pooled_dof"] == 4
      and q[2]["pooled_std"] == 4.0 and q[2]["pooled_dof"] == 2, str(q))
check("ch5_spread_pooled_verdicts", q[1]["held"] is False and q[1]["pooled_held"] is True,
      "11 against 9.24 (own) and 33.4 (pooled): " + str(q[1]))
# the failure mode: of 7440 bonds, jdem's runs broke fractions 0.25, 0.2501 and 0.2499 in tension
# (1860, 1860.744 -> 1861, 1859.256 -> 1859), liggghts-jdem's 0.26 (1934.4 -> 1934): the counts
# rounded from the fractions, the table headed by what it counts
t = lambda frac: {"formed": 7440, "broken": 5000, "tension": frac}
q = horizon_ch5.spread_rows([{"case": "group2_model1", "breaks": {"totals": {"jdem": t(0.25), "liggghts-jdem": t(0.26)}}}],
                            {"group2_model1": {"jdem": [{"jitter": 1, "totals": t(0.2501)},
                                                        {"jitter": 2, "totals": t(0.2499)}]}}, "tension")
check("ch5_spread_tension_counts", q[0]["counts"] == {"jdem": [1860, 1861, 1859], "liggghts-jdem": [1934]}
      and q[0]["difference"] == 74.0, str(q[0]["counts"]))
check("ch5_spread_tension_table", "| case | bonds broken in tension by the end, jdem (K µm: count) |"
      in horizon_ch5.spread_table(q), horizon_ch5.spread_table(q)[:200])

# repeated counts: jdem 10, 10, 10, 16 (3 equal pairs; std 3, so 6 pairs x 1/(2 sqrt(pi) 3) =
# 0.564 expected) and liggghts-jdem 10, 12 (none; std sqrt(2), 1/(2 sqrt(pi) sqrt(2)) = 0.199):
# 3 against 0.76, more than twice; the engines' spreads differ by 3 / sqrt(2) = 2.1x
rows = [{"case": "group2_model1", "counts": {"jdem": [10, 10, 10, 16], "liggghts-jdem": [10, 12]}}]
text = horizon_ch5.repeats(rows)
check("ch5_repeats_equal_pairs", text.startswith("Pairs of runs of one case and engine that end with the same "
                                                 "count: 3, where") and "would give 0.8:" in text
      and text.endswith("differ by up to 2.1x (group2_model1)."), text)
rows[0]["counts"]["jdem"] = [10, 13, 16, 19]
text = horizon_ch5.repeats(rows)
check("ch5_repeats_none", "count: 0, where" in text and "few values" not in text, text)

finish()
