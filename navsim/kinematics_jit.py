"""Compiled twin of :mod:`navsim.kinematics` (numba): one quaternion-kinematics step at a time,
for the compiled filter and truth loops. Tested equal to the vectorised functions."""

import numpy as np

from startrack import njit


@njit
def quat_derivative(q, w):
    """q̇ = ½ q ⊗ [ω, 0] (eq. 9 of 000)."""
    out = np.empty(4)
    out[0] = 0.5 * (q[3] * w[0] + q[1] * w[2] - q[2] * w[1])
    out[1] = 0.5 * (q[3] * w[1] - q[0] * w[2] + q[2] * w[0])
    out[2] = 0.5 * (q[3] * w[2] + q[0] * w[1] - q[1] * w[0])
    out[3] = -0.5 * (q[0] * w[0] + q[1] * w[1] + q[2] * w[2])
    return out

@njit
def rk4_hold(q, w, dt):
    """Classical RK4 step of q̇ = ½ q ⊗ [ω, 0] with ω held over dt, renormalised.

    For a held rate the ODE is linear with constant coefficients, q̇ = A q with (A dt)² = −a² I,
    a = |ω|dt/2, so RK4's four stages sum exactly to its quartic Taylor polynomial:
    q_next = (1 − a²/2 + a⁴/24) q + (1 − a²/6) dt q̇ — one derivative instead of four, the same
    step as :func:`navsim.kinematics.rk4_step` (tested to 1e-15).
    """
    a2 = 0.25 * dt * dt * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    c0 = 1.0 - 0.5 * a2 + a2 * a2 / 24.0
    c1 = 0.5 * dt * (1.0 - a2 / 6.0)
    out = np.empty(4)
    out[0] = c0 * q[0] + c1 * (q[3] * w[0] + q[1] * w[2] - q[2] * w[1])
    out[1] = c0 * q[1] + c1 * (q[3] * w[1] - q[0] * w[2] + q[2] * w[0])
    out[2] = c0 * q[2] + c1 * (q[3] * w[2] + q[0] * w[1] - q[1] * w[0])
    out[3] = c0 * q[3] - c1 * (q[0] * w[0] + q[1] * w[1] + q[2] * w[2])
    norm = np.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2 + out[3] ** 2)
    for i in range(4):
        out[i] /= norm
    return out

