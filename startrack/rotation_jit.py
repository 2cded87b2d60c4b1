"""Compiled twin of :mod:`startrack.rotation` for one quaternion / vector at a time (numba), used
inside the compiled filter and identification loops. Same convention and the same numbers; each
function is tested against its vectorised counterpart."""

import numpy as np

from startrack.jit import njit


@njit
def quat_multiply(p, q):
    """Hamilton product p ⊗ q, scalar-last (4,)."""
    out = np.empty(4)
    out[0] = p[3] * q[0] + p[0] * q[3] + p[1] * q[2] - p[2] * q[1]
    out[1] = p[3] * q[1] - p[0] * q[2] + p[1] * q[3] + p[2] * q[0]
    out[2] = p[3] * q[2] + p[0] * q[1] - p[1] * q[0] + p[2] * q[3]
    out[3] = p[3] * q[3] - p[0] * q[0] - p[1] * q[1] - p[2] * q[2]
    return out


@njit
def quat_from_rotation_vector(phi):
    """exp(φ/2) as a scalar-last quaternion; series below 1e-4 rad."""
    angle = np.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2)
    if angle < 1e-4:
        k = 0.5 - angle * angle / 48.0
    else:
        k = np.sin(0.5 * angle) / angle
    out = np.empty(4)
    out[0] = k * phi[0]
    out[1] = k * phi[1]
    out[2] = k * phi[2]
    out[3] = np.cos(0.5 * angle)
    return out


@njit
def quat_to_matrix(q):
    """R(q) of a unit quaternion, the matrix rotating vectors by q (R_IB for q_IB)."""
    x, y, z, w = q[0], q[1], q[2], q[3]
    R = np.empty((3, 3))
    R[0, 0] = 1 - 2 * (y * y + z * z)
    R[0, 1] = 2 * (x * y - z * w)
    R[0, 2] = 2 * (x * z + y * w)
    R[1, 0] = 2 * (x * y + z * w)
    R[1, 1] = 1 - 2 * (x * x + z * z)
    R[1, 2] = 2 * (y * z - x * w)
    R[2, 0] = 2 * (x * z - y * w)
    R[2, 1] = 2 * (y * z + x * w)
    R[2, 2] = 1 - 2 * (x * x + y * y)
    return R


@njit
def rotation_vector(q):
    """Rotation vector of a unit quaternion (angle in [0, π]), shortest-path sign."""
    s = np.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2)
    w = q[3]
    sign = 1.0
    if w < 0.0:
        sign = -1.0
        w = -w
    out = np.empty(3)
    if s < 1e-12:
        scale = 2.0 * sign
    else:
        scale = sign * 2.0 * np.arctan2(s, w) / s
    out[0] = scale * q[0]
    out[1] = scale * q[1]
    out[2] = scale * q[2]
    return out


@njit
def skew(v):
    """[v×] (3, 3)."""
    S = np.zeros((3, 3))
    S[0, 1] = -v[2]
    S[0, 2] = v[1]
    S[1, 0] = v[2]
    S[1, 2] = -v[0]
    S[2, 0] = -v[1]
    S[2, 1] = v[0]
    return S
