"""Boresight (optical-axis) solves of 001 ch. 2-3 in the contest's geometry (12 x 12 deg, 512 px)."""

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from startrack.attitude import boresight as bs
from startrack.base.errors import InputError

ARCSEC = np.pi / 180.0 / 3600.0
FOCAL = 256.0 / np.tan(np.radians(6.0))       # 001 2.1.3: f = 256 / tan 6 deg ~ 2435.7 px
SIGMA_PX = 0.05


def angle(a, b):
    return np.arctan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b))


def scene(seed, n):
    """(ref_I (n, 3), xy (n, 2) [px], R_IS, boresight_I) of n stars uniform on a 512 x 512 image."""
    rng = np.random.default_rng(seed)
    R_IS = Rotation.random(random_state=rng).as_matrix()
    xy = rng.uniform(-255.5, 255.5, size=(n, 2))
    ref = bs.sensor_directions(xy, FOCAL) @ R_IS.T
    return ref, xy, R_IS, R_IS[:, 2], rng


@pytest.mark.parametrize("seed", range(4))
def test_noiseless_recovery_every_model(seed):
    ref, xy, R_IS, w, _ = scene(seed, 10)
    radii = np.hypot(xy[:, 0], xy[:, 1])
    t = [0, 1, 2]
    solutions = [
        bs.solve_scalar_known_f(ref[t], radii[t], FOCAL),
        bs.solve_scalar_known_f(ref[t], radii[t], FOCAL, method="linearised"),
        bs.solve_scalar_unknown_f(ref[t], radii[t], (1000.0, 6000.0)),
        bs.solve_vector_known_f(ref[t], xy[t], FOCAL),
        bs.solve_vector_unknown_f(ref[t], xy[t]),
        bs.solve_vector_unknown_f(ref[t], xy[t], method="numeric", focal_bounds_px=(1000.0, 6000.0)),
        bs.solve_scalar_all_stars(ref, radii, FOCAL),
        bs.solve_scalar_all_stars(ref, radii, FOCAL, method="constrained"),
        bs.solve_vector_all_stars(ref, xy, FOCAL),
        bs.solve_vector_all_stars(ref, xy),
        bs.solve_vector_constrained(ref, xy, focal_px=FOCAL),
        bs.solve_vector_constrained(ref, xy),
    ]
    # Noise-free: 1e-4" is 1.2e-6 px at f = 2436 px, 2e-5 of the 0.05 px centroid noise; f to 1e-9 (2.4e-6 px);
    # the iterative solves stop far below (brentq at xtol 1e-15, Ipopt at tol 1e-14: 2e-13 rad, 5e-13 of f seen)
    for solution in solutions:
        assert angle(solution.boresight_I, w) < 1e-4 * ARCSEC, solution.method
        assert solution.focal_px == pytest.approx(FOCAL, rel=1e-9), solution.method
        if solution.q_IS is not None:
            R = Rotation.from_quat(solution.q_IS).as_matrix()
            assert np.abs(R - R_IS).max() < 1e-9, solution.method


def test_scalar_triple_error_within_the_error_bound_of_2_3_1():
    """|w - w_true| <= |M| |da| (001 2.3.1) for small radius errors, M from the measured data."""
    ref, xy, _, w, rng = scene(11, 3)
    radii = np.hypot(xy[:, 0], xy[:, 1])
    for _ in range(200):
        da = rng.normal(scale=SIGMA_PX, size=3)
        solution = bs.solve_scalar_known_f(ref, radii + da, FOCAL)
        _, norms = bs.error_bound_norms(ref, FOCAL, radii_px=radii + da)
        assert angle(solution.boresight_I, w) <= 1.001 * norms[0] * np.linalg.norm(da)


def test_bound_norm_is_the_first_order_sensitivity():
    """The largest error direction of M, applied as da, moves w by |M| |da| to first order."""
    ref, xy, _, w, _ = scene(12, 3)
    radii = np.hypot(xy[:, 0], xy[:, 1])
    b = bs.cos_gamma(radii, FOCAL)
    slope = -FOCAL * radii / (FOCAL ** 2 + radii ** 2) ** 1.5
    M = (np.eye(3) - np.outer(w, w)) @ np.linalg.inv(ref) @ np.diag(slope)
    _, s, Vt = np.linalg.svd(M)
    da = 1e-3 * Vt[0]
    moved = bs.solve_scalar_known_f(ref, radii + da, FOCAL).boresight_I
    assert angle(moved, w) == pytest.approx(s[0] * 1e-3, rel=1e-3)
    _, norms = bs.error_bound_norms(ref, FOCAL, radii_px=radii)
    assert norms[0] == pytest.approx(s[0], rel=1e-12)  # rounding level: the same spectral norm of the same M
    assert b.shape == (3,)


def test_noisy_solves_recover_the_axis():
    """sigma = 0.05 px: every estimator's RMS error stays within a few times the vector-triple RMS."""
    ref, xy, R_IS, w, rng = scene(13, 12)
    t = [0, 5, 9]
    errors = {}
    for _ in range(60):
        xy_n = xy + rng.normal(scale=SIGMA_PX, size=xy.shape)
        radii = np.hypot(xy_n[:, 0], xy_n[:, 1])
        for solution in (bs.solve_scalar_known_f(ref[t], radii[t], FOCAL),
                         bs.solve_scalar_known_f(ref[t], radii[t], FOCAL, method="linearised"),
                         bs.solve_vector_known_f(ref[t], xy_n[t], FOCAL),
                         bs.solve_vector_unknown_f(ref[t], xy_n[t]),
                         bs.solve_scalar_all_stars(ref, radii, FOCAL),
                         bs.solve_scalar_all_stars(ref, radii, FOCAL, method="constrained"),
                         bs.solve_vector_all_stars(ref, xy_n, FOCAL),
                         bs.solve_vector_constrained(ref, xy_n, focal_px=FOCAL)):
            errors.setdefault(solution.method, []).append(angle(solution.boresight_I, w))
    rms = {k: np.sqrt(np.mean(np.square(v))) / ARCSEC for k, v in errors.items()}
    pixel = SIGMA_PX / FOCAL / ARCSEC          # 0.05 px ~ 4.2 arcsec
    for method, value in rms.items():
        assert value < 10 * pixel, (method, value)
    assert rms["vector_all_stars_ols"] < rms["vector_known_f_svd"]
    assert rms["scalar_all_stars_ols"] < rms["scalar_known_f_normalised"]


def test_constrained_ls_is_the_minimum_on_the_sphere():
    ref, xy, _, w, rng = scene(14, 15)
    radii = np.hypot(*(xy + rng.normal(scale=1.0, size=xy.shape)).T)    # large noise: OLS != CLS
    b = bs.cos_gamma(radii, FOCAL)
    cls = bs.solve_scalar_all_stars(ref, radii, FOCAL, method="constrained").boresight_I
    ols = bs.solve_scalar_all_stars(ref, radii, FOCAL).boresight_I

    def cost(v):
        return np.sum((ref @ (v / np.linalg.norm(v)) - b) ** 2)

    brute = minimize(cost, ols, method="Nelder-Mead", options={"xatol": 1e-13, "fatol": 1e-22, "maxiter": 20000}).x
    # cls is the exact minimum (its brentq root at xtol 1e-15): above Nelder-Mead's cost by rounding alone
    assert cost(cls) <= cost(brute) * (1 + 1e-9) + 1e-24
    assert cost(cls) <= cost(ols)
    # 0.01", 1e-4 of the 1 px noise's 85": Nelder-Mead (xatol 1e-13) may stop short of the minimum, not by that
    assert angle(cls, brute / np.linalg.norm(brute)) < 0.01 * ARCSEC


def test_collinear_stars_give_two_candidates_one_true():
    _, _, R_IS, w, _ = scene(15, 3)
    s = np.array([-200.0, 40.0, 170.0])
    xy = np.column_stack([s, 0.4 * s + 60.0])           # a straight image line = a great circle
    ref = bs.sensor_directions(xy, FOCAL) @ R_IS.T
    solution = bs.solve_scalar_known_f(ref, np.hypot(xy[:, 0], xy[:, 1]), FOCAL)
    assert solution.candidates.shape == (2, 3)
    # noise-free: 1 mas, 1e-5 px (1e-9" seen); the candidates are unit vectors to rounding
    assert min(angle(c, w) for c in solution.candidates) < 1e-3 * ARCSEC
    np.testing.assert_allclose(np.linalg.norm(solution.candidates, axis=1), 1.0)
    with pytest.raises(InputError, match="misses the unit sphere"):    # every star claimed on the axis
        bs.solve_scalar_known_f(ref, np.zeros(3), FOCAL)


def test_rank_one_and_degenerate_inputs_raise():
    ref, xy, _, _, _ = scene(16, 3)
    radii = np.hypot(xy[:, 0], xy[:, 1])
    same = np.repeat(ref[:1], 3, axis=0)
    with pytest.raises(InputError, match="rank"):
        bs.solve_scalar_known_f(same, radii, FOCAL)
    with pytest.raises(InputError, match="method"):
        bs.solve_scalar_known_f(ref, radii, FOCAL, method="magic")
    with pytest.raises(InputError, match="focal_px"):
        bs.solve_vector_known_f(ref, xy, -1.0)
    with pytest.raises(InputError, match="exactly 3"):
        bs.solve_vector_known_f(np.vstack([ref, ref[:1]]), np.vstack([xy, xy[:1]]), FOCAL)
    with pytest.raises(InputError, match="radii_px"):
        bs.solve_scalar_known_f(ref, [1.0, np.nan, 2.0], FOCAL)


def test_no_real_positive_root_of_the_focal_cubic():
    """Three distinct catalog stars imaged on one point: the cubic's only root is t = -rho^2 < 0."""
    ref, _, _, _, _ = scene(17, 3)
    xy = np.array([[100.0, 50.0]] * 3)
    with pytest.raises(InputError, match="no real positive root"):
        bs.focal_from_angular_distances(ref, xy)
    with pytest.raises(InputError, match="no real positive root"):
        bs.solve_vector_unknown_f(ref, xy)


def test_unknown_f_outside_bounds_is_reported():
    ref, xy, _, _, _ = scene(18, 3)
    radii = np.hypot(xy[:, 0], xy[:, 1])
    with pytest.raises(InputError, match="no focal length"):
        bs.solve_scalar_unknown_f(ref, radii, (100.0, 200.0))
    with pytest.raises(InputError, match="f_min < f_max"):
        bs.solve_scalar_unknown_f(ref, radii, (300.0, 200.0))


def test_best_triple_is_the_minimum_norm_triple():
    ref, xy, _, _, _ = scene(19, 7)
    triples, norms = bs.error_bound_norms(ref, FOCAL, xy_px=xy)
    assert len(triples) == 35
    best = bs.best_triple(ref, FOCAL, xy_px=xy)
    np.testing.assert_array_equal(best, triples[np.argmin(norms)])
    # brute force of the vector bound |P^-1 N_3| for one triple
    t = triples[3]
    rho2 = np.sum(xy[t] ** 2, axis=1)
    N3 = np.zeros((3, 6))
    for i in range(3):
        N3[i, 2 * i:2 * i + 2] = -FOCAL * xy[t[i]] / (FOCAL ** 2 + rho2[i]) ** 1.5
    assert norms[3] == pytest.approx(np.linalg.norm(np.linalg.inv(ref[t]) @ N3, 2), rel=1e-12)  # rounding level
    with pytest.raises(InputError, match="exactly one"):
        bs.error_bound_norms(ref, FOCAL)


def test_casadi_constrained_fit_with_unknown_f():
    ref, xy, R_IS, w, rng = scene(20, 14)
    xy_n = xy + rng.normal(scale=SIGMA_PX, size=xy.shape)
    fit = bs.solve_vector_constrained(ref, xy_n)
    assert fit.method == "vector_constrained_ipopt"
    assert fit.focal_px == pytest.approx(FOCAL, rel=2e-3)
    assert angle(fit.boresight_I, w) < 10 * SIGMA_PX / FOCAL

    def cost(R, f):
        return np.sum((ref @ R.T - bs.sensor_directions(xy_n, f)) ** 2)

    start = bs.solve_vector_all_stars(ref, xy_n)              # closed form: f from the cubic, R by SVD
    R_fit = Rotation.from_quat(fit.q_IS).as_matrix().T
    R_start = Rotation.from_quat(start.q_IS).as_matrix().T
    assert cost(R_fit, fit.focal_px) <= cost(R_start, start.focal_px) + 1e-18
    with pytest.raises(InputError, match="f_min < f_max"):
        bs.solve_vector_constrained(ref, xy_n, focal_bounds_px=(10.0, 5.0))
