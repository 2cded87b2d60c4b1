"""The navigation filter's aiding sensors as the closed loop sees them: position fixes and a baro.

Both are open-loop (their errors do not depend on the filter), so a run draws every measurement when
it starts (:func:`draw_record`) into an :class:`AidingRecord` on the frame grid; the loop reads it
frame by frame (:class:`AidingRun`, :class:`AidingFrame`), or the navigation filter takes the whole
record at once on its compiled fast path. A frame without a measurement of a kind holds NaN there.

- Position fix (GNSS-like): the true (L, λ, h) plus white NED noise n of σ (σ_N, σ_E, σ_D) [m]: the point n_N, n_E
  from the truth along its NED axes (:func:`navsim.earth.wander.displaced`: L̃ = L + n_N/(R_M + h),
  λ̃ = λ + n_E/((R_N + h) cos L) to first order, and regular at the poles), h̃ = h − n_D.
- Baro: :class:`navsim.sensors.baro.BaroModel` sampled at its rate (bias, random walk, noise, lag).
"""

from dataclasses import dataclass, field

import numpy as np

from navsim.earth.wander import displaced
from navsim.sensors.recorded_run import RecordedRun


@dataclass(frozen=True)
class PositionFixSensor:
    """Position fixes every ``every`` frames with NED σ ``sigma_ned`` (3,) [m]."""

    every: int
    sigma_ned: np.ndarray

    def measure(self, lat, lon, h, rng):
        """Fixes (K, 3) [rad, rad, m] of the true positions (K,) each: the truth plus NED noise."""
        noise = self.sigma_ned * rng.standard_normal((np.size(lat), 3))
        return np.stack([*displaced(lat, lon, h, noise[:, 0], noise[:, 1]), h - noise[:, 2]], axis=-1)


@dataclass(frozen=True)
class AidingRecord:
    """Every frame's aiding measurements: ``position`` (F, 3) [rad, rad, m] with NED σ
    ``position_sigma`` (3,) [m], and ``baro`` (F,) heights [m] with σ ``baro_sigma`` [m]; NaN rows
    where a frame has none."""

    position: np.ndarray
    position_sigma: np.ndarray
    baro: np.ndarray
    baro_sigma: float


def draw_record(truth, frame_k, position_sensor, baro_model, baro_every, position_ss, baro_ss):
    """The :class:`AidingRecord` of a run: fixes of ``position_sensor`` (or None) and heights of
    ``baro_model`` every ``baro_every`` frames (or None), for the truth (a
    :class:`~navsim.truth.trajectory.Trajectory`) at the frames' IMU samples ``frame_k`` (F,),
    drawn from the seed sequences ``position_ss`` and ``baro_ss``."""
    n = frame_k.size
    position, sigma = np.full((n, 3), np.nan), np.zeros(3)
    if position_sensor is not None:
        k = frame_k[position_sensor.every - 1 :: position_sensor.every]
        rows = slice(position_sensor.every - 1, None, position_sensor.every)
        position[rows] = position_sensor.measure(truth.lat[k], truth.lon[k], truth.h[k], np.random.default_rng(position_ss))
        sigma = np.asarray(position_sensor.sigma_ned, dtype=float)
    baro, baro_sigma = np.full(n, np.nan), 0.0
    if baro_model is not None:
        k = frame_k[baro_every - 1 :: baro_every]
        baro[baro_every - 1 :: baro_every] = baro_model.measure(truth.h[k], baro_ss).h
        baro_sigma = float(np.hypot(baro_model.noise_sigma, baro_model.bias_sigma))
    return AidingRecord(position=position, position_sigma=sigma, baro=baro, baro_sigma=baro_sigma)


@dataclass(frozen=True)
class AidingFrame:
    """One frame's aiding measurements, ((kind, arguments of the filter's update), ...)."""

    measurements: tuple
    info: dict = field(default_factory=dict)


class AidingRun(RecordedRun):
    """The per-run aiding sensors: they read their :class:`AidingRecord` frame by frame."""

    def observe(self, request):
        r, j = self._record, request.index
        measurements = []
        if not np.isnan(r.position[j, 0]):
            measurements.append(("position", (*r.position[j], r.position_sigma)))
        if not np.isnan(r.baro[j]):
            measurements.append(("baro", (r.baro[j], r.baro_sigma)))
        return AidingFrame(measurements=tuple(measurements))
