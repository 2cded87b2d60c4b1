"""Filter consistency: the NEES of logged errors and the chi-square bands it is judged against.

For a consistent filter the NEES of one run is χ²(n) at every frame, and the NEES averaged over M
independent runs, ε̄ = (1/M) Σ εᵢ, satisfies M ε̄ ~ χ²(M n) (Bar-Shalom, Li & Kirubarajan,
*Estimation with Applications to Tracking and Navigation*, 2001, §5.4.2). The band is the
two-sided 95 % interval; every summary, campaign aggregate, report and test takes it from here.
"""

import numpy as np
from scipy.special import gammaincinv

from navsim.estimation.linalg import quadratic_forms

BAND_PROBABILITY = 0.95
#: The most degrees of freedom :func:`mean_square_band` takes: its band is then within 1e-5 of E either way.
MAX_DOF = 1e12


def chi2_quantile(probability, dof):
    """The ``probability`` quantile of χ²(dof): 2 P⁻¹(dof/2, p), P the regularised lower incomplete
    gamma function (what scipy.stats.chi2.ppf computes, without importing scipy.stats)."""
    return 2.0 * gammaincinv(np.multiply(dof, 0.5), probability)


def chi2_band(dof, runs=1, probability=BAND_PROBABILITY):
    """Two-sided ``probability`` interval of the NEES averaged over ``runs`` runs of ``dof`` dof each."""
    tail = (1.0 - probability) / 2.0
    total = np.multiply(dof, runs)
    return chi2_quantile(tail, total) / runs, chi2_quantile(1.0 - tail, total) / runs


def nees(P, errors):
    """eᵢᵀ Pᵢ⁻¹ eᵢ at every frame for covariances P (F, m, m) and errors e (F, m) (Cholesky, compiled)."""
    if np.shape(P)[1:] != (np.shape(errors)[1],) * 2:
        raise ValueError(f"NEES: covariances {np.shape(P)} do not match errors {np.shape(errors)}")
    return quadratic_forms(np.ascontiguousarray(P), np.ascontiguousarray(errors))


def nees_statistics(values, dof, runs=1):
    """{dof, runs, band_95, mean, fraction_in_band} of per-frame NEES ``values`` (run-averaged over ``runs``)."""
    lo, hi = chi2_band(dof, runs)
    return {"dof": int(dof), "runs": int(runs), "band_95": [float(lo), float(hi)], "mean": float(np.mean(values)),
            "fraction_in_band": float(np.mean((values >= lo) & (values <= hi)))}


def mean_square_band(expected, variance, runs, probability=BAND_PROBABILITY):
    """Two-sided ``probability`` interval of the mean over ``runs`` independent draws of a squared error
    whose expectation is ``expected`` and variance ``variance`` (arrays alike): the draw taken as a scaled
    χ² of ν = 2 E²/Var dof (exact for a central Gaussian error of equal variances; Satterthwaite's
    approximation otherwise, e.g. for |y|² of y ~ N(m, C): E = tr C + |m|², Var = 2 tr C² + 4 mᵀ C m), so
    the mean is E χ²(runs ν)/(runs ν). A draw without spread (Var = 0: a fixed error, or none) has the band E."""
    expected, variance = np.asarray(expected, dtype=float), np.asarray(variance, dtype=float)
    spread = variance > 0.0
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        dof = np.clip(runs * 2.0 * expected**2 / np.where(spread, variance, 1.0), np.finfo(float).tiny, MAX_DOF)
    tail = (1.0 - probability) / 2.0
    lo, hi = expected * chi2_quantile(tail, dof) / dof, expected * chi2_quantile(1.0 - tail, dof) / dof
    return np.where(spread, lo, expected), np.where(spread, hi, expected)
