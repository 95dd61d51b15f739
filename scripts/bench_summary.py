"""bench_summary.py — the bench's records (OUT/runs.jsonl) summarised (scripts/bench.py, step 5):
medians per size, variant, engine, ranks and threads, the throughput measure, and the flatness of
jdem's cost per particle-step over N."""
import json
import os
import statistics

from scripts.bench_config import ENGINES, FLATNESS_TARGET, SIZES, VARIANT_NAMES, is_bonded
from scripts.bench_runs import LOOP_PARTS, jdem_loop_seconds


def load_runs(path):
    runs = []
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                line = line.strip()
                if line:
                    runs.append(json.loads(line))
    return runs


def loop_of(r):
    """The wall time of a timing's loop, output included: LIGGGHTS' Loop time, jdem's loop timer
    (also for runs recorded with the older run(S) - run(1) as wall_s)."""
    if r["engine"] == "jdem" and r.get("jdem_split"):
        return jdem_loop_seconds(r["jdem_split"])
    return r["wall_s"]


def output_of(r):
    """The part of a timing's loop spent writing output: jdem's `output=`, LIGGGHTS' "Outpt"
    share of its Loop time (0 for records without a split)."""
    if r["engine"] == "jdem":
        return (r.get("jdem_split") or {}).get("output", 0.0)
    return r["wall_s"] * (r.get("liggghts_split_percent") or {}).get("outpt", 0.0) / 100.0


def wall_of(r):
    """The throughput tables' measure: the loop's wall time less its output (see the module
    docstring, 3), so that the engines are timed on the same work."""
    return loop_of(r) - output_of(r)


def summarise(runs):
    groups = {}
    calib = {}
    for r in runs:
        if r["engine"].endswith("/calib"):
            calib.setdefault((r["size"], r["variant"], r["engine"][:-6], r["steps"]), []).append(r["cpu_s"])
    runs = [r for r in runs if not r["engine"].endswith("/calib")]
    for r in runs:
        groups.setdefault((r["size"], r["variant"], r["engine"], r["ranks"], r.get("threads", 1)), []).append(r)
    rows = []
    for (size, variant, engine, ranks, threads), rs in sorted(groups.items(), key=lambda kv: (
            SIZES.get(kv[0][0], 0), VARIANT_NAMES.index(kv[0][1]) if kv[0][1] in VARIANT_NAMES else 99,
            ENGINES.index(kv[0][2]), kv[0][3], kv[0][4])):
        walls = [wall_of(r) for r in rs]
        wall = statistics.median(walls)
        loop_with_output = statistics.median(loop_of(r) for r in rs)
        n, steps = rs[0]["n"], rs[0]["steps"]
        rss = max(r["peak_rss"] for r in rs)
        cpu = statistics.median(r["cpu_s"] for r in rs)
        if engine == "jdem":
            cpu_loop = cpu if threads == 1 else None  # already run(S) - run(1); threads add up CPU
        elif ranks == 1 and (size, variant, engine, steps) in calib:
            cpu_loop = cpu - statistics.median(calib[(size, variant, engine, steps)])
        else:
            cpu_loop = None  # MPI ranks busy-wait: CPU time is not work
        cpp = statistics.median(r["contacts_per_particle"] for r in rs)
        splits = [r["jdem_split"] for r in rs if r.get("jdem_split")]
        split = ({k: statistics.median(s[k] for s in splits) for k in splits[0]} if splits else None)
        engine_bytes = split.get("engine_bytes") if split else None
        # the sum of jdem's --timing parts but the output (the loop timer less the per-step checks)
        timer = sum(split[k] for k in LOOP_PARTS if k != "output") if split else None
        bonds = rs[0].get("bonds_start")
        # a bond is a per-pair record like a contact's history: the bonded beds' budget counts
        # the bonds at the start as contacts too
        budget = 300.0 * n + 100.0 * (0.5 * cpp * n + (bonds or 0))
        rows.append(dict(scene="%s_%s" % (size, variant), size=size, variant=variant, engine=engine,
                         threads=threads, ranks=ranks, N=n, steps=steps, dt=rs[0]["dt"], repeats=len(rs),
                         wall_seconds=wall, wall_seconds_all=walls,
                         loop_seconds_with_output=loop_with_output,
                         cpu_seconds_loop=cpu_loop,
                         particle_steps_per_cpu_second=(n * steps / cpu_loop) if cpu_loop and cpu_loop > 0 else None,
                         particle_steps_per_second=n * steps / wall if wall > 0 else float("nan"),
                         particle_steps_per_second_best=n * steps / min(walls) if min(walls) > 0 else None,
                         contacts_per_particle=cpp,
                         ns_per_particle_step=1e9 * wall / (n * steps),
                         jdem_timer_seconds=timer,
                         ns_per_particle_step_timer=1e9 * timer / (n * steps) if timer else None,
                         bonds=bonds, bonds_intact_end=min((r.get("bonds_end") for r in rs), default=None)
                         if bonds is not None else None,
                         ns_per_bond_step=1e9 * wall / (bonds * steps) if bonds else None,
                         peak_rss_bytes=rss, bytes_per_particle=rss * ranks / n,
                         memory_budget_bytes=budget,
                         engine_bytes=engine_bytes,
                         engine_bytes_per_particle=engine_bytes / n if engine_bytes else None,
                         engine_memory_within_budget=engine_bytes <= budget if engine_bytes else None,
                         timing="jdem loop timer" if engine == "jdem" else rs[0]["timing"], jdem_split_seconds=split,
                         liggghts_split_percent=rs[0].get("liggghts_split_percent"),
                         load_average=statistics.median(r.get("load_average", 0.0) for r in rs)))
    # the bonds' own cost: the bonded row against the same bed, engine and threads without bonds
    # (same steps; the bonded dt may be shorter, which does not change the work per step)
    ix = {(r["size"], r["variant"], r["engine"], r["ranks"], r["threads"]): r for r in rows}
    for r in rows:
        plain = ix.get((r["size"], r["variant"][:-len("_bonded")], r["engine"], r["ranks"], r["threads"]))
        if r["bonds"] and is_bonded(r["variant"]) and plain:
            r["bond_marginal_ns_per_bond_step"] = (1e9 * (r["wall_seconds"] - plain["wall_seconds"])
                                                   / (r["bonds"] * r["steps"]))
    return rows


def flatness(rows):
    """Issue 6's scaling target: jdem's ns per particle-step, max / min over the sizes run, per
    variant and thread count (1 process), from wall time and (1 thread) from CPU time."""
    groups = {}
    for r in rows:
        if r["engine"] == "jdem" and r["ranks"] == 1:
            groups.setdefault((r["variant"], r["threads"]), []).append(r)
    out = []
    for (variant, threads), rs in groups.items():
        if len(rs) < 2:
            continue
        rs.sort(key=lambda r: r["N"])
        wall = [r["ns_per_particle_step"] for r in rs]
        timer = [r["ns_per_particle_step_timer"] for r in rs if r.get("ns_per_particle_step_timer")]
        cpu = [1e9 / r["particle_steps_per_cpu_second"] for r in rs if r.get("particle_steps_per_cpu_second")]
        out.append(dict(variant=variant, threads=threads, sizes=[r["size"] for r in rs], N=[r["N"] for r in rs],
                        ns_per_particle_step=wall, ratio_wall=max(wall) / min(wall),
                        timer_ns_per_particle_step=timer if len(timer) == len(rs) else None,
                        ratio_timer=max(timer) / min(timer) if len(timer) == len(rs) else None,
                        cpu_ns_per_particle_step=cpu if len(cpu) == len(rs) else None,
                        ratio_cpu=max(cpu) / min(cpu) if len(cpu) == len(rs) else None,
                        target=FLATNESS_TARGET, met_wall=max(wall) / min(wall) <= FLATNESS_TARGET,
                        met_timer=max(timer) / min(timer) <= FLATNESS_TARGET if len(timer) == len(rs) else None))
    out.sort(key=lambda f: (VARIANT_NAMES.index(f["variant"]) if f["variant"] in VARIANT_NAMES else 99, f["threads"]))
    return out


def machine_info():
    """The machine a timing was taken on: core count, the CPU's name, family and model (a virtual
    machine may name only the vendor), and its widest SIMD extension, which sets how far jdem's
    vectorised loops pull ahead of LIGGGHTS' scalar ones (docs/mixing.md §10)."""
    info = {"cpus": os.cpu_count()}
    fields = {}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if not line.strip():
                    break                      # the first processor's block is enough
                key, _, value = line.partition(":")
                fields[key.strip()] = value.strip()
    except OSError:
        return info
    if "model name" in fields:
        info["cpu"] = fields["model name"]
    if "cpu family" in fields and "model" in fields:
        info["cpu_family_model"] = f"{fields['cpu family']}/{fields['model']}"
    flags = set(fields.get("flags", "").split())
    info["simd"] = next((f for f in ("avx512f", "avx2", "avx", "sse2") if f in flags), "none")
    return info
