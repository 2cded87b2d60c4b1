"""Camera model: pinhole closed forms, round trips to 1e-9 px, distortion inverse, field tests."""

import dataclasses

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from startrack.base.errors import InputError
from startrack.camera.model import Camera
from startrack.geometry.attitude_angles import quaternion_from_radec_roll

DEG = np.pi / 180.0


def _random_pixels(camera, n, rng):
    return np.column_stack([rng.uniform(-0.5, camera.width - 0.5, n), rng.uniform(-0.5, camera.height - 0.5, n)])


@pytest.mark.parametrize("k1, k2", [(0.0, 0.0), (-0.3, 0.1), (0.2, 0.05)])
def test_pixel_round_trip_to_1e9_px(k1, k2):
    rng = np.random.default_rng(1)
    camera = Camera.from_fov(20 * DEG, 1024, 768, k1=k1, k2=k2, cx=515.2, cy=380.7)
    uv = _random_pixels(camera, 2000, rng)
    uv_back, visible = camera.project_body(camera.unproject(uv))
    assert np.all(visible)
    # 1e-9 px, far below any centroid error; the distortion inverse's Newton stops at 1e-16 of r (rounding, 1e-13 px)
    assert np.max(np.abs(uv_back - uv)) < 1e-9


@pytest.mark.parametrize("k1, k2", [(0.0, 0.0), (-0.3, 0.1)])
def test_inertial_round_trip_through_attitude(k1, k2):
    rng = np.random.default_rng(2)
    camera = Camera.from_fov(16 * DEG, 1024, 1024, k1=k1, k2=k2)
    q_IS = Rotation.random(random_state=3).as_quat()
    uv = _random_pixels(camera, 500, rng)
    v_I = Rotation.from_quat(q_IS).apply(camera.unproject(uv))
    uv_back, visible = camera.project(q_IS, v_I)
    assert np.all(visible)
    assert np.max(np.abs(uv_back - uv)) < 1e-9  # as above


def test_distortion_inverse_against_root_finding():
    camera = Camera.from_fov(30 * DEG, 1024, 1024, k1=-0.25, k2=0.08)
    rng = np.random.default_rng(4)
    xy_d = rng.uniform(-0.27, 0.27, (50, 2))
    xy_n = camera.undistort(xy_d)
    assert np.max(np.abs(camera.distort(xy_n) - xy_d)) < 1e-15  # rounding level: Newton stops at 1e-16 of r
    for (xd, yd), (xn, yn) in zip(xy_d, xy_n):
        rd = np.hypot(xd, yd)
        r = brentq(lambda r: r * (1 + camera.k1 * r**2 + camera.k2 * r**4) - rd, 0.0, 1.0, xtol=1e-15)
        # brentq stops within xtol 1e-15 + rtol 9e-16 r of the root (Newton at rounding): 1e-14 is ~8 times that
        assert np.hypot(xn, yn) == pytest.approx(r, abs=1e-14)
        assert np.arctan2(yn, xn) == pytest.approx(np.arctan2(yd, xd), abs=1e-13)  # rounding level: radial scaling


def test_pinhole_closed_form_and_fov():
    camera = Camera.from_fov(20 * DEG, 1024, 512)  # rounding level throughout: closed forms
    assert camera.focal_px == pytest.approx(512 / np.tan(10 * DEG), rel=1e-15)
    assert camera.fov_x == pytest.approx(20 * DEG, rel=1e-14)
    assert camera.fov_y == pytest.approx(2 * np.arctan(256 / camera.focal_px), rel=1e-14)
    assert camera.fov_diagonal == pytest.approx(2 * np.arctan(np.hypot(512, 256) / camera.focal_px), rel=1e-14)
    theta = 3.0 * DEG
    uv, visible = camera.project_body([[0, 0, 1], [np.sin(theta), 0, np.cos(theta)], [0, -np.sin(theta), np.cos(theta)]])
    assert np.all(visible)
    np.testing.assert_allclose(uv[0], [511.5, 255.5], atol=1e-12)
    np.testing.assert_allclose(uv[1], [511.5 + camera.focal_px * np.tan(theta), 255.5], atol=1e-10)
    np.testing.assert_allclose(uv[2], [511.5, 255.5 - camera.focal_px * np.tan(theta)], atol=1e-10)
    pitch = Camera.from_pitch(0.05, 5.5e-6, 2048, 2048)
    assert pitch.focal_px == pytest.approx(0.05 / 5.5e-6)


def test_attitude_convention_east_right_north_down():
    """At roll 0 (004 eq. 19) +u points east (RA increasing) and +v north (Dec increasing)."""
    camera = Camera.from_fov(20 * DEG, 1024, 1024)
    ra, dec = 195 * DEG, 10 * DEG
    q_IS = quaternion_from_radec_roll(ra, dec, 0.0)

    def vec(a, d):
        return [np.cos(d) * np.cos(a), np.cos(d) * np.sin(a), np.sin(d)]

    uv, visible = camera.project(q_IS, [vec(ra, dec), vec(ra + 1 * DEG, dec), vec(ra, dec + 1 * DEG)])
    assert np.all(visible)
    np.testing.assert_allclose(uv[0], [camera.cx, camera.cy], atol=1e-9)  # rounding level: closed forms
    assert uv[1, 0] > camera.cx + 40 and abs(uv[1, 1] - camera.cy) < 2
    assert uv[2, 1] > camera.cy + 40 and abs(uv[2, 0] - camera.cx) < 1e-6  # on the central meridian: rounding


def test_circular_and_rectangular_fields():
    rect = Camera.from_fov(20 * DEG, 1024, 1024)
    circ = Camera.from_fov(20 * DEG, 1024, 1024, circular_fov=True)
    q = np.array([0.0, 0.0, 0.0, 1.0])
    half = 10 * DEG
    diag = np.arctan(np.sqrt(2) * np.tan(half) * 0.98)  # inside the square's corner, outside the circle
    dirs = np.array([
        [0, 0, 1],
        [np.sin(0.99 * half), 0, np.cos(0.99 * half)],
        [np.sin(1.01 * half), 0, np.cos(1.01 * half)],
        [np.sin(diag) / np.sqrt(2), np.sin(diag) / np.sqrt(2), np.cos(diag)],
        [0, 0, -1],
    ])
    np.testing.assert_array_equal(rect.stars_in_field(q, dirs), [0, 1, 3])
    np.testing.assert_array_equal(circ.stars_in_field(q, dirs), [0, 1])
    np.testing.assert_array_equal(rect.stars_in_field(q, dirs, margin_px=20.0), [0, 1, 2, 3])
    uv, visible = rect.project(q, dirs)
    np.testing.assert_array_equal(visible, [True, True, False, True, False])
    assert np.all(np.isnan(uv[4]))


def test_roll_track_rotates_about_principal_point():
    camera = Camera.from_fov(20 * DEG, 1024, 1024)
    q = quaternion_from_radec_roll(1.0, 0.3, 0.2)
    uv0 = np.array([[700.0, 300.0]])
    v_I = Rotation.from_quat(q).apply(camera.unproject(uv0))
    omega = np.array([0.0, 0.0, 0.5])
    times = np.array([-0.1, 0.0, 0.2])
    track = camera.angular_velocity_track(q, omega, times, v_I)[0]
    x, y = uv0[0] - [camera.cx, camera.cy]
    a = omega[2] * times
    expected = np.column_stack([camera.cx + x * np.cos(a) + y * np.sin(a), camera.cy - x * np.sin(a) + y * np.cos(a)])
    np.testing.assert_allclose(track, expected, atol=1e-9)  # rounding level: closed forms of a roll


def test_bad_camera_input_is_refused():
    with pytest.raises(InputError, match="width"):
        Camera(0, 10, 100.0)
    with pytest.raises(InputError, match="focal_px"):
        Camera(10, 10, -1.0)
    with pytest.raises(InputError, match="not invertible"):
        Camera.from_fov(40 * DEG, 1024, 1024, k1=-3.0)
    with pytest.raises(InputError, match="field of view"):
        Camera.from_fov(200 * DEG, 1024, 1024)
    camera = Camera.from_fov(20 * DEG, 64, 64)
    with pytest.raises(InputError, match="quaternion"):
        camera.project([0, 0, 0, 0], [[0, 0, 1]])
    with pytest.raises(InputError, match=r"\(N, 2\)"):
        camera.unproject([1.0, 2.0, 3.0])


def test_a_centroid_covariance_becomes_the_direction_covariance():
    """At the principal point of a pinhole an isotropic σ [px] is σ/f [rad] on x and y of S, nothing along
    the boresight (closed form; the central differences are exact for the pinhole's linear x, y there to
    ~(0.01/f)²); off-axis and with distortion, the covariance stays perpendicular to the unit vector and
    matches a Monte Carlo of unproject (10⁵ draws: 2 % of the largest entry, 4σ of a sample covariance)."""
    camera = Camera.from_fov(np.radians(16.0), 1024, 1024)
    centre = [[camera.cx, camera.cy]]
    cov = camera.unproject_covariance(centre, np.eye(2)[None] * 0.25)[0]
    np.testing.assert_allclose(cov, np.diag([0.25, 0.25, 0.0]) / camera.focal_px**2, atol=1e-8 / camera.focal_px**2)
    distorted = dataclasses.replace(camera, k1=-0.1)
    uv, cov_uv = np.array([[900.0, 150.0]]), np.array([[[0.30, 0.12], [0.12, 0.20]]])
    cov = distorted.unproject_covariance(uv, cov_uv)[0]
    s = distorted.unproject(uv)[0]
    assert np.linalg.norm(cov @ s) < 1e-6 * np.linalg.norm(cov)
    draws = np.random.default_rng(2).multivariate_normal(uv[0], cov_uv[0], 100000)
    np.testing.assert_allclose(np.cov(distorted.unproject(draws).T), cov, rtol=0.0, atol=0.02 * np.abs(cov).max())
