"""speed_ch4.py — the Chapter 4 fill's speed in the three engines, measured in one run
(`make mixing-speed`; docs/mixing.md §10).

    python3 -m scripts.mixing.speed_ch4 [--case model1] [--end-time 5] [--rounds 3] [--out out/mixing/speed]

The first END_TIME seconds of the case's fill at the seed's dt (--force: the guard refuses it),
run by jdem on 1 and 2 threads (as the campaign runs it, without energy accounts, and with
them: `jdem-energy`, output.energy: true), by liggghts-jdem (our law and walls, fix jdem/inlet) on 1 and 2
ranks, and by LIGGGHTS' own hertz/history pair and primitive walls (the deck generator's
--builtin mode) with our inlet on 1 and 2 ranks, at jdem's neighbour skin (0.2 R_max) and at
0.5 R_max (`liggghts-skin0.5`), where LIGGGHTS runs the fill faster (liggghts-jdem runs at the
campaign's, plan_ch4.LIGGGHTS_SKIN); the ratio to stock LIGGGHTS takes its faster skin.  Every
LIGGGHTS configuration sorts its atoms every 1000 steps, LIGGGHTS' default and the campaign's
(plan_ch4.LIGGGHTS_SORT_EVERY).
--only ENGINE,... times a subset.  The engines are run in turn, so they see the
same spell of the shared machine, in ROUNDS rounds, every other one in the reverse order, so that
no engine always runs first or last in a spell; the report gives each configuration's median and
range, and the ratios of the medians.  Each engine's time is its time loop without output (jdem's
`loop - output` of --timing, LIGGGHTS' Loop time less its Outpt share): every engine writes the
same H5MD frames.  The work is the particle-steps of the growing set, the sum over the inserted
particles of the steps after their insertion step (jdem's --inlet-record; the stream is the same
in every engine by construction).  Writes OUT/summary.json and OUT/report.md.
"""
import argparse
import csv
import json
import os
import re
import statistics
import subprocess

import yaml

from scripts import engines
from scripts.bench_summary import machine_info
from scripts.mixing.plan_ch4 import LIGGGHTS_SKIN, LIGGGHTS_SORT_EVERY

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GENERATE = os.path.join(ROOT, "reference_runs", "mixing", "ch4", "generate.py")
RUNS = (("jdem", 1), ("jdem", 2), ("jdem-energy", 1), ("jdem-energy", 2), ("liggghts-jdem", 1),
        ("liggghts-jdem", 2), ("liggghts", 1), ("liggghts", 2), ("liggghts-skin0.5", 1),
        ("liggghts-skin0.5", 2))
# each LIGGGHTS configuration's neighbour skin over R_max (None: the deck generator's, jdem's 0.2)
SKIN = {"liggghts-jdem": LIGGGHTS_SKIN, "liggghts": None, "liggghts-skin0.5": 0.5}
STOCK = ("liggghts", "liggghts-skin0.5")
OUTPT_RE = re.compile(r"(?m)^Outpt\s+time \(%\) = \S+ \(([0-9.eE+-]+)\)")


def particle_steps(record, steps):
    """Sum over the inserted particles of the steps they take part in."""
    with open(record) as f:
        return sum(steps - int(row["step"]) for row in csv.DictReader(f))


def run_jdem(resolved, d, threads, name="jdem"):
    out = os.path.join(d, f"{name}_t{threads}.h5")
    rec = os.path.join(d, "inlet_record.csv")
    r = engines.jdem("run", resolved, "-o", out, "--force", "--quiet", "--timing",
                     "--threads", str(threads), "--inlet-record", rec, check=True)
    t = engines.jdem_timing(r.stderr)
    return {"loop_s": t["loop"] - t["output"], "steps": int(t["steps"]), "record": rec}


def run_liggghts(resolved, d, engine, ranks):
    deck_dir = os.path.join(d, f"{engine}_deck")
    deck = os.path.join(deck_dir, "in.jdem")
    engines.write_deck(resolved, deck, "--force", "--trajectory",   # every run: never a stale deck
                       os.path.join(d, f"{engine}.h5"),
                       *(["--builtin"] if engine in STOCK else []),
                       *(["--skin", repr(SKIN[engine])] if SKIN[engine] is not None else []),
                       "--sort-every", str(LIGGGHTS_SORT_EVERY), check=True)
    log = f"log.{ranks}"
    engines.run_deck(deck_dir, ranks=ranks, log=log, mpi_flags=("--bind-to", "none"), check=True)
    text = open(os.path.join(deck_dir, log), errors="replace").read()
    loop, _, steps, _ = engines.liggghts_loops(text)[-1]
    tail = text[text.rfind("Loop time of"):]
    outpt = OUTPT_RE.search(tail)
    share = float(outpt.group(1)) / 100.0 if outpt else 0.0
    return {"loop_s": float(loop) * (1.0 - share), "steps": int(steps)}


def with_energy_accounts(scene, d):
    """The resolved scene of `scene` with output.energy: true, written into d."""
    with open(scene) as f:
        doc = yaml.load(f, Loader=yaml.CSafeLoader)
    doc["output"]["energy"] = True
    path, resolved = os.path.join(d, "fill_energy.yaml"), os.path.join(d, "resolved_energy.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(doc, f, sort_keys=False)
    with open(resolved, "w") as f:
        f.write(engines.resolve(path, check=True).stdout)
    return resolved


def table(summary):
    """The runs' table: median and range of each configuration, its rate and its ratio to jdem;
    then jdem against the faster stock LIGGGHTS skin per core count."""
    runs = summary["runs"]
    rows = ["| engine | cores | loop without output, median (range) [s] | particle-steps/s | "
            "jdem (same cores) is faster by |",
            "|---|---:|---:|---:|---:|"]
    for r in runs:
        ref = next((q for q in runs if q["engine"] == "jdem" and q["cores"] == r["cores"]), None)
        rows.append(f"| {r['engine']} | {r['cores']} | {r['loop_s']:.1f} "
                    f"({min(r['loop_all']):.1f}–{max(r['loop_all']):.1f}) | {r['rate']:.3g} | "
                    + (f"{r['loop_s'] / ref['loop_s']:.2f}x |" if ref else "— |"))
    for cores in sorted({r["cores"] for r in runs}):
        ref = next((q for q in runs if q["engine"] == "jdem" and q["cores"] == cores), None)
        stock = [q for q in runs if q["engine"] in STOCK and q["cores"] == cores]
        if ref and stock:
            best = min(stock, key=lambda q: q["loop_s"])
            rows.append(f"\nOn {cores} core{'s' if cores > 1 else ''}, jdem is faster than stock "
                        f"LIGGGHTS at its faster skin ({best['engine']}) by "
                        f"{best['loop_s'] / ref['loop_s']:.2f}x.")
    return "\n".join(rows) + "\n"


def on_machine(summary):
    """', on CPUS cores of CPU (family/model, SIMD)' where the summary records the machine."""
    m = summary.get("machine")
    if not m:
        return ""
    return (f", on {m['cpus']} cores of {m.get('cpu', 'an unnamed CPU')} "
            f"(family/model {m.get('cpu_family_model', '?')}, {m.get('simd', '?')})")


def describe(summary):
    """What was timed, in one paragraph."""
    return (f"Case {summary['case']}, the first {summary['end_time']} s of the fill at dt = "
            f"{summary['dt']} s ({summary['steps']} steps, {summary['inserted']} spheres inserted, "
            f"{summary['particle_steps']:.4g} particle-steps); {summary['rounds']} rounds, every "
            f"other one in the reverse order; load average before the runs "
            f"{summary['load_before']:.2f}, after {summary['load_after']:.2f}; commit "
            f"{summary['commit']}{on_machine(summary)}.  `liggghts` is LIGGGHTS' own hertz/history pair and primitive "
            f"walls with our inlet; `jdem-energy` is jdem with the energy accounts (output.energy: "
            f"true), which the campaign's Ch. 4 fills leave out and stock LIGGGHTS does not keep.")


def report(summary):
    return "# Chapter 4 fill: speed of the three engines\n\n" + describe(summary) + "\n\n" + table(summary)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", default="model1")
    ap.add_argument("--end-time", type=float, default=5.0, help="simulated time [s]")
    ap.add_argument("--rounds", type=int, default=3, help="runs of each configuration")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "mixing", "speed"))
    ap.add_argument("--only", help="comma-separated ENGINE or ENGINE/CORES of the runs to time "
                    "(default all: %s)" % ", ".join(f"{e}/{c}" for e, c in RUNS))
    a = ap.parse_args()
    chosen = RUNS if not a.only else tuple(
        r for r in RUNS if any(w in (r[0], f"{r[0]}/{r[1]}") for w in a.only.split(",")))
    if not chosen:
        raise SystemExit(f"speed_ch4: --only {a.only}: no run matches; valid: "
                         + ", ".join(f"{e}/{c}" for e, c in RUNS))
    d = os.path.abspath(a.out)
    os.makedirs(d, exist_ok=True)
    scene, resolved = os.path.join(d, "fill.yaml"), os.path.join(d, "resolved.yaml")
    subprocess.run([engines.PY, GENERATE, "fill", "--case", a.case, "--dt", "1e-4",
                    "--end-time", repr(a.end_time), "-o", scene], check=True, env=engines.python_env())
    with open(resolved, "w") as f:
        f.write(engines.resolve(scene, check=True).stdout)
    resolved_energy = with_energy_accounts(scene, d)
    load_before = os.getloadavg()[0]
    if a.rounds < 1:
        raise SystemExit(f"speed_ch4: --rounds {a.rounds}: need at least 1")
    times = {run: [] for run in chosen}
    for k in range(a.rounds):
        for engine, cores in (chosen if k % 2 == 0 else chosen[::-1]):
            if engine == "jdem":
                r = run_jdem(resolved, d, cores)
            elif engine == "jdem-energy":
                r = run_jdem(resolved_energy, d, cores, engine)
            else:
                r = run_liggghts(resolved, d, engine, cores)
            times[(engine, cores)].append(r)
            print(f"speed_ch4: round {k + 1}/{a.rounds}, {engine} on {cores}: {r['loop_s']:.1f} s",
                  flush=True)
    runs = []
    for (engine, cores), rs in times.items():
        loops = [r["loop_s"] for r in rs]
        runs.append(dict(rs[0], engine=engine, cores=cores, loop_s=statistics.median(loops),
                         loop_all=loops))
    steps = runs[0]["steps"]
    if any(r["steps"] != steps for r in runs):
        raise SystemExit("speed_ch4: the engines ran different numbers of steps: "
                         + ", ".join(f"{r['engine']}/{r['cores']}={r['steps']}" for r in runs))
    record = os.path.join(d, "inlet_record.csv")
    if not any(r.get("record") for r in runs):   # no jdem run in the subset: the stream's record
        engines.jdem("run", resolved, "-o", os.path.join(d, "record.h5"), "--force", "--quiet",
                     "--inlet-record", record, check=True)
    work = particle_steps(record, steps)
    with open(record) as f:
        inserted = sum(1 for _ in f) - 1
    for r in runs:
        r.pop("record", None)
        r["rate"] = work / r["loop_s"]
    summary = {"case": a.case, "end_time": a.end_time, "dt": 1e-4, "steps": steps,
               "inserted": inserted, "particle_steps": work, "rounds": a.rounds,
               "load_before": load_before,
               "load_after": os.getloadavg()[0], "machine": machine_info(), "runs": runs,
               "commit": subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                                        capture_output=True, text=True).stdout.strip()}
    with open(os.path.join(d, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    with open(os.path.join(d, "report.md"), "w") as f:
        f.write(report(summary))
    print(report(summary))


if __name__ == "__main__":
    main()
