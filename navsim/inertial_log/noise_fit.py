"""The IEEE 952 noise model fitted to an Allan variance curve by generalised least squares on its logarithm.

The model (annex C of IEEE 952: the Allan variance of each noise term and their sum; IEEE 1554 likewise):

    σ²(τ) = 3 Q²/τ² + N²/τ + (2 ln 2/π) B² + K² τ/3 + R² τ²/2

quantisation Q [unit·s], white noise (angle / velocity random walk) N [unit/√s], bias instability B [unit] (the
flicker floor: σ ≥ 0.664 B), random walk of the rate K [unit/s/√s], rate ramp R [unit/s].

Each cluster time's estimate is taken as a chi-square variable of ν equivalent degrees of freedom, so ln σ̂² has the
mean ln σ² + ψ(ν/2) − ln(ν/2) and the variance ψ′(ν/2) (Bartlett & Kendall 1946); ν and the correlation between
cluster times come from the covariance of the estimates for the current fit (:mod:`.estimate_covariance`), and the
fit minimises rᵀ C⁻¹ r of r = ln σ̂² − ψ(ν/2) + ln(ν/2) − ln σ²(τ) over the squared coefficients c ≥ 0
(``_PASSES`` passes, the covariance from the fit before). A coefficient's σ comes from the fit's covariance
(Jᵀ C⁻¹ J)⁻¹; a term is resolved when its c exceeds ``RESOLVED_SIGMAS`` σ_c, otherwise it is dropped and the fit
done again, the term then reported by its upper bound √(c + 2 σ_c) fitted beside the resolved ones.
"""

from dataclasses import dataclass

import numpy as np
from scipy import linalg, optimize, special

from navsim.inertial_log.estimate_covariance import covariance_terms, estimate_covariance

#: The terms, in the order of the model.
TERMS = ("Q", "N", "B", "K", "R")
#: A term is resolved when its squared coefficient exceeds this many of its σ (one-sided 0.13 % by chance).
RESOLVED_SIGMAS = 3.0
#: The upper bound of a term not resolved: c + this many σ_c.
BOUND_SIGMAS = 2.0
_PASSES = 2
_EIGEN_FLOOR = 1e-3


@dataclass(frozen=True)
class Term:
    """One fitted term: its coefficient ``value`` and ``sigma`` (SI; None when not resolved), else ``upper_bound``."""

    value: float | None
    sigma: float | None
    upper_bound: float | None

    @property
    def resolved(self):
        return self.value is not None


@dataclass(frozen=True)
class NoiseFit:
    """The fitted terms {name: :class:`Term`}, the fit's chi-square for its degrees of freedom, and the estimates'
    EDF ``dof`` at each cluster time (of the fitted model)."""

    terms: dict
    chi_square: float
    fit_dof: int
    dof: np.ndarray

    def avar(self, tau):
        """The fitted σ²(τ) [unit²] at cluster times ``tau`` [s]."""
        return self.term_avar(tau).sum(axis=1)

    def term_avar(self, tau):
        """Each resolved term's σ²(τ) (T, 5) in the order of :data:`TERMS` (0 for a term not resolved)."""
        return basis(tau) * self.coefficients()

    def coefficients(self):
        """The squared coefficients (Q², N², B², K², R²), 0 for a term not resolved."""
        return np.array([t.value**2 if t.resolved else 0.0 for t in self.terms.values()])


def basis(tau):
    """The terms' σ²(τ) for unit coefficients (T, 5): 3/τ², 1/τ, 2 ln 2/π, τ/3, τ²/2 (the model above)."""
    tau = np.asarray(tau, dtype=float)
    return np.column_stack([3.0 / tau**2, 1.0 / tau, np.full(tau.shape, 2.0 * np.log(2.0) / np.pi), tau / 3.0,
                            tau**2 / 2.0])


@dataclass(frozen=True)
class _Log:
    """What the fit needs of one axis: its cluster times, sizes and estimates, the log's length, and the covariance
    terms of its estimates (:func:`.estimate_covariance.covariance_terms`)."""

    tau: np.ndarray
    sizes: np.ndarray
    avar: np.ndarray
    samples: int
    terms: np.ndarray

    def covariance(self, coefficients):
        """Cov(σ̂²_a, σ̂²_b) for a noise of squared ``coefficients`` (:mod:`.estimate_covariance`)."""
        return estimate_covariance(self.terms, coefficients)


@dataclass(frozen=True)
class _Solution:
    c: np.ndarray  # squared coefficients of the active terms
    sigma: np.ndarray
    chi_square: float


def fit_noise(tau, avar, samples, sizes, rate_hz):
    """The :class:`NoiseFit` of an Allan variance ``avar`` [unit²] at cluster times ``tau`` [s] (cluster ``sizes``
    m of a log of ``samples`` rates at ``rate_hz``)."""
    log = _Log(np.asarray(tau, dtype=float), np.asarray(sizes), np.asarray(avar, dtype=float), samples,
               covariance_terms(sizes, samples, rate_hz))
    active, dropped = list(range(len(TERMS))), []
    solution = None
    while active:
        solution = _fit(log, active)
        significance = solution.c / solution.sigma
        if np.all(significance > RESOLVED_SIGMAS):
            break
        dropped.append(active.pop(int(np.argmin(significance))))
    bounds = {i: _upper_bound(log, active, i) for i in dropped}
    return _result(solution, active, bounds, log)


def _fit(log, active):
    """Generalised least squares of the ``active`` terms (indices into :data:`TERMS`) in ``_PASSES`` passes."""
    rows = basis(log.tau)[:, active] / log.avar[:, None]
    c, _ = optimize.nnls(rows, np.ones(log.tau.size))  # a first fit: the relative errors' least squares
    solution = _Solution(c, np.full(c.shape, np.inf), np.inf)
    for _ in range(_PASSES):
        solution = _weighted_fit(log, active, solution)
    return solution


def _weighted_fit(log, active, previous):
    """One pass: the estimates' covariance from the ``previous`` solution, then the fit with it."""
    full = np.zeros(len(TERMS))
    full[active] = previous.c
    model = np.maximum(basis(log.tau) @ full, 1e-6 * log.avar)
    covariance = log.covariance(full)
    dof = _dof(model, covariance, log.samples)
    spread = model * np.sqrt(2.0 / dof)
    correlation = covariance / np.outer(spread, spread)
    np.fill_diagonal(correlation, 1.0)
    half = dof / 2.0
    log_sigma = np.sqrt(special.polygamma(1, half))
    factor = np.linalg.cholesky(_nearest_correlation(correlation) * np.outer(log_sigma, log_sigma))
    target = np.log(log.avar) - special.digamma(half) + np.log(half)
    return _solve(basis(log.tau)[:, active], target, factor, previous.c)


def _dof(avar, covariance, samples):
    """The EDF ν = 2 σ⁴ / Var(σ̂²) at each cluster time, at most the log's ``samples`` (a model of deterministic or
    no noise leaves Var = 0)."""
    return np.minimum(2.0 * avar**2 / np.maximum(np.diag(covariance), 1e-300), float(samples))


def _nearest_correlation(correlation):
    """``correlation`` with its eigenvalues kept above ``_EIGEN_FLOOR`` (the lags' sampling and reach of
    :mod:`.estimate_covariance` can leave it slightly indefinite), its diagonal put back to 1."""
    values, vectors = np.linalg.eigh(correlation)
    kept = (vectors * np.maximum(values, _EIGEN_FLOOR)) @ vectors.T
    d = np.sqrt(np.diag(kept))
    return kept / np.outer(d, d)


def _solve(columns, target, factor, start):
    """Minimise |L⁻¹ (target − ln σ²(τ))|² (L the Cholesky ``factor``, σ²(τ) = ``columns`` @ c) over c ≥ 0 from
    ``start``; the σ of c from (Jᵀ J)⁻¹ of the whitened Jacobian with respect to c (finite at c = 0)."""
    scale = np.median(np.exp(target)[:, None] / columns, axis=0)  # each term near the data: well conditioned

    def residual(p):
        return linalg.solve_triangular(factor, target - np.log(np.maximum(columns @ (p * scale), 1e-300)), lower=True)

    def jacobian(c):  # of the residual with respect to c
        return -linalg.solve_triangular(factor, columns / np.maximum(columns @ c, 1e-300)[:, None], lower=True)

    done = optimize.least_squares(residual, start / scale, jac=lambda p: jacobian(p * scale) * scale,
                                  bounds=(0.0, np.inf), x_scale="jac", xtol=1e-10, ftol=1e-10)
    c = done.x * scale
    return _Solution(c, _sigma(jacobian(c)), float(np.sum(done.fun**2)))


def _sigma(jacobian):
    """The parameters' σ from the whitened residuals' Jacobian: the diagonal of (Jᵀ J)⁻¹ (inf when singular)."""
    try:
        diagonal = np.diag(np.linalg.inv(jacobian.T @ jacobian))
    except np.linalg.LinAlgError:
        return np.full(jacobian.shape[1], np.inf)
    return np.where(diagonal > 0.0, np.sqrt(np.abs(diagonal)), np.inf)


def _upper_bound(log, active, term):
    """The bound √(c + 2 σ_c) of a dropped ``term``'s coefficient, fitted beside the resolved ones."""
    with_term = sorted([*active, term])
    solution = _fit(log, with_term)
    k = with_term.index(term)
    return float(np.sqrt(solution.c[k] + BOUND_SIGMAS * solution.sigma[k]))


def _result(solution, active, bounds, log):
    terms = {}
    for i, name in enumerate(TERMS):
        if i in active:
            value = float(np.sqrt(solution.c[active.index(i)]))
            terms[name] = Term(value, float(solution.sigma[active.index(i)] / (2.0 * value)), None)
        else:
            terms[name] = Term(None, None, bounds[i])
    fit = NoiseFit(terms, solution.chi_square, log.tau.size - len(active), None)
    return NoiseFit(**{**fit.__dict__, "dof": _dof(fit.avar(log.tau), log.covariance(fit.coefficients()), log.samples)})
