"""The IEEE 952 noise model fitted to an Allan variance curve by generalised least squares on its logarithm.

The model (annex C of IEEE 952, eq. (C.12)-(C.16) and their sum; IEEE 1554 §7):

    σ²(τ) = 3 Q²/τ² + N²/τ + (2 ln 2/π) B² + K² τ/3 + R² τ²/2

quantisation Q [unit·s], white noise (angle / velocity random walk) N [unit/√s], bias instability B [unit] (the
flicker floor: σ ≥ 0.664 B), random walk of the rate K [unit/s/√s], rate ramp R [unit/s]. With ``bias_model=
"gauss-markov"`` the flicker term is replaced by the first-order Gauss-Markov bias of the project's sensor models
(steady σ_g, correlation time T; :func:`navsim.sensors.inertial.allan_variance`), and B is the floor of the same
Allan peak: 0.664 B = 0.6174 σ_g.

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
from navsim.sensors.inertial import FLICKER_FLOOR_FACTOR, GAUSS_MARKOV_PEAK_ADEV

#: The terms, in the order of the model.
TERMS = ("Q", "N", "B", "K", "R")
BIAS_MODELS = ("flicker", "gauss-markov")
#: A term is resolved when its squared coefficient exceeds this many of its σ (one-sided 0.13 % by chance).
RESOLVED_SIGMAS = 3.0
#: The upper bound of a term not resolved: c + this many σ_c.
BOUND_SIGMAS = 2.0
_PASSES = 2
_EIGEN_FLOOR = 1e-3
_BIAS = 2


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
    """The fitted terms {name: :class:`Term`} (B the flicker floor whatever the bias model); with the Gauss-Markov
    bias model also its ``sigma_g`` (a :class:`Term`) and ``correlation_time`` [s] with its σ; the fit's chi-square
    for its degrees of freedom, and the estimates' EDF ``dof`` at each cluster time."""

    terms: dict
    bias_model: str
    correlation_time: float | None
    correlation_time_sigma: float | None
    sigma_g: Term | None
    chi_square: float
    fit_dof: int
    dof: np.ndarray

    def avar(self, tau):
        """The fitted σ²(τ) [unit²] at cluster times ``tau`` [s]."""
        return self.term_avar(tau).sum(axis=1)

    def term_avar(self, tau):
        """Each resolved term's σ²(τ) (T, 5) in the order of :data:`TERMS` (0 for a term not resolved)."""
        return basis(tau, self.correlation_time) * self.coefficients()

    def coefficients(self):
        """The squared coefficients (Q², N², B² or σ_g², K², R²), 0 for a term not resolved."""
        c = np.array([t.value**2 if t.resolved else 0.0 for t in self.terms.values()])
        if self.sigma_g is not None:
            c[_BIAS] = self.sigma_g.value**2 if self.sigma_g.resolved else 0.0
        return c


def basis(tau, correlation_time=None):
    """The terms' σ²(τ) for unit coefficients (T, 5): 3/τ², 1/τ, 2 ln 2/π, τ/3, τ²/2 (the model above); with a
    Gauss-Markov ``correlation_time`` T its σ²(τ) of unit σ_g in the third column:
    [2 (r − 1 + e^(−r)) − (1 − e^(−r))²] / r², r = τ/T (IEEE 952 annex C)."""
    tau = np.asarray(tau, dtype=float)
    out = np.column_stack([3.0 / tau**2, 1.0 / tau, np.full(tau.shape, 2.0 * np.log(2.0) / np.pi), tau / 3.0,
                           tau**2 / 2.0])
    if correlation_time is not None:
        r = tau / correlation_time
        e = np.exp(-r)
        out[:, _BIAS] = (2.0 * (r - 1.0 + e) - (1.0 - e) ** 2) / r**2
    return out


@dataclass(frozen=True)
class _Log:
    """What the fit needs of one axis: its cluster times, sizes and estimates, the log's length and rate, and the
    covariance terms of its estimates by Gauss-Markov time (None: the flicker bias) as they are computed."""

    tau: np.ndarray
    sizes: np.ndarray
    avar: np.ndarray
    samples: int
    rate_hz: float
    terms: dict

    def covariance(self, coefficients, correlation_time):
        """Cov(σ̂²_a, σ̂²_b) for a noise of squared ``coefficients`` (:mod:`.estimate_covariance`)."""
        if correlation_time not in self.terms:
            self.terms[correlation_time] = covariance_terms(self.sizes, self.samples, self.rate_hz, correlation_time)
        return estimate_covariance(self.terms[correlation_time], coefficients)


@dataclass(frozen=True)
class _Solution:
    c: np.ndarray  # squared coefficients of the active terms
    sigma: np.ndarray
    correlation_time: float | None
    correlation_time_sigma: float | None
    chi_square: float
    dof: np.ndarray


def fit_noise(tau, avar, samples, sizes, rate_hz, bias_model="flicker"):
    """The :class:`NoiseFit` of an Allan variance ``avar`` [unit²] at cluster times ``tau`` [s] (cluster ``sizes``
    m of a log of ``samples`` rates at ``rate_hz``)."""
    log = _Log(np.asarray(tau, dtype=float), np.asarray(sizes), np.asarray(avar, dtype=float), samples, rate_hz, {})
    gauss_markov = bias_model == "gauss-markov"
    active, dropped = list(range(len(TERMS))), []
    solution = None
    while active:
        solution = _fit(log, active, gauss_markov)
        significance = solution.c / solution.sigma
        if np.all(significance > RESOLVED_SIGMAS):
            break
        dropped.append(active.pop(int(np.argmin(significance))))
    bounds = {i: _upper_bound(log, active, i, gauss_markov) for i in dropped}
    return _result(solution, active, bounds, gauss_markov, log)


def _fit(log, active, gauss_markov):
    """Generalised least squares of the ``active`` terms (indices into :data:`TERMS`) in ``_PASSES`` passes."""
    gauss_markov = gauss_markov and _BIAS in active
    solution = _start(log, active, gauss_markov)
    for _ in range(_PASSES):
        solution = _weighted_fit(log, active, solution)
    return solution


def _start(log, active, gauss_markov):
    """A first fit by non-negative least squares of the relative errors (the Gauss-Markov time on a grid)."""
    times = np.geomspace(log.tau[0] / 4.0, log.tau[-1] * 4.0, 4 * log.tau.size) if gauss_markov else [None]
    best = None
    for t in times:
        rows = basis(log.tau, t)[:, active] / log.avar[:, None]
        c, misfit = optimize.nnls(rows, np.ones(log.tau.size))
        if best is None or misfit < best[0]:
            best = (misfit, c, t)
    _, c, t = best
    return _Solution(c, np.full(c.shape, np.inf), t, None, np.inf, None)


def _weighted_fit(log, active, previous):
    """One pass: the estimates' covariance from the ``previous`` solution, then the fit with it."""
    full = np.zeros(len(TERMS))
    full[active] = previous.c
    model = np.maximum(basis(log.tau, previous.correlation_time) @ full, 1e-6 * log.avar)
    covariance = log.covariance(full, previous.correlation_time)
    dof = _dof(model, covariance, log.samples)
    spread = model * np.sqrt(2.0 / dof)
    correlation = covariance / np.outer(spread, spread)
    np.fill_diagonal(correlation, 1.0)
    half = dof / 2.0
    log_sigma = np.sqrt(special.polygamma(1, half))
    factor = np.linalg.cholesky(_nearest_correlation(correlation) * np.outer(log_sigma, log_sigma))
    target = np.log(log.avar) - special.digamma(half) + np.log(half)
    return _solve(log.tau, target, factor, active, previous, dof)


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


def _solve(tau, target, factor, active, start, dof):
    """Minimise |L⁻¹ (target − ln σ²(τ))|² (L the Cholesky ``factor``) over c ≥ 0 (and ln T for a Gauss-Markov)."""
    n = len(active)
    free_time = start.correlation_time is not None

    def columns(p):
        return basis(tau, np.exp(p[n]) if free_time else None)[:, active]

    scale = np.median(np.exp(target)[:, None] / columns(np.log([start.correlation_time or 1.0] * (n + 1))), axis=0)

    def residual(p):
        return linalg.solve_triangular(factor, target - np.log(np.maximum(columns(p) @ (p[:n] * scale), 1e-300)),
                                       lower=True)

    p0 = np.append(start.c / scale, np.log(start.correlation_time) if free_time else [])
    low, high = np.zeros(p0.size), np.full(p0.size, np.inf)
    if free_time:
        low[n], high[n] = np.log(tau[0] / 16.0), np.log(tau[-1] * 16.0)
    p0 = np.clip(p0, low, high)
    done = optimize.least_squares(residual, p0, bounds=(low, high), x_scale="jac", xtol=1e-10, ftol=1e-10)
    jacobian = done.jac.copy()
    jacobian[:, :n] = -linalg.solve_triangular(factor, columns(done.x) / (columns(done.x) @ (done.x[:n] * scale))[:, None],
                                               lower=True)  # with respect to c itself: finite at c = 0
    sigma = _sigma(jacobian)
    t = float(np.exp(done.x[n])) if free_time else None
    return _Solution(done.x[:n] * scale, sigma[:n], t, t * sigma[n] if free_time else None,
                     float(np.sum(done.fun**2)), dof)


def _sigma(jacobian):
    """The parameters' σ from the whitened residuals' Jacobian: the diagonal of (Jᵀ J)⁻¹ (inf when singular)."""
    try:
        diagonal = np.diag(np.linalg.inv(jacobian.T @ jacobian))
    except np.linalg.LinAlgError:
        return np.full(jacobian.shape[1], np.inf)
    return np.where(diagonal > 0.0, np.sqrt(np.abs(diagonal)), np.inf)


def _upper_bound(log, active, term, gauss_markov):
    """The bound √(c + 2 σ_c) of a dropped ``term``'s coefficient, fitted beside the resolved ones."""
    with_term = sorted([*active, term])
    solution = _fit(log, with_term, gauss_markov)
    k = with_term.index(term)
    return float(np.sqrt(solution.c[k] + BOUND_SIGMAS * solution.sigma[k]))


def _result(solution, active, bounds, gauss_markov, log):
    terms = {}
    for i, name in enumerate(TERMS):
        if i in active:
            value = float(np.sqrt(solution.c[active.index(i)]))
            terms[name] = Term(value, float(solution.sigma[active.index(i)] / (2.0 * value)), None)
        else:
            terms[name] = Term(None, None, bounds[i])
    sigma_g, timed = None, gauss_markov and _BIAS in active
    if gauss_markov:
        sigma_g = terms["B"]
        terms["B"] = Term(*(None if v is None else v * GAUSS_MARKOV_PEAK_ADEV / FLICKER_FLOOR_FACTOR
                            for v in (sigma_g.value, sigma_g.sigma, sigma_g.upper_bound)))
    fit = NoiseFit(terms, "gauss-markov" if gauss_markov else "flicker", solution.correlation_time if timed else None,
                   solution.correlation_time_sigma if timed else None, sigma_g, solution.chi_square,
                   log.tau.size - len(active) - timed, None)
    return _with_dof(fit, log)


def _with_dof(fit, log):
    """The fit with the estimates' EDF ν = 2 σ⁴ / Var(σ̂²) of its own model at each cluster time."""
    covariance = log.covariance(fit.coefficients(), fit.correlation_time)
    dof = _dof(fit.avar(log.tau), covariance, log.samples)
    return NoiseFit(**{**fit.__dict__, "dof": dof})
