"""The numbers an attitude report quotes and draws beside those every kind shares
(:mod:`navsim.typeset.statistics`): the attitude error envelopes across a campaign and the per-run
metrics tabulated over it. Units at this edge: arcsec."""

import numpy as np

from navsim.typeset.statistics import common_frames, envelopes_of
from startrack import units

#: Error of the attitude states is rows 0:3 of the filter state.
ATTITUDE = slice(0, 3)


def envelopes(campaign):
    """:class:`~navsim.typeset.statistics.Envelopes` of the attitude error [arcsec] with the filter's ±3σ (when P_diag was logged)."""
    t = common_frames(campaign)
    n = t.size
    err = units.rad_to_arcsec(np.stack([r.series["attitude_error"][:n] for r in campaign.runs]))
    sigma = None
    if all("P_diag" in r.series for r in campaign.runs):
        var = np.mean(np.stack([r.series["P_diag"][:n, ATTITUDE] for r in campaign.runs]), axis=0)
        sigma = units.rad_to_arcsec(np.sqrt(var))
    return envelopes_of(t, err, sigma)


#: Per-run metrics tabulated across a campaign: (label, unit, path in summary.json).
RUN_METRICS = (
    ("cross-boresight RMS", "arcsec", ("cross_boresight_rms_arcsec",)),
    ("roll RMS", "arcsec", ("roll_rms_arcsec",)),
    ("x RMS", "arcsec", ("attitude_error_rms_arcsec", "x")),
    ("y RMS", "arcsec", ("attitude_error_rms_arcsec", "y")),
    ("z RMS", "arcsec", ("attitude_error_rms_arcsec", "z")),
    ("NEES mean", "", ("nees", "mean")),
    ("NEES in 95 % band", "%", ("nees", "fraction_in_band")),
    ("NIS mean per dof", "", ("nis", "mean_per_dof")),
    ("wall time", "s", ("timing", "wall_seconds")),
)
