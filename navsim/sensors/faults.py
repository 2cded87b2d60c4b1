"""Faults a scenario can switch on (``[faults]``, built in SI units by :mod:`navsim.build.faults`).

Gyro bias steps change the true bias (and so the gyro output) from their time on
(:func:`apply_bias_steps`); outages, dropped frames and false-star storms act on the star sensor
(:class:`SensorFaults`); attitude jumps knock the filter's estimate off (:class:`AttitudeJumps`).
"""

from dataclasses import dataclass, field

import numpy as np


def apply_bias_steps(omega, bias, t_samples, steps):
    """Gyro output and true bias with each of the bias ``steps`` ((time [s], step (3,) [rad/s]), ...)
    added from its time on.

    ``t_samples`` (M,) are the sample times [s] (end of each gyro interval)."""
    if not steps:
        return omega, bias
    omega, bias = omega.copy(), bias.copy()
    for time_s, delta in steps:
        after = t_samples > time_s
        omega[after] += delta
        bias[after] += delta
    return omega, bias


@dataclass(frozen=True)
class SensorFaults:
    """Outages (start, end [s], reason), dropped frame times [s] and false-star storms (start, end
    [s], tracks per frame) of ``scenario['faults']``; ``frame_interval`` [s]; the frames the sky
    excludes (``excluded_s`` (E,) [s], sorted, and their ``excluded_reasons``: the Sun, the Moon or the
    horizon too near the boresight, :mod:`navsim.navigation.exclusion`)."""

    outages: tuple
    dropped_s: np.ndarray
    storms: tuple
    frame_interval: float
    excluded_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    excluded_reasons: tuple = ()

    def status(self, t):
        """(mode, reason) when the frame at t [s] is lost to an outage, dropped or excluded, else None."""
        for start, end, reason in self.outages:
            if start <= t < end:
                return "outage", reason
        if self.dropped_s.size and np.any(np.abs(self.dropped_s - t) < 0.5 * self.frame_interval):
            return "dropped", "frame dropped"
        j = self._excluded_index(np.array([t]))[0]
        return None if j < 0 else ("excluded", self.excluded_reasons[j])

    def available(self, t_frames):
        """False for the frames (times t_frames [s]) that :meth:`status` takes away."""
        t_frames = np.asarray(t_frames, dtype=float)
        available = np.ones(t_frames.shape, dtype=bool)
        for start, end, _ in self.outages:
            available &= ~((t_frames >= start) & (t_frames < end))
        for t in self.dropped_s:
            available &= np.abs(t_frames - t) >= 0.5 * self.frame_interval
        return available & (self._excluded_index(t_frames) < 0)

    def _excluded_index(self, t_frames):
        """The index in ``excluded_s`` of each frame time's exclusion, −1 where it has none."""
        half = 0.5 * self.frame_interval
        if not self.excluded_s.size:
            return np.full(t_frames.shape, -1)
        j = np.minimum(np.searchsorted(self.excluded_s, t_frames - half), self.excluded_s.size - 1)
        return np.where(np.abs(self.excluded_s[j] - t_frames) < half, j, -1)

    def storm_count(self, t):
        """False-star tracks per frame at t [s] (0 outside a storm)."""
        return next((count for start, end, count in self.storms if start <= t < end), 0)


class AttitudeJumps:
    """The attitude-jump fault of one run: at each time of ``jumps`` ((time [s], angle [rad]), ... in time
    order) the
    filter's estimate is knocked off by its angle about a random axis drawn from ``rng`` (a tracking
    loss the sensor must recover)."""

    def __init__(self, jumps, rng):
        self._pending = list(jumps)
        self._rng = rng

    def due(self, t):
        """Rotation vectors [rad] of the jumps at or before t [s] not yet applied, in time order."""
        out = []
        while self._pending and self._pending[0][0] <= t:
            _, angle = self._pending.pop(0)
            axis = self._rng.standard_normal(3)
            axis /= np.linalg.norm(axis)
            out.append(angle * axis)
        return out
