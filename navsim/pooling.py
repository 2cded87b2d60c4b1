"""What a campaign pools the same way whatever the kind of its runs: the run-averaged NEES against its
band, the divergent runs, the spread of a per-run figure and the final normalised errors of the
filter's calibration states."""

import numpy as np

from navsim.estimation.consistency import nees_statistics
from navsim.estimation.intervals import as_json, mean_interval

#: A run diverged when an error exceeds this many σ of its filter (at least; more for a long run:
#: :func:`divergence_sigmas`), or its NEES mean this many dof.
DIVERGENCE_SIGMAS = 5.0
#: The chance that a consistent run's largest normalised error passes the divergence threshold.
FALSE_DIVERGENCE = 1e-3


def divergence_sigmas(samples):
    """The normalised error beyond which a run of ``samples`` Gaussian errors is called divergent: 5, or the
    two-sided family-wise level at which a consistent run reaches it with probability :data:`FALSE_DIVERGENCE`
    (Šidák 1967: Φ⁻¹(1 − p/2N) for N samples; 5.23 for the 5874 of a campaign run's 1958 kept frames × 3 axes —
    at 5 such a run trips the test once in 300 runs, a 50-run campaign in 16 %)."""
    from scipy.stats import norm

    return max(DIVERGENCE_SIGMAS, float(norm.isf(0.5 * FALSE_DIVERGENCE / max(int(samples), 1))))


def divergence(errors, sigmas):
    """A run's divergence test on every steady frame (its summary's ``divergence``): the largest normalised error
    |e|/σ of ``errors`` (F, m) against their filter's ``sigmas`` (F, m), the ``samples`` F·m and the family-wise
    ``threshold`` (:func:`divergence_sigmas`) for them; a NaN error or σ is passed over, as a comparison with it is."""
    e, s = np.abs(np.asarray(errors, dtype=float)), np.asarray(sigmas, dtype=float)
    z = np.divide(e, s, out=np.where(e > 0.0, np.inf, 0.0), where=s > 0.0)  # σ = 0: any error passes, none does not
    return {"max_normalised_error": float(np.fmax.reduce(z, axis=None, initial=0.0)), "samples": int(z.size),
            "threshold": divergence_sigmas(z.size)}


def diverged(summary):
    """True when a run's largest normalised error passed its threshold (:func:`divergence`, tested when the run was
    summarised, on every frame: a campaign keeps fewer) or its NEES mean is above 5 times its dof."""
    test = summary["divergence"]
    return test["max_normalised_error"] > test["threshold"] or summary["nees"]["mean"] > DIVERGENCE_SIGMAS * summary["nees"]["dof"]


def run_averaged_nees(series):
    """(t, mean): the NEES averaged over the runs (their ``series``, each with ``t`` and ``nees``) at every
    frame they share (the shortest run's), and those frames' times [s] (the first run's)."""
    frames = min(len(s["nees"]) for s in series)
    return series[0]["t"][:frames], np.mean(np.array([s["nees"][:frames] for s in series]), axis=0)


def averaged_nees(finished, settle):
    """The run-averaged NEES at the steady frames (after ``settle`` [s]) against the band of that many runs,
    with the dof the runs' summaries record (:func:`navsim.estimation.consistency.nees_statistics`), and
    ``mean_interval_95``: the 95 % interval of its mean, Student's t over the runs' own means of those frames
    ([lo, null] for one run: :func:`navsim.estimation.intervals.mean_interval`)."""
    series = [series for _, _, series in finished]
    t, mean_nees = run_averaged_nees(series)
    steady = t >= settle
    per_run = [np.mean(s["nees"][: t.size][steady]) for s in series]
    return {**nees_statistics(mean_nees[steady], finished[0][1]["nees"]["dof"], len(finished)),
            "mean_interval_95": as_json(mean_interval(per_run, lowest=0.0))}


def spread(values):
    """{mean, p50, p95, max} of a per-run figure over the runs."""
    return {"mean": float(np.mean(values)), "p50": float(np.percentile(values, 50)),
            "p95": float(np.percentile(values, 95)), "max": float(np.max(values))}


def calibration(runs):
    """Final normalised errors of calibration states over the runs (each a summary's
    ``gyro_calibration`` or ``imu_calibration``): RMS per state (1 for a consistent filter) and the
    share within 3σ; None without any."""
    runs = [r for r in runs if r]
    if not runs:
        return None
    out = {"runs": len(runs)}
    for name in runs[0]:
        errors = np.array([r[name]["normalised_error"] for r in runs])
        out[name] = {"normalised_error_rms": [float(v) for v in np.sqrt(np.mean(errors**2, axis=0))],
                     "within_3_sigma": float(np.mean(np.abs(errors) <= 3.0))}
    return out
