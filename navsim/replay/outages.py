"""Simulated GNSS outages of a replay: windows in which the recording's fixes are held out of the filter and kept as
the reference its error is measured against.

Given as a list of [start, duration] [s after the replay's start], or as a schedule: outages of the given lengths,
the first at ``first_s``, each after ``spacing_s`` of aiding that follows the one before. Each must lie inside the
replay and after its alignment, and none may overlap another: else an :class:`InputError`.
"""

import numpy as np

from startrack import InputError


def scheduled(first, lengths, spacing):
    """[start, duration] (K, 2) [s] of outages of ``lengths`` [s], the first at ``first`` [s], ``spacing`` [s] of aiding
    between the end of one and the start of the next."""
    lengths = np.asarray(lengths, dtype=float)
    starts = first + np.concatenate([[0.0], np.cumsum(lengths[:-1] + spacing)])
    return np.stack([starts, lengths], axis=1)


def checked(windows, aligned, duration):
    """``windows`` (K, 2) [s] checked against a replay of ``duration`` [s] aligned at ``aligned`` [s] and sorted."""
    windows = np.asarray(windows, dtype=float).reshape(-1, 2)
    windows = windows[np.argsort(windows[:, 0])]
    for start, length in windows:
        if not length > 0.0:
            raise InputError(f"outages: an outage of {length:g} s; a duration must be > 0")
        if start < aligned or start + length > duration:
            raise InputError(f"outages: the outage [{start:g}, {length:g}] s is outside the recording after its "
                             f"alignment ({aligned:.1f} to {duration:.1f} s)")
    overlap = np.flatnonzero(windows[1:, 0] < windows[:-1].sum(axis=1))
    if overlap.size:
        raise InputError(f"outages: the outages starting at {windows[overlap[0], 0]:g} s and "
                         f"{windows[overlap[0] + 1, 0]:g} s overlap")
    return windows


def held_out(t, windows):
    """(N,) the index of the outage each time ``t`` [s] falls in, −1 where none."""
    inside = (t[:, None] >= windows[:, 0]) & (t[:, None] < windows.sum(axis=1))
    return np.where(inside.any(axis=1), inside.argmax(axis=1), -1)
