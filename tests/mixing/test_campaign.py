#!/usr/bin/python3
"""The campaign driver (scripts/campaign.py) with dummy units: resume after a killed run, skip of
finished units, validation, selection by model / engine / unit, needs, progress and ETA."""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import yaml

from tests.mixing.common import ROOT, check, finish

CAMPAIGN = os.path.join(ROOT, "scripts", "campaign.py")

# A dummy unit appends its name to runs.log, spends BURN_<name> CPU seconds (default 0; then
# writes the CPU time it measured to OUTPUT.cpu), sleeps SLEEP_<name> seconds (default 0.1) and
# writes "ok" (or the content of CONTENT_<name>) to its output.
PLAN = '''
import os, sys
from scripts.campaign import Unit

HERE = {here!r}
WORKER = [sys.executable, "-c", """
import os, sys, time
name, out = sys.argv[1], sys.argv[2]
again = os.path.exists(out + ".started")  # left by an interrupted run of this unit
open(os.path.join({here!r}, "runs.log"), "a").write(name + ("-again" if again else "") + "\\\\n")
open(out + ".started", "w").close()
burn = float(os.environ.get("BURN_" + name, "0"))   # CPU seconds to spend first
while time.process_time() < burn:
    pass
if burn:
    open(out + ".cpu", "w").write(repr(time.process_time()))
time.sleep(float(os.environ.get("SLEEP_" + name, "0.1")))
open(out, "w").write(os.environ.get("CONTENT_" + name, "ok"))
"""]


def valid(path):
    text = open(path).read()
    return None if text == "ok" else f"content {{text!r}}, expected 'ok'"


def kept(name):
    """Unit.committed: the units named in COMMITTED (comma-separated) have a committed result."""
    return lambda: ("summary.json: " + name) if name in os.environ.get("COMMITTED", "").split(",") \
        else None


def units(argv):
    out = lambda n: os.path.join(HERE, "out", n + ".txt")
    plan = [
        Unit("a", [out("a")], WORKER + ["a", "{{out0}}"], model="m1", engine="e1", validate=valid,
             committed=kept("a")),
        Unit("b", [out("b")], WORKER + ["b", "{{out0}}"], model="m1", engine="e2", validate=valid,
             needs=["a"], committed=kept("b")),
        Unit("c", [out("c")], WORKER + ["c", "{{out0}}"], model="m2", engine="e1", validate=valid,
             cost=2.0, committed=kept("c")),
    ]
    if os.environ.get("WITH_R"):  # r: the resumable unit's test only
        return plan + [Unit("r", [out("r")], WORKER + ["r", "{{out0}}"], model="m4", engine="e1",
                            validate=valid, resumes=True)]
    if os.environ.get("WITH_S"):  # s: the worker under a shell, the killed shell's test only
        return plan + [Unit("s", [out("s")], ["sh", "-c", '"$0" "$@" & wait'] + WORKER + ["s", "{{out0}}"],
                            model="m6", engine="e1", validate=valid)]
    if os.environ.get("WITH_F"):  # f: its own directory, the times file's test only
        return plan + [Unit("f", [os.path.join(HERE, "out_f", "f.txt")], WORKER + ["f", "{{out0}}"],
                            model="m5", engine="e4", validate=valid)]
    if not os.environ.get("WITH_D"):  # d and e: the not-yet-runnable test's only
        return plan
    return plan + [
        Unit("d", [out("d")], WORKER + ["d", "{{out0}}"], model="m3", engine="e3", validate=valid,
             blocked=lambda: os.environ.get("BLOCKED_d")),
        Unit("e", [out("e")], WORKER + ["e", "{{out0}}"], model="m3", engine="e3", validate=valid,
             needs=["d"]),
    ]
'''


def campaign(here, *args, env=None, wait=True):
    cmd = [sys.executable, CAMPAIGN, os.path.join(here, "plan.py"), *args]
    e = {**os.environ, **(env or {})}
    if not wait:
        return subprocess.Popen(cmd, env=e, stderr=subprocess.PIPE, text=True,
                                start_new_session=True)
    return subprocess.run(cmd, env=e, stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def runs(here):
    path = os.path.join(here, "runs.log")
    return open(path).read().split() if os.path.exists(path) else []


def reset_log(here):
    if os.path.exists(os.path.join(here, "runs.log")):
        os.remove(os.path.join(here, "runs.log"))


def final(here, name):
    return os.path.join(here, "out", name + ".txt")


def setup():
    here = tempfile.mkdtemp()
    with open(os.path.join(here, "plan.py"), "w") as f:
        f.write(PLAN.format(scripts=os.path.join(ROOT, "scripts"), here=here))
    return here


def test_killed_run_resumes():
    here = setup()
    proc = campaign(here, env={"SLEEP_b": "30"}, wait=False)
    started = os.path.join(here, "out", ".partial", "b", "b.txt.started")
    deadline = time.monotonic() + 20
    while not os.path.exists(started) and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the driver and its running unit, as a power cut would
    proc.wait()
    check("killed_run_kept_finished_unit", open(final(here, "a")).read() == "ok", "a missing")
    check("killed_run_no_partial_final", not os.path.exists(final(here, "b")),
          "b exists under its final name")
    reset_log(here)
    r = campaign(here)
    check("resume_exit_status", r.returncode == 0, r.stderr)
    check("resume_skips_finished", runs(here) == ["b", "c"], f"ran {runs(here)}")
    check("resume_says_skip", "campaign: skip a (done)" in r.stderr, r.stderr)
    check("resume_clears_partial", not os.path.exists(os.path.join(here, "out", ".partial", "b")),
          "partial directory left")
    # progress and an ETA from the measured units: before c, 1 cost unit of b took ~0.1 s and
    # c costs 2, so the ETA is given
    check("progress_and_eta", "[2/2] c: running; ETA " in r.stderr
          and "[1/2] b: done in " in r.stderr, r.stderr)
    reset_log(here)
    r = campaign(here)
    check("rerun_runs_nothing", r.returncode == 0 and runs(here) == [], f"ran {runs(here)}")


def test_resumable_unit_continues():
    """A unit that resumes (a checkpointing run) finds what its killed run left in its partial
    directory, and the driver says it continues; an ordinary unit (b above) starts afresh.  Its
    recorded time covers both attempts: the killed one's wall and CPU time as last written to the
    partial directory (every campaign.SPENT_EVERY s), the CPU its worker measured itself."""
    here = setup()
    env = {"WITH_R": "1", "SLEEP_r": "30", "BURN_r": "1.0"}
    proc = campaign(here, "--unit", "r", env=env, wait=False)
    partial = os.path.join(here, "out", ".partial", "r")
    spent = os.path.join(partial, ".spent.json")
    deadline = time.monotonic() + 40
    while not os.path.exists(spent) and time.monotonic() < deadline:
        time.sleep(0.05)
    burned = float(open(os.path.join(partial, "r.txt.cpu")).read())
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    reset_log(here)
    r = campaign(here, "--unit", "r", env={"WITH_R": "1", "OMP_NUM_THREADS": "3"})
    check("resumable_unit_sees_its_partial_run", r.returncode == 0 and runs(here) == ["r-again"],
          f"ran {runs(here)}: {r.stderr}")
    check("resumable_unit_says_it_continues",
          "[1/1] r: continuing its interrupted run" in r.stderr, r.stderr)
    check("resumable_unit_final_output", open(final(here, "r")).read() == "ok", "r.txt")
    t = json.load(open(os.path.join(here, "out", ".campaign_times.json")))["r"]
    check("resumable_unit_time_counts_both_attempts",
          t["attempts"] == 2 and t["seconds"] >= 10.0 and t["cpu_seconds"] >= burned,
          f"recorded {t}; the killed attempt ran >= 10 s and its worker burned {burned:.2f} CPU s")
    # the threads a jdem run takes from the environment (stepper/main.c), and the machine
    cpu_name = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                     if line.startswith("model name")), None)
    check("unit_time_records_threads_and_machine",
          t.get("threads") == 3 and cpu_name is not None and t.get("machine", "").startswith(cpu_name),
          f"recorded {t}; OMP_NUM_THREADS=3, /proc/cpuinfo's model name {cpu_name!r}")


def test_killed_shell_keeps_its_cpu():
    """A unit's shell killed by SIGTERM while the worker under it runs on (as a session's end
    kills the lanes): the attempt's recorded CPU time keeps what the worker had burned, as last
    sampled from the process tree, although the campaign never waits for that worker."""
    here = setup()
    proc = campaign(here, "--unit", "s", env={"WITH_S": "1", "BURN_s": "1.5", "SLEEP_s": "14"}, wait=False)
    partial = os.path.join(here, "out", ".partial", "s")
    spent, deadline = os.path.join(partial, ".spent.json"), time.monotonic() + 40
    while time.monotonic() < deadline and not (os.path.exists(spent) and
                                                json.load(open(spent))["cpu_seconds"] >= 1.0):
        time.sleep(0.1)
    shells = [int(n) for n in os.listdir("/proc") if n.isdigit() and os.path.exists(f"/proc/{n}/stat")
              and open(f"/proc/{n}/stat").read().rsplit(")", 1)[1].split()[1] == str(proc.pid)]
    for pid in shells:
        os.kill(pid, signal.SIGTERM)
    proc.wait()
    burned = float(open(os.path.join(partial, "s.txt.cpu")).read())
    got = json.load(open(spent))
    # /proc counts user and system time each in whole clock ticks, rounded down: 2 ticks at most
    tick = 1.0 / os.sysconf("SC_CLK_TCK")
    check("killed_shell_attempt_keeps_worker_cpu", len(shells) == 1 and "s: FAILED" in proc.stderr.read()
          and got["cpu_seconds"] >= burned - 2 * tick,
          f"shells {shells}, recorded {got}, the worker burned {burned:.2f} CPU s")
    time.sleep(6)   # the orphaned worker sleeps past the first sample (campaign.SPENT_EVERY), then ends
    shutil.rmtree(here, ignore_errors=True)


def test_validation_and_selection():
    here = setup()
    r = campaign(here, "--unit", "a", env={"CONTENT_a": "garbage"})
    check("invalid_output_fails", r.returncode == 1 and "a: FAILED" in r.stderr
          and "output a.txt does not validate: content 'garbage', expected 'ok'" in r.stderr,
          r.stderr)
    check("invalid_output_not_final", not os.path.exists(final(here, "a")), "a.txt exists")
    reset_log(here)
    r = campaign(here, "--model", "m1", env={"CONTENT_a": "garbage"})
    check("need_failed_skips", r.returncode == 1 and runs(here) == ["a"]
          and "[2/2] b: skipped: needs a, which did not finish" in r.stderr
          and "campaign: 0 run, 1 failed, 1 skipped after a failure," in r.stderr,
          f"ran {runs(here)}: {r.stderr}")
    r = campaign(here, "--engine", "e2")
    check("needs_unfinished", r.returncode == 2 and "campaign: unit b needs a, which is neither "
          "done nor selected" in r.stderr, r.stderr)
    reset_log(here)
    r = campaign(here, "--model", "m1")
    check("select_model", r.returncode == 0 and runs(here) == ["a", "b"], f"ran {runs(here)}")
    reset_log(here)
    r = campaign(here, "--engine", "e1")
    check("select_engine", r.returncode == 0 and runs(here) == ["c"], f"ran {runs(here)}")
    r = campaign(here, "--model", "m9")
    check("select_nothing", r.returncode == 2 and "no unit matches --model m9" in r.stderr, r.stderr)
    r = campaign(here, "--list")
    check("list", r.stdout.split("\n")[:3] == ["done a", "done b", "done c"], r.stdout)


def test_committed_results():
    """On a machine without the outputs, a committed unit is skipped unless a unit to run reads
    it; a unit derived from one that runs again runs too; --rerun-committed runs them all."""
    here = setup()
    r = campaign(here, env={"COMMITTED": "a,c"})
    check("committed_need_runs_again", r.returncode == 0 and runs(here) == ["a", "b"]
          and "skip c (committed in summary.json: c)" in r.stderr
          and r.stderr.rstrip().endswith("0 already done, 1 committed"), f"ran {runs(here)}: {r.stderr}")
    here = setup()
    r = campaign(here, env={"COMMITTED": "a,b,c"})
    check("all_committed_none_runs", r.returncode == 0 and runs(here) == [], f"ran {runs(here)}")
    r = campaign(here, "--list", env={"COMMITTED": "a,b,c"})
    check("list_committed", r.stdout.split("\n")[0] == "committed a (summary.json: a)", r.stdout)
    r = campaign(here, env={"COMMITTED": "b,c"})   # a runs, so b (derived from it) does too
    check("derived_runs_again", r.returncode == 0 and runs(here) == ["a", "b"], f"ran {runs(here)}")
    here = setup()
    r = campaign(here, "--engine", "e2", env={"COMMITTED": "a"})
    check("committed_need_not_selected", r.returncode == 2 and "unit b needs a, which is neither "
          "done nor selected (its result is committed in summary.json: a, but not its output "
          "files: select it too)" in r.stderr, r.stderr)
    r = campaign(here, "--rerun-committed", env={"COMMITTED": "a,b,c"})
    check("rerun_committed", r.returncode == 0 and runs(here) == ["a", "b", "c"], f"ran {runs(here)}")
    r = campaign(here, env={"COMMITTED": "a,b,c"})   # done here: nothing runs, nothing committed
    check("done_beats_committed", runs(here) == ["a", "b", "c"]
          and r.stderr.rstrip().endswith("3 already done"), r.stderr)


def test_not_yet_runnable():
    """A unit whose engine lacks a feature is reported with the reason and skipped, with the
    units that need it; that is no failure; once the feature exists both run."""
    here = setup()
    r = campaign(here, "--model", "m3", env={"WITH_D": "1",
                                                  "BLOCKED_d": "the engine has no frobnicator"})
    check("blocked_not_run", r.returncode == 0 and runs(here) == [], f"ran {runs(here)}; {r.stderr}")
    check("blocked_says_why", "campaign: skip d: not yet runnable: the engine has no frobnicator"
          in r.stderr and "campaign: skip e: not yet runnable: needs d, which is not yet runnable"
          in r.stderr, r.stderr)
    check("blocked_counted", r.stderr.rstrip().endswith(
        "campaign: 0 run, 0 failed, 2 not yet runnable, 0 already done"), r.stderr)
    r = campaign(here, "--model", "m3", "--list", env={"WITH_D": "1", "BLOCKED_d": "no frobnicator"})
    check("blocked_listed", r.stdout.split("\n")[:2] == ["todo d (not yet runnable: no frobnicator)",
          "todo e (not yet runnable: needs d, which is not yet runnable)"], r.stdout)
    r = campaign(here, "--model", "m3", env={"WITH_D": "1"})
    check("unblocked_runs", r.returncode == 0 and runs(here) == ["d", "e"], f"ran {runs(here)}")


def test_times_beside_unrun_first_unit():
    """The measured times go beside the plan's first output (out/) even when the selection runs
    only a unit elsewhere (out_f/) and out/ does not exist yet."""
    here = setup()
    r = campaign(here, "--unit", "f", env={"WITH_F": "1"})
    times = os.path.join(here, "out", ".campaign_times.json")
    check("times_beside_unrun_first_unit", r.returncode == 0 and runs(here) == ["f"]
          and os.path.exists(times) and "f" in json.load(open(times)),
          f"exit {r.returncode}, ran {runs(here)}: {r.stderr[-400:]}")


def test_eta_per_engine():
    """The ETA prices each remaining unit at its own engine's measured seconds per unit of cost:
    e1 measured 10 s for cost 1, e2 30 s for cost 1; one unit of cost 2 of each remains:
    2 x 10 + 2 x 30 = 80 s.  An engine not measured yet takes the overall rate, into which an
    entry without an engine (recorded before 2026-12-07) counts too: 60 s / 4 = 15 s per cost;
    such an entry named "ENGINE/..." prices its engine (e3/old: 50 s per cost)."""
    from scripts.campaign import Times, Unit
    t = Times(os.path.join(tempfile.mkdtemp(), "times.json"))
    t.seconds = {"a": {"seconds": 10.0, "cost": 1.0, "engine": "e1"},
                 "b": {"seconds": 30.0, "cost": 1.0, "engine": "e2"}}
    unit = lambda engine: Unit("u", ["x"], ["true"], engine=engine, cost=2.0)
    check("eta_per_engine", t.eta([unit("e1"), unit("e2")]) == 80.0, t.eta([unit("e1"), unit("e2")]))
    t.seconds["old"] = {"seconds": 20.0, "cost": 2.0}
    check("eta_unmeasured_engine_overall", t.eta([unit("e3")]) == 2.0 * 60.0 / 4.0, t.eta([unit("e3")]))
    t.seconds["e3/old"] = {"seconds": 50.0, "cost": 1.0}   # recorded before entries named their engine
    check("eta_engine_from_an_older_entry_name", t.eta([unit("e3")]) == 100.0, t.eta([unit("e3")]))


def test_times_shared_by_campaigns_at_once():
    """Two campaign processes that loaded the times file before either finished a unit (as two
    `make mixing-bonded UNIT=...` started together do) keep both units' times: each add merges
    into the file as it is then, not as it was loaded."""
    from scripts.campaign import Times, Unit
    path = os.path.join(tempfile.mkdtemp(), "out", ".campaign_times.json")
    a, b = Times(path), Times(path)
    a.add(Unit("a", ["x"], ["true"]), 1.0, 1.0)
    b.add(Unit("b", ["y"], ["true"]), 2.0, 2.0)
    a.add(Unit("c", ["z"], ["true"]), 3.0, 3.0)
    got = json.load(open(path))
    check("times_shared_by_campaigns_at_once", sorted(got) == ["a", "b", "c"]
          and got["b"]["seconds"] == 2.0, f"{got}")


def test_ch4_plan():
    """The plan of make mixing (docs/mixing.md §4): 2 engines x 6 models x (2 fills, 1 second-
    pass scene, 2 x (1 cube-scene unit + 9 compressions)) = 276 units, plus the run-to-run
    spread's realisations (jdem: one of every model, two of Model 3; liggghts-jdem: two of Model
    3) and the 6 cross-engine horizons last, unique names, and every need an earlier unit."""
    from scripts.mixing import plan_ch4
    units = plan_ch4.units([])
    seen = set()
    order_ok = True
    for u in units:
        order_ok &= all(n in seen for n in u.needs)
        seen.add(u.name)
    want = 276 + (6 + 1) + 2 + 6
    check("ch4_plan_units", len(units) == want and len(seen) == want, f"{len(units)} units")
    cross = [u.name for u in units[-6:] if u.engine == "cross"]
    check("ch4_plan_horizons_last", cross == ["cross/model%d/horizon" % m for m in range(1, 7)]
          and "--frame-every" in units[-1].command
          and units[-1].command[units[-1].command.index("--frame-every") + 1] == "200",
          f"{[u.name for u in units[-6:]]}")
    check("ch4_plan_needs_come_first", order_ok, "a need after its unit")
    m3 = [u.name for u in units if u.model == "model3" and u.engine == "liggghts-jdem"]
    check("ch4_plan_model_engine", len(m3) == 23 + 2 and m3[0] == "liggghts-jdem/model3/fill1"
          and m3[-1] == "liggghts-jdem/model3/fill1_jitter2", f"{len(m3)}: {m3[:3]} ... {m3[-1:]}")
    j1 = [u.name for u in units if u.model == "model1" and "jitter" in u.name]
    check("ch4_plan_spread_of_every_model", j1 == ["jdem/model1/fill1_jitter1"], f"{j1}")


def test_ch4_fill_resumes():
    """The plan's jdem fill command, killed after its first checkpoint and run again as the
    campaign would, continues from the checkpoint and gives the uninterrupted trajectory bit for
    bit (a small conveyor fill, a checkpoint every 0.2 s of wall time)."""
    from scripts.mixing import plan_ch4
    from tests.checkpoint.compare_h5 import differences
    scene = os.path.join(ROOT, "tests", "checkpoint", "scenes", "inlet_stream.yaml")
    d = tempfile.mkdtemp()
    ref, out = os.path.join(d, "ref.h5"), os.path.join(d, "fill.h5")
    subprocess.run([plan_ch4.jdem(), "run", scene, "-o", ref, "--quiet"], check=True)
    argv = [a.format(out0=out, dir=d) for a in  # as the driver's run_unit fills them
            plan_ch4.fill_command("jdem", scene, False, checkpoint_seconds=0.2)]
    proc = subprocess.Popen(argv, stderr=subprocess.DEVNULL, start_new_session=True)
    ck = os.path.join(d, "fill.ckpt.h5")
    while not os.path.exists(ck) and proc.poll() is None:
        time.sleep(0.01)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    check("ch4_fill_killed_after_a_checkpoint", os.path.exists(ck) and not os.path.exists(out),
          "the run ended before its first checkpoint")
    r = subprocess.run(argv, capture_output=True, text=True)
    check("ch4_fill_resumed", r.returncode == 0 and "resuming from" in r.stderr, r.stderr[-300:])
    diffs, n = differences(ref, out) if r.returncode == 0 else (["no output"], 0)
    check("ch4_fill_resumed_equals_uninterrupted", not diffs and n > 10, "; ".join(diffs[:3]))


def test_trajectory_lands_with_its_sidecar():
    """A unit whose output is a trajectory (a jdem run of a small conveyor fill) lands with its
    XDMF sidecar beside it, and the sidecar reads the trajectory by its basename there, as
    ParaView opens it (docs/output.md)."""
    from scripts import campaign
    from scripts.mixing import plan_ch4
    scene = os.path.join(ROOT, "tests", "checkpoint", "scenes", "inlet_stream.yaml")
    d = tempfile.mkdtemp()
    final = os.path.join(d, "runs", "fill.h5")
    unit = campaign.Unit("t/fill", [final], [plan_ch4.jdem(), "run", scene, "-o", "{out0}", "--quiet"],
                         validate=plan_ch4.valid_trajectory)
    failed, _, _ = campaign.run_unit(unit)
    side = os.path.join(d, "runs", "fill.xdmf")
    text = open(side).read() if os.path.exists(side) else ""
    landed = os.listdir(os.path.dirname(final)) if os.path.isdir(os.path.dirname(final)) else []
    check("campaign_trajectory_lands_with_sidecar", failed is None and os.path.exists(final)
          and "fill.h5:/jdem/vertex_index" in text and ".partial" not in text, "%s; %s" % (failed, landed))
    check("campaign_partial_directory_cleared", not os.path.exists(campaign.partial_dir(unit)))
    shutil.rmtree(d, ignore_errors=True)


test_killed_run_resumes()
test_resumable_unit_continues()
test_trajectory_lands_with_its_sidecar()
test_killed_shell_keeps_its_cpu()
def test_ch4_dt_variants():
    """The plan's time-step variants: the seed's 1e-4 s forced, the guard's dt as jdem states it
    when it refuses the seed's, and half of it, each in its own output tree."""
    import re
    from scripts.mixing import plan_ch4
    refused = subprocess.run([plan_ch4.jdem(), "run", plan_ch4.SCENE, "--case", "model1", "-o",
                              os.path.join(tempfile.mkdtemp(), "x.h5")], capture_output=True,
                             text=True)
    m = re.search(r"unsafe: .*largest safe dt = ([0-9.e+-]+) s", refused.stderr)
    check("ch4_seed_dt_refused", refused.returncode == 2 and m is not None, refused.stderr)
    safe = float(m.group(1)) if m else float("nan")
    for variant, dt, forced in (("seed", 1e-4, True), ("guard", safe, False),
                                ("half", safe / 2, False)):
        plan = plan_ch4.units(["--dt", variant])
        fill, horizon = plan[0], plan[-1]
        cmd = fill.command[2]
        got = float(re.search(r"--dt (\S+)", cmd).group(1))
        check(f"ch4_dt_{variant}", abs(got - dt) <= 1e-5 * dt and ("--force" in cmd) == forced
              and fill.outputs[0].startswith(plan_ch4.OUT[variant] + os.sep),
              f"dt {got} (expected {dt:.6g}), command {cmd}, output {fill.outputs[0]}")
        hc = horizon.command   # the same dt, frames every 0.02 s in steps of it
        got = float(hc[hc.index("--dt") + 1])
        check(f"ch4_horizon_dt_{variant}", abs(got - dt) <= 1e-5 * dt and ("--force" in hc) == forced
              and int(hc[hc.index("--frame-every") + 1]) == round(0.02 / got)
              and horizon.outputs[0].startswith(plan_ch4.OUT[variant] + os.sep),
              f"command {hc}, output {horizon.outputs[0]}")
        # a variant's committed results are its own summary's: Model 1's fills and cubes, where
        # the summary has them, and no other model's (the dt study runs Model 1)
        with open(os.path.join(plan_ch4.VARIANT_RESULTS[variant], "summary.json")) as f:
            has = json.load(f)["results"]["jdem"]
        units = {u.name: u for u in plan}
        kept = {name: units[name].committed() for name in ("jdem/model1/fill1", "jdem/model1/pass2_cube9",
                                                          "jdem/model2/fill1")}
        summary = os.path.relpath(os.path.join(plan_ch4.VARIANT_RESULTS[variant], "summary.json"), ROOT)
        want = {"jdem/model1/fill1": "fill1" in has.get("model1", {}),
                "jdem/model1/pass2_cube9": len(has.get("model1", {}).get("pass2_cubes", [])) == 9,
                "jdem/model2/fill1": "fill1" in has.get("model2", {})}
        check(f"ch4_committed_{variant}", all((kept[n] or "").startswith(summary + ":") == want[n]
                                              and (kept[n] is None) != want[n] for n in kept)
              and want["jdem/model1/fill1"], f"committed {kept}; summary {summary} has {want}")


def test_ch4_ranks():
    """--ranks N (make mixing NP=N): each liggghts-jdem fill on N ranks split along y, jdem's
    fills and the cubes unchanged; the plan's arguments after "--" follow the driver's options."""
    from scripts.mixing import plan_ch4
    plan = {u.name: u for u in plan_ch4.units(["--ranks", "2"])}
    lig, jd = plan["liggghts-jdem/model1/fill1"].command[2], plan["jdem/model1/fill1"].command[2]
    cube = plan["liggghts-jdem/model1/pass1_cube1"].command
    check("ch4_ranks_fill", "--np 2 --processors 1 2 1" in lig and "--np" not in jd
          and "--np" not in cube, f"liggghts-jdem: {lig}; jdem: {jd}; cube: {cube}")
    check("ch4_liggghts_skin", "--skin 0.5" in lig and "--skin" not in jd
          and "--skin" in cube and cube[cube.index("--skin") + 1] == "0.5",
          f"liggghts-jdem: {lig}; jdem: {jd}; cube: {cube}")
    check("ch4_liggghts_sort", "--sort-every 1000 " in lig and "--checkpoint-every 2000" in lig
          and "--sort-every" not in jd and cube[cube.index("--sort-every") + 1] == "1000",
          f"liggghts-jdem: {lig}; jdem: {jd}; cube: {cube}")
    r = subprocess.run([sys.executable, CAMPAIGN, os.path.join(ROOT, "scripts", "mixing", "plan_ch4.py"),
                        "--unit", "liggghts-jdem/model1/fill1", "--list", "--", "--ranks", "2"],
                       capture_output=True, text=True)
    check("ch4_plan_args_after_options", r.returncode == 0 and
          r.stdout.split()[1:2] == ["liggghts-jdem/model1/fill1"], r.stdout + r.stderr)


def test_ch5_fill_scenes():
    """Chapter 5: jdem's fills of Models 2 and 4 run the case itself, with its energy accounts;
    every other fill (liggghts-jdem's, jdem's other models and the rigid cements) runs it without
    them (generate.py fill --no-energy); the written scene is the case, resolved by the engine, in
    every line but output.energy."""
    from scripts.mixing import plan_ch5
    plan = {u.name: u for u in plan_ch5.units([])}
    command = {name: plan[f"{name}/fill"].command[2] for name in (
        "jdem/group2_model4", "jdem/group3_model2", "jdem/group1_model5", "jdem/rigid_model3",
        "liggghts-jdem/group2_model4")}
    accounts = {name: " resolve " in c and "--no-energy" not in c for name, c in command.items()}
    without = {name: f"generate.py fill --case {name.split('/')[1]} --no-energy" in c
               for name, c in command.items()}
    check("ch5_fill_scene_commands",
          [n for n in command if accounts[n]] == ["jdem/group2_model4", "jdem/group3_model2"]
          and [n for n in command if without[n]] == ["jdem/group1_model5", "jdem/rigid_model3",
                                                     "liggghts-jdem/group2_model4"], repr(command))
    jdem = os.path.join(ROOT, "build", "jdem")
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "fill.yaml")
        r = subprocess.run([sys.executable, plan_ch5.GENERATE, "fill", "--case", "group2_model4",
                            "--no-energy", "-o", scene], capture_output=True, text=True,
                           env=dict(os.environ, PYTHONPATH=ROOT))
        got = subprocess.run([jdem, "resolve", scene], capture_output=True, text=True).stdout
        case = subprocess.run([jdem, "resolve", plan_ch5.SCENE, "--case", "group2_model4"],
                              capture_output=True, text=True).stdout
    differ = [(a, b) for a, b in zip(case.splitlines(), got.splitlines()) if a != b]
    check("ch5_fill_scene_no_energy", r.returncode == 0 and len(got.splitlines()) == len(case.splitlines())
          and differ == [("  energy: true", "  energy: false")], r.stderr + repr(differ[:3]))


def test_ch5_realisation_scene():
    """Chapter 5's realisations: the unit's command writes the case without accounts and with
    --jitter K; that scene is the case, resolved by the engine, in every line but output.energy
    and the inlet's origin, moved by K micrometres in y."""
    from scripts.mixing import plan_ch5
    plan = {u.name: u for u in plan_ch5.units([])}
    unit = plan["liggghts-jdem/group3_model5/fill_jitter1"]
    check("ch5_realisation_command", "--no-energy --jitter 1 " in unit.command[2]
          and unit.outputs[0].endswith("liggghts-jdem/group3_model5/fill_jitter1.h5"), unit.command[2])
    jdem = os.path.join(ROOT, "build", "jdem")
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "fill.yaml")
        r = subprocess.run([sys.executable, plan_ch5.GENERATE, "fill", "--case", "group3_model3",
                            "--no-energy", "--jitter", "2", "-o", scene], capture_output=True, text=True,
                           env=dict(os.environ, PYTHONPATH=ROOT))
        got = subprocess.run([jdem, "resolve", scene], capture_output=True, text=True).stdout
        case = subprocess.run([jdem, "resolve", plan_ch5.SCENE, "--case", "group3_model3"],
                              capture_output=True, text=True).stdout
    differ = [(a, b) for a, b in zip(case.splitlines(), got.splitlines()) if a != b]
    moved = [(yaml.load(a, Loader=yaml.CSafeLoader)["origin"], yaml.load(b, Loader=yaml.CSafeLoader)["origin"]) for a, b in differ if "origin:" in a]
    check("ch5_realisation_scene", r.returncode == 0 and len(differ) == 2
          and ("  energy: true", "  energy: false") in differ and len(moved) == 1
          and moved[0][1][0] == moved[0][0][0] and moved[0][1][2] == moved[0][0][2]
          and abs(moved[0][1][1] - moved[0][0][1] - 2e-6) < 1e-15, r.stderr + repr(differ[:3]))


test_validation_and_selection()
test_committed_results()
test_not_yet_runnable()
test_times_beside_unrun_first_unit()
test_times_shared_by_campaigns_at_once()
test_eta_per_engine()
test_ch4_dt_variants()
test_ch4_ranks()
test_ch4_plan()
test_ch4_fill_resumes()
test_ch5_fill_scenes()
test_ch5_realisation_scene()
finish()
