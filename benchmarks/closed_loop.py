"""Closed-loop speed: wall milliseconds per simulated second of `navsim.run` at vector fidelity.

Configurations (600 s each, 000's high-dynamic profile with a tactical gyro, vector fidelity): gyro and
star-sensor attitude fixes both at 10 Hz with the 6-state filter (the set-up in which Basilisk's C
core with its UKF took 0.35-0.47 ms per simulated second on this kind of machine), the same with 9
states (scale factors), 15 (scale factors and misalignments) and 18 (also the Gauss-Markov bias: the
default for this gyro), with star-vector updates (6 and 18 states), and a 100 Hz gyro with 10 Hz fixes.
The first run of each configuration is a warm-up (numba compilation or cache load) and is not counted.

    python benchmarks/closed_loop.py [--repeats 3]

Prints a table and writes benchmarks/results/closed_loop.json. Asserts nothing.
"""

import argparse
import json
import platform
import time
from pathlib import Path

import navsim

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper000_high_dynamic.toml"  # vector fidelity
BASILISK_MS_PER_SIM_S = (0.35, 0.47)

TEN_HZ = {"gyro.rate_hz": 10.0, "star_sensor.rate_hz": 10.0, "truth.rate_hz": 40.0}
STATES = {  # filter groups of each state count (6: attitude and bias only)
    6: {"filter.bias_instability": "ignore", "filter.scale_factor": "ignore", "filter.gyro_misalignment": "ignore"},
    9: {"filter.bias_instability": "ignore", "filter.scale_factor": "estimate", "filter.gyro_misalignment": "ignore"},
    15: {"filter.bias_instability": "ignore", "filter.scale_factor": "estimate", "filter.gyro_misalignment": "estimate"},
    18: {"filter.bias_instability": "estimate", "filter.scale_factor": "estimate", "filter.gyro_misalignment": "estimate"},
}
CONFIGS = {
    **{f"gyro10_fix10_attitude_{n}state": {**TEN_HZ, "star_sensor.measurement": "attitude", **groups}
       for n, groups in STATES.items()},
    "gyro10_fix10_stars": {**TEN_HZ, "star_sensor.measurement": "stars", **STATES[6]},
    "gyro10_fix10_stars_18state": {**TEN_HZ, "star_sensor.measurement": "stars", **STATES[18]},
    "gyro100_fix10_attitude": {"gyro.rate_hz": 100.0, "star_sensor.rate_hz": 10.0, "truth.rate_hz": 400.0,
                               "star_sensor.measurement": "attitude", **STATES[6]},
}


def measure(overrides, duration_s, repeats):
    overrides = {**overrides, "duration_s": duration_s}
    navsim.run(SCENARIO, seed=0, overrides=overrides)  # warm-up
    times = []
    for seed in range(repeats):
        start = time.perf_counter()
        navsim.run(SCENARIO, seed=seed, overrides=overrides)
        times.append(time.perf_counter() - start)
    best = min(times)
    return {"duration_s": duration_s, "wall_s": times, "ms_per_sim_s_best": 1e3 * best / duration_s,
            "ms_per_sim_s_median": 1e3 * sorted(times)[len(times) // 2] / duration_s}


IMAGE_SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper000_predictive_catalog.toml"


def measure_image(duration_s, repeats):
    """Image fidelity on 000's scenario (2 Hz, 1024 x 1024, full frames while acquiring, windows while
    tracking), without its tracking-failure probes: simulated seconds per wall second."""
    overrides = {"duration_s": duration_s, "faults.tracking_failure_probes": None}
    from navsim.simulation import prepare, simulate

    prepared = prepare(IMAGE_SCENARIO, overrides)  # catalog, identifier: once per scenario
    simulate(prepared, 0)  # warm-up
    times = []
    for seed in range(repeats):
        start = time.perf_counter()
        result = simulate(prepared, seed)
        times.append(time.perf_counter() - start)
    frame_ms = result.timing_series["frame_ms"]
    return {"duration_s": duration_s, "wall_s": times, "realtime_factor_best": duration_s / min(times),
            "frame_ms_median": float(sorted(frame_ms)[len(frame_ms) // 2]), "frame_ms_max": float(max(frame_ms))}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--duration-s", type=float, default=600.0)
    args = parser.parse_args()
    results = {name: measure(o, args.duration_s, args.repeats) for name, o in CONFIGS.items()}
    print(f"{'configuration':30s} {'ms / simulated s (best)':>24s} {'median':>8s}")
    for name, r in results.items():
        print(f"{name:30s} {r['ms_per_sim_s_best']:24.3f} {r['ms_per_sim_s_median']:8.3f}")
    image = measure_image(60.0, args.repeats)
    results["image_paper000"] = image
    print(f"image fidelity, 000 scenario: {image['realtime_factor_best']:.1f}x faster than real time "
          f"(frame median {image['frame_ms_median']:.1f} ms, max {image['frame_ms_max']:.1f} ms); goal >= 10x")
    print(f"Basilisk (C core, UKF, gyro + fixes at 10 Hz): {BASILISK_MS_PER_SIM_S[0]}-{BASILISK_MS_PER_SIM_S[1]} ms / simulated s")
    out = Path(__file__).resolve().parent / "results" / "closed_loop.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    payload = {"machine": platform.platform(), "python": platform.python_version(),
               "basilisk_ms_per_sim_s": BASILISK_MS_PER_SIM_S, "results": results}
    out.write_text(json.dumps(payload, indent=2) + "\n")
    print(f"written {out}")


if __name__ == "__main__":
    main()
