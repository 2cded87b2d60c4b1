"""The least-squares fit of attitude and intrinsics (startrack.camera.fit) against independent references:
the exact camera (noise-free), scipy's least_squares on the same data with the model written through
startrack.camera.model.Camera, and the scatter of seeded Monte Carlo fits against the covariance it reports."""

import numpy as np
import pytest
from scipy.optimize import least_squares

from startrack.camera.fit import CameraCalibration, fit
from startrack.camera.model import Camera
from startrack.camera.projection_kernels import camera_array
from startrack.geometry.rotation import from_matrix, from_rotation_vector, to_matrix, to_rotation_vector
from startrack.image.synthetic import random_attitude

TRUE = Camera(1024, 768, 2100.0, cx=520.0, cy=380.0, k1=-0.12, k2=0.03)
FREE_ALL = np.array([True, True, True, True, True])
NO_PRIOR = (np.zeros(5), np.full(5, np.inf))


def _stars(rng, n=150):
    """Unit vectors in I of n stars spread over TRUE's image, and the attitude q_IS."""
    q_IS = random_attitude(rng)
    uv = rng.uniform([10.0, 10.0], [1014.0, 758.0], (n, 2))
    return TRUE.unproject(uv) @ to_matrix(q_IS).T, q_IS


def _params(camera):
    return camera_array(camera)


def _start(q_IS):
    """A start 1 % off in f, 4 px in the principal point, k's at zero, the attitude 0.2 deg off."""
    wrong = Camera(1024, 768, 2121.0, cx=516.0, cy=384.0)
    R = to_matrix(q_IS) @ to_matrix(from_rotation_vector(np.radians([0.1, -0.15, 0.05])))
    return R, _params(wrong)


def test_noise_free_stars_give_the_camera_back():
    rng = np.random.default_rng(1)
    ref_I, q_IS = _stars(rng)
    uv, _ = TRUE.project(q_IS, ref_I)
    ok, R, params, covariance, reduced = fit(uv, np.full(len(uv), 0.1), ref_I, *_start(q_IS), FREE_ALL, *NO_PRIOR, 20)
    # rms residual < 1e-7 px (reduced chi^2 at sigma 0.1 px): far below any centroid error, far above rounding
    assert ok and reduced < 1e-12
    # Each parameter within 1e-3 of its sigma from the fit's covariance: the fit's own stopping rule (CONVERGED:
    # no step above 1e-3 sigma); noise-free Gauss-Newton converges quadratically, so the error left is far smaller.
    sigma = np.sqrt(np.diag(covariance))
    error = params[[0, 1, 2, 5, 6]] - [2100.0, 520.0, 380.0, -0.12, 0.03]
    np.testing.assert_allclose(error / sigma[3:], 0.0, rtol=0, atol=1e-3)
    dtheta = to_rotation_vector(from_matrix(to_matrix(q_IS).T @ R))  # attitude error in S, the fit's dtheta
    np.testing.assert_allclose(dtheta / sigma[:3], 0.0, rtol=0, atol=1e-3)


def test_same_solution_as_scipy_least_squares():
    rng = np.random.default_rng(2)
    ref_I, q_IS = _stars(rng)
    uv = TRUE.project(q_IS, ref_I)[0] + rng.normal(0.0, 0.2, (len(ref_I), 2))
    ok, R, params, covariance, _ = fit(uv, np.full(len(uv), 0.2), ref_I, *_start(q_IS), FREE_ALL, *NO_PRIOR, 20)
    R0, start = _start(q_IS)

    def residuals(x):  # the attitude R0 exp([x[:3] x]) and the intrinsics x[3:], projected by Camera
        camera = Camera(1024, 768, x[3], cx=x[4], cy=x[5], k1=x[6], k2=x[7])
        R_IS = R0 @ to_matrix(from_rotation_vector(x[:3]))
        return (camera.project_body(ref_I @ R_IS)[0] - uv).ravel()

    reference = least_squares(residuals, np.r_[np.zeros(3), start[[0, 1, 2, 5, 6]]], x_scale="jac", xtol=1e-14,
                              ftol=1e-14, gtol=1e-14)
    # 1 % of each parameter's sigma from the fit's covariance: the fit stops when no step exceeds 1e-3 sigma
    # (CONVERGED), scipy at xtol/ftol 1e-14; they differ by ~1e-5 sigma (k2: 1.2e-6 against a sigma of 0.11).
    sigma = np.sqrt(np.diag(covariance))
    np.testing.assert_allclose((params[[0, 1, 2, 5, 6]] - reference.x[3:]) / sigma[3:], 0.0, rtol=0, atol=1e-2)
    R_reference = R0 @ to_matrix(from_rotation_vector(reference.x[:3]))
    dtheta = to_rotation_vector(from_matrix(R_reference.T @ R))  # the attitude difference in S, the fit's dtheta
    np.testing.assert_allclose(dtheta / sigma[:3], 0.0, rtol=0, atol=1e-2)  # likewise 1 % of its sigma


def test_reported_sigma_matches_the_scatter_of_fits():
    rng = np.random.default_rng(3)
    ref_I, q_IS = _stars(rng, 80)
    clean = TRUE.project(q_IS, ref_I)[0]
    estimates, sigmas = [], []
    for _ in range(200):
        uv = clean + rng.normal(0.0, 0.3, clean.shape)
        ok, _, params, covariance, _ = fit(uv, np.full(len(uv), 0.3), ref_I, *_start(q_IS), FREE_ALL, *NO_PRIOR, 20)
        assert ok
        estimates.append(params[[0, 5]])
        sigmas.append(np.sqrt(np.diag(covariance)[[3, 6]]))
    spread = np.std(estimates, axis=0)
    reported = np.mean(sigmas, axis=0)
    np.testing.assert_allclose(spread / reported, 1.0, atol=0.15)  # 200 draws: 5 % statistical error


def test_too_few_stars_are_reported_not_raised():
    rng = np.random.default_rng(4)
    ref_I, q_IS = _stars(rng, 2)
    uv, _ = TRUE.project(q_IS, ref_I)
    ok = fit(uv, np.full(2, 0.1), ref_I, *_start(q_IS), FREE_ALL, *NO_PRIOR, 5)[0]
    assert not ok


def test_calibration_record_sigma_and_centre():
    calibration = CameraCalibration(TRUE, np.diag([1e-10, 1e-10, 1e-10, 4.0, 1.0, 1.0, 1e-4, 0.0]), 1.0, 0.2, 50, 60, 7.5)
    sigma = calibration.sigma  # rounding level (default approx): square roots of the diagonal given above
    assert sigma["focal_px"] == pytest.approx(2.0) and sigma["k1"] == pytest.approx(0.01) and sigma["k2"] == 0.0
    assert sigma["fov_deg"] > 0.0
    q_IS = random_attitude(np.random.default_rng(5))
    ra, dec, _ = calibration.camera.center_radec_roll(q_IS)
    centre = TRUE.unproject([[511.5, 383.5]])[0] @ to_matrix(q_IS).T  # rounding level: closed forms of one direction
    assert np.allclose(centre, [np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)], atol=1e-12)
