"""The campaign statistics of navigation runs (the INS): CEP50/95 of the final horizontal position
error, the vertical error, the spread of the runs' velocity, tilt and heading errors, the
run-averaged NEES over the filter's own error state, divergent runs and the IMU error states."""

import numpy as np

from navsim.pooling import averaged_nees, calibration, diverged, spread
from startrack import units


def pool(finished, settle):
    """The navigation fields of a :class:`~navsim.navigation.records.CampaignSummary` from the finished runs
    [(index, summary, series), ...]: CEP50/CEP95 are the median and 95th percentile over the runs
    of the final horizontal position error (its radial distance from the truth)."""
    summaries = [summary for _, summary, _ in finished]
    divergent = [k for k, summary, _ in finished if diverged(summary)]
    horizontal = np.array([s["position_error_m"]["horizontal"]["final"] for s in summaries])
    vertical = np.array([s["position_error_m"]["vertical"]["final"] for s in summaries])

    def per_run(*path):
        values = []
        for s in summaries:
            value = s[path[0]]
            for key in path[1:]:
                value = value[key]
            values.append(value)
        return spread(values)

    return {
        "position_error_m": {"horizontal": {**cep(horizontal), "rms": _rms(horizontal), "max": float(horizontal.max())},
                             "vertical": {"p50": float(np.percentile(vertical, 50)), "p95": float(np.percentile(vertical, 95)),
                                          "rms": _rms(vertical), "max": float(vertical.max())}},
        "position_error_nmi": {"horizontal": cep(horizontal / units.NAUTICAL_MILE)},
        "velocity_error_m_per_s": {"horizontal": per_run("velocity_error_m_per_s", "horizontal", "rms"),
                                   "vertical": per_run("velocity_error_m_per_s", "vertical", "rms")},
        "tilt_error_arcsec": per_run("tilt_error_arcsec", "rms"),
        "heading_error_arcsec": per_run("heading_error_arcsec", "rms"),
        "nees": averaged_nees(finished, settle),
        "divergent_runs": divergent,
        "imu_calibration": calibration([s.imu_calibration for s in summaries]),
        "star_identification": identification([(s.celestial or {}).get("star_identification") for s in summaries]),
    }


def identification(per_run):
    """The runs' ``celestial.star_identification`` summed (None when the runs have none): frames and stars detected
    and identified (and tracked), wrong identifications, the largest stated wrong-match probability and the sum of
    the stated probabilities (the wrong identifications expected)."""
    if not per_run or any(r is None for r in per_run):
        return None
    total = {key: int(sum(r[key] for r in per_run)) for key in ("frames_detected", "frames_identified", "stars_detected",
                                                                 "stars_identified", "stars_tracked", "wrong")}
    return {"runs": len(per_run), **total, "wrong_probability_max": max(r["wrong_probability_max"] for r in per_run),
            "wrong_expected": float(sum(r["wrong_expected"] for r in per_run))}


def cep(radial):
    """{cep50, cep95}: the circular error probable (50 %) and its 95 % twin, the median and 95th
    percentile of radial horizontal errors ``radial`` over the runs."""
    return {"cep50": float(np.percentile(radial, 50)), "cep95": float(np.percentile(radial, 95))}


def _rms(values):
    return float(np.sqrt(np.mean(np.square(values))))
