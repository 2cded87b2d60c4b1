"""The covariance of the overlapping Allan variance estimates of one log at all its cluster times, for a noise model.

The estimate at a cluster of m samples is σ̂²_m = Σ_i d_m(i)² / (2 τ² n_m), d_m(i) = x_(i+2m) − 2 x_(i+m) + x_i over
its n_m = N + 1 − 2m second differences (:mod:`.allan`). For Gaussian noise whose phase x has the (generalised)
structure function D(s), the second differences' cross-covariance is R_ab(l) = −½ Σ_p Σ_q c_p c_q D((l + s_q − s_p) τ0)
(c = (1, −2, 1) at s = (0, m, 2m)), and

    Cov(σ̂²_a, σ̂²_b) = 2 Σ_l n_ab(l) R_ab(l)² / (4 τ_a² τ_b² n_a n_b)

with n_ab(l) the pairs (i, i + l) in both sums -- the variance of a quadratic form of Gaussian variables, the sum
Greenhall & Riley 2003 evaluate for the EDF of one power-law noise; ν = 2 σ⁴ / Var(σ̂²) is its
EDF, here of the fitted mixture. The model's terms (:mod:`.noise_fit`) give D(s): quantisation 2 Q² (s ≠ 0), white
rate N² |s|, flicker rate −(B²/π) s² ln|s|, rate random walk −K² |s|³/6 (each gives the term's σ²(τ) = (4 D(τ) − D(2τ)) / (2 τ²) of IEEE 952's model; a rate ramp is deterministic and adds
none by itself, but its second differences R τ² shift the noise's, which adds 4 R² τ_a² τ_b² Σ_l n_ab(l) R_ab(l) to the
numerator above). The sum over lags is taken at a step of min(m_a, m_b)/16 (the cluster sizes are powers of two: R_ab is
smooth between multiples of it), the quantisation's part, non-zero only at the lags where the two differences share a
point, exactly at those, over the lags where the two differences share data and 4 (m_a + m_b) more (the flicker
term's reach); cluster times more than ``_REACH`` octaves apart are taken as uncorrelated. Since R_ab is linear in the squared
coefficients c, the covariance is Σ_ij c_i c_j G_ij: :func:`covariance_terms` computes the G of a log once, and
:func:`estimate_covariance` is the sum for any c.
"""

import numpy as np

from startrack import njit

_STEPS_PER_CLUSTER = 16
_REACH = 10
_TERMS = 5


def covariance_terms(sizes, samples, rate_hz):
    """G (T, T, 5, 5) [unit⁴ per unit of the c_i c_j]: the covariance of the estimates at cluster ``sizes`` of a log of
    ``samples`` at ``rate_hz`` for each pair of terms (Q, N, B, K, R) of unit squared coefficients (the ramp's with each
    noise term; ramp with ramp 0)."""
    return _covariance_terms(np.asarray(sizes, dtype=np.int64), samples, 1.0 / rate_hz)


def estimate_covariance(terms, coefficients):
    """Cov(σ̂²_a, σ̂²_b) (T, T) [unit⁴] of a noise of squared ``coefficients`` (Q², N², B², K², R²) from its
    log's :func:`covariance_terms`."""
    c = np.asarray(coefficients, dtype=float)
    return np.einsum("abij,i,j->ab", terms, c, c)


@njit
def _unit_cross(lag, ma, mb, tau0, out):
    """R_ab(lag) of each term of unit coefficient but the quantisation (out[0] = 0): −½ Σ_p Σ_q c_p c_q D_i(...)."""
    weights = (1.0, -2.0, 1.0)
    for i in range(_TERMS):
        out[i] = 0.0
    for p in range(3):
        for q in range(3):
            s = abs((lag + q * mb - p * ma) * tau0)
            if s == 0.0:
                continue
            w = -0.5 * weights[p] * weights[q]
            out[1] += w * s
            out[2] -= w * s * s * np.log(s) / np.pi
            out[3] -= w * s**3 / 6.0


@njit
def _quantization_cross(lag, ma, mb):
    """The quantisation's R_ab(lag) of unit Q²: Σ c_p c_q over the points the two differences share (its D is
    2 Q² but −2 Q² at s = 0, and the constant adds nothing to a second difference)."""
    weights = (1.0, -2.0, 1.0)
    total = 0.0
    for p in range(3):
        for q in range(3):
            if lag + q * mb == p * ma:
                total += weights[p] * weights[q]
    return total


@njit
def _pair(ma, mb, na, nb, tau0):
    """Σ_l n_ab(l) R_i R_j (5, 5) and Σ_l n_ab(l) R_i (5) of one pair of cluster sizes."""
    total = np.zeros((_TERMS, _TERMS))
    linear = np.zeros(_TERMS)
    r = np.empty(_TERMS)
    extra = 4 * (ma + mb)
    step = max(1, ma // _STEPS_PER_CLUSTER)
    low = max(-(na - 1), -2 * mb - extra)
    high = min(nb - 1, 2 * ma + extra)
    low = -((-low) // step) * step
    for lag in range(low, high + 1, step):
        pairs = min(na, nb - lag) - max(0, -lag)
        if pairs > 0:
            _unit_cross(lag, ma, mb, tau0, r)
            for i in range(1, _TERMS - 1):  # the quantisation's and the ramp's parts are 0 here
                linear[i] += step * pairs * r[i]
                for j in range(1, _TERMS - 1):
                    total[i, j] += step * pairs * r[i] * r[j]
    seen = np.empty(9, dtype=np.int64)
    count = 0
    for p in range(3):  # the quantisation's lags, exactly
        for q in range(3):
            lag = p * ma - q * mb
            pairs = min(na, nb - lag) - max(0, -lag)
            known = False
            for j in range(count):
                known = known or seen[j] == lag
            if known or pairs <= 0:
                continue
            seen[count] = lag
            count += 1
            _unit_cross(lag, ma, mb, tau0, r)
            rq = _quantization_cross(lag, ma, mb)
            for i in range(_TERMS):
                total[0, i] += pairs * rq * r[i]
                total[i, 0] += pairs * rq * r[i]
            total[0, 0] += pairs * rq * rq
            linear[0] += pairs * rq
    return total, linear


@njit
def _covariance_terms(sizes, samples, tau0):
    k = sizes.size
    out = np.zeros((k, k, _TERMS, _TERMS))
    for a in range(k):
        for b in range(a, min(k, a + _REACH + 1)):
            ma, mb = sizes[a], sizes[b]
            na, nb = samples + 1 - 2 * ma, samples + 1 - 2 * mb
            quadratic, linear = _pair(ma, mb, na, nb, tau0)
            g = 2.0 * quadratic / (4.0 * (ma * tau0) ** 2 * (mb * tau0) ** 2 * na * nb)
            for i in range(_TERMS - 1):  # the ramp's: its second differences R τ² times the noise's, halved for i, j
                g[i, _TERMS - 1] = 0.5 * linear[i] / (na * nb)
                g[_TERMS - 1, i] = 0.5 * linear[i] / (na * nb)
            out[a, b] = g
            out[b, a] = g
    return out
