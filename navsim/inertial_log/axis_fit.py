"""Each axis of a log through the Allan deviation, its confidence interval and the noise fit."""

import sys
from dataclasses import dataclass

import numpy as np

from navsim.inertial_log import allan
from navsim.inertial_log.noise_fit import NoiseFit, fit_noise
from startrack import InputError

#: The confidence of the Allan deviation's interval (two-sided).
CONFIDENCE = 0.95
#: Logs of at least this many samples report their progress on standard error.
LONG_LOG = 1_000_000


@dataclass(frozen=True)
class AxisFit:
    """One axis: its cluster times ``tau`` [s], Allan deviation ``adev`` and its ``CONFIDENCE`` interval ``low``,
    ``high`` [unit], and the :class:`~navsim.inertial_log.noise_fit.NoiseFit` (whose EDF gives the interval)."""

    tau: np.ndarray
    adev: np.ndarray
    low: np.ndarray
    high: np.ndarray
    fit: NoiseFit


def fit_axes(log, progress=None):
    """{axis name: :class:`AxisFit`} of an :class:`~navsim.inertial_log.reading.ImuLog`; ``progress`` (None: on
    standard error for a log of ``LONG_LOG`` samples or more, False: silent) is called with a line per axis."""
    sizes = allan.cluster_sizes(log.samples)
    if sizes.size < allan.MIN_CLUSTER_TIMES:
        least = allan.MIN_CLUSTERS * 2 ** (allan.MIN_CLUSTER_TIMES - 1)
        raise InputError(f"the log's {log.samples} samples are too short for the Allan fit: it takes at least {least} "
                         f"({allan.MIN_CLUSTER_TIMES} cluster times of {allan.MIN_CLUSTERS} clusters or more)")
    if progress is None:
        progress = _stderr if log.samples >= LONG_LOG else False
    tau = sizes / log.rate_hz
    out = {}
    for k, (name, rates) in enumerate(log.axes.items()):
        if progress:
            progress(f"allan fit: axis {name} ({k + 1} of {len(log.axes)}, {log.samples} samples)")
        avar = allan.overlapping_avar(rates, log.rate_hz, sizes)
        if np.any(avar <= 0.0):
            raise InputError(f"axis {name}: the Allan variance is 0 at τ = {tau[np.argmax(avar <= 0.0)]:g} s "
                             "(a channel that repeats itself)")
        fit = fit_noise(tau, avar, log.samples, sizes, log.rate_hz)
        low, high = allan.chi_square_interval(avar, fit.dof, CONFIDENCE)
        out[name] = AxisFit(tau, np.sqrt(avar), np.sqrt(low), np.sqrt(high), fit)
    return out


def _stderr(line):
    print(line, file=sys.stderr, flush=True)
