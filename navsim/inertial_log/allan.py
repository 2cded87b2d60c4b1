"""The overlapping Allan deviation of a rate log, its equivalent degrees of freedom and chi-square interval.

A log of interval-mean rates y_k (a gyro's rad/s, an accelerometer's m/s²) at τ0 = 1/rate is integrated to
the increments' sum x_i = τ0 Σ_(k<i) y_k (x_0 = 0, N + 1 points), and at a cluster of m samples (τ = m τ0)

    σ²(τ) = Σ_(i=0)^(N−2m) (x_(i+2m) − 2 x_(i+m) + x_i)² / (2 τ² (N + 1 − 2m))

(the overlapping estimator: eq. (11) of Riley 2008, the Allan variance of IEEE 952 annex C with every cluster).
Cluster times are octave-spaced, m = 1, 2, 4, ... while the log holds at least ``MIN_CLUSTERS`` clusters.
The mean of the log is removed before the sum (σ² does not change; the sum keeps its precision). The estimates'
equivalent degrees of freedom come from the fitted noise model (:mod:`.estimate_covariance`).
"""

import numpy as np
from scipy import stats

from startrack import njit

#: The longest cluster leaves this many disjoint clusters in the log.
MIN_CLUSTERS = 4
#: Fewest cluster times an Allan fit works on.
MIN_CLUSTER_TIMES = 3

def cluster_sizes(samples):
    """The octave-spaced cluster sizes m = 1, 2, 4, ... of a log of ``samples`` (int array, may be empty)."""
    sizes = []
    m = 1
    while MIN_CLUSTERS * m <= samples:
        sizes.append(m)
        m *= 2
    return np.array(sizes, dtype=np.int64)


def overlapping_avar(rates, rate_hz, sizes):
    """σ²(τ) [unit²] of one axis of interval-mean ``rates`` (N,) [unit] sampled at ``rate_hz`` [Hz] at the cluster
    sizes ``sizes`` (τ = m / rate_hz [s]): the overlapping estimator of the module docstring."""
    rates = np.asarray(rates, dtype=float)
    tau0 = 1.0 / rate_hz
    phase = np.empty(rates.size + 1)
    phase[0] = 0.0
    np.cumsum((rates - rates.mean()) * tau0, out=phase[1:])
    return _second_differences(phase, np.asarray(sizes, dtype=np.int64)) / (2.0 * (sizes * tau0) ** 2)


@njit
def _second_differences(phase, sizes):
    """Mean of (x_(i+2m) − 2 x_(i+m) + x_i)² over every i, for each m of ``sizes``."""
    out = np.empty(sizes.size)
    n = phase.size
    for j in range(sizes.size):
        m = sizes[j]
        total = 0.0
        for i in range(n - 2 * m):
            d = phase[i + 2 * m] - 2.0 * phase[i + m] + phase[i]
            total += d * d
        out[j] = total / (n - 2 * m)
    return out


def chi_square_interval(avar, dof, confidence):
    """The two-sided ``confidence`` interval (low, high) of a variance estimate ``avar`` of ``dof`` equivalent degrees
    of freedom: ν σ̂² / χ²_(ν, 1−p/2) ≤ σ² ≤ ν σ̂² / χ²_(ν, p/2), p = 1 − confidence (the chi-square interval of Riley 2008)."""
    p = 1.0 - confidence
    return dof * avar / stats.chi2.ppf(1.0 - p / 2.0, dof), dof * avar / stats.chi2.ppf(p / 2.0, dof)
