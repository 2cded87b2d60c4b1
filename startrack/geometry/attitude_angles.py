"""Attitude angles of the star sensor: RA, Dec and roll (003 §1.1) and the 3-1-3 angles of 004 eq. 19.

Conventions (docs/design.md): ``q_IS`` is a scalar-last Hamilton quaternion [x, y, z, w] exactly as
``scipy.spatial.transform.Rotation``; it rotates star-sensor (S) vectors into the inertial frame
(I): ``v_I = R_IS v_S`` with ``R_IS = Rotation.from_quat(q_IS).as_matrix()``.  The documents'
attitude ("transfer") matrix from I to S is ``M_st = R_IS^T``; its rows are the S axes written in I.
S: +z boresight, +x along image columns (u, right), +y along image rows (v, down).

Two angle sets are provided, both with the boresight right ascension ``ra`` and declination ``dec``:

* **RA, Dec, roll of 003 §1.1** (called there yaw alpha, pitch delta and roll kappa).  003 defines the
  roll as "the angle from the projection of +Z_I onto the X_S Y_S plane to the +Y_S axis, counted
  counter-clockwise, in [-180, 180) deg".  Counter-clockwise is taken about +Z_S (right-handed), so
  with n = Z_I written in S, ``roll = atan2(n_x, n_y)``.  Roll 0 therefore means +Y_S (image rows,
  downwards in the image) points to the celestial north pole, and +X_S to local east; in general the
  projection of the north pole lies at the angle roll from +Y_S towards +X_S, and R_IS has the
  columns x_S = cos(roll) east + sin(roll) north, y_S = -sin(roll) east + cos(roll) north, z_S = boresight.
* **3-1-3 Euler angles of 004 eq. 19**: phi = 90 deg + alpha, theta = 90 deg - delta, psi = gamma;
  ``M_st = R3(psi) R1(theta) R3(phi)`` with the passive (frame) rotations R1, R3.  004 prints two
  misprinted entries in eq. 19: M[1,3] (row 2, column 3) must be cos(delta) cos(gamma) and M[3,1]
  must be cos(alpha) cos(delta) (the third row is the boresight in I); :func:`matrix_from_euler313`
  implements the correct product.  Column 3 of M_st is Z_I in S = (cos d sin g, cos d cos g, sin d),
  so 004's gamma is *the same angle* as 003's roll kappa; the two sets differ only in range (004
  quotes gamma in [0, 360) deg, Table 2; 003 in [-180, 180) deg).

Both directions are robust at the poles and across RA = 0: the roll is read against the local
east/north basis built from the recovered (ra, dec), so ``angles -> matrix -> angles -> matrix`` closes
to rounding everywhere.  At dec = +-90 deg only ra +- roll is defined; the conversion then returns the
RA given by ``atan2`` of the (rounded) boresight components (0 at an exact pole) and puts the rest of
the rotation into the roll, which reproduces the attitude exactly.
"""

import numpy as np

from startrack.geometry.rotation import from_matrix, to_matrix
from startrack.geometry.sphere import local_frame

_TWO_PI = 2.0 * np.pi


def matrix_from_radec_roll(ra, dec, roll):
    """R_IS (..., 3, 3) from boresight RA, Dec and roll [rad] (003 §1.1, roll as in the module doc).

    Columns of R_IS are the S axes in I: x_S = cos(roll) east + sin(roll) north,
    y_S = -sin(roll) east + cos(roll) north, z_S = boresight (cos d cos a, cos d sin a, sin d).
    This is the transpose of 004 eq. 19 with gamma = roll.
    """
    ra, dec, roll = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (ra, dec, roll)))
    boresight, east, north = local_frame(ra, dec)
    cos_r, sin_r = np.cos(roll)[..., None], np.sin(roll)[..., None]
    x_s = cos_r * east + sin_r * north
    y_s = -sin_r * east + cos_r * north
    return np.stack([x_s, y_s, boresight], axis=-1)


def radec_roll_from_matrix(R_IS):
    """(ra in [0, 2 pi), dec in [-pi/2, pi/2], roll in [-pi, pi)) [rad] of R_IS (..., 3, 3).

    Inverse of :func:`matrix_from_radec_roll`; roll = atan2(x_S . north, x_S . east) with the east/
    north basis at the recovered (ra, dec), which stays well conditioned at the poles.
    """
    R_IS = np.asarray(R_IS, dtype=float)
    b = R_IS[..., :, 2]
    ra = np.mod(np.arctan2(b[..., 1], b[..., 0]), _TWO_PI)
    dec = np.arctan2(b[..., 2], np.hypot(b[..., 0], b[..., 1]))
    _, east, north = local_frame(ra, dec)
    x_s = R_IS[..., :, 0]
    roll = np.arctan2(np.sum(x_s * north, axis=-1), np.sum(x_s * east, axis=-1))
    roll = np.mod(roll + np.pi, _TWO_PI) - np.pi
    return ra, dec, roll


def quaternion_from_radec_roll(ra, dec, roll):
    """q_IS (..., 4) scalar-last from boresight RA, Dec and 003 roll [rad]."""
    return from_matrix(matrix_from_radec_roll(ra, dec, roll))


def radec_roll_from_quaternion(q_IS):
    """(ra, dec, roll) [rad] of q_IS (..., 4); ranges as :func:`radec_roll_from_matrix`."""
    return radec_roll_from_matrix(to_matrix(q_IS))


def matrix_from_euler313(phi, theta, psi):
    """004 eq. 19: M_st = R3(psi) R1(theta) R3(phi) (I -> S) from 3-1-3 angles [rad], (..., 3, 3).

    Passive rotations R3(a) = [[c, s, 0], [-s, c, 0], [0, 0, 1]], R1(a) = [[1, 0, 0], [0, c, s],
    [0, -s, c]].  With phi = pi/2 + ra, theta = pi/2 - dec, psi = gamma this is R_IS^T of
    :func:`matrix_from_radec_roll` with roll = gamma (the two misprints of eq. 19 corrected).
    """
    phi, theta, psi = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (phi, theta, psi)))
    c1, s1 = np.cos(phi), np.sin(phi)
    c2, s2 = np.cos(theta), np.sin(theta)
    c3, s3 = np.cos(psi), np.sin(psi)
    return np.stack([
        np.stack([c3 * c1 - s3 * c2 * s1, c3 * s1 + s3 * c2 * c1, s3 * s2], axis=-1),
        np.stack([-s3 * c1 - c3 * c2 * s1, -s3 * s1 + c3 * c2 * c1, c3 * s2], axis=-1),
        np.stack([s2 * s1, -s2 * c1, c2], axis=-1),
    ], axis=-2)


def euler313_from_matrix(M_st):
    """3-1-3 angles (phi, theta, psi) [rad] of 004 eq. 19 from M_st = R_IS^T (..., 3, 3).

    phi in [0, 2 pi), theta in [0, pi], psi in [0, 2 pi) (004 quotes gamma = psi in [0, 360) deg).
    Obtained through the RA/Dec/roll inversion (phi = pi/2 + ra, theta = pi/2 - dec, psi = roll),
    so it inherits its robustness at theta = 0 and pi (gimbal lock: only phi +- psi is defined there).
    """
    ra, dec, roll = radec_roll_from_matrix(np.swapaxes(np.asarray(M_st, dtype=float), -1, -2))
    return np.mod(0.5 * np.pi + ra, _TWO_PI), 0.5 * np.pi - dec, np.mod(roll, _TWO_PI)


def radec_gamma_from_quaternion(q_IS):
    """(ra, dec, gamma) [rad] of 004: as the 003 angles but with gamma = roll wrapped to [0, 2 pi)."""
    ra, dec, roll = radec_roll_from_quaternion(q_IS)
    return ra, dec, np.mod(roll, _TWO_PI)
