"""Quaternion kinematics in the one convention of DESIGN.md.

Quaternions are scalar-last ``[x, y, z, w]`` with the Hamilton product, exactly
scipy's :class:`~scipy.spatial.transform.Rotation` convention. ``q_IB`` rotates
body vectors into the inertial frame: ``R_IB = Rotation.from_quat(q_IB).as_matrix()``.
Kinematics: ``q̇_IB = ½ q_IB ⊗ [ω_B, 0]`` — the ``q̇ = ½ Ω(ω) q`` of eq. 9 of 000.

Every function takes and returns plain arrays with a leading batch shape
``(..., 4)`` / ``(..., 3)`` so that the same code serves one run and a batch.
"""

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
    q = np.asarray(q, dtype=float)
    return q * np.array([-1.0, -1.0, -1.0, 1.0])


def normalize(q):
    """Unit quaternion (..., 4) with non-negative scalar part (one sign for each rotation)."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., 3:4] < 0.0, -q, q)


def from_rotation_vector(phi):
    """Quaternion (..., 4) of the rotation vector ``phi`` (..., 3) [rad]: exp(phi/2)."""
    phi = np.asarray(phi, dtype=float)
    angle = np.linalg.norm(phi, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(a/2)/a with its series below 1e-4 rad (error < 1e-18).
    small = angle < 1e-4
    safe = np.where(small, 1.0, angle)
    k = np.where(small, 0.5 - angle**2 / 48.0, np.sin(half) / safe)
    return np.concatenate([k * phi, np.cos(half)], axis=-1)


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
    w = q[..., 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def to_matrix(q):
    """Rotation matrices (..., 3, 3) of unit quaternions (..., 4) (``R_IB`` for ``q_IB``)."""
    q = np.asarray(q, dtype=float)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def skew(v):
    """Cross-product matrix ``[v×]`` (..., 3, 3) so that ``[v×] u = v × u``."""
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


def omega_matrix(omega):
    """The 4x4 matrix Ω(ω) of eq. 9 of 000: ``q̇ = ½ Ω(ω) q`` for scalar-last q.

    Ω(ω) = [[-[ω×], ω], [-ωᵀ, 0]]; with ω in body axes this equals the right
    product ``q ⊗ [ω, 0]`` of DESIGN.md.
    """
    omega = np.asarray(omega, dtype=float)
    shape = omega.shape[:-1]
    out = np.zeros(shape + (4, 4))
    out[..., :3, :3] = -skew(omega)
    out[..., :3, 3] = omega
    out[..., 3, :3] = -omega
    return out


def derivative(q, omega):
    """Quaternion rate ``q̇ = ½ q ⊗ [ω, 0]`` (..., 4) for body rate ω (..., 3) [rad/s]."""
    q = np.asarray(q, dtype=float)
    omega = np.asarray(omega, dtype=float)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    ox, oy, oz = omega[..., 0], omega[..., 1], omega[..., 2]
    return 0.5 * np.stack(
        [
            w * ox + y * oz - z * oy,
            w * oy - x * oz + z * ox,
            w * oz + x * oy - y * ox,
            -x * ox - y * oy - z * oz,
        ],
        axis=-1,
    )


def rk4_step(q, omega_start, omega_mid, omega_end, dt):
    """One classical RK4 step of ``q̇ = ½ q ⊗ [ω, 0]`` (eq. 9 of 000), renormalised.

    ``omega_start``, ``omega_mid``, ``omega_end`` are the body rates [rad/s] at
    t, t + dt/2 and t + dt; pass the same rate three times for a rate held
    constant over the step. Local error O(dt⁵), global O(dt⁴).
    """
    k1 = derivative(q, omega_start)
    k2 = derivative(q + 0.5 * dt * k1, omega_mid)
    k3 = derivative(q + 0.5 * dt * k2, omega_mid)
    k4 = derivative(q + dt * k3, omega_end)
    q_next = q + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return q_next / np.linalg.norm(q_next, axis=-1, keepdims=True)


def propagate_constant_rate(q, omega, dt):
    """Exact propagation under a constant body rate: ``q ⊗ exp(ω dt / 2)``."""
    return multiply(q, from_rotation_vector(np.asarray(omega, dtype=float) * dt))


def attitude_error(q_est, q_true):
    """Small-angle error δθ (..., 3) [rad] in body axes with ``q_true = q_est ⊗ δq(δθ)`` (DESIGN.md)."""
    return to_rotation_vector(multiply(conjugate(q_est), q_true))


def boresight_radec(q_IB, R_BS=None):
    """Boresight right ascension and declination [rad] (eq. 10 of 000).

    The boresight in I is ``R_IB R_BS e_z``; RA = atan2(y, x) in [0, 2π), Dec = asin(z).
    With ``R_BS = I`` and q_IB = (q1, q2, q3, q4) this is eq. 10 of 000:
    tan α = (q2 q3 − q1 q4)/(q1 q3 + q2 q4) (quadrant from the signs), sin δ = −q1² − q2² + q3² + q4².
    """
    q_IB = np.asarray(q_IB, dtype=float)
    axis_B = np.array([0.0, 0.0, 1.0]) if R_BS is None else np.asarray(R_BS, dtype=float)[:, 2]
    b = rotate(q_IB, np.broadcast_to(axis_B, q_IB.shape[:-1] + (3,)))
    ra = np.mod(np.arctan2(b[..., 1], b[..., 0]), 2.0 * np.pi)
    dec = np.arcsin(np.clip(b[..., 2], -1.0, 1.0))
    return ra, dec
