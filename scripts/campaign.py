#!/usr/bin/python3
"""campaign.py — run a campaign: a list of units, each with its own output files.

    scripts/campaign.py PLAN.py [--model M] [--engine E] [--unit NAME] [--list] [-- PLAN ARGS]

PLAN.py defines units(argv) returning a list of Unit.  A unit is done when every one of its
final outputs exists and validates; a rerun skips the done units, so an interrupted campaign
resumes where it stopped.  A unit whose result is committed to the repository (its `committed`
says where) is skipped too on a machine that lacks its outputs (a fresh clone), unless a unit
that runs reads them: then it runs again, and so do the chosen units derived from it, so that no
committed result stands beside a new source.  --rerun-committed ignores the committed results.  A unit runs with its outputs in a directory of its own next to the
first output (DIR/.partial/UNIT/, the same file names), and they are moved to their final names
(os.replace, atomic per file) only once all of them validate, each trajectory with its XDMF
sidecar: a killed run never leaves a partial file under a final name, and its partial directory
is cleared when the unit runs again.
--model, --engine and --unit run part of the campaign (a unit whose needs are neither done nor
selected is an error).  A unit the engines cannot run yet (its `blocked` says why, e.g. a scene
key not implemented) is reported as "not yet runnable: WHY" and skipped with the units that need
it; it does not count as a failure, and the closing line counts it.  Progress and the ETA go to stderr: the ETA is the remaining units'
estimated cost times the measured seconds per unit of cost of the units of its engine finished so
far, else of all units (in this run and earlier ones: DIR/.campaign_times.json beside the first
unit's output).  A unit's recorded
wall and CPU time are its whole: an interrupted attempt's, written to its partial directory every
SPENT_EVERY seconds, are added to the attempt that finishes it.
"""
import argparse
import functools
import importlib.util
import json
import os
import resource
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field


@dataclass
class Unit:
    name: str                   # unique, e.g. "jdem/model2/fill1"
    outputs: list               # final output paths
    command: list               # argv; "{out0}", "{out1}", ... stand for the outputs being
                                # written, "{dir}" for the directory that holds them
    model: str = None
    engine: str = None
    needs: list = field(default_factory=list)  # names of the units whose outputs it reads
    validate: object = None     # f(path) -> None if valid, else the reason; default: non-empty
    cost: float = 1.0           # relative cost, for the ETA (e.g. particle-steps)
    blocked: object = None      # f() -> None if the engines can run the unit, else why not
                                # (a feature still missing); such a unit is reported, not run
    resumes: bool = False       # the command continues from what an interrupted run of it left
                                # in "{dir}" (a checkpoint), so that directory is kept
    ranks: int = 1              # the processes it runs on (MPI ranks), recorded with its times
    committed: object = None    # f() -> None, or where the repository keeps the unit's result
                                # (a committed summary): see runs()


def non_empty(path):
    return None if os.path.getsize(path) > 0 else "empty file"


def invalid_reason(unit, path):
    """None when path exists and validates, else why not."""
    if not os.path.exists(path):
        return "missing"
    return (unit.validate or non_empty)(path)


def is_done(unit):
    return all(invalid_reason(unit, p) is None for p in unit.outputs)


def committed_where(unit):
    return unit.committed() if unit.committed else None


def runs(chosen, use_committed=True):
    """The names of the chosen units to run: those neither done here nor committed; the chosen
    needs of those that are not done here (a committed result holds no output file to read); and
    the chosen units, not done here, that read a unit that runs."""
    done = {u.name: is_done(u) for u in chosen}   # once: a validation may open an HDF5 file
    out = {u.name for u in chosen if not done[u.name] and not (use_committed and committed_where(u))}
    grew = True
    while grew:
        grew = False
        for u in chosen:
            new = [n for n in u.needs if u.name in out and n in done and n not in out
                   and not done[n]]
            if u.name not in out and not done[u.name] and any(n in out for n in u.needs):
                new.append(u.name)
            out.update(new)
            grew = grew or bool(new)
    return out


def blocked_reason(unit, by_name, memo):
    """None when the unit and every unit it needs can run, else why not (evaluated once)."""
    if unit.name not in memo:
        memo[unit.name] = unit.blocked() if unit.blocked else None
        for n in unit.needs:
            if memo[unit.name] is None and n in by_name and not is_done(by_name[n]):
                if blocked_reason(by_name[n], by_name, memo):
                    memo[unit.name] = f"needs {n}, which is not yet runnable"
    return memo[unit.name]


def partial_dir(unit):
    return os.path.join(os.path.dirname(os.path.abspath(unit.outputs[0])), ".partial",
                        unit.name.replace("/", "_"))


def select(units, model=None, engine=None, name=None):
    return [u for u in units if (model is None or u.model == model)
            and (engine is None or u.engine == engine) and (name is None or u.name == name)]


def check_needs(units, chosen, to_run):
    """None, or why a unit to run cannot: it needs an unknown unit, or one whose outputs are not
    here and that is not selected (a committed result holds no output file to read)."""
    names = {u.name for u in chosen}
    by_name = {u.name: u for u in units}
    for u in chosen:
        for n in u.needs:
            if n not in by_name:
                return f"unit {u.name} needs unknown unit {n}"
            if u.name in to_run and n not in names and not is_done(by_name[n]):
                where = committed_where(by_name[n])
                return (f"unit {u.name} needs {n}, which is neither done nor selected"
                        + (f" (its result is committed in {where}, but not its output files: "
                           f"select it too)" if where else ""))
    return None


class Times:
    """Measured seconds per unit, kept across runs.  Campaign processes running at once share
    the file: each add re-reads it under an exclusive lock and merges its own entry, so that
    none drops another's (written atomically)."""

    def __init__(self, path):
        self.path = path
        self.seconds = self.read()

    def read(self):
        try:
            with open(self.path) as f:
                return json.load(f)
        except (OSError, ValueError):
            return {}

    def add(self, unit, seconds, cpu_seconds, attempts=1):
        """seconds, cpu_seconds: the unit's wall and CPU time over all its attempts (a resumed
        unit's earlier ones from its partial directory's SPENT)."""
        import fcntl
        entry = {"seconds": seconds, "cpu_seconds": cpu_seconds, "cost": unit.cost, "engine": unit.engine,
                 "ranks": unit.ranks, "threads": unit_threads(unit), "attempts": attempts,
                 "machine": machine_name()}
        # beside the plan's first output, whose directory a selection without that unit never made
        os.makedirs(os.path.dirname(self.path), exist_ok=True)
        with open(self.path + ".lock", "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            self.seconds = dict(self.read(), **{unit.name: entry})
            tmp = "%s.%d.tmp" % (self.path, os.getpid())
            with open(tmp, "w") as f:
                json.dump(self.seconds, f, indent=1)
            os.replace(tmp, self.path)

    def eta(self, remaining):
        """The remaining units' cost times the seconds per unit of cost measured so far: of the
        units of the same engine where any is measured (one engine's fill can take twice
        another's for the same cost), else of all."""
        def rate(done):
            cost = sum(d["cost"] for d in done)
            return sum(d["seconds"] for d in done) / cost if cost > 0 else None
        overall = rate(list(self.seconds.values()))
        if overall is None:
            return None
        engines = {u.engine for u in remaining}
        by_engine = {}
        for name, d in self.seconds.items():   # an entry from before 2026-12-07: its name's engine
            engine = d.get("engine") or next((e for e in engines if e and name.startswith(e + "/")), None)
            if engine is not None:
                by_engine.setdefault(engine, []).append(d)
        rates = {e: rate(done) for e, done in by_engine.items()}
        return sum(u.cost * (rates.get(u.engine) or overall) for u in remaining)


def times_path(units):
    """Where a plan's measured times are kept: beside its first unit's first output."""
    return os.path.join(os.path.dirname(os.path.abspath(units[0].outputs[0])), ".campaign_times.json")


def unit_threads(unit):
    """The OpenMP threads a unit's jdem runs on: jdem's default, OMP_NUM_THREADS if set, else 1
    (stepper/main.c); a liggghts-jdem unit's processes are its ranks."""
    if unit.engine == "liggghts-jdem":
        return 1
    try:
        return max(1, int(os.environ.get("OMP_NUM_THREADS", "1")))
    except ValueError:
        return 1


@functools.lru_cache(maxsize=None)
def machine_name():
    """The CPU a unit's times were taken on (bench_summary.machine_info), which a cost comparison
    between units run in different sessions needs."""
    from scripts.bench_summary import machine_info
    info = machine_info()
    return " ".join(str(info[k]) for k in ("cpu", "cpu_family_model", "simd") if k in info)


def resuming(unit):
    """True when the unit continues an interrupted run of itself (see Unit.resumes)."""
    return unit.resumes and os.path.isdir(partial_dir(unit))


SPENT = ".spent.json"     # in a unit's partial directory: what its earlier attempts cost
SPENT_EVERY = 10.0        # [s] how often a running attempt's cost is written there


def read_spent(tmp):
    """{seconds, cpu_seconds, attempts} of the attempts before this one (zero for a fresh unit)."""
    try:
        with open(os.path.join(tmp, SPENT)) as f:
            d = json.load(f)
        return {k: float(d[k]) for k in ("seconds", "cpu_seconds", "attempts")}
    except (OSError, ValueError, KeyError, TypeError):
        return {"seconds": 0.0, "cpu_seconds": 0.0, "attempts": 0.0}


def write_spent(tmp, spent):
    path = os.path.join(tmp, SPENT)
    with open(path + ".tmp", "w") as f:
        json.dump(spent, f)
    os.replace(path + ".tmp", path)


def tree_cpu(pid):
    """User + system CPU seconds of process pid and its live descendants, with the children each
    has waited for (/proc: utime, stime, cutime, cstime), so that every CPU second is counted once."""
    children, ticks = {}, {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            try:
                with open(f"/proc/{name}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:   # gone meanwhile: its parent's cutime has it once waited for
                continue
            children.setdefault(int(fields[1]), []).append(int(name))
            ticks[int(name)] = sum(int(x) for x in fields[11:15])
    total, todo = 0, [pid]
    while todo:
        p = todo.pop()
        total += ticks.get(p, 0)
        todo += children.get(p, [])
    return total / os.sysconf("SC_CLK_TCK")


def run_command(argv, tmp, before, start):
    """Run argv, writing what this attempt has cost so far (added to before) into tmp every
    SPENT_EVERY seconds: a campaign killed mid-unit loses at most that much of the count.
    Returns (exit status, the CPU seconds of the process tree last sampled): a command whose
    shell is killed before the engine under it ends (a session's SIGTERM) leaves the engine's
    CPU out of the campaign's own count of its waited-for children, but not out of the sample."""
    proc, sampled = subprocess.Popen(argv), 0.0
    while True:
        try:
            return proc.wait(timeout=SPENT_EVERY), sampled
        except subprocess.TimeoutExpired:   # a shell dying mid-scan samples low: keep the highest
            sampled = max(sampled, tree_cpu(proc.pid))
            write_spent(tmp, {"seconds": before["seconds"] + time.monotonic() - start,
                              "cpu_seconds": before["cpu_seconds"] + sampled,
                              "attempts": before["attempts"] + 1})


def run_unit(unit):
    """Run one unit into its partial directory; returns (None or the reason it failed, what the
    earlier attempts of an interrupted unit cost: {seconds, cpu_seconds, attempts}, this
    attempt's CPU seconds)."""
    tmp = partial_dir(unit)
    if not resuming(unit):
        shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp, exist_ok=True)
    before, start, cpu0 = read_spent(tmp), time.monotonic(), children_cpu()
    staged = [os.path.join(tmp, os.path.basename(p)) for p in unit.outputs]
    subs = {f"out{i}": p for i, p in enumerate(staged)}
    subs["dir"] = tmp
    argv = [a.format(**subs) for a in unit.command]
    rc, sampled = run_command(argv, tmp, before, start)
    cpu = max(children_cpu() - cpu0, sampled)
    write_spent(tmp, {"seconds": before["seconds"] + time.monotonic() - start,
                      "cpu_seconds": before["cpu_seconds"] + cpu, "attempts": before["attempts"] + 1})
    if rc != 0:
        return f"exit status {rc}", before, cpu
    for s in staged:
        reason = invalid_reason(unit, s)
        if reason:
            return f"output {os.path.basename(s)} does not validate: {reason}", before, cpu
    for s, final in zip(staged, unit.outputs):
        os.makedirs(os.path.dirname(os.path.abspath(final)), exist_ok=True)
        for side, final_side in zip(sidecars(s), sidecars(final)):   # before the output it reads
            if os.path.exists(side):
                os.replace(side, final_side)
            elif os.path.exists(final_side):   # an earlier run's, which would describe another file
                os.remove(final_side)
        os.replace(s, final)
    shutil.rmtree(tmp, ignore_errors=True)
    return None, before, cpu


def sidecars(path):
    """The files an output carries beside it: a trajectory's XDMF sidecar (OUT.h5 -> OUT.xdmf,
    docs/output.md), which reads it by its basename, so the two move together and ParaView
    opens the campaign's trajectories where they land."""
    stem, ext = os.path.splitext(path)
    return [stem + ".xdmf"] if ext == ".h5" else []


def children_cpu():
    """User + system CPU seconds of the finished child processes: a unit's cost on a shared
    machine, where its wall time also counts the other jobs."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def fmt_seconds(s):
    return f"{s:.1f} s" if s < 120 else f"{s / 60:.1f} min" if s < 7200 else f"{s / 3600:.1f} h"


def run(units, times, everything=None, log=sys.stderr, to_run=None):
    """Run the units in order, skipping the done and the committed ones (those not in to_run,
    default runs(units)) and reporting those not yet runnable; returns (number failed, number
    not yet runnable).  everything: the whole plan (for the needs of a selection; default
    `units`)."""
    by_name = {u.name: u for u in (everything or units)}
    memo = {}
    to_run = runs(units) if to_run is None else to_run
    todo = [u for u in units if u.name in to_run]
    for u in units:
        if u not in todo:
            print(f"campaign: skip {u.name} (" + ("done" if is_done(u) else
                  f"committed in {committed_where(u)}") + ")", file=log, flush=True)
    blocked = [u for u in todo if blocked_reason(u, by_name, memo)]
    todo = [u for u in todo if u not in blocked]
    for u in blocked:
        print(f"campaign: skip {u.name}: not yet runnable: {memo[u.name]}", file=log, flush=True)
    failed = skipped = 0
    for i, u in enumerate(todo):
        unmet = [n for n in u.needs if n in by_name and not is_done(by_name[n])]
        if unmet:  # a need failed earlier in this run: this unit would only fail after it
            skipped += 1
            print(f"campaign: [{i + 1}/{len(todo)}] {u.name}: skipped: needs {unmet[0]}, which did "
                  f"not finish", file=log, flush=True)
            continue
        eta = times.eta(todo[i:])
        print(f"campaign: [{i + 1}/{len(todo)}] {u.name}: "
              + ("continuing its interrupted run" if resuming(u) else "running")
              + (f"; ETA {fmt_seconds(eta)}" if eta is not None else ""), file=log, flush=True)
        start = time.monotonic()
        reason, before, cpu = run_unit(u)
        took = time.monotonic() - start
        if reason:
            failed += 1
            print(f"campaign: [{i + 1}/{len(todo)}] {u.name}: FAILED after {fmt_seconds(took)}: "
                  f"{reason}", file=log, flush=True)
            continue
        times.add(u, before["seconds"] + took, before["cpu_seconds"] + cpu, int(before["attempts"]) + 1)
        eta = times.eta(todo[i + 1:])
        print(f"campaign: [{i + 1}/{len(todo)}] {u.name}: done in {fmt_seconds(took)}; "
              f"{len(todo) - i - 1} left, ETA {fmt_seconds(eta)}", file=log, flush=True)
    here = sum(1 for u in units if u not in todo and is_done(u))
    print(f"campaign: {len(todo) - failed - skipped} run, {failed} failed, "
          + (f"{skipped} skipped after a failure, " if skipped else "")
          + f"{len(blocked)} not yet runnable, {here} already done"
          + (f", {len(units) - len(todo) - len(blocked) - here} committed"
             if len(units) - len(todo) - len(blocked) - here else ""),
          file=log, flush=True)
    return failed, len(blocked)


def load_plan(path, argv):
    spec = importlib.util.spec_from_file_location("campaign_plan", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.units(argv)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("plan")
    ap.add_argument("--model")
    ap.add_argument("--engine")
    ap.add_argument("--unit")
    ap.add_argument("--list", action="store_true",
                    help="list the units and whether they are done, committed or to do")
    ap.add_argument("--rerun-committed", action="store_true",
                    help="run the units whose result is committed but whose outputs are not here")
    # the plan's own arguments follow "--", wherever the driver's options stand (argparse alone
    # matches an optional positional list once, next to `plan`, and refuses later ones)
    cut = argv.index("--") if "--" in argv else len(argv)
    a = ap.parse_args(argv[:cut])
    units = load_plan(a.plan, argv[cut + 1:])
    names = [u.name for u in units]
    if len(set(names)) != len(names):
        print(f"campaign: {a.plan}: unit names are not unique", file=sys.stderr)
        return 2
    chosen = select(units, a.model, a.engine, a.unit)
    if not chosen:
        print(f"campaign: no unit matches --model {a.model} --engine {a.engine} --unit {a.unit}; "
              f"valid models: {sorted({str(u.model) for u in units})}, engines: "
              f"{sorted({str(u.engine) for u in units})}", file=sys.stderr)
        return 2
    by_name = {u.name: u for u in units}
    to_run = runs(chosen, not a.rerun_committed)
    if a.list:
        memo = {}
        for u in chosen:
            why = blocked_reason(u, by_name, memo) if u.name in to_run else None
            state = "todo" if u.name in to_run else "done" if is_done(u) else "committed"
            print(f"{state} {u.name}" + (f" (not yet runnable: {why})" if why else "")
                  + (f" ({committed_where(u)})" if state == "committed" else ""))
        return 0
    problem = check_needs(units, chosen, to_run)
    if problem:
        print(f"campaign: {problem}", file=sys.stderr)
        return 2
    times = Times(times_path(units))
    failed, _ = run(chosen, times, units, to_run=to_run)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
