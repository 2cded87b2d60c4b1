"""Confidence intervals from independent runs (navsim.estimation.intervals): Student's t of a mean against scipy
and by its coverage on time-correlated NEES, where a χ² over every frame fails; the order-statistic interval of a
quantile by its coverage on seeded samples of a known law, its ranks against scipy's binomial law, and the runs that
bound it against the closed form."""

import numpy as np
import pytest
from scipy import stats

from navsim.estimation.consistency import chi2_band
from navsim.estimation.intervals import (
    as_json,
    contains,
    interval_text,
    mean_interval,
    order_statistic_ranks,
    quantile_interval,
    runs_to_bound,
)


def test_the_mean_interval_is_scipys_student_t():
    x = np.array([1.03, 0.94, 0.85, 0.93])
    lo, hi = mean_interval(x)
    expected = stats.t.interval(0.95, x.size - 1, loc=x.mean(), scale=stats.sem(x))
    assert (lo, hi) == pytest.approx(expected, rel=1e-12)
    assert mean_interval([5.0, 7.0, 6.0], probability=0.9) == pytest.approx(
        stats.t.interval(0.9, 2, loc=6.0, scale=stats.sem([5.0, 7.0, 6.0])), rel=1e-12)


def test_one_run_gives_no_mean_interval_and_a_clip_keeps_it_positive():
    assert mean_interval([0.9]) == (-np.inf, np.inf)
    assert mean_interval([0.9], lowest=0.0) == (0.0, np.inf)
    assert mean_interval([0.1, 3.0], lowest=0.0)[0] == 0.0  # t with 1 dof reaches below 0
    assert as_json(mean_interval([0.9], lowest=0.0)) == [0.0, None]
    assert contains([0.0, None], 1e9) and contains([0.5, 1.5], 1.0) and not contains([0.5, 0.9], 1.0)
    assert interval_text([0.82, None]) == "[0.82, unbounded]" and interval_text([1.0, 2.0], 1, "m") == "[1.0, 2.0] m"


def ar1_nees(rng, runs, frames, dof, phi):
    """NEES of a consistent filter whose errors are AR(1) in time with coefficient ``phi``: (runs, frames)."""
    e = np.empty((runs, frames, dof))
    e[:, 0] = rng.standard_normal((runs, dof))
    drive = np.sqrt(1.0 - phi**2) * rng.standard_normal((runs, frames, dof))
    for k in range(1, frames):
        e[:, k] = phi * e[:, k - 1] + drive[:, k]
    return np.sum(e**2, axis=2)


def test_the_t_interval_of_run_means_covers_a_correlated_nees_and_the_frames_chi_square_does_not():
    """4 runs of 400 frames of 3-dof NEES correlated over ~100 frames (AR(1), φ = 0.98) from a consistent filter:
    over 1000 seeded campaigns Student's t over the run means covers the expectation 3 in 93.3 % of them (exact for
    Gaussian run means; these, each worth about 8 independent frames, are skewed and undercover a little: 92-97 %
    allowed, a binomial σ being 0.7 %), while the χ² band of every frame as if independent (4·400 draws of χ²(3))
    holds the pooled mean in 18.7 %: a run's frames are not independent."""
    rng = np.random.default_rng(20240664)
    dof, runs, frames, trials = 3, 4, 400, 1000
    lo, hi = chi2_band(dof, runs * frames)
    t_hits = chi2_hits = 0
    for _ in range(trials):
        nees = ar1_nees(rng, runs, frames, dof, 0.98)
        t_hits += contains(mean_interval(nees.mean(axis=1)), dof)
        chi2_hits += lo <= nees.mean() <= hi
    assert 0.92 <= t_hits / trials <= 0.97
    assert chi2_hits / trials < 0.5


@pytest.mark.parametrize("runs", [4, 10, 40, 80])
@pytest.mark.parametrize("p", [0.5, 0.95])
def test_the_quantile_interval_covers_a_rayleigh_quantile_as_the_binomial_law_says(runs, p):
    """Radial errors of a circular Gaussian (Rayleigh, σ = 1: its p-quantile √(−2 ln(1 − p))): over 4000 seeded
    samples of ``runs`` the order-statistic interval covers the true quantile as often as P(r ≤ B ≤ s − 1) of
    B ~ Bin(runs, p) says (within 4 σ of a binomial count), and that is at least 95 %."""
    rng = np.random.default_rng([runs, int(100 * p)])
    truth = np.sqrt(-2.0 * np.log(1.0 - p))
    samples = np.hypot(*rng.standard_normal((2, 4000, runs)))
    lo, hi = quantile_interval(samples, p, axis=1, lowest=0.0)
    covered = np.mean((lo <= truth) & (truth <= hi))
    r, s = order_statistic_ranks(runs, p)
    exact = stats.binom.cdf(s - 1, runs, p) - stats.binom.cdf(r - 1, runs, p)
    assert exact >= 0.95
    assert covered == pytest.approx(exact, abs=4.0 * np.sqrt(exact * (1.0 - exact) / 4000) + 1e-9)


def test_the_ranks_are_the_equal_tailed_binomial_ones():
    """r: the largest rank with P(B ≤ r − 1) ≤ 2.5 %, s: the smallest with P(B ≤ s − 1) ≥ 97.5 %, by scipy's binomial law
    searched over every rank; 0 and runs + 1 where none bounds."""
    for runs in (1, 2, 5, 6, 20, 59, 71, 72, 200):
        for p in (0.5, 0.9, 0.95):
            cdf = stats.binom.cdf(np.arange(runs + 1), runs, p)
            r = max([k + 1 for k in range(runs + 1) if cdf[k] <= 0.025], default=0)
            s = min(k + 1 for k in range(runs + 1) if cdf[k] >= 0.975)
            assert order_statistic_ranks(runs, p) == (r, s), (runs, p)


def test_too_few_runs_leave_a_quantile_unbounded_and_the_closed_form_says_how_many_bound_it():
    """CEP50 needs 6 runs, CEP95 72 (0.95^72 = 2.49 % ≤ 2.5 % < 0.95^71); a 4-run CEP95 is unbounded above, as the
    issue's 4-run campaign; the same rule gives Wilks's 59 runs for a one-sided 95 % bound."""
    assert runs_to_bound(0.5) == 6 and runs_to_bound(0.95) == 72 and runs_to_bound(0.95, probability=0.9) == 59
    for p in (0.5, 0.8, 0.95, 0.99):
        n = runs_to_bound(p)
        assert order_statistic_ranks(n, p)[1] <= n and order_statistic_ranks(n - 1, p)[1] == n
    x = np.array([1.2, 3.4, 0.7, 2.5])
    assert quantile_interval(x, 0.95, lowest=0.0) == (2.5, np.inf)  # X(3): P(B ≤ 2) = 1.4 % for B ~ Bin(4, 0.95)
    assert quantile_interval(x, 0.5, lowest=0.0) == (0.0, np.inf)
