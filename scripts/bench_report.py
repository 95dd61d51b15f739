"""bench_report.py — OUT/report.md and its plots from the summary rows of scripts/bench.py."""
import json
import math
import os
import re
import subprocess
import sys

from scripts import engines

ENGINE_LABEL = {"jdem": "jdem", "jdem/2t": "jdem, 2 threads", "liggghts-jdem": "liggghts-jdem (gran/jiang)",
                "liggghts": "stock liggghts (hertz/history)"}
SIZE_ORDER = ["5k", "20k", "80k", "320k", "1M"]


def fmt(v, spec=".3g"):
    return "–" if v is None or v != v else format(v, spec)


def index(rows):
    """(size, variant, engine, ranks) -> row of one thread; jdem's 2-thread rows under engine
    "jdem/2t" (and so on for other thread counts)."""
    ix = {}
    for r in rows:
        t = r.get("threads", 1)
        ix[(r["size"], r["variant"], r["engine"] if t == 1 else "%s/%dt" % (r["engine"], t), r["ranks"])] = r
    return ix


def plots(out, rows, variants, sizes):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ix = index(rows)
    files = []
    nrow = max(1, math.ceil(len(variants) / 4))
    fig, axes = plt.subplots(nrow, 4, figsize=(16, 3.75 * nrow), sharey=True, squeeze=False)
    for ax in axes.flat[len(variants):]:
        ax.set_visible(False)
    for ax, v in zip(axes.flat, variants):
        for e, mk in (("jdem", "o-"), ("jdem/2t", "o-."), ("liggghts-jdem", "s--"), ("liggghts", "^:")):
            pts = [(ix[(s, v, e, 1)]["N"], ix[(s, v, e, 1)]["particle_steps_per_second"])
                   for s in sizes if (s, v, e, 1) in ix]
            if pts:
                ax.plot(*zip(*pts), mk, label=ENGINE_LABEL.get(e, e))
        ax.set_xscale("log")
        ax.set_title(v)
        ax.set_xlabel("N")
        ax.grid(alpha=0.3)
    for row in axes:
        row[0].set_ylabel("particle-steps / s (1 rank)")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    p = os.path.join(out, "throughput.png")
    fig.savefig(p, dpi=90)
    plt.close(fig)
    files.append(p)

    fig, ax = plt.subplots(figsize=(8, 5))
    for v in variants:
        pts = []
        for s in sizes:
            a, b = ix.get((s, v, "jdem", 1)), ix.get((s, v, "liggghts", 1))
            if a and b:
                pts.append((a["N"], a["particle_steps_per_second"] / b["particle_steps_per_second"]))
        if pts:
            ax.plot(*zip(*pts), "o-", label=v)
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("N")
    for v in variants:
        pts = []
        for s in sizes:
            a, b = ix.get((s, v, "jdem/2t", 1)), ix.get((s, v, "liggghts", 1))
            if a and b:
                pts.append((a["N"], a["particle_steps_per_second"] / b["particle_steps_per_second"]))
        if pts:
            ax.plot(*zip(*pts), "x--", label=v + " (jdem 2 threads)")
    ax.axhline(3.0, color="g", lw=0.8, ls=":")
    ax.set_ylabel("speed ratio jdem / stock LIGGGHTS (1 rank; dashed: jdem 2 threads)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    p = os.path.join(out, "ratio.png")
    fig.savefig(p, dpi=90)
    plt.close(fig)
    files.append(p)
    return files


def profile_section(out):
    path = os.path.join(out, "profile.json")
    if not os.path.exists(path):
        return []
    pr = json.load(open(path))
    L = ["## Where jdem's time goes (callgrind)\n\n",
         "`valgrind --tool=callgrind --toggle-collect=sim_step` on `%s` (%d particles, %d steps, 1 thread; "
         "instruction counts of the time loop, set-up and output excluded). %s\n\n"
         % (pr["scene"], pr["n"], pr["steps"], pr.get("note", "")),
         "| part | instructions | share of the loop | per particle-step |\n|---|---:|---:|---:|\n"]
    for name, ir in pr["parts"]:
        L.append("| %s | %.3g | %.1f %% | %.0f |\n" % (name, ir, 100.0 * ir / pr["loop"], ir / (pr["n"] * pr["steps"])))
    L.append("\n")
    return L


JDEM_PARTS = (("neighbour", "neighbour search (check + rebuilds, renumbering)"), ("pairs", "pair force loop"),
              ("walls", "wall force loop"), ("integration", "integration"), ("output", "output"))


def split_section(rows, sizes, variants):
    """Where jdem's time goes (its --timing split of the S-step run, medians)."""
    jr = [r for r in rows if r["engine"] == "jdem" and r.get("jdem_split_seconds")]
    if not jr:
        return []
    L = ["## Where jdem's time goes (`jdem run --timing`)\n\n",
         "Wall time of each part of the time loop of the S-step run (median over repeats), as a share of "
         "the loop and in nanoseconds per particle-step; for stock LIGGGHTS' own split see the table above "
         "(Pair = force loop, Neigh = neighbour search, Other/Modify = walls and integration).\n\n",
         "| size | variant | threads | builds | " + " | ".join(p for _, p in JDEM_PARTS) + " |\n",
         "|---|---|---:|---:|" + "---:|" * len(JDEM_PARTS) + "\n"]
    for r in sorted(jr, key=lambda r: (SIZE_ORDER.index(r["size"]) if r["size"] in SIZE_ORDER else 99,
                                       variants.index(r["variant"]) if r["variant"] in variants else 99, r["threads"])):
        sp = r["jdem_split_seconds"]
        tot = sum(sp.get(k, 0.0) for k, _ in JDEM_PARTS)
        ps = r["N"] * r["steps"]
        cells = ["%.0f %% (%.0f ns)" % (100.0 * sp.get(k, 0.0) / tot if tot else 0.0, 1e9 * sp.get(k, 0.0) / ps)
                 for k, _ in JDEM_PARTS]
        L.append("| %s | %s | %d | %d | %s |\n" % (r["size"], r["variant"], r["threads"], int(sp.get("builds", 0)),
                                                   " | ".join(cells)))
    L.append("\n")
    return L


def feature_section(fc):
    if not fc:
        return []
    L = ["## Scene-specialised force loops\n\n",
         "%s (`%s`, N = %d, %d steps, medians of %d timings alternated, 1 thread: wall time by jdem's loop "
         "timer less its output, CPU time as run(S) - run(1)).\n\n"
         % (fc["description"], fc["scene"], fc["N"], fc["steps"], fc["repeats"]),
         "| loop | bonds | wall [s] | CPU [s] | ratio to specialised: wall | CPU | trajectory bit-identical |\n"
         "|---|---:|---:|---:|---:|---:|---|\n",
         "| specialised (friction only) | 0 | %.3f | %.3f | 1 | 1 | – |\n"
         % (fc["specialised"]["wall_s_median"], fc["specialised"]["cpu_s_median"])]
    rows = [("general (`--all-laws`, zero-stiffness bonds): the issue's check", "general", "")]
    if "general_contact_laws" in fc:
        rows.append(("general contact laws only (`--all-laws`, no bonds)", "general_contact_laws", "_contact_laws"))
    for name, key, sfx in rows:
        g = fc[key]
        L.append("| %s | %s | %.3f | %.3f | **%.2f** | %.2f | %s |\n" % (
            name, g.get("bonds") or 0, g["wall_s_median"], g["cpu_s_median"], fc["speed_ratio_wall" + sfx],
            fc["speed_ratio_cpu" + sfx], "yes" if fc["identical_trajectory" + sfx] else "NO"))
    L.append("\nTarget: the scene without rolling, bonds and damping at least 1.3x faster than the same scene "
             "with those laws enabled at zero coefficients (the first general row). The second row shows "
             "what the contact loop's specialisation alone saves.\n\n")
    return L


def flatness_section(flat):
    if not flat:
        return []
    L = ["## Cost per particle-step against N (jdem)\n\n",
         "Nanoseconds per particle-step of jdem at each size run, and the flatness ratio max / min over the "
         "sizes (target: <= %.2f from 5k to 1M), from three measures of the loop: wall time by jdem's loop "
         "timer less its output (the throughput tables' measure), the sum of the loop's `--timing` parts but "
         "the output (the same less the per-step checks), and CPU time as run(S) - run(1) (1 thread; its set-up, scene parsing, "
         "varies by more than the loop takes from 80k up). On a loaded "
         "machine the wall-time ratios measure the load as much as the code.\n\n" % flat[0]["target"],
         "| variant | threads | sizes | ns/particle-step: wall | timer | CPU | ratio: wall | timer | CPU | "
         "target met (timer) |\n|---|---:|---|---|---|---|---:|---:|---:|---|\n"]
    for f in flat:
        cpu, timer = f.get("cpu_ns_per_particle_step"), f.get("timer_ns_per_particle_step")
        L.append("| %s | %d | %s | %s | %s | %s | %.2f | **%s** | %s | %s |\n" % (
            f["variant"], f["threads"], ", ".join(f["sizes"]), ", ".join("%.0f" % v for v in f["ns_per_particle_step"]),
            ", ".join("%.0f" % v for v in timer) if timer else "–", ", ".join("%.0f" % v for v in cpu) if cpu else "–",
            f["ratio_wall"], fmt(f.get("ratio_timer"), ".2f"), fmt(f.get("ratio_cpu"), ".2f"),
            "–" if f.get("met_timer") is None else "yes" if f["met_timer"] else "no"))
    L.append("\n")
    return L


def bonded_section(rows):
    """ns per particle-step and per bond-step of the bonded variants."""
    br = [r for r in rows if r.get("bonds")]
    if not br:
        return []
    L = ["## Bonded beds\n\n",
         "The same beds with a parallel bond between every touching pair (formed at step 0), at the guard's dt "
         "with the bonds' bound. Stock LIGGGHTS has no parallel-bond model: **n/a**. Per bond-step: the whole "
         "loop divided by bonds x steps, and the bonds' own share (bonded minus the same bed without bonds, same "
         "engine and threads, divided by bonds x steps; comparable with `make bonds`' ns per bond-step).\n\n",
         "| size | variant | engine | threads | ranks | N | bonds (start / end) | dt [s] | ns/particle-step | "
         "ns/bond-step (whole loop) | ns/bond-step (bonds' share) | stock liggghts |\n"
         "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n"]
    for r in br:
        L.append("| %s | %s | %s | %d | %d | %d | %d / %s | %.2g | %.0f | %s | %s | n/a |\n" % (
            r["size"], r["variant"], r["engine"], r["threads"], r["ranks"], r["N"], r["bonds"],
            r["bonds_intact_end"] if r.get("bonds_intact_end") is not None else "–", r["dt"],
            r["ns_per_particle_step"], fmt(r.get("ns_per_bond_step"), ".0f"),
            fmt(r.get("bond_marginal_ns_per_bond_step"), ".0f")))
    L.append("\n")
    return L


def beds_section(beds):
    tiled = {k: v for k, v in (beds or {}).items() if v.get("tiled_from")}
    if not tiled:
        return []
    L = ["## Tiled beds\n\n",
         "80k, 320k and 1M are k x k copies of the settled, relaxed 20k bed side by side (reference_runs/bench/"
         "README.md). Contacts per particle of the generated bed (every contact at the bed's touch overlap) "
         "against the base bed's.\n\n",
         "| bed | tiles | N | seam gap [m] | pairs/particle (base / tiled) | wall contacts/particle (base / tiled) | "
         "all contacts, tiled / base | max start overlap [m] | generation [s] |\n"
         "|---|---|---:|---:|---|---|---:|---:|---:|\n"]
    for name, b in sorted(tiled.items(), key=lambda kv: kv[1]["n"]):
        L.append("| %s | %d x %d of %s | %d | %.3g | %.3f / %.3f | %.3f / %.3f | %.4f | %.3g | %.1f |\n" % (
            name, b["tiles"][0], b["tiles"][1], b["tiled_from"], b["n"], b["seam_gap"],
            b["base"]["pairs_per_particle"], b["tiled"]["pairs_per_particle"],
            b["base"]["wall_contacts_per_particle"], b["tiled"]["wall_contacts_per_particle"],
            b["contacts_per_particle_ratio"], b["max_overlap"], b["generation_seconds"]))
    L.append("\n")
    return L


def failures_section(failures):
    if not failures:
        return []
    L = ["## Failed runs\n\n| size | variant | engine | ranks | threads | repeat | message |\n|---|---|---|---:|---:|---:|---|\n"]
    for f in failures:
        L.append("| %s | %s | %s | %d | %d | %d | %s |\n" % (f["size"], f["variant"], f["engine"], f["ranks"],
                                                           f["threads"], f["repeat"],
                                                           f["failed"].strip().splitlines()[-1][:200].replace("|", "/")))
    L.append("\n")
    return L


def write_report(out, rows, machine, feature_check=None, flat=None, beds=None, failures=None):
    ix = index(rows)
    sizes = [s for s in SIZE_ORDER if any(r["size"] == s for r in rows)]
    variants = []
    for r in rows:
        if r["variant"] not in variants:
            variants.append(r["variant"])
    try:
        pngs = plots(out, rows, variants, sizes)
    except Exception as exc:  # plots are a convenience; the tables carry the numbers
        pngs = []
        print("bench_report: no plots (%s)" % exc)
    loads = [r.get("load_average") or 0.0 for r in rows]
    L = ["# jdem performance benchmark\n\n",
         "Generated by `make bench` (scripts/bench.py; scenes and method: reference_runs/bench/README.md). "
         "Machine: %s, %s logical CPUs. Medians of %s repeats; wall time of the time loop "
         "less its output (jdem: its loop timer, `--timing`, less `output`; LIGGGHTS: its \"Loop time\" less "
         "its \"Outpt\" share), because the engines write different output: jdem and liggghts-jdem write two "
         "full frames (at 1M 12 %% of jdem's loop), stock LIGGGHTS only thermo lines; the loop with its "
         "output is in summary.json (loop_seconds_with_output). LIGGGHTS: one thread per rank; "
         "jdem: one process with 1 or 2 OpenMP threads. "
         "1-minute load average during the runs: %.1f–%.1f (other jobs shared the machine; timings "
         "under load are noisy — compare engines within a row, not across reports).\n\n"
         % (machine.get("cpu", "?"), machine.get("cpus", "?"), "/".join(sorted({str(r["repeats"]) for r in rows})),
            min(loads) if loads else 0, max(loads) if loads else 0)]
    L.append("Engines: **jdem** (standalone stepper), **liggghts-jdem** (LIGGGHTS 3.8 + `pair_style gran/jiang`, "
             "`fix wall/jiang`), **liggghts** (stock `/usr/bin/liggghts`, `pair_style gran model hertz tangential "
             "history [rolling_friction epsd2]`, `fix wall/gran ... primitive`). Same initial state, dt and steps.\n\n")
    for key, title, note in (
            ("particle_steps_per_second", "Throughput, 1 rank, wall time (million particle-steps per second)",
             "Wall time of the loop, as requested; inflated by whatever else ran on the machine (see the load average)."),
            ("particle_steps_per_cpu_second", "Throughput, 1 rank, CPU time (million particle-steps per CPU second)",
             "CPU time of the loop: GNU time's user+sys of the S-step run minus that of a 1-step run of the same "
             "input (all three engines the same way). Less disturbed by other jobs than wall time; use this column "
             "for the engine comparison when the load average is above the number of cores."),
            ("particle_steps_per_second_best", "Throughput, 1 rank, best of the repeats (million particle-steps per second)",
             "Each engine's fastest repeat (wall time). On a virtual machine whose neighbours load the shared "
             "cache and memory, repeats of one binary can differ by 1.5x, the memory-bound ones most; the fastest "
             "is the least disturbed. The targets are judged on the medians above.")):
        L.append("## %s\n\n%s\n\n" % (title, note))
        L.append("| size | variant | N | steps | dt [s] | contacts/particle (jdem / stock) | jdem | jdem 2 threads | "
                 "liggghts-jdem | liggghts | jdem / liggghts | jdem 2 threads / 1 | liggghts-jdem / liggghts |\n"
                 "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n")
        for s in sizes:
            for v in variants:
                a, b, c = ix.get((s, v, "jdem", 1)), ix.get((s, v, "liggghts-jdem", 1)), ix.get((s, v, "liggghts", 1))
                a2 = ix.get((s, v, "jdem/2t", 1))
                base = a or b or c
                if not base:
                    continue
                tp = lambda r: r[key] / 1e6 if r and r.get(key) else None
                ratio = lambda x, y: x[key] / y[key] if x and y and x.get(key) and y.get(key) else None
                na = v.endswith("_bonded")  # stock LIGGGHTS has no parallel bonds
                L.append("| %s | %s | %d | %d | %.2g | %s / %s | %s | %s | %s | %s | %s | %s | %s |\n" % (
                    s, v, base["N"], base["steps"], base["dt"],
                    fmt(a["contacts_per_particle"] if a else None, ".2f"),
                    "n/a" if na else fmt(c["contacts_per_particle"] if c else None, ".2f"),
                    fmt(tp(a), ".2f"), fmt(tp(a2), ".2f"), fmt(tp(b), ".2f"), "n/a" if na else fmt(tp(c), ".2f"),
                    "n/a" if na else fmt(ratio(a, c), ".2f"),
                    fmt(ratio(a2, a), ".2f"), "n/a" if na else fmt(ratio(b, c), ".2f")))
        L.append("\n")
    for p in pngs:
        L.append("![%s](%s)\n\n" % (os.path.basename(p), os.path.basename(p)))
    multi = [r for r in rows if r["ranks"] > 1]
    if multi:
        L.append("## MPI ranks (LIGGGHTS engines)\n\n| size | variant | engine | 1 rank [Mps/s] | 2 ranks [Mps/s] | speed-up |\n"
                 "|---|---|---|---:|---:|---:|\n")
        for r in multi:
            one = ix.get((r["size"], r["variant"], r["engine"], 1))
            if one:
                L.append("| %s | %s | %s | %.2f | %.2f | %.2f |\n" % (
                    r["size"], r["variant"], r["engine"], one["particle_steps_per_second"] / 1e6,
                    r["particle_steps_per_second"] / 1e6,
                    r["particle_steps_per_second"] / one["particle_steps_per_second"]))
        L.append("\njdem runs on one process; its OpenMP threads are in the throughput tables.\n\n")
    L.append("## Memory (peak resident set, largest process)\n\n| size | variant | jdem [MB] | liggghts-jdem [MB] | liggghts [MB] | "
             "bytes/particle jdem | liggghts-jdem | liggghts | jdem engine [MB] | jdem engine B/particle | "
             "jdem budget [MB] (300 B/particle + 100 B/contact) | engine within budget |\n"
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n")
    for s in sizes:
        for v in variants:
            rr = [ix.get((s, v, e, 1)) for e in ("jdem", "liggghts-jdem", "liggghts")]
            if not any(rr):
                continue
            eng = (rr[0] or {}).get("jdem_split_seconds") or {}
            ok = rr[0].get("engine_memory_within_budget") if rr[0] else None
            na = v.endswith("_bonded")  # stock LIGGGHTS has no parallel bonds
            L.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n" % (
                s, v, *["n/a" if na and e == 2 else fmt(r["peak_rss_bytes"] / 1e6 if r else None, ".0f")
                        for e, r in enumerate(rr)],
                *["n/a" if na and e == 2 else fmt(r["bytes_per_particle"] if r else None, ".0f")
                  for e, r in enumerate(rr)],
                fmt(eng["engine_bytes"] / 1e6 if eng.get("engine_bytes") else None, ".1f"),
                fmt(rr[0].get("engine_bytes_per_particle") if rr[0] else None, ".0f"),
                fmt(rr[0]["memory_budget_bytes"] / 1e6 if rr[0] and rr[0].get("memory_budget_bytes") else None, ".1f"),
                "–" if ok is None else "yes" if ok else "NO"))
    L.append("\nPeak RSS includes the executable and its libraries (LIGGGHTS: ~35–55 MB before any atom), "
             "so bytes/particle is meaningful only at the larger sizes. jdem's peak also holds the parsed "
             "scene: the bench scenes list every particle in YAML, and libyaml's document tree of them is "
             "the largest single item; \"jdem engine\" is what the engine itself holds during the run "
             "(particle arrays, contact lists at capacity, cells, bonds; `jdem run --timing`), the figure to hold "
             "against the budget. The budget counts as contacts the particle-particle contacts at the last step "
             "(contacts/particle x N / 2, from the trajectory's /observables/contacts) and, in the bonded beds, "
             "the bonds at the start (a per-pair record like a contact's history); wall contacts are not in it.\n\n")
    L.append("## LIGGGHTS' own time split (median run, % of loop time)\n\n| size | variant | engine | ranks | Pair | Neigh | Comm | Outpt | Other (fixes: walls, integration, gravity) |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n")
    for r in rows:
        sp = r.get("liggghts_split_percent")
        if sp:
            L.append("| %s | %s | %s | %d | %s | %s | %s | %s | %s |\n" % (
                r["size"], r["variant"], r["engine"], r["ranks"], fmt(sp.get("pair"), ".0f"), fmt(sp.get("neigh"), ".0f"),
                fmt(sp.get("comm"), ".0f"), fmt(sp.get("outpt"), ".1f"), fmt(sp.get("other"), ".0f")))
    L.append("\n")
    L += flatness_section(flat)
    L += bonded_section(rows)
    L += beds_section(beds)
    L += failures_section(failures)
    L += split_section(rows, sizes, variants)
    L += feature_section(feature_check)
    L += profile_section(out)
    L.append("## Files\n\n`summary.json` (one entry per scene, engine and rank count: medians), `runs.jsonl` (every timing), "
             "`scenes/` (the bench scenes), `decks/` (the LIGGGHTS decks and logs), `beds/` (settle runs and beds).\n")
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write("".join(L))


def profile_jdem(out, scene, n, steps=200):
    """Callgrind on a short run of `scene`; writes OUT/profile.json.  Returns False when valgrind
    is missing or cannot decode the build."""
    import shutil
    if not shutil.which("valgrind") or not shutil.which("callgrind_annotate"):
        return False
    d = os.path.join(out, "profile")
    os.makedirs(d, exist_ok=True)
    text = open(scene).read()
    text = re.sub(r"(?m)^  steps: \d+", "  steps: %d" % steps, text)
    text = re.sub(r"(?m)^  (every|observables_every): \d+", r"  \1: %d" % steps, text)
    sc = os.path.join(d, "profile.yaml")
    open(sc, "w").write(text)
    cg = os.path.join(d, "callgrind.out")
    # only the time loop (sim_step and what it calls) is collected; 1 thread
    r = subprocess.run(["valgrind", "--tool=callgrind", "--toggle-collect=sim_step", "--callgrind-out-file=" + cg,
                        engines.JDEM, "run", sc, "-o", os.path.join(d, "p.h5"), "--quiet", "--threads", "1"],
                       capture_output=True, text=True)
    if "unhandled instruction" in r.stderr:  # valgrind decodes at most AVX2
        sys.stderr.write("bench: no callgrind profile: valgrind cannot decode this build's AVX-512 "
                         "instructions (profile a build made with `make ARCH=-march=x86-64-v3`)\n")
        return False
    ann = subprocess.run(["callgrind_annotate", "--inclusive=no", "--threshold=100", cg],
                         capture_output=True, text=True).stdout
    # exclusive counts per "file:function": inlined code is attributed to the file it comes
    # from, so the contact law (kernel/jdem_kernel.h) and the geometry show up inside the loops
    rules = (("contact law (kernel/jdem_kernel.h, inlined into the force loops)", ("kernel/jdem_kernel.h",), None),
             ("contact geometry and per-pair constants (jdem_geometry.h, stepper/geometry.h)",
              ("jdem_geometry.h", "stepper/geometry.h"), None),
             ("force loops outside the law: list walk, gathers, force scatter, reduction, gravity",
              ("stepper/forces.c",), None),
             ("zeroing f and torque (memset)", ("memset",), None),
             ("integration (half kicks, drift, non-finite probes)", ("stepper/integrate.c",), None),
             ("neighbour check and rebuilds (incl. renumbering)", ("stepper/neighbour.c", "stepper/reorder.c"), None))
    parts = {name: 0 for name, _, _ in rules}
    other, total = 0, 0
    for line in ann.splitlines():
        m = re.match(r"^\s*([0-9,]+)\s+(?:\([^)]*\)\s+)?(\S+)", line)
        if not m or ":" not in m.group(2):
            if m and "PROGRAM TOTALS" in line:
                total = int(m.group(1).replace(",", ""))
            continue
        ir, where = int(m.group(1).replace(",", "")), m.group(2)
        for name, keys, _ in rules:
            if any(k in where for k in keys):
                parts[name] += ir
                break
        else:
            other += ir
    plist = [(name, parts[name]) for name, _, _ in rules] + [("other (libgomp, libc, clock)", other)]
    json.dump(dict(scene=os.path.relpath(scene, out), n=n, steps=steps, loop=total, parts=plist,
                   note="Instruction counts (1 thread) are not time (memory stalls and divisions/square roots cost "
                        "more per instruction), but they are deterministic on a shared machine and the split is a fair guide."),
              open(os.path.join(out, "profile.json"), "w"), indent=1)
    return True
