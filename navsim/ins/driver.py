"""Small drivers of the INS core: one position-aided filter run on a truth trajectory with simulated
sensors, and its consistency statistics. (The scenario-level closed loop is the second phase's.)

A run draws every random number from one seed: SeedSequence(seed).spawn(4) gives the gyro, the
accelerometer, the initial navigation errors and the position-fix noise.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.wgs84 import radii
from navsim.estimation.consistency import nees
from navsim.estimation.nav_filter import ImuNoise, NavFilter, error_state
from startrack import rotation as rot
from startrack.errors import InputError


@dataclass(frozen=True)
class AidedRun:
    """One position-aided run logged after each fix: times ``t`` [s], the error state ``error``
    (K, 15) (est − true, docs/design.md), its covariance diagonal ``sigma`` (K, 15), ``nees`` (K,),
    the fixes' ``nis`` (K,) and ``accepted`` (K,)."""

    t: np.ndarray
    error: np.ndarray
    sigma: np.ndarray
    nees: np.ndarray
    nis: np.ndarray
    accepted: np.ndarray


def check_aiding_rate(imu_rate_hz, aiding_rate_hz, key):
    """The IMU intervals per aiding epoch; an aiding sensor faster than the IMU, or not an integer
    divisor of its rate, is bad input named by ``key``."""
    if not aiding_rate_hz > 0.0:
        raise InputError(f"{key}: must be > 0, got {aiding_rate_hz!r}")
    if aiding_rate_hz > imu_rate_hz:
        raise InputError(f"{key}: {aiding_rate_hz} Hz is faster than the IMU ({imu_rate_hz} Hz)")
    ratio = imu_rate_hz / aiding_rate_hz
    if abs(ratio - round(ratio)) > 1e-9:
        raise InputError(f"{key}: the IMU rate {imu_rate_hz} Hz is not a multiple of {aiding_rate_hz} Hz")
    return int(round(ratio))


def initial_covariance(gyro, accel, attitude_sigma, velocity_sigma, position_sigma, lat, h):
    """P0 (15x15) of the base error state: attitude σ (3,) [rad], velocity σ [m/s], NED position σ
    [m] (3,) at (L, h), and the sensors' bias spread (turn-on and bias-instability σ in quadrature)."""
    r_m, r_n = radii(lat)
    position_sigma = np.broadcast_to(np.asarray(position_sigma, dtype=float), (3,))
    sigma = np.concatenate([
        np.broadcast_to(attitude_sigma, (3,)), np.broadcast_to(velocity_sigma, (3,)),
        position_sigma / np.array([r_m + h, (r_n + h) * np.cos(lat), 1.0]),
        np.full(3, np.hypot(gyro.bias_turn_on_sigma, gyro.bias_instability_sigma)),
        np.full(3, np.hypot(accel.bias_turn_on_sigma, accel.bias_instability_sigma)),
    ])
    return np.diag(sigma**2)


def position_aided_run(truth, gyro, accel, P0, fix_rate_hz, fix_sigma, seed, covariance_interval=20):
    """One run of :class:`~navsim.estimation.nav_filter.NavFilter` on ``truth`` (a
    :class:`~navsim.truth.trajectory.Trajectory`) with the gyro and accelerometer models sampled at
    the truth's rate, initial errors drawn from ``P0`` (biases: the sensors' own draw, estimates 0),
    and position fixes at ``fix_rate_hz`` with NED σ ``fix_sigma`` [m]. Returns an :class:`AidedRun`."""
    ratio = check_aiding_rate(truth.rate_hz, fix_rate_hz, "aiding.rate_hz")
    gyro_seed, accel_seed, init_seed, fix_seed = np.random.SeedSequence(seed).spawn(4)
    gyro_record = gyro.measure(truth.dtheta / truth.dt, gyro_seed)
    accel_record = accel.measure(truth.dv / truth.dt, accel_seed)
    x0 = np.linalg.cholesky(P0[:9, :9]) @ np.random.default_rng(init_seed).standard_normal(9)
    q0 = rot.multiply(rot.from_rotation_vector(-x0[0:3]), truth.q_nb[0])
    noise = ImuNoise(arw=gyro.arw, vrw=accel.vrw, gyro_bias_rw=gyro.filter_rrw, accel_bias_rw=accel.filter_bias_rw)
    nav_filter = NavFilter(truth.lat[0] + x0[6], truth.lon[0] + x0[7], truth.h[0] + x0[8], truth.v_n[0] + x0[3:6],
                           q0, P0, noise, truth.dt, covariance_interval=covariance_interval)
    fix_sigma = np.broadcast_to(np.asarray(fix_sigma, dtype=float), (3,))
    fix_rng = np.random.default_rng(fix_seed)
    epochs = np.arange(ratio, truth.dtheta.shape[0] + 1, ratio)
    states, P_log, nis, accepted = [], [], [], []
    for k0, k1 in zip(np.concatenate([[0], epochs[:-1]]), epochs):
        nav_filter.predict(gyro_record.omega[k0:k1] * truth.dt, accel_record.force[k0:k1] * truth.dt)
        result = nav_filter.update_position(*_noisy_fix(truth, k1, fix_sigma, fix_rng))
        snapshot = nav_filter.snapshot()
        states.append(np.concatenate([[snapshot["lat"], snapshot["lon"], snapshot["h"]], snapshot["v_n"],
                                      snapshot["q_nb"], snapshot["gyro_bias"], snapshot["accel_bias"]]))
        P_log.append(snapshot["P"])
        nis.append(result.nis[0])
        accepted.append(result.accepted[0])
    s, P_log = np.array(states), np.array(P_log)
    error = error_state(s[:, 0], s[:, 1], s[:, 2], s[:, 3:6], s[:, 6:10], s[:, 10:13], s[:, 13:16],
                        truth.lat[epochs], truth.lon[epochs], truth.h[epochs], truth.v_n[epochs], truth.q_nb[epochs],
                        gyro_record.bias[epochs - 1], accel_record.bias[epochs - 1])
    return AidedRun(t=truth.t[epochs], error=error, sigma=np.sqrt(np.diagonal(P_log, axis1=1, axis2=2)),
                    nees=nees(P_log, error), nis=np.array(nis), accepted=np.array(accepted))


def _noisy_fix(truth, k, sigma, rng):
    """(L, λ, h, σ) of a position fix at sample k: the truth plus NED noise of σ [m]."""
    r_m, r_n = radii(truth.lat[k])
    noise = sigma * rng.standard_normal(3)
    return (truth.lat[k] + noise[0] / (r_m + truth.h[k]),
            truth.lon[k] + noise[1] / ((r_n + truth.h[k]) * np.cos(truth.lat[k])), truth.h[k] - noise[2], sigma)
