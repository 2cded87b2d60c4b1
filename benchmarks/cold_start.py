"""Cold start: where the first image-fidelity run of an installation spends its time (issue 25).

Each measurement runs in fresh processes with an empty kernel folder (``$NUMBA_CACHE_DIR`` a new temporary
directory; the built tables stay cached):

- every compile-ahead task of an image-fidelity attitude run (``navsim.attitude.run.IMAGE_LANES``) alone: wall
  and CPU seconds -- their sum is about what one process compiling at first call pays (a kernel two tasks
  share counted in each; the set-up before
  ``startrack.compiled.compile_ahead``);
- the lanes at once (``compile_ahead``: the first here, the other spawned), wall;
- then, on those kernels, the demo (``navsim run scenarios/demo.toml --report``) as ``make demo`` runs it, and
  the same demo once more (everything loaded).

    python benchmarks/cold_start.py [--repeats 1]

Prints a table and writes benchmarks/results/cold_start.json. Asserts nothing. The machine's own noise is
large here (the same compilation measured 40-49 s within an hour on the 2-core test machine): --repeats.
"""

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from navsim.attitude.run import IMAGE_LANES as ATTITUDE_IMAGE

ROOT = Path(__file__).resolve().parents[1]
NAVSIM = Path(sys.executable).with_name("navsim")


def _timed(command, env):
    """(wall s, CPU s of the children) of ``command``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, env=env, cwd=ROOT, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return time.perf_counter() - start, cpu


def _task(task):
    module, function = task.split(":")
    return [sys.executable, "-c", f"from {module} import {function}; {function}()"]


def _demo(out):
    return [str(NAVSIM), "run", "scenarios/demo.toml", "--out", str(out), "--report", str(out / "report.pdf")]


def measure(work):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(work / "tasks")}
    tasks = {}
    for lane in ATTITUDE_IMAGE:
        for task in lane:
            env["NUMBA_CACHE_DIR"] = str(work / task.replace(":", "."))  # each alone, from nothing
            wall, cpu = _timed(_task(task), env)
            tasks[task] = {"wall_s": wall, "cpu_s": cpu}
    env["NUMBA_CACHE_DIR"] = str(work / "lanes")
    lanes = f"from startrack.compiled.compile_ahead import compile_ahead; compile_ahead({ATTITUDE_IMAGE!r})"
    lanes_wall, lanes_cpu = _timed([sys.executable, "-c", lanes], env)
    demo_wall, _ = _timed(_demo(work / "demo"), env)
    again_wall, _ = _timed(_demo(work / "demo_again"), env)
    return {"tasks": tasks, "tasks_cpu_sum_s": sum(t["cpu_s"] for t in tasks.values()),
            "lanes_wall_s": lanes_wall, "lanes_cpu_s": lanes_cpu, "demo_after_lanes_wall_s": demo_wall,
            "demo_warm_wall_s": again_wall}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    runs = []
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as folder:
            runs.append(measure(Path(folder)))
    for k, run in enumerate(runs):
        print(f"repeat {k}:")
        for task, t in run["tasks"].items():
            print(f"  {task:48s} alone  {t['wall_s']:6.1f} s wall {t['cpu_s']:6.1f} s CPU")
        print(f"  {'sum of the tasks (one process, first call)':48s}        {run['tasks_cpu_sum_s']:6.1f} s CPU")
        print(f"  {'the lanes at once (compile_ahead)':48s}        {run['lanes_wall_s']:6.1f} s wall "
              f"{run['lanes_cpu_s']:6.1f} s CPU")
        print(f"  {'then the demo with its report':48s}        {run['demo_after_lanes_wall_s']:6.1f} s wall")
        print(f"  {'the demo again':48s}        {run['demo_warm_wall_s']:6.1f} s wall")
    out = ROOT / "benchmarks" / "results" / "cold_start.json"
    out.write_text(json.dumps({"machine": {"cpus": os.cpu_count(), "processor": platform.processor(),
                                           "python": platform.python_version()}, "runs": runs}, indent=2) + "\n")
    print(f"written to {out}")


if __name__ == "__main__":
    main()
