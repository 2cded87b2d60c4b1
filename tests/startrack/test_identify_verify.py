"""Verification pieces: binomial tail, false-match probability, matching, SVD fit, field-star cells, k-vector."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import binom

from startrack.attitude.solvers import SvdWahba
from startrack.camera.model import Camera
from startrack.catalog.hipparcos import load_star_catalog
from startrack.catalog.navigation import load_navigation_catalog
from startrack.identify.pairs import PairTable, kvector_range, pair_range
from startrack.identify.verify import FieldStars, binomial_tail, false_match_probability, match_nearest, wahba_svd


@pytest.mark.parametrize("n, k, p", [(30, 3, 1e-4), (30, 0, 0.3), (10, 10, 0.5), (50, 7, 2e-3), (5, 6, 0.1),
                                     (40, 1, 1e-9), (25, 12, 0.4)])
def test_binomial_tail_matches_scipy(n, k, p):
    expected = binom.sf(k - 1, n, p)
    # rounding level: the first term's exp(lgamma ...) carries |log term| eps ~ 1e-13, the sum stops at 1e-17
    assert binomial_tail(n, k, p) == pytest.approx(expected, rel=1e-9, abs=1e-300)


def test_false_match_probability_model():
    gate, density = 1e-4, 400.0
    p = 1.0 - math.exp(-density * 2.0 * math.pi * (1.0 - math.cos(gate)))
    assert false_match_probability(20, 4, gate, density, 1000) == pytest.approx(1000 * binom.sf(3, 20, p), rel=1e-9)  # as above
    # more matches, fewer hypotheses, a narrower gate: less likely by chance
    assert false_match_probability(20, 6, gate, density, 1000) < false_match_probability(20, 4, gate, density, 1000)
    assert false_match_probability(20, 4, gate, density, 10) < false_match_probability(20, 4, gate, density, 1000)
    assert false_match_probability(20, 4, gate / 2, density, 1000) < false_match_probability(20, 4, gate, density, 1000)
    assert false_match_probability(20, 0, gate, density, 1000) == 1.0


def test_match_nearest_is_mutual_and_one_to_one():
    rng = np.random.default_rng(11)
    pred = rng.normal(size=(40, 3)) * [0.1, 0.1, 0.0] + [0, 0, 1]
    pred /= np.linalg.norm(pred, axis=1, keepdims=True)
    obs = np.concatenate([pred[:25] + rng.normal(0, 2e-4, (25, 3)), rng.normal(size=(5, 3)) * [0.1, 0.1, 0] + [0, 0, 1]])
    obs /= np.linalg.norm(obs, axis=1, keepdims=True)
    gate = 1e-3
    oi, pi = match_nearest(obs, pred, gate)
    angles = np.arccos(np.clip(obs @ pred.T, -1, 1))
    brute = [(i, int(np.argmin(angles[i]))) for i in range(len(obs))
             if np.argmin(angles[:, np.argmin(angles[i])]) == i and angles[i].min() <= gate]
    assert list(zip(oi.tolist(), pi.tolist())) == brute
    assert len(set(pi.tolist())) == len(pi)
    assert set(oi.tolist()) == set(range(25))  # the 25 true stars, none of the 5 strays


@pytest.mark.parametrize("n", [3, 4, 10, 30])
def test_wahba_svd_equals_attitude_layer(n):
    rng = np.random.default_rng(n)
    for _ in range(50):
        R = Rotation.random(random_state=rng).as_matrix()
        b = rng.normal(size=(n, 3)) * [0.1, 0.1, 0.0] + [0, 0, 1]
        b /= np.linalg.norm(b, axis=1, keepdims=True)
        obs = b + rng.normal(0, 1e-4, b.shape)
        obs /= np.linalg.norm(obs, axis=1, keepdims=True)
        ref = b @ R.T
        difference = Rotation.from_matrix(wahba_svd(ref, obs)).inv() * Rotation.from_matrix(SvdWahba().solve(ref, obs).R_IS)
        # rad; rounding level: Jacobi on BᵀB squares B's condition number (>= 1e2 for a 0.1 rad field; 2.7e-11 seen),
        # and 1e-9 is 1e-5 of the attitude's sigma (1e-4 rad / √n)
        assert difference.magnitude() < 1e-9


@pytest.fixture(scope="module")
def catalog():
    return load_navigation_catalog()


def test_field_cells_hold_every_star_in_the_field(catalog):
    """Brute force over all stars: the cell of any boresight contains every star the camera sees."""
    camera = Camera.from_fov(np.radians(16.0), 1024, 1024)
    stars = load_star_catalog(2000.0)
    field = FieldStars.from_star_catalog(catalog, camera, stars, 6.0)
    rng = np.random.default_rng(5)
    quaternions = np.concatenate([Rotation.random(300, random_state=rng).as_quat(),
                                  Rotation.from_euler("yx", [[0, 89.9], [0, -89.9], [30, 89.0]], degrees=True).as_quat()])
    for q in quaternions:
        R = Rotation.from_quat(q).as_matrix()
        seen = set(field.hip[camera.stars_in_field(q, field.vectors)].tolist())
        predicted = set(field.hip[field.in_field(R)[0]].tolist())
        assert seen == predicted


def test_close_pairs_are_left_out_of_the_field_stars(catalog):
    camera = Camera.from_fov(np.radians(16.0), 1024, 1024)
    field = FieldStars.from_star_catalog(catalog, camera, load_star_catalog(2000.0), 6.0, resolution_px=3.0)
    separation = np.arccos(np.clip(field.vectors @ field.vectors.T, -1, 1))
    np.fill_diagonal(separation, np.inf)
    assert separation.min() * camera.focal_px >= 3.0
    assert 71683 not in field.hip and 71681 not in field.hip  # alpha Cen A/B, 0.2 px apart in 2000


def test_kvector_ranges_contain_the_exact_ranges(catalog):
    table = PairTable.full_sky(catalog)
    rng = np.random.default_rng(9)
    for _ in range(200):
        low = rng.uniform(0.0, 0.3)
        high = low + rng.uniform(0.0, 3e-3)
        lo, hi = kvector_range(table.theta, table.k, table.slope, table.intercept, low, high)
        exact_lo, exact_hi = np.searchsorted(table.theta, low), np.searchsorted(table.theta, high, "right")
        assert lo <= exact_lo and hi >= exact_hi and hi - lo <= exact_hi - exact_lo + 16  # a bucket or two each side
        assert pair_range(table.arrays, low, high) == (exact_lo, exact_hi)
