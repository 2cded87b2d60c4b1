"""Compiled twin of :mod:`startrack.geometry.rotation` for one quaternion / vector / attitude profile at a time
(numba), used inside the compiled filter and identification loops. Same convention and the same
numbers; each function is tested against its vectorised counterpart."""

import numpy as np

from startrack.compiled.numba_setup import njit
from startrack.compiled.sorts import argsort


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
def quat_from_matrix(R):
    """Scalar-last unit quaternion, w >= 0, of the rotation matrix R (3, 3) (Shepperd's pivot, as
    :func:`startrack.geometry.rotation.from_matrix`)."""
    trace = R[0, 0] + R[1, 1] + R[2, 2]
    q = np.empty(4)
    if trace >= R[0, 0] and trace >= R[1, 1] and trace >= R[2, 2]:
        q[0], q[1], q[2], q[3] = R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1], 1.0 + trace
    elif R[0, 0] >= R[1, 1] and R[0, 0] >= R[2, 2]:
        q[0], q[1], q[2], q[3] = 1.0 + R[0, 0] - R[1, 1] - R[2, 2], R[0, 1] + R[1, 0], R[0, 2] + R[2, 0], R[2, 1] - R[1, 2]
    elif R[1, 1] >= R[2, 2]:
        q[0], q[1], q[2], q[3] = R[0, 1] + R[1, 0], 1.0 - R[0, 0] + R[1, 1] - R[2, 2], R[1, 2] + R[2, 1], R[0, 2] - R[2, 0]
    else:
        q[0], q[1], q[2], q[3] = R[0, 2] + R[2, 0], R[1, 2] + R[2, 1], 1.0 - R[0, 0] - R[1, 1] + R[2, 2], R[1, 0] - R[0, 1]
    norm = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return q / (-norm if q[3] < 0.0 else norm)


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


@njit
def _symmetric_eigen(M):
    """(eigenvalues (3,), eigenvectors (3, 3) as columns) of a symmetric 3x3 matrix by cyclic Jacobi sweeps."""
    A = M.copy()
    V = np.eye(3)
    for _ in range(64):
        off = A[0, 1] ** 2 + A[0, 2] ** 2 + A[1, 2] ** 2
        if off <= 1e-34 * (A[0, 0] ** 2 + A[1, 1] ** 2 + A[2, 2] ** 2):
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            if A[p, q] == 0.0:
                continue
            theta = (A[q, q] - A[p, p]) / (2.0 * A[p, q])
            t = 1.0 / (theta + np.sqrt(theta * theta + 1.0)) if theta >= 0.0 else -1.0 / (-theta + np.sqrt(theta * theta + 1.0))
            c = 1.0 / np.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):
                a_kp, a_kq = A[k, p], A[k, q]
                A[k, p], A[k, q] = c * a_kp - s * a_kq, s * a_kp + c * a_kq
            for k in range(3):
                a_pk, a_qk = A[p, k], A[q, k]
                A[p, k], A[q, k] = c * a_pk - s * a_qk, s * a_pk + c * a_qk
            for k in range(3):
                v_kp, v_kq = V[k, p], V[k, q]
                V[k, p], V[k, q] = c * v_kp - s * v_kq, s * v_kp + c * v_kq
    return np.array([A[0, 0], A[1, 1], A[2, 2]]), V


@njit
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def _unit(a):
    return a / np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit
def _apply(M, a):
    return np.array([_dot(M[0], a), _dot(M[1], a), _dot(M[2], a)])


@njit
def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit
def wahba_svd(ref_I, obs_S):
    """R_IS (3, 3) minimising sum |obs_i - R_IS^T ref_i|^2, equal weights (SVD, Markley 1988): the
    compiled twin of :func:`startrack.geometry.rotation.nearest_rotation` of the transposed attitude profile.

    B = sum obs_i ref_i^T = U S V^T and A = U diag(1, 1, det U det V) V^T (I -> S), R_IS = A^T: the
    solution of :class:`startrack.attitude.solvers.SvdWahba` (used for every fit inside the identification).
    The SVD of the 3x3 B comes from the symmetric eigenproblem B^T B = V S^2 V^T (Jacobi sweeps):
    u_i = B v_i / s_i for the two largest s_i, and v_3 = v_1 x v_2, u_3 = u_1 x u_2, which is exactly
    the determinant correction of Markley's formula.  Needs two non-parallel stars.
    """
    B = np.zeros((3, 3))
    for n in range(obs_S.shape[0]):
        for r in range(3):
            for c in range(3):
                B[r, c] += obs_S[n, r] * ref_I[n, c]
    BtB = np.zeros((3, 3))
    for r in range(3):
        for c in range(3):
            BtB[r, c] = B[0, r] * B[0, c] + B[1, r] * B[1, c] + B[2, r] * B[2, c]
    eigenvalues, V = _symmetric_eigen(BtB)
    order = argsort(-eigenvalues)
    v1 = V[:, order[0]].copy()
    v2 = _unit(V[:, order[1]] - _dot(V[:, order[1]], v1) * v1)
    v3 = _cross(v1, v2)
    u1 = _unit(_apply(B, v1))
    u2 = _apply(B, v2)
    u2 = _unit(u2 - _dot(u2, u1) * u1)
    u3 = _cross(u1, u2)
    R_IS = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            R_IS[r, c] = v1[r] * u1[c] + v2[r] * u2[c] + v3[r] * u3[c]  # (U V^T)^T = V U^T
    return R_IS


@njit
def worst_cosine(ref_I, obs_S, R_IS):
    """Smallest cosine between obs_S[i] and R_IS^T ref_I[i] over the pairs (n, 3): the largest residual of
    an attitude fit as a cosine."""
    worst = 1.0
    for i in range(ref_I.shape[0]):
        c = 0.0
        for k in range(3):
            c += (ref_I[i, 0] * R_IS[0, k] + ref_I[i, 1] * R_IS[1, k] + ref_I[i, 2] * R_IS[2, k]) * obs_S[i, k]
        worst = min(worst, c)
    return worst
