"""The false-match probability of startrack.identify.chance against scipy and a seeded Monte Carlo."""

import numpy as np
import pytest
from scipy.spatial import cKDTree
from scipy.stats import poisson

from startrack.identify.chance import chance_match_probability, poisson_tail


@pytest.mark.parametrize("mean, k", [(0.01, 1), (0.5, 3), (3.0, 10), (12.0, 45), (40.0, 20), (2.0, 0)])
def test_poisson_tail_is_scipys(mean, k):
    # rounding level: the first term's exp(log ...) carries |log term| eps ~ 1e-13, the sum stops at 1e-17
    assert poisson_tail(mean, k) == pytest.approx(poisson.sf(k - 1, mean), rel=1e-9, abs=1e-300)


def test_bound_holds_for_chance_neighbours_of_a_crowd():
    """Predicted stars and unrelated detections, both uniform on a frame: the count of predicted stars
    with a detection within d never exceeds its Poisson tail more often than the tail says."""
    rng = np.random.default_rng(9)
    width, height, n_pred, n_obs, radius = 1024.0, 768.0, 300, 3000, 1.5
    expected = np.full(n_pred, n_obs / (width * height) * np.pi * radius**2)
    counts = []
    for _ in range(400):
        pred = rng.uniform([0, 0], [width, height], (n_pred, 2))
        obs = rng.uniform([0, 0], [width, height], (n_obs, 2))
        nearest, _ = cKDTree(obs).query(pred, distance_upper_bound=radius)
        counts.append(int(np.count_nonzero(np.isfinite(nearest))))
    counts = np.array(counts)
    for k in (20, 30, 40):
        empirical = np.mean(counts >= k)
        assert empirical <= chance_match_probability(expected, k, 1.0) + 3.0 * np.sqrt(0.25 / len(counts))
    assert chance_match_probability(expected, 120, 1e9) < 1e-30  # far beyond chance
    assert chance_match_probability(expected, 5, 10.0) == 1.0  # the Bonferroni factor caps at 1
