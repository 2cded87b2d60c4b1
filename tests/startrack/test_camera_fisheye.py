"""The fisheye camera (equidistant with radial terms, Kannala & Brandt 2006) against closed forms: the
equisolid and stereographic lenses' radii, the hemisphere's solid angle, the projection's round trip, its
Jacobian against central differences, the fit against scipy's least_squares, and the ZPN WCS against
astropy."""

import math

import numpy as np
import pytest
from scipy.optimize import least_squares

from startrack.base.errors import InputError
from startrack.base.units import ARCSEC, DEG
from startrack.camera.file import read_camera_file, write_camera_file
from startrack.camera.fit import CameraCalibration, _jacobian_rows, fit
from startrack.camera.model import Camera
from startrack.camera.projection_kernels import camera_array, project_one
from startrack.geometry.rotation import from_matrix, from_rotation_vector, to_matrix, to_rotation_vector
from startrack.geometry.sphere import vector_to_radec
from startrack.identify.verify import field_solid_angle
from startrack.image.synthetic import random_attitude

#: A 140 deg fisheye (f = 420 px over 1024 px) with an off-centre principal point.
FISHEYE = Camera(1024, 768, 420.0, cx=520.0, cy=380.0, k1=-0.04, k2=0.002, projection="fisheye")


def _off_axis(camera, theta):
    """Directions in S at angles ``theta`` (n,) [rad] from the axis, azimuths spread round the circle."""
    phi = np.linspace(0.0, 2.0 * math.pi, theta.size, endpoint=False)
    return np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


@pytest.mark.parametrize("name, k1, k2, radius", [
    ("equisolid", -1.0 / 24.0, 1.0 / 1920.0, lambda t: 2.0 * np.sin(t / 2.0)),
    ("stereographic", 1.0 / 12.0, 1.0 / 120.0, lambda t: 2.0 * np.tan(t / 2.0))])
def test_the_radial_terms_reach_the_classic_fisheye_lenses(name, k1, k2, radius):
    """theta (1 + k1 theta^2 + k2 theta^4) is the Taylor series of 2 sin(theta/2) (stereographic: 2 tan) to
    theta^5: out to 60 deg the image radius agrees with the closed form within the theta^7 remainder."""
    camera = Camera(2001, 2001, 800.0, k1=k1, k2=k2, projection="fisheye")
    theta = np.linspace(0.0, 60.0 * DEG, 61)
    uv, visible = camera.project_body(_off_axis(camera, theta))
    r = np.hypot(uv[:, 0] - camera.cx, uv[:, 1] - camera.cy)
    remainder = {"equisolid": 1.0 / 322560.0, "stereographic": 17.0 / 20160.0}[name] * theta**7 * camera.focal_px
    assert visible.all()
    assert np.all(np.abs(r - camera.focal_px * radius(theta)) <= 1.2 * remainder + 1e-9)


def test_projection_round_trip_beyond_ninety_degrees():
    """unproject(project(v)) = v to rounding over a 190 deg circular fisheye, directions behind the lens's
    plane included (z < 0), and the field's angles: fov_x = W / f for an undistorted one."""
    camera = Camera(2000, 2000, 2000.0 / (190.0 * DEG), projection="fisheye", k1=0.01, k2=-0.001)
    rng = np.random.default_rng(1)
    theta = rng.uniform(0.0, 94.0 * DEG, 500)
    v = _off_axis(camera, theta)
    uv, visible = camera.project_body(v)
    assert visible.all() and (v[:, 2] < 0).any()
    np.testing.assert_allclose(camera.unproject(uv), v, rtol=0, atol=1e-12)
    plain = Camera(2000, 1000, 600.0, projection="fisheye")
    assert plain.fov_x == pytest.approx(2000.0 / 600.0, abs=1e-15) and plain.angular_width == pytest.approx(plain.fov_x)


def test_solid_angle_of_a_hemisphere():
    """A circular 180 deg fisheye sees 2 pi sr; the sum over 256^2 blocks misses the circle's edge by about a
    block's share of its perimeter (~1 %)."""
    camera = Camera(1000, 1000, 1000.0 / math.pi, projection="fisheye", circular_fov=True)
    assert field_solid_angle(camera, blocks=256) == pytest.approx(2.0 * math.pi, rel=0.01)


def test_jacobian_against_central_differences():
    """d(u, v)/d(dtheta, f, cx, cy, k1, k2) of the compiled fit against central differences of its own
    projection (steps 1e-6 rad and 1e-6 of each intrinsic: truncation and rounding both ~1e-7 px)."""
    params = camera_array(FISHEYE)
    rows, scratch = np.empty((2, 8)), np.empty((2, 3))
    for v in _off_axis(FISHEYE, np.radians([0.0, 1e-6, 5.0, 40.0, 75.0, 100.0])):
        _jacobian_rows(v, params, rows, scratch)
        for p in range(8):
            step = 1e-6
            if p < 3:
                turn = np.zeros(3)
                turn[p] = step
                ends = [to_matrix(from_rotation_vector(sign * turn)).T @ v for sign in (1.0, -1.0)]  # v_S after R exp(dtheta)
                numeric = (np.array(project_one(*ends[0], params)) - np.array(project_one(*ends[1], params))) / (2 * step)
            else:
                moved = [params.copy(), params.copy()]
                index = (0, 1, 2, 5, 6)[p - 3]
                moved[0][index] += step
                moved[1][index] -= step
                numeric = (np.array(project_one(*v, moved[0])) - np.array(project_one(*v, moved[1]))) / (2 * step)
            np.testing.assert_allclose(rows[:, p], numeric, rtol=0, atol=2e-4 * max(1.0, np.abs(numeric).max()))


def _stars(rng, n=150):
    q_IS = random_attitude(rng)
    uv = rng.uniform([10.0, 10.0], [1014.0, 758.0], (n, 2))
    return FISHEYE.unproject(uv) @ to_matrix(q_IS).T, q_IS


def _start(q_IS):
    """1 % off in f, 4 px in the principal point, the k's at zero, the attitude 0.2 deg off."""
    wrong = Camera(1024, 768, 424.2, cx=516.0, cy=384.0, projection="fisheye")
    return to_matrix(q_IS) @ to_matrix(from_rotation_vector(np.radians([0.1, -0.15, 0.05]))), camera_array(wrong)


def test_fit_recovers_a_fisheye_and_agrees_with_scipy():
    """Noise-free stars give the camera back (within 1e-3 of each sigma: the fit's stopping rule); with
    0.2 px of noise the fit lands where scipy's least_squares on the Camera class's projection does (within
    1 % of each sigma)."""
    free, no_prior = np.ones(5, bool), (np.zeros(5), np.full(5, np.inf))
    rng = np.random.default_rng(2)
    ref_I, q_IS = _stars(rng)
    exact = FISHEYE.project(q_IS, ref_I)[0]
    ok, R, params, covariance, reduced = fit(exact, np.full(len(exact), 0.1), ref_I, *_start(q_IS), free, *no_prior, 20)
    sigma = np.sqrt(np.diag(covariance))
    assert ok and reduced < 1e-12
    np.testing.assert_allclose((params[[0, 1, 2, 5, 6]] - [420.0, 520.0, 380.0, -0.04, 0.002]) / sigma[3:], 0.0, atol=1e-3)
    uv = exact + rng.normal(0.0, 0.2, exact.shape)
    ok, R, params, covariance, _ = fit(uv, np.full(len(uv), 0.2), ref_I, *_start(q_IS), free, *no_prior, 20)
    R0, start = _start(q_IS)

    def residuals(x):
        camera = Camera(1024, 768, x[3], cx=x[4], cy=x[5], k1=x[6], k2=x[7], projection="fisheye")
        return (camera.project_body(ref_I @ (R0 @ to_matrix(from_rotation_vector(x[:3]))))[0] - uv).ravel()

    reference = least_squares(residuals, np.r_[np.zeros(3), start[[0, 1, 2, 5, 6]]], x_scale="jac", xtol=1e-14,
                              ftol=1e-14, gtol=1e-14)
    sigma = np.sqrt(np.diag(covariance))
    np.testing.assert_allclose((params[[0, 1, 2, 5, 6]] - reference.x[3:]) / sigma[3:], 0.0, atol=1e-2)
    dtheta = to_rotation_vector(from_matrix((R0 @ to_matrix(from_rotation_vector(reference.x[:3]))).T @ R))
    np.testing.assert_allclose(dtheta / sigma[:3], 0.0, atol=1e-2)


def test_camera_file_keeps_the_projection(tmp_path):
    calibration = CameraCalibration(FISHEYE, np.diag([1e-10] * 3 + [1.0, 0.5, 0.5, 1e-4, 1e-6]), 1.0, 0.2, 50, 60, 6.0)
    path = write_camera_file(tmp_path / "fisheye.toml", calibration, "frame.png")
    assert read_camera_file(path).camera == FISHEYE
    bad = tmp_path / "bad.toml"
    bad.write_text(path.read_text().replace('projection = "fisheye"', 'projection = "fish"'))
    with pytest.raises(InputError, match="projection 'fish'"):
        read_camera_file(bad)


def test_zpn_wcs_reproduces_the_fisheye():
    """astropy.wcs reads the ZPN header (CD, PV2_1/3/5) back to the camera model within 0.01" over a 150 deg
    field, and maps the directions back to the pixels within 1e-6 px."""
    from astropy.io import fits
    from astropy.wcs import WCS

    from startrack.camera.wcs import frame_wcs

    camera = Camera(1600, 1200, 1600.0 / (150.0 * DEG), cx=790.3, cy=610.2, k1=1.0 / 12.0, k2=1.0 / 120.0,
                    projection="fisheye")
    q_IS = from_rotation_vector(np.array([0.4, 1.1, 0.3]))
    wcs = WCS(fits.Header(frame_wcs(camera, q_IS).cards()))
    u, v = np.meshgrid(np.linspace(-0.5, 1599.5, 21), np.linspace(-0.5, 1199.5, 21))
    uv = np.column_stack([u.ravel(), v.ravel()])
    truth = camera.unproject(uv) @ to_matrix(q_IS).T
    ra, dec = np.radians(wcs.all_pix2world(uv[:, 0] + 1.0, uv[:, 1] + 1.0, 1))
    seen = np.column_stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])
    assert np.arccos(np.clip(np.sum(seen * truth, axis=1), -1.0, 1.0)).max() < 0.01 * ARCSEC
    ra_t, dec_t = vector_to_radec(truth)
    back = np.column_stack(wcs.all_world2pix(np.degrees(ra_t), np.degrees(dec_t), 1)) - 1.0
    np.testing.assert_allclose(back, uv, rtol=0, atol=1e-6)
