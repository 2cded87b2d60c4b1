"""RA/Dec/roll (003 §1.1) and 3-1-3 angles (004 eq. 19): both directions, poles, RA = 0.

Every tolerance here is at the rounding level of closed forms and their round trips (near the poles,
rounding amplified by the conditioning of RA and roll, 1 / cos Dec)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from startrack.geometry.attitude_angles import (
    euler313_from_matrix,
    matrix_from_euler313,
    matrix_from_radec_roll,
    quaternion_from_radec_roll,
    radec_gamma_from_quaternion,
    radec_roll_from_matrix,
    radec_roll_from_quaternion,
)

ARCSEC = np.pi / 180.0 / 3600.0






def test_roll_definition_of_003():
    """Roll = angle from the projection of Z_I on the X_S Y_S plane to +Y_S, counter-clockwise about +Z_S."""
    rng = np.random.default_rng(2)
    ra, dec, roll = rng.uniform(0, 2 * np.pi, 200), rng.uniform(-1.4, 1.4, 200), rng.uniform(-np.pi, np.pi, 200)
    R_IS = matrix_from_radec_roll(ra, dec, roll)
    np.testing.assert_allclose(R_IS[:, :, 2], np.column_stack(
        [np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)]), atol=1e-15)
    pole_in_S = R_IS[:, 2, :]                                   # row 3 of R_IS = Z_I in S
    projection_angle = np.arctan2(pole_in_S[:, 1], pole_in_S[:, 0])
    counter_clockwise_to_y = np.angle(np.exp(1j * (np.pi / 2 - projection_angle)))
    np.testing.assert_allclose(np.angle(np.exp(1j * (counter_clockwise_to_y - roll))), 0, atol=1e-12)
    assert np.allclose(np.linalg.det(R_IS), 1.0)


def test_roundtrip_random_attitudes():
    rotations = Rotation.random(2000, random_state=3)
    q = rotations.as_quat()
    ra, dec, roll = radec_roll_from_quaternion(q)
    assert ra.min() >= 0 and ra.max() < 2 * np.pi and np.abs(dec).max() <= np.pi / 2
    assert roll.min() >= -np.pi and roll.max() < np.pi
    err = (Rotation.from_quat(quaternion_from_radec_roll(ra, dec, roll)).inv() * rotations).magnitude()
    assert err.max() < 1e-6 * ARCSEC


@pytest.mark.parametrize("dec", [np.pi / 2, -np.pi / 2, np.pi / 2 - 1e-9, -np.pi / 2 + 1e-13, np.pi / 2 - 1e-3])
@pytest.mark.parametrize("roll", [-np.pi, -1.0, 0.0, 2.5])
def test_roundtrip_at_and_near_poles(dec, roll):
    for ra in (0.0, 1.0, 4.0):
        R_IS = matrix_from_radec_roll(ra, dec, roll)
        ra2, dec2, roll2 = radec_roll_from_matrix(R_IS)
        np.testing.assert_allclose(matrix_from_radec_roll(ra2, dec2, roll2), R_IS, atol=1e-14)
        np.testing.assert_allclose(dec2, dec, atol=1e-14)
        if abs(abs(dec) - np.pi / 2) > 1e-6:   # away from the exact pole every angle is recovered (to rounding / cos Dec)
            assert abs(np.angle(np.exp(1j * (ra2 - ra)))) < 1e-10
            assert abs(np.angle(np.exp(1j * (roll2 - roll)))) < 1e-10
        else:                                   # at the pole only ra +- roll is defined
            sign = 1.0 if dec > 0 else -1.0
            assert abs(np.angle(np.exp(1j * ((ra2 + sign * roll2) - (ra + sign * roll))))) < 1e-6


def test_continuity_across_ra_zero():
    eps = np.array([-1e-9, -1e-12, 0.0, 1e-12, 1e-9])
    R_IS = matrix_from_radec_roll(eps, 0.3, 0.2)
    ra, dec, roll = radec_roll_from_matrix(R_IS)
    np.testing.assert_allclose(np.angle(np.exp(1j * (ra - eps))), 0, atol=1e-15)
    assert np.all((ra >= 0) & (ra < 2 * np.pi))
    np.testing.assert_allclose(dec, 0.3, atol=1e-15)
    np.testing.assert_allclose(roll, 0.2, atol=1e-14)
    assert ra[0] > 6.28 and ra[-1] < 1e-8


def test_euler313_is_the_transpose_of_radec_roll_matrix():
    rng = np.random.default_rng(4)
    ra, dec, gamma = rng.uniform(0, 2 * np.pi, 300), rng.uniform(-np.pi / 2, np.pi / 2, 300), rng.uniform(0, 2 * np.pi, 300)
    M = matrix_from_euler313(np.pi / 2 + ra, np.pi / 2 - dec, gamma)
    np.testing.assert_allclose(M, np.swapaxes(matrix_from_radec_roll(ra, dec, gamma), 1, 2), atol=1e-14)
    phi, theta, psi = euler313_from_matrix(M)
    np.testing.assert_allclose(matrix_from_euler313(phi, theta, psi), M, atol=1e-14)
    assert psi.min() >= 0 and psi.max() < 2 * np.pi and theta.min() >= 0 and theta.max() <= np.pi


def test_euler313_matches_004_eq19_entries_except_its_two_misprints():
    """Entry by entry against 004 eq. 19 as printed; (2,3) and (3,1) are the misprinted ones."""
    a, d, g = 0.7, 0.4, 1.1
    sa, ca, sd, cd, sg, cg = np.sin(a), np.cos(a), np.sin(d), np.cos(d), np.sin(g), np.cos(g)
    printed = np.array([
        [-sa * cg - ca * sd * sg, ca * cg - sa * sd * sg, cd * sg],
        [sa * sg - ca * sd * cg, -ca * sg - sa * sd * cg, cd * sg],     # misprint: cd * cg
        [ca * sd, sa * cd, sd],                                         # misprint: ca * cd
    ])
    M = matrix_from_euler313(np.pi / 2 + a, np.pi / 2 - d, g)
    same = np.ones((3, 3), bool)
    same[1, 2] = same[2, 0] = False
    np.testing.assert_allclose(M[same], printed[same], atol=1e-15)
    assert M[1, 2] == pytest.approx(cd * cg) and M[2, 0] == pytest.approx(ca * cd)


def test_gamma_of_004_equals_roll_wrapped():
    q = quaternion_from_radec_roll(np.radians(45), np.radians(45), np.radians(-0.5))
    ra, dec, gamma = radec_gamma_from_quaternion(q)
    assert np.degrees(gamma) == pytest.approx(359.5)
    assert np.degrees(ra) == pytest.approx(45) and np.degrees(dec) == pytest.approx(45)
