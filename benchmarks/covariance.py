"""Sizing speed: the linear covariance analysis of the 1 h `sins_cns_aircraft_vector` beside the Monte Carlo
campaign it matches, in one run, and a 10 x 10 sweep of it.

Measured, after a warm-up analysis (numba compilation or cache load, not counted):
- the analysis end to end (the scenario's nominal trajectory, catalog, stars, the pass: `navsim.covariance`)
  and its pass alone, the median of ``--repeats``;
- the ``--runs``-run campaign of the same scenario (`navsim montecarlo`, all cores), and the ratio;
- a 10 x 10 sweep over the gyro's ARW and the star sensor's σ (`navsim sweep`, all cores), unless ``--no-sweep``.

    python benchmarks/covariance.py [--runs 500] [--repeats 5] [--no-sweep]

Prints a table and writes benchmarks/results/covariance.json. Asserts nothing.
"""

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import navsim
from navsim.campaign.montecarlo import run_campaign
from navsim.campaign.sweep import run_sweep
from navsim.kinds import resolve_scenario

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "sins_cns_aircraft_vector.toml"
ONE_HOUR = ("duration_s=3600",)
ARW = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0]
STAR_SIGMA = [1, 2, 3, 5, 7, 10, 15, 20, 30, 50]


def analysis_times(scenario, repeats):
    """(end-to-end, the pass alone) median seconds of the analysis."""
    navsim.covariance(scenario)  # warm-up
    total, passes = [], []
    for _ in range(repeats):
        started = time.perf_counter()
        result = navsim.covariance(scenario)
        total.append(time.perf_counter() - started)
        passes.append(result.wall_seconds)  # its own clock: nominal, catalog stars, the pass
    return statistics.median(total), statistics.median(passes)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=500)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--no-sweep", action="store_true")
    args = parser.parse_args()
    scenario = resolve_scenario(SCENARIO, ONE_HOUR)
    total, pass_s = analysis_times(scenario, args.repeats)
    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        run_campaign(scenario, args.runs, Path(tmp) / "campaign", progress=False)
        campaign_s = time.perf_counter() - started
        sweep_s = None
        if not args.no_sweep:
            started = time.perf_counter()
            run_sweep(SCENARIO, [("imu.gyro.arw_deg_per_sqrt_h", ARW), ("star_sensor.star_sigma_arcsec", STAR_SIGMA)],
                      "horizontal_position@1h", Path(tmp) / "sweep", requirement=500.0, overrides=ONE_HOUR, progress=False)
            sweep_s = time.perf_counter() - started
    result = {"machine": {"cpu": platform.processor() or platform.machine(), "cores": os.cpu_count(),
                          "python": platform.python_version()},
              "scenario": "sins_cns_aircraft_vector, 1 h", "analysis_s": round(total, 3), "analysis_own_clock_s": round(pass_s, 3),
              "campaign_runs": args.runs, "campaign_s": round(campaign_s, 1), "speedup": round(campaign_s / total, 1),
              "sweep_10x10_s": None if sweep_s is None else round(sweep_s, 1)}
    print(f"covariance analysis, 1 h sins_cns_aircraft_vector   {total:8.3f} s (in the analysis: {pass_s:.3f} s)")
    print(f"Monte Carlo campaign, {args.runs} runs, {os.cpu_count()} cores         {campaign_s:8.1f} s   ({campaign_s / total:.0f}x)")
    if sweep_s is not None:
        print(f"10 x 10 sweep (ARW x star σ), {os.cpu_count()} cores           {sweep_s:8.1f} s")
    out = ROOT / "benchmarks" / "results" / "covariance.json"
    out.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print(f"written to {out}")


if __name__ == "__main__":
    main()
