"""The campaign statistics of navigation runs (the INS): CEP50/95 of the final horizontal position
error and the vertical error's percentiles, each with its 95 % interval, the spread of the runs' velocity, tilt
and heading errors, the run-averaged NEES over the filter's own error state, divergent runs and the IMU error
states."""

import numpy as np

from navsim.estimation.intervals import as_json, quantile_interval, runs_to_bound
from navsim.pooling import averaged_nees, calibration, diverged, spread
from startrack import units


def pool(finished, settle):
    """The navigation fields of a :class:`~navsim.navigation.records.CampaignSummary` from the finished runs
    [(index, summary, series), ...]: CEP50/CEP95 are the median and 95th percentile over the runs
    of the final horizontal position error (its radial distance from the truth), each with its 95 % interval
    (:func:`percentiles`), as the vertical error's p50/p95."""
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
                             "vertical": {**percentiles(vertical, {"p50": 0.5, "p95": 0.95}), "rms": _rms(vertical),
                                          "max": float(vertical.max())}},
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
    """{cep50, cep95, interval_95, runs_to_bound}: the circular error probable (50 %) and its 95 % twin, the
    median and 95th percentile of radial horizontal errors ``radial`` over the runs (:func:`percentiles`)."""
    return percentiles(radial, {"cep50": 0.5, "cep95": 0.95})


def percentiles(sizes, named):
    """{name: the p-quantile of ``sizes`` (errors' magnitudes, one per run) for each (name, p) of ``named``,
    ``interval_95``: {name: [lo, hi]} its distribution-free 95 % interval (the order statistics around it: 0 below
    and null above where no run bounds it), ``runs_to_bound``: {name: the runs that bound it}}
    (:mod:`navsim.estimation.intervals`)."""
    out = {name: float(np.percentile(sizes, 100.0 * p)) for name, p in named.items()}
    out["interval_95"] = {name: as_json(quantile_interval(sizes, p, lowest=0.0)) for name, p in named.items()}
    out["runs_to_bound"] = {name: runs_to_bound(p) for name, p in named.items()}
    return out


def _rms(values):
    return float(np.sqrt(np.mean(np.square(values))))
