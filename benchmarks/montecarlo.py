"""Monte Carlo speed: milliseconds per 600 s run at 10 Hz (gyro and attitude fixes), vector fidelity.

Paths: the batched path (`navsim.simulation.run_batch`, K runs sharing the seed-free part, with
1 and 2 threads), the campaign engine on a local process pool with 1 and 2 workers (each run
written to disk, resumable), and the same engine on a 2-worker Dask LocalCluster on loopback.
Basilisk's Monte Carlo took 1.26 s per such run on this kind of machine.

    python benchmarks/montecarlo.py [--k 1 100 1000] [--campaign-runs 40]

Prints a table and writes benchmarks/results/montecarlo.json. Asserts nothing.
"""

import argparse
import json
import platform
import shutil
import tempfile
import time
from pathlib import Path

from navsim.campaign.montecarlo import run_campaign
from navsim.simulation import run_batch

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper000_high_dynamic.toml"  # vector fidelity
# Basilisk's set-up: a 6-state attitude/bias filter, gyro and star-tracker attitude fixes at 10 Hz.
OVERRIDES = {"duration_s": 600.0, "gyro.rate_hz": 10.0, "star_sensor.rate_hz": 10.0, "truth.rate_hz": 40.0,
             "star_sensor.measurement": "attitude", "filter.bias_instability": "ignore", "filter.scale_factor": "ignore",
             "filter.gyro_misalignment": "ignore"}
BASILISK_MS_PER_RUN = 1260.0


def batched(k, threads):
    run_batch(SCENARIO, [0], overrides=OVERRIDES)  # warm-up: compiled kernels
    start = time.perf_counter()
    run_batch(SCENARIO, range(k), overrides=OVERRIDES, threads=threads)
    return 1e3 * (time.perf_counter() - start) / k


def campaign(runs, **backend):
    work = Path(tempfile.mkdtemp(prefix="navsim-mc-bench-"))
    try:
        start = time.perf_counter()
        run_campaign(SCENARIO, runs, work / "c", overrides=OVERRIDES, progress=False, **backend)
        return 1e3 * (time.perf_counter() - start) / runs
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--k", type=int, nargs="+", default=[1, 100, 1000])
    parser.add_argument("--campaign-runs", type=int, default=40)
    args = parser.parse_args()
    results = {}
    for k in args.k:
        for threads in (1, 2):
            results[f"batched_K{k}_threads{threads}"] = batched(k, threads)
    results["pool_1_worker"] = campaign(args.campaign_runs, workers=1)
    results["pool_2_workers"] = campaign(args.campaign_runs, workers=2)
    try:
        from distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None) as cluster, \
                Client(cluster) as client:
            campaign(2, scheduler=client)  # warm-up of the workers
            results["dask_2_workers"] = campaign(args.campaign_runs, scheduler=client)
    except ImportError:
        results["dask_2_workers"] = None
    print(f"{'path':28s} {'ms per 600 s run':>18s} {'vs Basilisk 1260 ms':>20s}")
    for name, ms in results.items():
        if ms is not None:
            print(f"{name:28s} {ms:18.1f} {BASILISK_MS_PER_RUN / ms:19.0f}x")
    speedup = results["pool_1_worker"] / results["pool_2_workers"]
    print(f"pool speed-up 1 -> 2 workers: {speedup:.2f}x")
    out = Path(__file__).resolve().parent / "results" / "montecarlo.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"machine": platform.platform(), "basilisk_ms_per_run": BASILISK_MS_PER_RUN,
                               "ms_per_run": results, "pool_speedup": speedup}, indent=2) + "\n")
    print(f"written {out}")


if __name__ == "__main__":
    main()
