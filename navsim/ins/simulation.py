"""Navigation runs (a scenario with a ``[trajectory]`` table): the INS through the closed loop.

:func:`prepare` computes the seed-free part once (the truth trajectory with its exactly consistent
IMU increments, the sensor models, the frame grid); :func:`simulate` is one seeded run: the IMU and
aiding measurements are drawn, the navigation filter starts from an error drawn from its P0 and runs
through :func:`navsim.closed_loop.run_loop` (its compiled fast path for the open-loop aiding), and
the run's series and :class:`~navsim.records.RunSummary` follow (:mod:`navsim.ins.summary`).

Random sub-streams (``SeedSequence(seed).spawn(6)``, in this fixed order): 0 gyro, 1 accelerometer,
2 the filter's initial error, 3 position fixes, 4 baro, 5 a random gravity disturbance (the truth
is then generated per run).
"""

import time
from dataclasses import dataclass

import numpy as np

from navsim.closed_loop import FrameGrid, run_loop
from navsim.earth.gravity import GravityDisturbance
from navsim.ins.summary import navigation_series, summarize
from navsim.records import RunResult
from navsim.scenario import build_navigation as build
from navsim.scenario.navigation import frame_rate
from navsim.sensors.aiding import AidingRun, draw_record
from navsim.truth import trajectory
from startrack import rotation as rot


@dataclass(frozen=True)
class NavigationPrepared:
    """The seed-free part of a navigation scenario: the truth (None when a random gravity disturbance
    makes it the run's own), the frame grid, the IMU, baro and position-fix models."""

    scenario: object
    truth: trajectory.Trajectory | None
    grid: FrameGrid
    gyro: object
    accel: object
    baro: object
    baro_every: int
    position_sensor: object
    disturbance: GravityDisturbance | None


def prepare(scenario):
    """The :class:`NavigationPrepared` of a validated navigation scenario."""
    imu_hz = scenario["imu"]["rate_hz"]
    frame_hz = frame_rate(scenario.data, scenario.source)
    ratio = int(round(imu_hz / frame_hz))
    n_frames = int(round(scenario["duration_s"] * imu_hz)) // ratio
    disturbance = build.gravity_disturbance(scenario)
    random_field = disturbance is not None and disturbance.correlation_length > 0.0
    truth = None if random_field else _truth(scenario, disturbance, None)
    gyro, accel = build.imu(scenario)
    baro = build.baro(scenario)
    return NavigationPrepared(scenario=scenario, truth=truth, grid=FrameGrid(dt=1.0 / imu_hz, ratio=ratio, n_frames=n_frames),
                              gyro=gyro, accel=accel, baro=baro,
                              baro_every=0 if baro is None else int(round(frame_hz / baro.rate_hz)),
                              position_sensor=build.position_sensor(scenario, frame_hz), disturbance=disturbance)


def _truth(scenario, disturbance, seed):
    return trajectory.generate(build.profile(scenario), scenario["imu"]["rate_hz"], disturbance, seed,
                               duration=scenario["duration_s"])


def simulate(prepared, seed, compiled=True):
    """One seeded navigation run; returns a :class:`~navsim.records.RunResult`. ``compiled=False``
    keeps the step-by-step loop where the filter's fast path would run."""
    started = time.perf_counter()
    p, scenario, grid = prepared, prepared.scenario, prepared.grid
    gyro_ss, accel_ss, init_ss, position_ss, baro_ss, gravity_ss = np.random.SeedSequence(seed).spawn(6)
    truth = p.truth if p.truth is not None else _truth(scenario, p.disturbance, gravity_ss)
    n = grid.n_frames * grid.ratio
    gyro = p.gyro.measure(truth.dtheta[:n] / grid.dt, gyro_ss)
    accel = p.accel.measure(truth.dv[:n] / grid.dt, accel_ss)
    P0 = build.initial_covariance(scenario, p.gyro, p.accel, truth.lat[0], truth.h[0])
    filt = build.nav_filter(scenario, p.gyro, p.accel, _start(truth, P0, init_ss), P0, grid.dt)
    record = draw_record(truth, grid.frame_k, p.position_sensor, p.baro, p.baro_every, position_ss, baro_ss)
    log = run_loop(filt, AidingRun(record), np.hstack([gyro.omega, accel.force]), truth, grid, compiled=compiled)
    series = navigation_series(truth, grid.frame_k, log.arrays, gyro, accel)
    summary = summarize(scenario, seed, series, grid)
    summary = summary.replace(timing={"wall_seconds": round(time.perf_counter() - started, 4)})
    return RunResult(summary=summary, series=series, scenario=scenario.data)


def _start(truth, P0, seed):
    """(L, λ, h, v_n, q_nb) of the filter: the truth at t = 0 with an error x0 ~ N(0, P0) in attitude
    (C_nb,est = (I − [φ×]) C_nb,true: q_est = q(−φ) ⊗ q_true), velocity and position."""
    x0 = np.linalg.cholesky(P0[:9, :9]) @ np.random.default_rng(seed).standard_normal(9)
    q0 = rot.multiply(rot.from_rotation_vector(-x0[0:3]), truth.q_nb[0])
    return truth.lat[0] + x0[6], truth.lon[0] + x0[7], truth.h[0] + x0[8], truth.v_n[0] + x0[3:6], q0
