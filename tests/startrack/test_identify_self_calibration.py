"""The early drop of a hopeless hypothesis (startrack.identify.self_calibration._hopeless) against scipy's Poisson."""

import math

import numpy as np
import pytest
from scipy.stats import poisson

from startrack.identify.plate_solver import _density_grid
from startrack.identify.self_calibration import HOPELESS, SEEDS, _hopeless


@pytest.mark.parametrize("n_detections", [300, 2500])
def test_a_pass_matching_what_chance_would_is_hopeless(n_detections):
    """Uniform detections on a 1024 x 768 frame, 150 predicted stars, a 2 px gate: dropped exactly when the
    chance of at least its matches beyond the seeds, P[Poisson(sum 1 - exp(-rho pi g^2)) >= k], is above HOPELESS."""
    rng = np.random.default_rng(n_detections)
    grid = _density_grid(rng.uniform([0.0, 0.0], [1024.0, 768.0], (n_detections, 2)), 1024, 768)
    predicted = rng.uniform([0.0, 0.0], [1024.0, 768.0], (150, 2))
    mean = 150.0 * -math.expm1(-n_detections / (1024.0 * 768.0) * math.pi * 4.0)  # the grid never goes below the mean
    decided = 0
    for k in range(0, 40):
        dropped = _hopeless(predicted, grid, 2.0, SEEDS + k)
        if abs(poisson.sf(k - 1, mean) - HOPELESS) > 0.1:  # away from the edge, where the grid's local excess decides
            assert dropped == (poisson.sf(k - 1, mean) > HOPELESS), (k, mean)
            decided += 1
    assert decided > 30 and _hopeless(predicted, grid, 2.0, SEEDS) and not _hopeless(predicted, grid, 2.0, SEEDS + 40)
