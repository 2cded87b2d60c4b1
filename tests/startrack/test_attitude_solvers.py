"""Attitude solvers: exact recovery, Monte Carlo against their covariance and the Cramer-Rao bound,
agreement with scipy's align_vectors and with the ahrs package."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from startrack.attitude.solvers import SOLVERS, cramer_rao_covariance, get_solver
from startrack.base.errors import InputError

ARCSEC = np.pi / 180.0 / 3600.0
ALL = list(SOLVERS)
OPTIMAL = ["svd", "q_method", "quest"]


def star_field(rng, n, half_fov_deg=8.0):
    """n unit vectors in S uniform on the focal plane of a 2*half_fov square field."""
    t = np.tan(np.radians(half_fov_deg))
    xy = rng.uniform(-t, t, size=(n, 2))
    v = np.column_stack([xy, np.ones(n)])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def perturb(rng, obs, sigma, trials):
    """(trials, N, 3) noisy unit vectors: tangential Gaussian noise of per-axis std sigma [rad]."""
    noise = rng.normal(size=(trials,) + obs.shape) * np.reshape(sigma, (1, -1, 1))
    noise -= np.sum(noise * obs, axis=-1, keepdims=True) * obs
    noisy = obs + noise
    return noisy / np.linalg.norm(noisy, axis=-1, keepdims=True)


def attitude_error(q_est, q_true):
    """Rotation vectors dtheta [rad] in S axes with R_true = R_est exp([dtheta x])."""
    return (Rotation.from_quat(q_est).inv() * Rotation.from_quat(q_true)).as_rotvec()


ATTITUDES = [Rotation.from_euler("zyx", [30, 40, 10], degrees=True).as_quat(),
             np.array([1.0, 0.0, 0.0, 0.0]),                  # 180 deg about x: QUEST's singular case
             np.array([0.0, 0.6, 0.8, 0.0]),                  # 180 deg about an oblique axis
             np.array([0.0, 0.0, 0.0, 1.0])]


@pytest.mark.parametrize("name", ALL)
@pytest.mark.parametrize("n", [3, 10])
@pytest.mark.parametrize("case", range(len(ATTITUDES)))
def test_noiseless_exact_recovery(name, n, case):
    rng = np.random.default_rng(100 + case)
    q_true = ATTITUDES[case]
    obs = star_field(rng, n)
    ref = obs @ Rotation.from_quat(q_true).as_matrix().T
    solution = get_solver(name).solve(ref, obs, 1.0 * ARCSEC)
    # 10 µas, 1e-5 of the stars' 1" sigma: exact data leave rounding (amplified by the narrow field's roll
    # conditioning; 2e-14 rad seen) and QUEST's Newton, which stops at 1e-15 in λ
    assert np.linalg.norm(attitude_error(solution.q_IS, q_true)) < 1e-5 * ARCSEC
    assert solution.residuals.shape == (n,) and solution.residuals.max() < 1e-5 * ARCSEC
    assert solution.method == name and solution.q_IS[3] >= 0.0
    np.testing.assert_allclose(solution.R_IS, Rotation.from_quat(q_true).as_matrix(), atol=1e-12)  # likewise


def test_triad_two_stars():
    rng = np.random.default_rng(5)
    q_true = ATTITUDES[0]
    obs = star_field(rng, 2)
    ref = obs @ Rotation.from_quat(q_true).as_matrix().T
    for name in ("triad", "svd", "q_method", "quest"):
        solution = get_solver(name).solve(ref, obs, 2.0 * ARCSEC)
        assert np.linalg.norm(attitude_error(solution.q_IS, q_true)) < 1e-5 * ARCSEC  # as above


def monte_carlo_ratios(name, trials, seed):
    """(cross-boresight RMS / predicted, roll RMS / predicted, P) for a fixed 4-star geometry."""
    rng = np.random.default_rng(seed)
    q_true = ATTITUDES[0]
    obs = star_field(rng, 4)
    ref = obs @ Rotation.from_quat(q_true).as_matrix().T
    sigma = np.array([1.0, 1.5, 2.0, 1.2]) * 5.0 * ARCSEC
    solver = get_solver(name)
    P = solver.solve(ref, obs, sigma).P
    noisy = perturb(rng, obs, sigma, trials)
    q_est = np.array([solver.solve(ref, o, sigma).q_IS for o in noisy])
    err = attitude_error(q_est, q_true)
    cross = np.sqrt(np.mean(np.sum(err[:, :2] ** 2, axis=1)) / np.trace(P[:2, :2]))
    roll = np.sqrt(np.mean(err[:, 2] ** 2) / P[2, 2])
    return cross, roll, P, obs, sigma


@pytest.mark.parametrize("name", ALL)
def test_monte_carlo_matches_covariance(name):
    """4000 trials: the relative standard error of an RMS is ~1.1 %, so 5 % is a > 4-sigma test."""
    cross, roll, P, obs, sigma = monte_carlo_ratios(name, 4000, seed=7)
    assert abs(cross - 1.0) < 0.05
    assert abs(roll - 1.0) < 0.05
    crb = cramer_rao_covariance(obs, sigma)
    if name in OPTIMAL:  # rounding level: their P is the same closed-form inverse Fisher matrix
        np.testing.assert_allclose(P, crb, rtol=1e-10)
    else:   # an inefficient estimator never beats the bound: P - CRB is positive semi-definite (to rounding)
        assert np.linalg.eigvalsh(P - crb).min() > -1e-12 * np.trace(crb)


@pytest.mark.slow
@pytest.mark.parametrize("name", ALL)
def test_monte_carlo_matches_covariance_tight(name):
    """40000 trials: relative standard error ~0.35 %, tolerance 2 %."""
    cross, roll, *_ = monte_carlo_ratios(name, 40000, seed=11)
    assert abs(cross - 1.0) < 0.02
    assert abs(roll - 1.0) < 0.02


def test_triad_cross_boresight_variance_is_twice_the_bound_for_equal_stars():
    """Shuster & Oh: TRIAD's variance about the normal of two equal stars is sigma^2, the bound sigma^2/2."""
    obs = np.array([[0.0, 0.0, 1.0], [np.sin(0.1), 0.0, np.cos(0.1)]])
    sigma = 3.0 * ARCSEC
    P = get_solver("triad").solve(obs, obs, sigma).P
    crb = cramer_rao_covariance(obs, sigma)  # rounding level: closed forms
    assert P[1, 1] == pytest.approx(sigma ** 2, rel=1e-12)
    assert crb[1, 1] == pytest.approx(sigma ** 2 / 2, rel=1e-12)


@pytest.mark.parametrize("name", ALL)
def test_agrees_with_scipy_align_vectors(name):
    rng = np.random.default_rng(21)
    q_true = Rotation.from_euler("xyz", [120, -35, 70], degrees=True).as_quat()
    obs0 = star_field(rng, 12)
    ref = obs0 @ Rotation.from_quat(q_true).as_matrix().T
    sigma = rng.uniform(1.0, 4.0, 12) * ARCSEC
    obs = perturb(rng, obs0, sigma, 1)[0]
    solution = get_solver(name).solve(ref, obs, sigma)
    scipy_rotation, _ = Rotation.align_vectors(ref, obs, weights=sigma ** -2)
    diff = attitude_error(solution.q_IS, scipy_rotation.as_quat())
    if name in OPTIMAL:            # the same optimum of Wahba's loss (2e-14 rad seen): 1e-4", 1.5e-4 of the
        assert np.linalg.norm(diff) < 1e-4 * ARCSEC  # smallest sigma of P (3.1e-6 rad)
    else:                          # a different estimator: within its own error ellipsoid
        assert diff @ np.linalg.solve(solution.P, diff) < 30.0


def test_triad_matches_ahrs():
    ahrs = pytest.importorskip("ahrs")
    rng = np.random.default_rng(3)
    for _ in range(5):
        q_true = Rotation.random(random_state=rng).as_quat()
        ref = star_field(rng, 2, half_fov_deg=40.0)
        obs = perturb(rng, ref @ Rotation.from_quat(q_true).as_matrix(), np.full(2, 20 * ARCSEC), 1)[0]
        triad = ahrs.filters.TRIAD(v1=ref[0], v2=ref[1])
        A = triad.estimate(w1=obs[0], w2=obs[1])          # maps references to the body: R_IS^T
        ours = get_solver("triad").solve(ref, obs, 1.0 * ARCSEC).R_IS
        np.testing.assert_allclose(ours, A.T, atol=1e-12)  # rounding level: the same closed-form TRIAD


@pytest.mark.parametrize("name", OPTIMAL)
def test_two_vector_wahba_matches_ahrs_quest(name):
    ahrs = pytest.importorskip("ahrs")
    rng = np.random.default_rng(4)
    quest = ahrs.filters.QUEST()
    ref = np.array([quest.g_q, quest.m_q / np.linalg.norm(quest.m_q)])
    for _ in range(5):
        q_true = Rotation.from_rotvec(rng.uniform(-1.5, 1.5, 3)).as_quat()
        obs = perturb(rng, ref @ Rotation.from_quat(q_true).as_matrix(), np.full(2, 60 * ARCSEC), 1)[0]
        w, x, y, z = quest.estimate(acc=obs[0], mag=obs[1])  # scalar first, Shuster's q of A = R_IS^T
        theirs = np.array([x, y, z, w])
        ours = get_solver(name).solve(ref, obs, 1.0 * ARCSEC).q_IS
        # 1 mas, 2e-5 of the 60" noise: ahrs's Newton runs >= 11 passes (and to 1e-8 in λ), converged like
        # ours, so both give the same optimum (9e-15 rad seen)
        assert np.linalg.norm(attitude_error(ours, theirs)) < 1e-3 * ARCSEC


def test_cramer_rao_covariance_closed_form():
    """Two stars separated by theta: Fisher eigenvalues sigma^-2 (2, 1 + cos theta, 1 - cos theta)."""
    theta = 0.2
    obs = np.array([[np.sin(theta / 2), 0, np.cos(theta / 2)], [-np.sin(theta / 2), 0, np.cos(theta / 2)]])
    P = cramer_rao_covariance(obs, 2.0)  # rounding level (default rtol): closed forms
    np.testing.assert_allclose(np.diag(P), 4.0 / np.array([1 + np.cos(theta), 2.0, 1 - np.cos(theta)]))


@pytest.mark.parametrize("name", ALL)
def test_bad_input_raises_input_error(name):
    solver = get_solver(name)
    rng = np.random.default_rng(0)
    obs = star_field(rng, 4)
    with pytest.raises(InputError, match="shape"):
        solver.solve(obs[:, :2], obs)
    with pytest.raises(InputError, match="unit"):
        solver.solve(2.0 * obs, obs)
    bad = obs.copy()
    bad[1, 0] = np.nan
    with pytest.raises(InputError, match="unit"):
        solver.solve(obs, bad)
    with pytest.raises(InputError, match="sigma"):
        solver.solve(obs, obs, -1.0)
    with pytest.raises(InputError, match="sigma"):
        solver.solve(obs, obs, np.ones(3))
    with pytest.raises(InputError, match="at least"):
        solver.solve(obs[:1], obs[:1])


@pytest.mark.parametrize("name", ["triad", "three_star"])
def test_parallel_anchor_stars_raise(name):
    obs = np.array([[0, 0, 1.0], [0, 0, 1.0], [0.1, 0, np.sqrt(0.99)]])
    with pytest.raises(InputError, match="parallel"):
        get_solver(name).solve(obs, obs)


def test_unknown_solver_name():
    with pytest.raises(InputError, match="unknown attitude solver"):
        get_solver("foam")
