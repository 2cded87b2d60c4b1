"""Attitude angles of the star sensor and the rotation-matrix / quaternion conversions.

Conventions (DESIGN.md): ``q_IS`` is a scalar-last Hamilton quaternion [x, y, z, w] exactly as
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

import math

import numpy as np

TWO_PI = 2.0 * np.pi


def quaternion_from_matrix(R):
    """Scalar-last unit quaternions (..., 4) of rotation matrices R (..., 3, 3) by Shepperd's method.

    Picks the largest of (trace, R11, R22, R33) as the pivot so the division is always by a
    component >= 1/2 in magnitude; the result is normalised (so a slightly non-orthogonal R gives
    the nearest-sense unit quaternion) and has w >= 0.  Same convention as scipy's
    ``Rotation.from_matrix(R).as_quat()``.
    """
    R = np.asarray(R, dtype=float)
    if R.shape == (3, 3):
        return _quaternion_from_one_matrix(R.tolist())
    m00, m11, m22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    trace = m00 + m11 + m22
    pivot = np.argmax(np.stack([trace, m00, m11, m22], axis=-1), axis=-1)
    d_x = R[..., 2, 1] - R[..., 1, 2]
    d_y = R[..., 0, 2] - R[..., 2, 0]
    d_z = R[..., 1, 0] - R[..., 0, 1]
    s_xy = R[..., 0, 1] + R[..., 1, 0]
    s_xz = R[..., 0, 2] + R[..., 2, 0]
    s_yz = R[..., 1, 2] + R[..., 2, 1]
    # 4 * (x, y, z, w) * (pivot component) for each pivot choice
    cand = np.stack([
        np.stack([d_x, d_y, d_z, 1.0 + trace], axis=-1),
        np.stack([1.0 + m00 - m11 - m22, s_xy, s_xz, d_x], axis=-1),
        np.stack([s_xy, 1.0 - m00 + m11 - m22, s_yz, d_y], axis=-1),
        np.stack([s_xz, s_yz, 1.0 - m00 - m11 + m22, d_z], axis=-1),
    ], axis=-2)
    q = np.take_along_axis(cand, pivot[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., 3:4] < 0.0, -q, q)


def _quaternion_from_one_matrix(R):
    """Shepperd's method for one matrix given as nested lists (scalar arithmetic, the hot path)."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = R
    trace = m00 + m11 + m22
    if trace >= m00 and trace >= m11 and trace >= m22:
        q = (m21 - m12, m02 - m20, m10 - m01, 1.0 + trace)
    elif m00 >= m11 and m00 >= m22:
        q = (1.0 + m00 - m11 - m22, m01 + m10, m02 + m20, m21 - m12)
    elif m11 >= m22:
        q = (m01 + m10, 1.0 - m00 + m11 - m22, m12 + m21, m02 - m20)
    else:
        q = (m02 + m20, m12 + m21, 1.0 - m00 - m11 + m22, m10 - m01)
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if q[3] < 0.0:
        norm = -norm
    return np.array([q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm])


def matrix_from_quaternion(q):
    """Rotation matrices (..., 3, 3) of scalar-last quaternions (..., 4) (normalised first)."""
    q = np.asarray(q, dtype=float)
    if q.shape == (4,):
        return _matrix_from_one_quaternion(*q.tolist())
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    return np.stack([
        np.stack([1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy)], axis=-1),
        np.stack([2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx)], axis=-1),
        np.stack([2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)], axis=-1),
    ], axis=-2)


def _matrix_from_one_quaternion(x, y, z, w):
    """Rotation matrix of one quaternion (scalar arithmetic, the hot path)."""
    scale = 2.0 / (x * x + y * y + z * z + w * w)
    xx, yy, zz = scale * x * x, scale * y * y, scale * z * z
    xy, xz, yz = scale * x * y, scale * x * z, scale * y * z
    wx, wy, wz = scale * w * x, scale * w * y, scale * w * z
    return np.array([[1.0 - yy - zz, xy - wz, xz + wy],
                     [xy + wz, 1.0 - xx - zz, yz - wx],
                     [xz - wy, yz + wx, 1.0 - xx - yy]])


def _east_north(ra, dec):
    """Local east and north unit vectors (..., 3) in I at (ra, dec) [rad]."""
    sin_ra, cos_ra = np.sin(ra), np.cos(ra)
    sin_dec, cos_dec = np.sin(dec), np.cos(dec)
    zero = np.zeros_like(sin_ra * sin_dec)
    east = np.stack([-sin_ra + zero, cos_ra + zero, zero], axis=-1)
    north = np.stack([-sin_dec * cos_ra, -sin_dec * sin_ra, cos_dec + zero], axis=-1)
    return east, north


def matrix_from_radec_roll(ra, dec, roll):
    """R_IS (..., 3, 3) from boresight RA, Dec and roll [rad] (003 §1.1, roll as in the module doc).

    Columns of R_IS are the S axes in I: x_S = cos(roll) east + sin(roll) north,
    y_S = -sin(roll) east + cos(roll) north, z_S = boresight (cos d cos a, cos d sin a, sin d).
    This is the transpose of 004 eq. 19 with gamma = roll.
    """
    ra, dec, roll = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (ra, dec, roll)))
    east, north = _east_north(ra, dec)
    cos_r, sin_r = np.cos(roll)[..., None], np.sin(roll)[..., None]
    cos_dec = np.cos(dec)
    boresight = np.stack([cos_dec * np.cos(ra), cos_dec * np.sin(ra), np.sin(dec)], axis=-1)
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
    ra = np.mod(np.arctan2(b[..., 1], b[..., 0]), TWO_PI)
    dec = np.arctan2(b[..., 2], np.hypot(b[..., 0], b[..., 1]))
    east, north = _east_north(ra, dec)
    x_s = R_IS[..., :, 0]
    roll = np.arctan2(np.sum(x_s * north, axis=-1), np.sum(x_s * east, axis=-1))
    roll = np.mod(roll + np.pi, TWO_PI) - np.pi
    return ra, dec, roll


def quaternion_from_radec_roll(ra, dec, roll):
    """q_IS (..., 4) scalar-last from boresight RA, Dec and 003 roll [rad]."""
    return quaternion_from_matrix(matrix_from_radec_roll(ra, dec, roll))


def radec_roll_from_quaternion(q_IS):
    """(ra, dec, roll) [rad] of q_IS (..., 4); ranges as :func:`radec_roll_from_matrix`."""
    return radec_roll_from_matrix(matrix_from_quaternion(q_IS))


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
    return np.mod(0.5 * np.pi + ra, TWO_PI), 0.5 * np.pi - dec, np.mod(roll, TWO_PI)


def radec_gamma_from_quaternion(q_IS):
    """(ra, dec, gamma) [rad] of 004: as the 003 angles but with gamma = roll wrapped to [0, 2 pi)."""
    ra, dec, roll = radec_roll_from_quaternion(q_IS)
    return ra, dec, np.mod(roll, TWO_PI)
