"""The numbers a navigation campaign report quotes and draws, from the runs' series and summaries:
horizontal error percentiles over time (CEP50, CEP95), position error envelopes with the filter's
mean 3σ, and the per-run metrics tabulated across the campaign. Units: metres, m/s, arcsec."""

from dataclasses import dataclass

import numpy as np

from navsim.estimation.intervals import quantile_interval
from navsim.navigation.summary import ned_metres
from navsim.typeset.statistics import common_frames, envelopes_of

#: Per-run metrics of navigation runs tabulated across a campaign: (label, unit, path in summary.json).
RUN_METRICS = (
    ("final horizontal error", "m", ("position_error_m", "horizontal", "final")),
    ("horizontal RMS", "m", ("position_error_m", "horizontal", "rms")),
    ("vertical RMS", "m", ("position_error_m", "vertical", "rms")),
    ("horizontal velocity RMS", "m/s", ("velocity_error_m_per_s", "horizontal", "rms")),
    ("tilt RMS", "arcsec", ("tilt_error_arcsec", "rms")),
    ("heading RMS", "arcsec", ("heading_error_arcsec", "rms")),
    ("NEES mean", "", ("nees", "mean")),
    ("NEES in 95 % band", "%", ("nees", "fraction_in_band")),
    ("NIS mean per dof", "", ("nis", "mean_per_dof")),
    ("wall time", "s", ("timing", "wall_seconds")),
)


@dataclass(frozen=True)
class HorizontalPercentiles:
    """Horizontal position error across M runs at each frame [m]: median (CEP50), 95th percentile
    (CEP95), each with its distribution-free 95 % interval ((2, F): lo, hi; hi inf where M runs are too few:
    :func:`navsim.estimation.intervals.quantile_interval`), RMS, and the filter's horizontal σ from the covariance
    averaged over the runs."""

    t: np.ndarray
    runs: int
    cep50: np.ndarray
    cep95: np.ndarray
    cep50_interval: np.ndarray
    cep95_interval: np.ndarray
    rms: np.ndarray
    sigma: np.ndarray


def _position_sigma(run, n):
    s = run.series
    return np.abs(ned_metres(s["error_sigma"][:n, 6:9]))


def horizontal_percentiles(campaign):
    t = common_frames(campaign)
    n = t.size
    errors = np.stack([r.series["position_error_m"][:n] for r in campaign.runs])
    radial = np.hypot(errors[..., 0], errors[..., 1])
    variance = np.mean(np.stack([_position_sigma(r, n)[:, :2] ** 2 for r in campaign.runs]), axis=0)
    p50, p95 = np.percentile(radial, [50, 95], axis=0)
    return HorizontalPercentiles(t=t, runs=radial.shape[0], cep50=p50, cep95=p95,
                                 cep50_interval=np.array(quantile_interval(radial, 0.5, lowest=0.0)),
                                 cep95_interval=np.array(quantile_interval(radial, 0.95, lowest=0.0)),
                                 rms=np.sqrt(np.mean(radial**2, axis=0)), sigma=np.sqrt(variance.sum(axis=1)))


def position_envelopes(campaign):
    """:class:`~navsim.typeset.statistics.Envelopes` of the NED position error [m] with the filter's ±3σ."""
    t = common_frames(campaign)
    n = t.size
    err = np.stack([r.series["position_error_m"][:n] for r in campaign.runs])
    sigma = np.sqrt(np.mean(np.stack([_position_sigma(r, n) ** 2 for r in campaign.runs]), axis=0))
    return envelopes_of(t, err, sigma)
