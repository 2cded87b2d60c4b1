"""A static IMU log read into SI rates, with its column map checked.

A log is a table of samples, one row each: CSV/TXT (comma, semicolon, tab or blank separated; header and ``#``
lines before the numbers skipped), NumPy ``.npy`` (a 2-D array), ``.npz`` or MATLAB ``.mat`` (a 2-D array named by
``variable``, or the only one). The column map names each column in order: ``t`` (time), ``gx gy gz`` (gyro),
``ax ay az`` (accelerometer), ``skip`` (a column not used). Units: gyro ``rad/s``, ``deg/s``, ``deg/h`` (rates) or
``rad``, ``deg`` (angle increments per sample); accelerometer ``m/s^2``, ``g``, ``mg`` (specific force) or ``m/s``
(velocity increments per sample); time ``s``, ``ms``, ``us``, ``ns``. The sample rate comes from the time column
or from ``rate_hz``.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from startrack import InputError, units

#: The names a column map may use, and the axes of each sensor.
AXES = {"gyro": ("gx", "gy", "gz"), "accelerometer": ("ax", "ay", "az")}
TIME, SKIP = "t", "skip"
#: Each unit as (factor to SI, whether it is an increment per sample).
GYRO_UNITS = {"rad/s": (1.0, False), "deg/s": (units.DEG, False), "deg/h": (units.DEG / units.HOUR, False),
              "rad": (1.0, True), "deg": (units.DEG, True)}
ACCELEROMETER_UNITS = {"m/s^2": (1.0, False), "g": (units.STANDARD_GRAVITY, False),
                       "mg": (1e-3 * units.STANDARD_GRAVITY, False), "m/s": (1.0, True)}
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
SUFFIXES = (".csv", ".txt", ".dat", ".npy", ".npz", ".mat")
#: The largest relative spread of the sample intervals of a log with a time column.
MAX_JITTER = 0.01


@dataclass(frozen=True)
class ImuLog:
    """A log in SI: ``rate_hz`` and ``axes`` {name (gx ... az): interval-mean rates (N,) [rad/s or m/s²]}."""

    rate_hz: float
    axes: dict

    @property
    def samples(self):
        return next(iter(self.axes.values())).size


def parse_columns(text):
    """The column map of ``text`` ("t,gx,gy,gz,ax,ay,az"): a tuple of names, each checked."""
    names = tuple(name.strip() for name in text.split(","))
    known = {TIME, SKIP, *AXES["gyro"], *AXES["accelerometer"]}
    for name in names:
        if name not in known:
            raise InputError(f"--columns: unknown column {name!r}; use t, gx, gy, gz, ax, ay, az or skip (not used)")
    repeated = sorted({n for n in names if n != SKIP and names.count(n) > 1})
    if repeated:
        raise InputError(f"--columns: {', '.join(repeated)} named more than once")
    if not set(names) & set(AXES["gyro"] + AXES["accelerometer"]):
        raise InputError("--columns: names no gyro or accelerometer axis (gx ... az)")
    return names


def parse_units(text):
    """{"gyro", "accelerometer", "time": unit} of ``text`` ("gyro=deg/s,accel=g,time=ms"), the others at their
    defaults (rad/s, m/s^2, s)."""
    chosen = {"gyro": "rad/s", "accelerometer": "m/s^2", "time": "s"}
    tables = {"gyro": GYRO_UNITS, "accelerometer": ACCELEROMETER_UNITS, "time": TIME_UNITS}
    for item in filter(None, (part.strip() for part in (text or "").split(","))):
        sensor, _, unit = item.partition("=")
        sensor = {"accel": "accelerometer"}.get(sensor.strip(), sensor.strip())
        if sensor not in tables:
            raise InputError(f"--units {item!r}: name gyro=, accel= or time=")
        if unit.strip() not in tables[sensor]:
            raise InputError(f"--units {item!r}: unknown {sensor} unit; use one of {', '.join(tables[sensor])}")
        chosen[sensor] = unit.strip()
    return chosen


def read_log(path, columns, unit_names, rate_hz=None, variable=None):
    """The :class:`ImuLog` of the file ``path`` with the column map ``columns`` (:func:`parse_columns`), the units
    ``unit_names`` (:func:`parse_units`), the sample rate ``rate_hz`` [Hz] (None: from the time column) and the
    array ``variable`` of an .npz or .mat file."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    if path.suffix.lower() not in SUFFIXES:
        raise InputError(f"{path}: not a log this reads; give a {', '.join(SUFFIXES)} file")
    table = _table(path, variable)
    if table.shape[1] != len(columns):
        raise InputError(f"{path}: {table.shape[1]} columns, but --columns names {len(columns)}")
    bad = ~np.all(np.isfinite(table), axis=1)
    if bad.any():
        raise InputError(f"{path}: {bad.sum()} rows hold NaN or infinite values (the first is row {np.argmax(bad) + 1})")
    rate_hz = _rate(path, table, columns, unit_names["time"], rate_hz)
    axes = {}
    for sensor, names in AXES.items():
        factor, increments = (GYRO_UNITS if sensor == "gyro" else ACCELEROMETER_UNITS)[unit_names[sensor]]
        for name in names:
            if name in columns:
                axes[name] = _axis(path, name, table[:, columns.index(name)], factor * (rate_hz if increments else 1.0))
    return ImuLog(rate_hz, axes)


def _table(path, variable):
    """The log's numbers (N, columns) as floats."""
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            table = np.load(path, allow_pickle=False)
        elif suffix == ".npz":
            with np.load(path, allow_pickle=False) as arrays:
                table = arrays[_variable(path, variable, arrays.files)]
        elif suffix == ".mat":
            table = _matlab(path, variable)
        else:
            table = _text(path)
    except InputError:  # already one line naming the problem (an InputError is a ValueError)
        raise
    except (ValueError, OSError, NotImplementedError) as error:  # NotImplementedError: a MATLAB v7.3 (HDF5) file
        raise InputError(f"{path}: cannot read the log ({str(error).splitlines()[0] if str(error) else type(error).__name__})") from None
    if table.ndim != 2 or not np.issubdtype(table.dtype, np.number):
        raise InputError(f"{path}: the log must be a 2-D numeric table (one row a sample), got shape {table.shape} "
                         f"of {table.dtype}")
    return np.asarray(table, dtype=float)


def _variable(path, variable, names):
    if variable is None:
        if len(names) != 1:
            raise InputError(f"{path}: holds {', '.join(names) or 'no arrays'}; name the log's with --variable")
        return names[0]
    if variable not in names:
        raise InputError(f"{path}: no array {variable!r} (it holds {', '.join(names)})")
    return variable


def _matlab(path, variable):
    from scipy import io

    names = [name for name, _, _ in io.whosmat(path)]
    return io.loadmat(path, variable_names=[_variable(path, variable, names)])[_variable(path, variable, names)]


def _text(path):
    """A CSV/TXT table: the lines before the first of numbers skipped, the separator of that line."""
    with open(path, encoding="utf-8", errors="replace") as handle:
        for skipped, line in enumerate(handle):
            fields = line.strip()
            if fields and not fields.startswith("#") and _numeric(fields):
                break
        else:
            raise InputError(f"{path}: holds no rows of numbers")
    delimiter = next((d for d in (",", ";", "\t") if d in fields), None)
    return np.atleast_2d(np.loadtxt(path, delimiter=delimiter, skiprows=skipped, comments="#", ndmin=2))


def _numeric(line):
    try:
        [float(x) for x in line.replace(",", " ").replace(";", " ").split()]
    except ValueError:
        return False
    return True


def _rate(path, table, columns, time_unit, rate_hz):
    """The sample rate [Hz]: from the time column (strictly increasing, even to ``MAX_JITTER``) or ``rate_hz``."""
    if rate_hz is not None and not (np.isfinite(rate_hz) and rate_hz > 0.0):
        raise InputError(f"--rate-hz {rate_hz}: must be a positive number")
    if TIME not in columns:
        if rate_hz is None:
            raise InputError(f"{path}: no time column (t) in --columns; give the sample rate with --rate-hz")
        return float(rate_hz)
    t = table[:, columns.index(TIME)] * TIME_UNITS[time_unit]
    step = np.diff(t)
    if step.size == 0:
        raise InputError(f"{path}: one sample is too short for any cluster")
    if np.any(step <= 0.0):
        raise InputError(f"{path}: the time is not increasing at row {np.argmax(step <= 0.0) + 2}")
    interval = (t[-1] - t[0]) / step.size
    if np.max(np.abs(step - interval)) > MAX_JITTER * interval:
        k = int(np.argmax(np.abs(step - interval)))
        raise InputError(f"{path}: uneven sampling: the interval at row {k + 2} is {step[k]:.6g} s, the mean "
                         f"{interval:.6g} s (a gap or a time in other units: see --units time=)")
    if rate_hz is not None and abs(rate_hz * interval - 1.0) > MAX_JITTER:
        raise InputError(f"--rate-hz {rate_hz}: the time column gives {1.0 / interval:.6g} Hz")
    return 1.0 / interval


def _axis(path, name, column, factor):
    if np.ptp(column) == 0.0:
        raise InputError(f"{path}: column {name} is constant ({column[0]:g}): a stuck or empty channel")
    return column * factor
