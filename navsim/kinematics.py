"""Quaternion kinematics (docs/design.md): ``q̇_IB = ½ q_IB ⊗ [ω_B, 0]``, the ``q̇ = ½ Ω(ω) q`` of
eq. 9 of 000, its RK4 integration and the boresight of eq. 10 of 000.

The rotation helpers (product, conjugate, rotation vectors, matrices) are :mod:`startrack.geometry.rotation`;
the compiled per-step twin of this module is :mod:`navsim.kinematics_jit`. Arrays carry a leading
batch shape ``(..., 4)`` / ``(..., 3)``.
"""

import numpy as np

from startrack import rotation as rot
from startrack import vector_to_radec


def omega_matrix(omega):
    """The 4x4 matrix Ω(ω) of eq. 9 of 000: ``q̇ = ½ Ω(ω) q`` for scalar-last q.

    Ω(ω) = [[-[ω×], ω], [-ωᵀ, 0]]; with ω in body axes this equals the right
    product ``q ⊗ [ω, 0]`` of docs/design.md.
    """
    omega = np.asarray(omega, dtype=float)
    shape = omega.shape[:-1]
    out = np.zeros(shape + (4, 4))
    out[..., :3, :3] = -rot.skew(omega)
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
    return rot.multiply(q, rot.from_rotation_vector(np.asarray(omega, dtype=float) * dt))


def boresight_radec(q_IB, R_BS=None):
    """Boresight right ascension and declination [rad] (eq. 10 of 000).

    The boresight in I is ``R_IB R_BS e_z``; RA = atan2(y, x) in [0, 2π), Dec = asin(z).
    With ``R_BS = I`` and q_IB = (q1, q2, q3, q4) this is eq. 10 of 000:
    tan α = (q2 q3 − q1 q4)/(q1 q3 + q2 q4) (quadrant from the signs), sin δ = −q1² − q2² + q3² + q4².
    """
    q_IB = np.asarray(q_IB, dtype=float)
    axis_B = np.array([0.0, 0.0, 1.0]) if R_BS is None else np.asarray(R_BS, dtype=float)[:, 2]
    b = rot.rotate(q_IB, np.broadcast_to(axis_B, q_IB.shape[:-1] + (3,)))
    return vector_to_radec(b)
