"""Strapdown INS speed: wall seconds per simulated hour, IMU at 200 Hz, ours and python-ins on the same data.

Data: the first hour of the 2 h aircraft flight of scenarios/position_aided_aircraft.toml (climb to
7 km, turns, speed changes), its exactly consistent increments at 200 Hz corrupted by the tactical
gyro/accelerometer presets, position fixes of 3 m at 1 Hz. Measured, best of --repeats after a
warm-up run (numba compilation or cache load):

- mechanization: our compiled strapdown (navsim.ins.strapdown.run) against python-ins 1.0.1
  (pyins.strapdown.compute_increments_from_imu + Integrator.integrate, its numba core);
- with the filter: our NavFilter (15 states, covariance at 10 Hz, 1 Hz fixes, its compiled
  whole-record path) against python-ins' run_feedback_filter (covariance at 10 Hz, same fixes) — the
  latter on --pyins-filter-minutes of data and scaled to the hour, as it is a Python loop;
- campaign: --campaign-runs (default 1000) runs of 1 h of that scenario at 200 Hz through the real
  campaign runner (navsim.campaign.montecarlo.run_campaign: IMU synthesis, filter, series, summary
  and files of every run, two worker processes with single-threaded BLAS), wall minutes.

    python benchmarks/strapdown.py [--repeats 3] [--pyins-filter-minutes 10] [--campaign-runs 1000]

Prints a table and writes benchmarks/results/strapdown.json. Asserts nothing.
"""

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from navsim.campaign.montecarlo import run_campaign  # noqa: E402
from navsim.estimation.nav_filter import NavFilter  # noqa: E402
from navsim.ins import strapdown  # noqa: E402
from navsim.kinds import load_scenario  # noqa: E402
from navsim.navigation import build as build_navigation  # noqa: E402
from navsim.sensors.aiding import PositionFixSensor, draw_record  # noqa: E402
from navsim.truth import trajectory  # noqa: E402
from navsim.truth.segments import Profile  # noqa: E402

RATE_HZ = 200.0
HOUR = 3600.0
GOALS = {"mechanization_s_per_h": 1.0, "filter_s_per_h": 2.0, "campaign_1000x1h_min_on_2_cores": 10.0}
SCENARIO = ROOT / "scenarios" / "position_aided_aircraft.toml"
#: The campaign's runs: the scenario's first hour with the IMU at 200 Hz.
HOUR_AT_200_HZ = {"duration_s": HOUR, "imu.rate_hz": RATE_HZ}


def scenario():
    return load_scenario(SCENARIO, HOUR_AT_200_HZ)


def first_hour():
    table = scenario()["trajectory"]
    segments = table["segments"][:9]
    head = Profile.from_table({**table, "segments": segments}).duration
    return Profile.from_table({**table, "segments": segments + [{"kind": "straight", "duration_s": HOUR - head}]})


def sensors():
    return build_navigation.imu(scenario())


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
    """The scenario's filter (15 states, datasheet noise) over the whole record of 1 Hz fixes of 3 m."""
    gyro, accel = sensors()
    s = scenario()
    config = build_navigation.filter_config(s, gyro, accel, truth.lat[0], truth.h[0], truth.dt)
    f = NavFilter(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0], config)
    frame_k = np.arange(1, int(HOUR) + 1) * int(RATE_HZ)
    record = draw_record(truth, frame_k, PositionFixSensor(every=1, sigma_ned=np.full(3, 3.0)), None, 0, 1, 2)
    f.process_record(np.hstack([dtheta, dv]) / truth.dt, int(RATE_HZ), truth.dt, record)
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


def campaign_minutes(runs, scenario=SCENARIO, overrides=HOUR_AT_200_HZ):
    """Wall minutes of ``runs`` runs of 1 h at 200 Hz (of ``scenario`` with ``overrides``) through the
    campaign runner on two workers, with the machine's 15-minute load average after them (a shared
    machine: other work slows the runs), and the campaign's NEES and divergent runs."""
    with tempfile.TemporaryDirectory(prefix="navsim-bench-") as tmp:
        start = time.perf_counter()
        summary = run_campaign(scenario, runs, Path(tmp) / "campaign", overrides=overrides, workers=2, progress=False)
        minutes = (time.perf_counter() - start) / 60.0
    return {"runs": runs, "wall_min_on_2_workers": minutes, "per_1000_runs_min": 1000.0 * minutes / runs,
            "load_average_15_min_after": os.getloadavg()[2],
            "runs_finished": summary["runs_finished"], "divergent_runs": len(summary["divergent_runs"]),
            "nees_dof": summary["nees"]["dof"], "nees_mean": summary["nees"]["mean"],
            "nees_band_95": summary["nees"]["band_95"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--pyins-filter-minutes", type=float, default=10.0)
    parser.add_argument("--campaign-runs", type=int, default=1000)
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
    results["campaign"] = campaign_minutes(args.campaign_runs)
    print(f"{'200 Hz, wall seconds per simulated hour':44s} {'ours':>8s} {'python-ins':>11s} {'goal':>6s}")
    print(f"{'mechanization':44s} {results['ours_mechanization']['s_per_h_best']:8.3f} "
          f"{results['pyins_mechanization']['s_per_h_best']:11.3f} {GOALS['mechanization_s_per_h']:6.1f}")
    print(f"{'with the filter (1 Hz position fixes)':44s} {results['ours_filter']['s_per_h_best']:8.3f} "
          f"{results['pyins_filter']['s_per_h_best']:11.1f} {GOALS['filter_s_per_h']:6.1f}")
    print(f"truth generation (not in the above): {results['truth_generation_s_per_h']:.2f} s per hour")
    campaign = results["campaign"]
    print(f"campaign of {campaign['runs']} x 1 h through navsim's campaign runner on 2 workers: "
          f"{campaign['wall_min_on_2_workers']:.1f} min, {campaign['per_1000_runs_min']:.1f} min per 1000 runs "
          f"(goal {GOALS['campaign_1000x1h_min_on_2_cores']:.0f})")
    out = Path(__file__).resolve().parent / "results" / "strapdown.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    payload = {"machine": platform.platform(), "python": platform.python_version(), "imu_rate_hz": RATE_HZ,
               "goals": GOALS, "results": results}
    out.write_text(json.dumps(payload, indent=2) + "\n")
    print(f"written {out}")


if __name__ == "__main__":
    main()
