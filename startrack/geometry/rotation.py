"""Rotations in the one convention of both packages (docs/design.md), vectorised.

Quaternions are scalar-last ``[x, y, z, w]`` with the Hamilton product, exactly scipy's
:class:`~scipy.spatial.transform.Rotation`: ``q_AB`` rotates B-frame vectors into A,
``R_AB = to_matrix(q_AB) = Rotation.from_quat(q_AB).as_matrix()``. Every function takes arrays
with a leading batch shape ``(..., 4)`` / ``(..., 3)`` / ``(..., 3, 3)``. The compiled twin of
the per-step helpers is :mod:`startrack.geometry.rotation_kernels`.
"""

import math

import numpy as np


def multiply(p, q):
    """Hamilton product ``p ⊗ q`` of scalar-last quaternions (..., 4)."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    px, py, pz, pw = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qx, qy, qz, qw = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz,
        ],
        axis=-1,
    )


def conjugate(q):
    """Inverse of a unit quaternion (..., 4)."""
    return np.asarray(q, dtype=float) * np.array([-1.0, -1.0, -1.0, 1.0])


def normalize(q):
    """Unit quaternion (..., 4) with non-negative scalar part (one sign for each rotation)."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., 3:4] < 0.0, -q, q)


def from_rotation_vector(phi):
    """Quaternion (..., 4) of the rotation vector ``phi`` (..., 3) [rad]: exp(phi/2)."""
    phi = np.asarray(phi, dtype=float)
    angle = np.linalg.norm(phi, axis=-1, keepdims=True)
    # sin(a/2)/a with its series below 1e-4 rad (error < 1e-18).
    small = angle < 1e-4
    safe = np.where(small, 1.0, angle)
    k = np.where(small, 0.5 - angle**2 / 48.0, np.sin(0.5 * angle) / safe)
    return np.concatenate([k * phi, np.cos(0.5 * angle)], axis=-1)


def to_rotation_vector(q):
    """Rotation vector (..., 3) [rad] of quaternion (..., 4), angle in [0, pi]."""
    q = normalize(q)
    v = q[..., :3]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., 3:4])
    small = s < 1e-12
    scale = np.where(small, 2.0, angle / np.where(small, 1.0, s))
    return scale * v


def rotate(q, v):
    """Rotate vectors v (..., 3) by quaternion q (..., 4): R(q) v."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    u = q[..., :3]
    t = 2.0 * np.cross(u, v)
    return v + q[..., 3:4] * t + np.cross(u, t)


def from_two_vectors(a, b):
    """Quaternion (..., 4) of the smallest rotation taking unit vectors ``a`` to ``b`` (..., 3): about
    a × b by the angle atan2(|a × b|, a · b) (undefined for opposite vectors)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    axis = np.cross(a, b)
    s = np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = np.arctan2(s, np.sum(a * b, axis=-1, keepdims=True))
    return from_rotation_vector(axis * (angle / np.where(s > 0.0, s, 1.0)))


def attitude_error(q_est, q_true):
    """Small-angle error δθ (..., 3) [rad] in the estimate's axes: ``q_true = q_est ⊗ δq(δθ)``."""
    return to_rotation_vector(multiply(conjugate(q_est), q_true))


def to_matrix(q):
    """Rotation matrices (..., 3, 3) of quaternions (..., 4) (need not be unit: 2/|q|² scaling)."""
    q = np.asarray(q, dtype=float)
    if q.shape == (4,):
        return _one_matrix(*q.tolist())
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    s = 2.0 / (x * x + y * y + z * z + w * w)
    xx, yy, zz = s * x * x, s * y * y, s * z * z
    xy, xz, yz = s * x * y, s * x * z, s * y * z
    wx, wy, wz = s * w * x, s * w * y, s * w * z
    return np.stack([
        np.stack([1.0 - yy - zz, xy - wz, xz + wy], axis=-1),
        np.stack([xy + wz, 1.0 - xx - zz, yz - wx], axis=-1),
        np.stack([xz - wy, yz + wx, 1.0 - xx - yy], axis=-1),
    ], axis=-2)


def _one_matrix(x, y, z, w):
    """:func:`to_matrix` of one quaternion in scalar arithmetic (the hot path, same numbers)."""
    s = 2.0 / (x * x + y * y + z * z + w * w)
    xx, yy, zz = s * x * x, s * y * y, s * z * z
    xy, xz, yz = s * x * y, s * x * z, s * y * z
    wx, wy, wz = s * w * x, s * w * y, s * w * z
    return np.array([[1.0 - yy - zz, xy - wz, xz + wy],
                     [xy + wz, 1.0 - xx - zz, yz - wx],
                     [xz - wy, yz + wx, 1.0 - xx - yy]])


def from_matrix(R):
    """Scalar-last unit quaternions (..., 4), w >= 0, of rotation matrices R (..., 3, 3) (Shepperd).

    The largest of (trace, R11, R22, R33) is the pivot, so the division is always by a component
    >= 1/2 in magnitude; the result is normalised (a slightly non-orthogonal R gives the
    nearest-sense unit quaternion). Same as scipy's ``Rotation.from_matrix(R).as_quat()``.
    """
    R = np.asarray(R, dtype=float)
    if R.shape == (3, 3):
        return _one_quaternion(R.tolist())
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


def _one_quaternion(R):
    """:func:`from_matrix` of one matrix given as nested lists (scalar arithmetic, the hot path)."""
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


def skew(v):
    """Cross-product matrices ``[v×]`` (..., 3, 3) so that ``[v×] u = v × u``."""
    v = np.asarray(v, dtype=float)
    zero = np.zeros_like(v[..., 0])
    return np.stack(
        [
            np.stack([zero, -v[..., 2], v[..., 1]], axis=-1),
            np.stack([v[..., 2], zero, -v[..., 0]], axis=-1),
            np.stack([-v[..., 1], v[..., 0], zero], axis=-1),
        ],
        axis=-2,
    )


def nearest_rotation(M):
    """The rotation closest to M (..., 3, 3) in Frobenius norm: U diag(1, 1, det U Vᵀ) Vᵀ for
    M = U S Vᵀ. With M the transposed attitude profile Bᵀ = Σ a_i r_i b_iᵀ this is the SVD solution
    of Wahba's problem (Markley 1988), R_IS."""
    U, _, Vt = np.linalg.svd(np.asarray(M, dtype=float))
    d = np.sign(np.linalg.det(U @ Vt))
    U = U.copy()
    U[..., :, 2] *= d[..., None]
    return U @ Vt
