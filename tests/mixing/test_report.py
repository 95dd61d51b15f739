#!/usr/bin/python3
"""report_ch4.py on a fresh machine: the results not under --out come from the committed
summary.json, each with the commit it came from; a local result wins and is stamped with this
commit; report.md names the rows taken from an earlier commit; an old entry keeps its commit when
written again.  The local fill is a hand-made trajectory whose mixing parameters follow in closed
form (spheres wholly inside the measuring spheres)."""
import json
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import yaml

from tests.mixing.common import ROOT, check, close, finish

REPORT = os.path.join(ROOT, "scripts", "mixing", "report_ch4.py")
POINTS = [(x, 0.5, z) for z in (0.2, 0.5, 0.7) for x in (0.25, 0.5, 0.75)]   # Table 4-2
R_SMALL, R_BIG, R_MEASURE, DENSITY = 0.015, 0.03, 0.1, 4000.0
COMMITTED, OLDER = "abc1234", "0ld5rc1"


def local_fill(path):
    """A small sphere at each point; at point 1 a second one touching it (one contact), at point
    5 a big one 0.05 m off (no contact); every sphere wholly inside its measuring sphere."""
    x = [list(p) for p in POINTS] + [[0.27, 0.5, 0.2], [0.55, 0.5, 0.5]]
    r = [R_SMALL] * 10 + [R_BIG]
    with h5py.File(path, "w") as f:
        p = f.create_group("particles/all")
        p["id"] = np.arange(1, len(r) + 1)
        p["species"] = np.array([0] * 10 + [1], np.int32)
        p["radius"] = np.array(r)
        p["mass"] = DENSITY * 4 / 3 * math.pi * np.array(r) ** 3
        p["position/value"] = np.array([x])
        p["position/step"] = np.array([100])
        p["position/time"] = np.array([27.0])
        f["parameters/scene"] = yaml.safe_dump({"walls": [BOX_FLOOR]}).encode()


# The box's extent for the height map (scripts/mixing_views.scene_geometry reads the plane walls).
BOX_FLOOR = {"type": "plane", "corners": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]}


def expected_bed_height():
    """The mean bed top of local_fill's columns (0.05 m, structure.height_map), by hand: the
    columns of x = 0.25 and 0.27, 0.5 and 0.75 hold small spheres at z = 0.2 (and above them,
    more than BED_GAP higher, at 0.5 and 0.7: not the bed), so their bed top is 0.2 + R_SMALL;
    the column of x = 0.55 holds only the big sphere at z = 0.5: 0.5 + R_BIG."""
    return (3 * (0.2 + R_SMALL) + (0.5 + R_BIG)) / 4


def expected_local_points():
    """The parameters of local_fill at the nine points, from the volumes of whole spheres."""
    v_t = R_MEASURE ** 3   # every volume below over 4/3 pi
    out = []
    for k in range(9):
        v_small = (2 if k == 0 else 1) * R_SMALL ** 3
        v_big = R_BIG ** 3 if k == 4 else 0.0
        v_s = v_small + v_big
        out.append({"phi_v": v_big / v_small, "phi_m": v_big / v_small, "e": (v_t - v_s) / v_s,
                    "n": (v_t - v_s) / v_t, "rho_b": DENSITY * v_s / v_t,
                    "Z": 2 * 1 / 2 if k == 0 else 0.0})
    return out


def hand_fill(phi, e, rho, z):
    points = [{"phi_v": phi + 0.001 * k, "phi_m": phi, "e": e + 0.01 * k, "n": e / (1 + e),
               "rho_b": rho + k, "Z": z + 0.01 * k} for k in range(9)]
    return {"particles": 41280, "deposit_height": 1.08, "points": points,
            "sides": {"big_right": 0.9, "small_left": 0.55},
            "summary": {key: {"mean": points[4][key], "std": 0.1} for key in points[0]}}


def hand_cubes():
    return [{"E": 1000.0 * k, "nu_xy": 0.1 * k, "nu_xz": 0.05 * k, "cond": 10.0 * k,
             "M_wall": 15000.0 + k, "M_best_fit": 30000.0 + k, "K0": 0.5 + 0.01 * k,
             "particles": 300 + k} for k in range(1, 10)]


def committed_summary():
    """jdem model1 (fill, cubes, times) from COMMITTED, model2's fill re-committed from OLDER,
    and an older model3 fill and time that the local ones replace."""
    model2 = dict(hand_fill(0.002, 0.54, 2598.0, 4.97), source=OLDER)
    times = {"jdem/model1/fill1": {"seconds": 7366.0, "cost": 1e10},
             "jdem/model3/fill1": {"seconds": 999.0, "cpu_seconds": 998.0, "cost": 1e10}}
    return {"commit": COMMITTED, "not_run": [], "results": {"jdem": {
        "model1": {"fill1": hand_fill(0.0, 0.547, 2586.0, 4.98), "pass1_cubes": hand_cubes(),
                   "jitter": [], "times": times},
        "model2": {"fill1": model2, "jitter": [], "times": {}},
        "model3": {"fill1": hand_fill(0.5, 0.1, 1000.0, 1.0), "jitter": [], "times": {}}}}}


def without_source(entry):
    if isinstance(entry, list):
        return [without_source(e) for e in entry]
    return {k: v for k, v in entry.items() if k != "source"}


def run_report(out, results):
    env = dict(os.environ, PYTHONPATH=ROOT)
    r = subprocess.run([sys.executable, REPORT, "--out", out, "--results", results],
                       capture_output=True, text=True, env=env)
    check("report_runs_" + os.path.basename(results), r.returncode == 0, r.stderr[-2000:])
    with open(os.path.join(results, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(results, "report.md")) as f:
        return summary, f.read()


def test_merge(tmp):
    out, results = os.path.join(tmp, "out"), os.path.join(tmp, "results")
    os.makedirs(os.path.join(out, "jdem", "model3"))
    os.makedirs(os.path.join(out, "jdem", "model1"))
    os.makedirs(results)
    local_fill(os.path.join(out, "jdem", "model3", "fill1.h5"))
    with open(os.path.join(out, "jdem", "model1", ".campaign_times.json"), "w") as f:
        json.dump({"jdem/model3/fill1": {"seconds": 12.5, "cpu_seconds": 11.0, "cost": 1.0}}, f)
    given = committed_summary()
    with open(os.path.join(results, "summary.json"), "w") as f:
        json.dump(given, f)
    rev = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                         text=True).stdout.strip() or "unknown"
    summary, text = run_report(out, results)
    got, want = summary["results"]["jdem"], given["results"]["jdem"]
    check("summary_commit_is_this_one", summary["commit"] == rev, f"{summary['commit']} vs {rev}")

    m1 = got["model1"]
    check("committed_fill_kept", without_source(m1["fill1"]) == want["model1"]["fill1"],
          f"{m1['fill1']}")
    check("committed_fill_source", m1["fill1"]["source"] == COMMITTED, m1["fill1"]["source"])
    check("committed_cubes_kept", without_source(m1["pass1_cubes"]) == want["model1"]["pass1_cubes"])
    check("committed_cubes_source", [c["source"] for c in m1["pass1_cubes"]] == [COMMITTED] * 9)
    check("recommitted_entry_keeps_its_commit", got["model2"]["fill1"]["source"] == OLDER,
          got["model2"]["fill1"]["source"])
    check("recommitted_entry_numbers", got["model2"]["fill1"] == want["model2"]["fill1"])

    t = m1["times"]
    check("committed_time_kept", t["jdem/model1/fill1"] == dict(
        want["model1"]["times"]["jdem/model1/fill1"], source=COMMITTED), f"{t['jdem/model1/fill1']}")
    check("local_time_wins", t["jdem/model3/fill1"] == {"seconds": 12.5, "cpu_seconds": 11.0,
                                                        "cost": 1.0, "source": rev},
          f"{t['jdem/model3/fill1']}")

    m3 = got["model3"]["fill1"]
    check("local_fill_wins_with_local_source", m3["source"] == rev and m3["particles"] == 11,
          f"source {m3['source']}, {m3['particles']} particles")
    close("local_fill_height", m3["deposit_height"], 0.7 + R_SMALL, 1e-15)
    close("local_fill_bed_height", m3["bed_height"], expected_bed_height(), 1e-15)
    for k, (g, w) in enumerate(zip(m3["points"], expected_local_points())):
        for key in w:
            close("local_point%d_%s" % (k + 1, key), g[key], w[key], 1e-12 * abs(w[key]) + 1e-15)

    check("committed_units_not_listed_as_not_run",
          "jdem/model1/fill1" not in summary["not_run"] and "jdem/model1/pass1_cubes (0 of 9)"
          not in summary["not_run"] and "jdem/model4/fill1" in summary["not_run"],
          f"{summary['not_run'][:6]}")
    for line in ("- jdem model1 pass 1: from commit %s" % COMMITTED,
                 "- jdem model2 pass 1: from commit %s" % OLDER,
                 "- jdem model1 pass 1 cubes: from commit %s" % COMMITTED,
                 "- jdem model1 units: from commit %s" % COMMITTED):
        check("report_footnote " + line, line in text.splitlines(), "missing")
    check("report_local_rows_not_footnoted", "jdem model3 pass 1: from commit" not in text
          and "model1–3" not in text)
    # E of the committed cubes 1000 ... 9000 Pa: the trimmed mean of 2000 ... 8000 and its std
    e_kept = np.arange(2000.0, 8001.0, 1000.0)
    cell = "| 1 | 1954 ± 841 | %.0f ± %.0f |" % (e_kept.mean(), e_kept.std(ddof=1))
    check("committed_cubes_in_table_4_3", cell in text, cell)
    check("figure_written_and_linked", "](fig4-11_jdem.png)" in text
          and os.path.exists(os.path.join(results, "fig4-11_jdem.png"))
          and os.path.exists(os.path.join(out, "fig4-11_jdem.png")))

    # Written again from the merged summary alone (another fresh machine): nothing is restamped.
    again = os.path.join(tmp, "again")
    os.makedirs(again)
    with open(os.path.join(again, "summary.json"), "w") as f:
        json.dump(summary, f)
    second, _ = run_report(os.path.join(tmp, "empty_out"), again)
    check("second_commit_keeps_every_entry", second["results"] == summary["results"])


def test_dt_study():
    """dt_study_ch4's rows: each variant's dt read back from its fill's cost (particles x time /
    dt, plan_ch4), and the largest move from the seed's dt in stds (phi_v 0.02 -> 0.025 at a std
    of 0.01: 0.50; the cubes alike: 0)."""
    from scripts.mixing import dt_study_ch4, plan_ch4

    def model(phi_v, dt, cpu, attempts):
        stat = lambda mean, std: {"mean": mean, "std": std}
        cost = plan_ch4.FILL_PARTICLES * plan_ch4.FILL_TIME / dt
        return {"fill1": {"summary": {"phi_v": stat(phi_v, 0.01), "e": stat(0.5, 0.02),
                                      "rho_b": stat(2500.0, 30.0), "Z": stat(5.0, 0.1)}},
                "pass1_cubes": [{"M_wall": 1000.0 * (k + 1), "K0": 0.6} for k in range(9)],
                "times": {"jdem/model1/fill1": dict({"cost": cost, "cpu_seconds": cpu},
                                                    **({"attempts": attempts} if attempts else {}))}}
    seed = {"jdem": {"model1": model(0.02, 1e-4, 100.0, None)}}
    guard = {"jdem": {"model1": model(0.025, 5.5e-5, 180.0, 2)}}
    dt_study_ch4.committed = lambda variant: guard if variant == "guard" else {}
    text = dt_study_ch4.table(seed, ("jdem",), ("model1",), (1, 2))
    rows = [line for line in text.splitlines() if line.startswith("| jdem | model1 | 1 |")]
    check("dt_study_two_rows", len(rows) == 2, text)
    check("dt_study_seed_row", rows[0].startswith("| jdem | model1 | 1 | 0.0001 (seed) | 0.0200 ± 0.0100")
          and rows[0].endswith("| (reference) | 100 (last attempt, if resumed) |"), rows[0])
    check("dt_study_guard_row", rows[1].startswith("| jdem | model1 | 1 | 5.5e-05 (guard) | 0.0250 ± 0.0100")
          and rows[1].endswith("| 0.50 (phi_v) | 180 |"), rows[1])
    check("dt_study_no_pass_2_rows", "| jdem | model1 | 2 |" not in text, text)


tmp = tempfile.mkdtemp()
def test_agreement():
    """agreement_ch4: the bed height of two realisations of Model 3 (the only spread) pooled for
    Model 1's engines, against 2 sqrt(2) s by hand; a fill without a bed height (an older result)
    gets a row that says so and no verdict."""
    from scripts.mixing import agreement_ch4
    fill = lambda bed, phi: dict(hand_fill(phi, 0.54, 2590.0, 5.0), bed_height=bed)
    found = {"jdem": {"model3": {"fill1": fill(1.000, 0.02), "jitter": [fill(1.010, 0.03)]},
                      "model1": {"fill1": fill(1.020, 0.0), "fill2": fill(1.0, 0.0)}},
             "liggghts-jdem": {"model1": {"fill1": fill(1.045, 0.0),
                                          "fill2": dict(hand_fill(0.0, 0.54, 2590.0, 5.0))}}}
    rows = {(r[1], r[2]): r for r in agreement_ch4.rows(found)}
    bound = 2 * math.sqrt(2) * np.std([1.000, 1.010], ddof=1)   # 0.0200
    bed = rows[(1, "bed height [m]")]
    check("agreement_bed_bound", bed[6] == "%.3f" % bound, f"{bed}")
    check("agreement_bed_not_held", bed[8] is False and bed[5] == "0.025", f"{bed}")   # 0.025 > 0.020
    check("agreement_bed_pooled_from", bed[7] == "pooled: jdem model3", f"{bed}")
    old = rows[(2, "bed height [m]")]
    check("agreement_older_fill_no_verdict", old[8] is None and old[4] == "—"
          and "before the bed height" in old[7], f"{old}")
    check("agreement_phi_held", rows[(1, "φv")][8] is True, f"{rows[(1, 'φv')]}")


test_merge(tmp)
test_dt_study()
test_agreement()
finish()
