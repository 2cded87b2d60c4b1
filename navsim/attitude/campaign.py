"""The campaign statistics of attitude runs: the errors pooled over every steady frame of every run, the
spread of the runs' RMS errors, the run-averaged NEES, the divergent runs, the gyro calibration states
and, at image fidelity, the frames per identification mode."""

import numpy as np

from navsim.pooling import averaged_nees, calibration, diverged, spread
from startrack import units


def pool(finished, settle):
    """The attitude fields of a :class:`~navsim.attitude.records.CampaignSummary` from the finished runs
    [(index, summary, series), ...] and the settling time [s]."""
    errors, sigmas, divergent = [], [], []
    for k, summary, series in finished:
        steady = series["t"] >= settle
        errors.append(series["attitude_error"][steady])
        sigmas.append(np.sqrt(series["P_diag"][steady, :3]))
        if diverged(summary):
            divergent.append(k)
    stacked, sigma = np.concatenate(errors), np.concatenate(sigmas)
    arcsec = units.rad_to_arcsec
    summaries = [summary for _, summary, _ in finished]
    return {
        "attitude_error_rms_arcsec": {axis: float(arcsec(np.sqrt(np.mean(stacked[:, i] ** 2)))) for i, axis in enumerate("xyz")},
        "attitude_error_percentiles_arcsec": {
            axis: {f"p{p}": float(arcsec(np.percentile(np.abs(stacked[:, i]), p))) for p in (50, 95, 99)}
            for i, axis in enumerate("xyz")},
        "filter_sigma_mean_arcsec": {axis: float(arcsec(np.mean(sigma[:, i]))) for i, axis in enumerate("xyz")},
        "cross_boresight_rms_arcsec": spread([s["cross_boresight_rms_arcsec"] for s in summaries]),
        "roll_rms_arcsec": spread([s["roll_rms_arcsec"] for s in summaries]),
        "nees": averaged_nees(finished, settle),
        "divergent_runs": divergent,
        "gyro_calibration": calibration([s.gyro_calibration for s in summaries]),
        "identification": _identification(summaries),
    }


def _identification(summaries):
    """Frames per identification mode over the runs and the fraction of frames with a fix (image fidelity)."""
    per_mode = {}
    for summary in summaries:
        for mode, stats in (summary.identification or {}).get("per_mode", {}).items():
            per_mode[mode] = per_mode.get(mode, 0) + stats["frames"]
    if not per_mode:
        return None
    frames = sum(per_mode.values())
    lost = sum(per_mode.get(mode, 0) for mode in ("no_fix", "outage", "dropped", "excluded"))
    return {"frames_per_mode": per_mode, "fix_fraction": 1.0 - lost / frames}
