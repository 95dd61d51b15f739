"""Running the cases in the engines: one trajectory per case and engine, with wall times."""
import concurrent.futures
import os
import sys

from scripts import engines
from . import cases
from .cases import ROOT, selected_cases, trajectory_path


def engine_command(engine, test, case, path):
    if engine == "jdem":
        return [engines.JDEM, "run", cases.scene_path(test), "--case", case, "-o", path, "--quiet"]
    return engines.script("liggghts_run", cases.scene_path(test), "--case", case, "-o", path)


def run_one(job):
    """Run one case; returns the job with its wall time [s] and exit status."""
    test, case, engine, path = job
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if os.path.exists(path):
        os.remove(path)  # a failed run must not leave an older trajectory to be analysed
    proc, seconds = engines.timed(engine_command(engine, test, case, path), cwd=ROOT, merge=True)
    return {"test": test, "case": case, "engine": engine, "seconds": seconds,
            "status": proc.returncode, "log": proc.stdout[-2000:]}


def run_all(out, tests, engines, jobs, quick):
    todo = [(t, c, e, trajectory_path(out, t, c, e))
            for t in tests for c in selected_cases(t, quick) for e in engines]
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        for res in pool.map(run_one, todo):
            if res["status"] != 0:
                print(f"run failed: test{res['test']} {res['case']} ({res['engine']}):\n{res['log']}",
                      file=sys.stderr)
            results.append(res)
    print(f"ran {len(todo)} cases in {sum(r['seconds'] for r in results):.1f} s of wall time "
          f"over {jobs} jobs", file=sys.stderr)
    return results
