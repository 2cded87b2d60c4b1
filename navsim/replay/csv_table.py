"""The numeric CSV files of a replay (the IMU log, a CSV GNSS solution, a reference attitude): comma-separated, ``#``
comments, one name per column by a column map (``"-"`` for a column to skip), read and checked here once; every
problem an :class:`InputError` naming the file or the map's key."""

from pathlib import Path

import numpy as np

from startrack import InputError


def existing(path, what):
    """``path`` as a :class:`Path`, an InputError naming ``what`` (e.g. "IMU log") when it is not a file."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: {what} not found")
    return path


def read_table(path, columns, what, key, known=None, required=()):
    """(path, table (N, len(columns))) of the CSV ``path`` of column map ``columns`` (the map's name ``key``); its
    names must be of ``known`` (None: checked elsewhere) and include ``required``."""
    path = existing(path, what)
    unknown = [c for c in columns if known is not None and c != "-" and c not in known]
    if unknown:
        raise InputError(f"{key}: unknown column {unknown[0]!r} (known: {', '.join(known)}, '-')")
    missing = [c for c in required if c not in columns]
    if missing:
        raise InputError(f"{key}: needs a {missing[0]!r} column")
    try:
        table = np.loadtxt(path, delimiter=",", ndmin=2, comments="#")
    except ValueError as error:
        raise InputError(f"{path}: not a numeric CSV ({str(error).splitlines()[0]})") from None
    if table.shape[1] != len(columns):
        raise InputError(f"{path}: {table.shape[1]} columns, {key} names {len(columns)}")
    return path, table


def named(table, columns):
    """{name: column (N,)} of the map's named columns."""
    return {c: table[:, i] for i, c in enumerate(columns) if c != "-"}


def check_rows(path, values):
    """An InputError for fewer than two rows or a row of ``values`` (N, k) not finite."""
    if values.shape[0] < 2:
        raise InputError(f"{path}: fewer than two rows")
    bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
    if bad.size:
        raise InputError(f"{path}: row {bad[0] + 1} is not finite (NaN or inf; {bad.size} such rows)")
