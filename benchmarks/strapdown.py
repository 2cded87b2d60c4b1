"""Strapdown INS speed: wall seconds per simulated hour, IMU at 200 Hz, ours and python-ins on the same data.

Data: the first hour of the 2 h aircraft flight (navsim.truth.tables.AIRCRAFT_2H: climb to 7 km,
turns, speed changes), its exactly consistent increments at 200 Hz corrupted by the tactical
gyro/accelerometer presets, position fixes of 3 m at 1 Hz. Measured, best of --repeats after a
warm-up run (numba compilation or cache load):

- mechanization: our compiled strapdown (navsim.ins.strapdown.run) against python-ins 1.0.1
  (pyins.strapdown.compute_increments_from_imu + Integrator.integrate, its numba core);
- with the filter: our NavFilter (15 states, covariance at 10 Hz, 1 Hz fixes) against python-ins'
  run_feedback_filter (covariance at 10 Hz, same fixes) — the latter on --pyins-filter-minutes of data
  and scaled to the hour, as it is a Python loop;
- campaign: Monte Carlo runs (IMU synthesis + filter + logging, 1 h each) timed in two worker
  processes at once (single-threaded BLAS), scaled to 1000 runs x 1 h on the two cores.

    python benchmarks/strapdown.py [--repeats 3] [--pyins-filter-minutes 10]

Prints a table and writes benchmarks/results/strapdown.json. Asserts nothing.
"""

import argparse
import json
import multiprocessing
import os
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from navsim.estimation.nav_filter import ImuNoise, NavFilter  # noqa: E402
from navsim.ins import driver, strapdown  # noqa: E402
from navsim.sensors.accelerometer import AccelerometerModel  # noqa: E402
from navsim.sensors.gyro import GyroModel  # noqa: E402
from navsim.truth import trajectory  # noqa: E402
from navsim.truth.segments import Profile  # noqa: E402
from navsim.truth.tables import AIRCRAFT_2H  # noqa: E402
from startrack import units  # noqa: E402

RATE_HZ = 200.0
HOUR = 3600.0
GOALS = {"mechanization_s_per_h": 1.0, "filter_s_per_h": 2.0, "campaign_1000x1h_min_on_2_cores": 10.0}


def first_hour():
    segments = AIRCRAFT_2H["segments"][:9]
    head = Profile.from_table({**AIRCRAFT_2H, "segments": segments}).duration
    return Profile.from_table({**AIRCRAFT_2H, "segments": segments + [{"kind": "straight", "duration_s": HOUR - head}]})


def sensors():
    return GyroModel.preset("tactical", RATE_HZ), AccelerometerModel.preset("tactical", RATE_HZ)


def measured_increments(truth, seed):
    gyro, accel = sensors()
    g_seed, a_seed = np.random.SeedSequence(seed).spawn(2)
    dtheta = gyro.measure(truth.dtheta / truth.dt, g_seed).omega * truth.dt
    return dtheta, accel.measure(truth.dv / truth.dt, a_seed).force * truth.dt


def best(function, repeats):
    function()  # warm-up
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times), times


def ours_mechanization(truth, dtheta, dv):
    nav = strapdown.initial_state(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0])
    return strapdown.run(nav, dtheta, dv, truth.dt, every=200)


def ours_filter(truth, dtheta, dv):
    gyro, accel = sensors()
    P0 = driver.initial_covariance(gyro, accel, np.array([0.05, 0.05, 0.3]) * units.DEG, 0.1, 5.0, truth.lat[0], truth.h[0])
    noise = ImuNoise(gyro.arw, accel.vrw, gyro.filter_rrw, accel.filter_bias_rw)
    f = NavFilter(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0], P0, noise, truth.dt)
    step = int(RATE_HZ)
    for k in range(0, dtheta.shape[0], step):
        f.predict(dtheta[k:k + step], dv[k:k + step])
        f.update_position(truth.lat[k + step], truth.lon[k + step], truth.h[k + step], 3.0)
    return f


def pyins_frames(truth, dtheta, dv, samples):
    """(imu frame with pyins' leading 'before' sample, initial pva series) of the first ``samples`` intervals."""
    import pandas as pd
    from scipy.spatial.transform import Rotation

    raw = np.hstack([dtheta[:samples], dv[:samples]])
    imu = pd.DataFrame(np.vstack([raw[:1], raw]), index=truth.t[:samples + 1],
                       columns=["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"])
    rph = Rotation.from_quat(truth.q_nb[0]).as_euler("xyz", degrees=True)
    pva = pd.Series(np.hstack([np.degrees([truth.lat[0], truth.lon[0]]), truth.h[0], truth.v_n[0], rph]),
                    index=["lat", "lon", "alt", "VN", "VE", "VD", "roll", "pitch", "heading"], name=truth.t[0])
    return imu, pva


def pyins_mechanization(truth, dtheta, dv):
    from pyins import strapdown as pyins_strapdown

    imu, pva = pyins_frames(truth, dtheta, dv, dtheta.shape[0])
    increments = pyins_strapdown.compute_increments_from_imu(imu, "increment")
    return pyins_strapdown.Integrator(pva).integrate(increments)


def pyins_filter(truth, dtheta, dv, samples):
    import pandas as pd
    from pyins import filters, inertial_sensor, measurements
    from pyins import strapdown as pyins_strapdown

    gyro, accel = sensors()
    imu, pva = pyins_frames(truth, dtheta, dv, samples)
    increments = pyins_strapdown.compute_increments_from_imu(imu, "increment")
    fixes = np.arange(int(RATE_HZ), samples + 1, int(RATE_HZ))
    positions = pd.DataFrame(np.stack([np.degrees(truth.lat[fixes]), np.degrees(truth.lon[fixes]), truth.h[fixes]], axis=-1),
                             index=truth.t[fixes], columns=["lat", "lon", "alt"])
    gyro_model = inertial_sensor.EstimationModel(bias_sd=np.full(3, gyro.bias_turn_on_sigma), noise=np.full(3, gyro.arw),
                                                 bias_walk=np.full(3, gyro.filter_rrw))
    accel_model = inertial_sensor.EstimationModel(bias_sd=np.full(3, accel.bias_turn_on_sigma), noise=np.full(3, accel.vrw),
                                                  bias_walk=np.full(3, accel.filter_bias_rw))
    return filters.run_feedback_filter(pva, 5.0, 0.1, 0.05, 0.3, increments, gyro_model, accel_model,
                                       measurements=[measurements.Position(positions, 3.0)], time_step=0.1)


def campaign_run(seed):
    """One Monte Carlo run of 1 h (IMU synthesis + filter) in a worker; returns its wall seconds."""
    truth = _WORKER_TRUTH
    start = time.perf_counter()
    gyro, accel = sensors()
    gyro = replace(gyro, scale_factor_sigma=0.0, misalignment_sigma=0.0)
    accel = replace(accel, scale_factor_sigma=0.0, misalignment_sigma=0.0)
    P0 = driver.initial_covariance(gyro, accel, np.array([0.05, 0.05, 0.3]) * units.DEG, 0.1, 5.0, truth.lat[0], truth.h[0])
    driver.position_aided_run(truth, gyro, accel, P0, 1.0, 3.0, seed, covariance_interval=20)
    return time.perf_counter() - start


_WORKER_TRUTH = None


def _init_worker():
    global _WORKER_TRUTH
    _WORKER_TRUTH = trajectory.generate(first_hour(), RATE_HZ)
    campaign_run(0)  # warm-up (compilation or cache load)


#: One BLAS thread per worker process: two processes of two OpenBLAS threads each on two cores spin
#: against each other (measured 2.6x slower per run).
SINGLE_THREADED = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def campaign_minutes(runs_per_worker=2):
    """Two spawned worker processes (single-threaded BLAS, set before they import numpy)."""
    saved = {key: os.environ.get(key) for key in SINGLE_THREADED}
    os.environ.update(SINGLE_THREADED)
    try:
        with ProcessPoolExecutor(max_workers=2, initializer=_init_worker,
                                 mp_context=multiprocessing.get_context("spawn")) as pool:
            times = list(pool.map(campaign_run, range(1, 1 + 2 * runs_per_worker)))
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key)
            else:
                os.environ[key] = value
    per_run = float(np.median(times))
    return {"run_wall_s_in_two_processes": times, "estimated_1000x1h_min_on_2_cores": 1000 * per_run / 2 / 60.0}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--pyins-filter-minutes", type=float, default=10.0)
    args = parser.parse_args()
    start = time.perf_counter()
    truth = trajectory.generate(first_hour(), RATE_HZ)
    generation_s = time.perf_counter() - start
    dtheta, dv = measured_increments(truth, 1)
    hours = truth.t[-1] / HOUR
    results = {"truth_generation_s_per_h": generation_s / hours}
    for name, function in (("ours_mechanization", lambda: ours_mechanization(truth, dtheta, dv)),
                           ("pyins_mechanization", lambda: pyins_mechanization(truth, dtheta, dv)),
                           ("ours_filter", lambda: ours_filter(truth, dtheta, dv))):
        best_s, times = best(function, args.repeats)
        results[name] = {"s_per_h_best": best_s / hours, "wall_s": times}
    samples = int(args.pyins_filter_minutes * 60 * RATE_HZ)
    best_s, times = best(lambda: pyins_filter(truth, dtheta, dv, samples), 1)
    results["pyins_filter"] = {"s_per_h_best": best_s * HOUR / (samples / RATE_HZ), "wall_s": times,
                               "simulated_s": samples / RATE_HZ}
    results["campaign"] = campaign_minutes()
    print(f"{'200 Hz, wall seconds per simulated hour':44s} {'ours':>8s} {'python-ins':>11s} {'goal':>6s}")
    print(f"{'mechanization':44s} {results['ours_mechanization']['s_per_h_best']:8.3f} "
          f"{results['pyins_mechanization']['s_per_h_best']:11.3f} {GOALS['mechanization_s_per_h']:6.1f}")
    print(f"{'with the filter (1 Hz position fixes)':44s} {results['ours_filter']['s_per_h_best']:8.3f} "
          f"{results['pyins_filter']['s_per_h_best']:11.1f} {GOALS['filter_s_per_h']:6.1f}")
    print(f"truth generation (not in the above): {results['truth_generation_s_per_h']:.2f} s per hour")
    print(f"campaign 1000 x 1 h on 2 cores (estimated from {len(results['campaign']['run_wall_s_in_two_processes'])} runs): "
          f"{results['campaign']['estimated_1000x1h_min_on_2_cores']:.1f} min "
          f"(goal {GOALS['campaign_1000x1h_min_on_2_cores']:.0f})")
    out = Path(__file__).resolve().parent / "results" / "strapdown.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    payload = {"machine": platform.platform(), "python": platform.python_version(), "imu_rate_hz": RATE_HZ,
               "goals": GOALS, "results": results}
    out.write_text(json.dumps(payload, indent=2) + "\n")
    print(f"written {out}")


if __name__ == "__main__":
    main()
