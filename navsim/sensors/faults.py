"""Faults a scenario can switch on (``[faults]``), built once in SI units.

Gyro bias steps change the true bias (and so the gyro output) from their time on
(:func:`apply_bias_steps`); outages, dropped frames and false-star storms act on the star sensor
(:class:`SensorFaults`); attitude jumps knock the filter's estimate off (:class:`AttitudeJumps`).
"""

from dataclasses import dataclass

import numpy as np

from startrack import units


def bias_steps(faults):
    """The gyro bias steps of ``scenario['faults']`` in SI: ((time [s], step (3,) [rad/s]), ...)."""
    return tuple((s["time_s"], units.deg_per_h_to_rad_per_s(s["step_deg_per_h"])) for s in faults["gyro_bias_steps"])


def apply_bias_steps(omega, bias, t_samples, steps):
    """Gyro output and true bias with each of :func:`bias_steps` added from its time on.

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
    [s], tracks per frame) of ``scenario['faults']``; ``frame_interval`` [s]."""

    outages: tuple
    dropped_s: np.ndarray
    storms: tuple
    frame_interval: float

    @classmethod
    def from_scenario(cls, faults, frame_interval):
        return cls(outages=tuple((o["start_s"], o["end_s"], o["reason"]) for o in faults["outages"]),
                   dropped_s=np.asarray(faults["dropped_frames_s"], dtype=float),
                   storms=tuple((s["start_s"], s["end_s"], s["count"]) for s in faults["false_star_storms"]),
                   frame_interval=frame_interval)

    def status(self, t):
        """(mode, reason) when the frame at t [s] is lost to an outage or dropped, else None."""
        for start, end, reason in self.outages:
            if start <= t < end:
                return "outage", reason
        if self.dropped_s.size and np.any(np.abs(self.dropped_s - t) < 0.5 * self.frame_interval):
            return "dropped", "frame dropped"
        return None

    def available(self, t_frames):
        """False for the frames (times t_frames [s]) that :meth:`status` takes away."""
        t_frames = np.asarray(t_frames, dtype=float)
        available = np.ones(t_frames.shape, dtype=bool)
        for start, end, _ in self.outages:
            available &= ~((t_frames >= start) & (t_frames < end))
        for t in self.dropped_s:
            available &= np.abs(t_frames - t) >= 0.5 * self.frame_interval
        return available

    def storm_count(self, t):
        """False-star tracks per frame at t [s] (0 outside a storm)."""
        return next((count for start, end, count in self.storms if start <= t < end), 0)


def attitude_jumps(faults):
    """The attitude jumps of ``scenario['faults']`` in time order: ((time [s], angle [rad]), ...)."""
    ordered = sorted(faults["attitude_jumps"], key=lambda j: j["time_s"])
    return tuple((j["time_s"], float(units.deg_to_rad(j["angle_deg"]))) for j in ordered)


class AttitudeJumps:
    """The attitude-jump fault of one run: at each time of ``jumps`` (:func:`attitude_jumps`) the
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
