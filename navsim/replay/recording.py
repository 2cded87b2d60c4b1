"""A recorded IMU: a CSV log of rates or increments with its own time tags, read into SI on a uniform grid.

A row holds the three accelerometer and three gyro channels and a time column, named by a column map
(``columns``: one name of :data:`CHANNELS` per CSV column, ``"-"`` for a column to skip). ``quantity`` says whether
the channels are rates (specific force [unit], angular rate [unit]) or increments over the row's interval (Δv, Δθ);
the units are named (:data:`ACCEL_UNITS`, :data:`GYRO_UNITS`, :data:`TIME_UNITS`). The time column is a counter;
with an RTKLIB time-tag file (``.tag``: the GPST of the first row and the counter's last tick,
:func:`read_time_tag`) the counter is scaled so that its span is the tag's, as RTKLIB's logger stamps it (the
IMU's oscillator drifts from GPS time), and ``time_offset_s`` is added (a logging delay).

The filter mechanizes one fixed interval dt, the mean of the rows' intervals. A gap — an interval longer than
:data:`GAP_FACTOR` dt — is reported and crossed honestly: its missing intervals are filled with the last sample
held (zero-order hold), so the mechanization and the covariance advance by the gap's real length, and the fill is
counted in the summary. Every row's channels must be finite, the time strictly increasing, and no channel
constant over the whole log (a dead sensor): each an :class:`InputError` naming the problem.
"""

import struct
from dataclasses import dataclass

import numpy as np

from navsim.replay import csv_table
from startrack import InputError, units

#: The channel names of a column map: accelerometer x, y, z, gyro x, y, z and the time counter.
CHANNELS = ("accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z", "time")
#: Specific force (rates) or Δv (increments): unit -> factor to m/s² or m/s.
ACCEL_UNITS = {"g": units.STANDARD_GRAVITY, "m/s2": 1.0, "m/s": 1.0}
#: Angular rate or Δθ: unit -> factor to rad/s or rad.
GYRO_UNITS = {"deg/s": units.DEG, "rad/s": 1.0, "deg": units.DEG, "rad": 1.0}
#: Time column: unit -> factor to s.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6}
#: The units each quantity takes.
QUANTITY_UNITS = {"rates": (("g", "m/s2"), ("deg/s", "rad/s")), "increments": (("m/s",), ("deg", "rad"))}
#: An interval longer than this many nominal intervals is a gap.
GAP_FACTOR = 1.5
#: Size of the RTKLIB time-tag header: a 60-byte text, the tick frequency, the start time (uint32 s, float64 s).
_TAG_HEADER = 60


@dataclass(frozen=True)
class ImuRecording:
    """The log on a uniform grid: ``t0`` [s] (GPST, or the counter's own scale without a tag) of the first row, the
    interval ``dt`` [s], ``samples`` (M, 6) the interval means [rad/s | m/s²] as the filter takes them (gyro first,
    :meth:`navsim.estimation.nav_filter.NavFilter.predict`), ``filled`` (M,) whether a row fills a gap, and the gaps
    found ``gaps`` (G, 2): start [s] and length [s]."""

    t0: float
    dt: float
    samples: np.ndarray
    filled: np.ndarray
    gaps: np.ndarray

    @property
    def end(self):
        return self.t0 + self.dt * self.samples.shape[0]


def read_time_tag(path):
    """(start [s GPST since 1970], last tick [s]) of an RTKLIB time-tag file: after the 60-byte header a uint32 tick
    frequency, the start as uint32 seconds and float64 fraction, then (uint32 tick [ms], uint32 file position)
    pairs, the last of which is the log's last tick."""
    path = csv_table.existing(path, "time-tag file")
    raw = path.read_bytes()
    body = len(raw) - _TAG_HEADER - 16
    if body < 8 or not raw.startswith(b"TIMETAG"):
        raise InputError(f"{path}: not an RTKLIB time-tag file (no TIMETAG header and ticks)")
    seconds, fraction = struct.unpack_from("<Id", raw, _TAG_HEADER + 4)
    last_tick = struct.unpack_from("<I", raw, _TAG_HEADER + 16 + 8 * (body // 8 - 1))[0]
    return seconds + fraction, last_tick * 1e-3


def read_imu(path, columns, quantity, accel_unit, gyro_unit, time_unit, time_tag=None, time_offset=0.0):
    """The :class:`ImuRecording` of a CSV log (module docstring); ``time_tag`` an RTKLIB ``.tag`` path or None,
    ``time_offset`` [s] added to every time."""
    accel_units, gyro_units = QUANTITY_UNITS[quantity]
    for name, unit, allowed in (("accel_unit", accel_unit, accel_units), ("gyro_unit", gyro_unit, gyro_units),
                                ("time_unit", time_unit, tuple(TIME_UNITS))):
        if unit not in allowed:
            raise InputError(f"{name}: unknown unit {unit!r} for {quantity} (known: {', '.join(allowed)})")
    path, table = csv_table.read_table(path, columns, "IMU log", "replay.imu.columns")
    csv_table.check_rows(path, table)
    pick = csv_table.named(table, columns)
    counter = pick["time"] * TIME_UNITS[time_unit]
    steps = np.diff(counter)
    if not (steps > 0.0).all():
        row = int(np.flatnonzero(steps <= 0.0)[0]) + 2
        raise InputError(f"{path}: time not increasing at row {row} ({counter[row - 2]!r} then {counter[row - 1]!r} s)")
    gyro = np.stack([pick[f"gyro_{a}"] for a in "xyz"], axis=1) * GYRO_UNITS[gyro_unit]
    accel = np.stack([pick[f"accel_{a}"] for a in "xyz"], axis=1) * ACCEL_UNITS[accel_unit]
    channels = np.concatenate([gyro, accel], axis=1)
    dead = [CHANNELS[(i + 3) % 6] for i in range(6) if np.ptp(channels[:, i]) == 0.0]
    if dead:
        raise InputError(f"{path}: column {dead[0]} is constant over the whole log (a dead channel)")
    if time_tag is not None:
        start, last_tick = read_time_tag(time_tag)
        counter = start + (counter - counter[0]) * (last_tick / (counter[-1] - counter[0]))
    counter = counter + time_offset
    if quantity == "increments":
        channels[1:] /= np.diff(counter)[:, None]  # Δθ, Δv over each row's interval: its mean rate
    return uniform(counter[0], counter[1:], channels[1:], hold=quantity == "rates")


def uniform(t0, times, samples, hold=True):
    """The :class:`ImuRecording` of interval means ``samples`` (M, 6) ending at ``times`` (M,) [s] after ``t0``: dt the
    mean interval, a gap of n intervals given n rows -- the sample before it held over the first n - 1 when the samples
    are rates (``hold``), the gap's own mean over all n when they are increments (exact)."""
    intervals = np.diff(np.concatenate([[t0], times]))
    nominal = float(np.median(intervals))
    gap = intervals > GAP_FACTOR * nominal
    span = np.where(gap, np.rint(intervals / nominal).astype(int), 1)
    index = np.repeat(np.arange(samples.shape[0]), span)
    filled = np.ones(index.size, dtype=bool)
    filled[np.cumsum(span) - 1] = False
    held = np.where(filled & hold, np.maximum(index - 1, 0), index)
    return ImuRecording(t0=float(t0), dt=float((times[-1] - t0) / span.sum()), samples=samples[held], filled=filled,
                        gaps=np.stack([(times - intervals)[gap], intervals[gap]], axis=1))
