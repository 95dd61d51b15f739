#!/usr/bin/python3
"""The seed's Chapter 4 claims (scripts/mixing/claims_ch4.py) on hand-made results whose verdicts
follow from the claims' definitions: each check must say "held" on a case built to hold, and
"not held" on the same case with one number moved across its boundary."""
import copy

from tests.mixing.common import check, finish
from scripts.mixing import agreement, claims_ch4, stats

MODELS = claims_ch4.MODELS


def fill(phi_values, rho=2600.0, z=5.0, big_right=0.9, small_left=0.6):
    """A fill result: nine points with these phi_v values, rho_b and Z varying by +-1 %."""
    wobble = [1 + 0.01 * ((k % 3) - 1) for k in range(9)]
    points = [{"phi_v": v, "rho_b": rho * w, "Z": z * w, "n": 0.36 * w}
              for v, w in zip(phi_values, wobble)]
    return {"points": points, "sides": {"big_right": big_right, "small_left": small_left},
            "summary": {k: stats.summary([q[k] for q in points])
                        for k in ("phi_v", "rho_b", "Z", "n")}}


def spread(mean, half):
    return [mean - half, mean, mean + half] * 3


def campaign():
    """Model 2 worst and split, 3 and 4 above 1 and 2, 5 above 3; the second pass converges.
    Model 3 has one shifted realisation, 0.001 above its fill: the run-to-run spread of every
    model (pooled) is then 0.0007, and a difference counts beyond 0.002."""
    first = {"model1": 0.010, "model2": 0.002, "model3": 0.040, "model4": 0.045,
             "model5": 0.050, "model6": 0.030}
    found = {"jdem": {}}
    for m in MODELS:
        found["jdem"][m] = {"fill1": fill(spread(first[m], 0.004)),
                            "fill2": fill(spread(0.06, 0.002))}
    found["jdem"]["model3"]["jitter"] = [fill(spread(0.041, 0.004))]
    return found


def verdicts(found, check_fn):
    return [line.endswith(": held") for line in check_fn(found, "jdem")]


def test_all_hold():
    f = campaign()
    for fn in (claims_ch4.model2_split, claims_ch4.obstacles_left, claims_ch4.second_pass,
               claims_ch4.phi_discriminates):
        v = verdicts(f, fn)
        check("holds_" + fn.__name__, v and all(v), f"{fn(f, 'jdem')}")


def test_each_fails():
    f = campaign()
    g = copy.deepcopy(f)
    g["jdem"]["model2"]["fill1"]["sides"]["small_left"] = 0.4   # small spheres not left
    check("split_not_held", verdicts(g, claims_ch4.model2_split)[0] is False)
    g = copy.deepcopy(f)
    g["jdem"]["model2"]["fill1"] = fill(spread(0.09, 0.004))     # model 2 no longer the worst
    check("worst_not_held", verdicts(g, claims_ch4.model2_split)[1] is False)
    g = copy.deepcopy(f)
    g["jdem"]["model5"]["fill1"] = fill(spread(0.035, 0.004))    # 5 below 3
    check("model5_not_held", verdicts(g, claims_ch4.obstacles_left) == [True, False])
    g = copy.deepcopy(f)
    g["jdem"]["model3"]["fill2"] = fill(spread(0.06, 0.02))      # wider after the second pass
    check("second_pass_spread_not_held", verdicts(g, claims_ch4.second_pass) == [True, False])
    g = copy.deepcopy(f)
    for m in MODELS:                                             # rho_b differs between models
        g["jdem"][m]["fill1"] = fill(spread(g["jdem"][m]["fill1"]["summary"]["phi_v"]["mean"], 0.004),
                                     rho=2000.0 + 100.0 * MODELS.index(m))
    check("rho_discriminates_not_held", verdicts(g, claims_ch4.phi_discriminates) == [False])


def test_no_spread_measured():
    """With no realisation anywhere there is no run-to-run spread: an ordering claim is not
    resolved, whatever the signs say (5 above 3, 3 and 4 above 1 and 2 here)."""
    g = campaign()
    del g["jdem"]["model3"]["jitter"]
    lines = claims_ch4.obstacles_left(g, "jdem")
    check("no_spread_not_resolved", len(lines) == 2 and all(x.endswith(": " + agreement.UNMEASURED)
                                                            for x in lines), lines)
    line = claims_ch4.second_pass(g, "jdem")[0]
    check("no_spread_second_pass_not_resolved", line.endswith(": " + agreement.UNMEASURED), line)


def test_discrimination_index():
    """Range of the model means over the mean within-model std, by hand for phi_v."""
    f = campaign()
    within = stats.summary(spread(0.01, 0.004))["std"]   # every model has the same spread
    want = (0.050 - 0.002) / within
    got = claims_ch4.discrimination(f, "jdem", "phi_v", 1)
    check("discrimination_index", abs(got - want) < 1e-12 * want, f"got {got}, expected {want}")


def test_incomplete_is_silent():
    f = campaign()
    del f["jdem"]["model4"]["fill1"]
    check("worst_needs_all_models", len(claims_ch4.model2_split(f, "jdem")) == 1)
    check("left_needs_models_1_to_4", len(claims_ch4.obstacles_left(f, "jdem")) == 1)


def test_run_to_run_spread():
    """With Model 3 repeated (trimmed means 0.040, 0.038, 0.042: s = 0.002), "Model 5 mixes
    better than Model 3" counts beyond 2 sqrt(s² + s²) = 0.005657 (Model 5 without repeats takes
    the pooled s, Model 3's): held at +0.010, not resolved at +0.004 and -0.004, not held at
    -0.006."""
    f = campaign()
    f["jdem"]["model3"]["jitter"] = [fill(spread(0.038, 0.004)), fill(spread(0.042, 0.004))]
    bound = 2.0 * (2.0 ** 0.5) * 0.002
    for phi5, want in ((0.050, "held"), (0.044, claims_ch4.UNRESOLVED),
                       (0.036, claims_ch4.UNRESOLVED), (0.034, "not held")):
        g = copy.deepcopy(f)
        g["jdem"]["model5"]["fill1"] = fill(spread(phi5, 0.004))
        line = claims_ch4.obstacles_left(g, "jdem")[1]
        check("model5_vs_3_at_%.3f" % phi5, line.endswith(": " + want), line)
        check("model5_bound_%.3f" % phi5, ("= %.4f)" % bound) in line, line)
    g = copy.deepcopy(f)   # pass 2's means as scattered as pass 1's, to within 2 s = 0.004
    first = [g["jdem"][m]["fill1"]["summary"]["phi_v"]["mean"] for m in MODELS]
    for m, v in zip(MODELS, first):
        g["jdem"][m]["fill2"] = fill(spread(v + 0.05, 0.002))
    line = claims_ch4.second_pass(g, "jdem")[0]
    check("second_pass_unresolved", line.endswith(": " + claims_ch4.UNRESOLVED)
          and "a change counts beyond 2 s = 0.0040" in line, line)
    g = copy.deepcopy(f)   # Model 2 within the spread of Model 1 (0.002 against 0.010 + 0.004)
    g["jdem"]["model1"]["fill1"] = fill(spread(0.006, 0.004))
    line = claims_ch4.model2_split(g, "jdem")[1]
    check("worst_unresolved", line.endswith(": " + claims_ch4.UNRESOLVED), line)
    # Model 5 repeated once (0.048 and 0.054): a std of one degree of freedom is not its own
    # (0.004243 would give a bound of 0.00938 and "not resolved") but joins the pool:
    # sqrt((8e-6 + 1.8e-5) / 3) = 0.002944, bound 2 sqrt(0.002² + 0.002944²) = 0.00712 < 0.008
    g = copy.deepcopy(f)
    g["jdem"]["model5"]["fill1"] = fill(spread(0.048, 0.004))
    g["jdem"]["model5"]["jitter"] = [fill(spread(0.054, 0.004))]
    line = claims_ch4.obstacles_left(g, "jdem")[1]
    check("one_repeat_joins_the_pool", line.endswith(": held") and "= 0.0071)" in line, line)
    # and two in the other engine too (0.050 and 0.052): two degrees of freedom, Model 5's own
    # over both engines, sqrt((1.8e-5 + 2e-6) / 2) = 0.003162, bound 2 sqrt(0.002² + 0.003162²) =
    # 0.0075 (the pool over every model would give 0.0066)
    g["liggghts-jdem"] = {"model5": {"fill1": fill(spread(0.050, 0.004)),
                                     "jitter": [fill(spread(0.052, 0.004))]}}
    line = claims_ch4.obstacles_left(g, "jdem")[1]
    h = copy.deepcopy(g)   # Model 1 repeated at φv 0.001 and 0.0: segregated, it stays out of the pool
    h["jdem"]["model1"]["fill1"] = fill(spread(0.001, 0.001))
    h["jdem"]["model1"]["jitter"] = [fill(spread(0.0, 0.0))]
    del h["liggghts-jdem"]
    one = claims_ch4.obstacles_left(h, "jdem")[1]
    check("segregated_model_stays_out_of_the_pool", one.endswith(": held") and "= 0.0071)" in one, one)
    check("own_spread_over_both_engines", line.endswith(": held") and "= 0.0075)" in line, line)


for t in (test_all_hold, test_each_fails, test_no_spread_measured, test_discrimination_index,
          test_incomplete_is_silent, test_run_to_run_spread):
    t()
finish()
