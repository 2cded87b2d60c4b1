"""Compiled star-sensor updates of the navigation filter (numba): the inertial attitude the INS
implies, its error in terms of the navigation error state, and the gated updates with an attitude
fix or with identified star vectors one by one.

The INS's inertial attitude is C_ib = C_ie C_ew C_wb (docs/design.md, frames i, e, w, b). With
C_wb,est = (I − [φ×]) C_wb,true and the estimated wander-azimuth frame turned from the true one by the
horizontal δθ = [δθ_x, δθ_y, 0] (C_ew,est = C_ew,true (I + [δθ×]); :mod:`navsim.estimation.nav_kernels`),
the estimate is C_ib,est = C_ib,true (I − [δθ_b×]) to first order, with the body-axes error

    δθ_b = C_bw (φ − δθ) = C_bw ψ,                                                              (1)

ψ = φ − δθ the psi angle (Titterton & Weston, 2nd ed., §12.2.1: ψ̇ = −ω_iw × ψ − C_wb ε, free of
the velocity and position errors; in NED δθ is [δλ cos L, −δL, −δλ sin L]). Eq. (1) is the attitude-difference
measurement of SINS/CNS: it couples the tilt φ with the position (the "mathematical horizon"; PSINS
``test_SINS_CNS_def``'s H of kfhk 184 in ENU; Yang et al. 2022), so the star sensor measures ψ, the accelerometers
hold φ to the local vertical through the Schuler loop, and their difference is the position. Its attitude
filter form — q_IB,true = q_IB ⊗ δq(δθ_b) — lets the star residuals and fix residuals of
:mod:`navsim.estimation.kernels` serve the INS: their H for (δθ_b, δm) is chained through
A = ∂δθ_b/∂x = C_bw [I₃ (φ), −I₃[:, 0:2] (δθ_x, δθ_y)].
"""

import numpy as np

from navsim.estimation.kernels import fix_residual, gate_stars, star_residuals, tangent_basis
from navsim.estimation.linalg import joseph_update, mm
from navsim.estimation.nav_kernels import DP, flush, gated_update, reset
from startrack import njit
from startrack import rotation_kernels as rk


@njit
def inertial_attitude(nav, q_ie):
    """q_IB of the INS, q_ie ⊗ q_ew ⊗ q_wb (C_ib = C_ie C_ew C_wb), for the navigation state ``nav`` and the
    Earth's orientation q_ie (4,) at the time of the update."""
    return rk.quat_multiply(rk.quat_multiply(q_ie, nav[0:4]), nav[8:12])


@njit
def attitude_jacobian(nav, n):
    """A (3, n) with δθ_b = A x (eq. 1 of the module): C_bw in the φ columns and −C_bw's first two columns in the
    δθ_x, δθ_y columns."""
    C_bw = rk.quat_to_matrix(nav[8:12]).T
    A = np.zeros((3, n))
    for i in range(3):
        for j in range(3):
            A[i, j] = C_bw[i, j]
        A[i, DP] = -C_bw[i, 0]
        A[i, DP + 1] = -C_bw[i, 1]
    return A


@njit
def _chain(H_att, A, mounting, out):
    """out (r, n) = H_att[:, 0:3] A, plus H_att's mounting columns (its last three) at ``mounting``."""
    k = H_att.shape[1]
    out[:, :] = mm(H_att[:, 0:3].copy(), A)
    if mounting >= 0:
        for r in range(H_att.shape[0]):
            for j in range(3):
                out[r, mounting + j] += H_att[r, k - 3 + j]


@njit
def fix_terms(nav, q_BS, q_ie, q_IS, R_S, layout, rho_I):
    """(z (3,) [rad], H (3, n), R (3, 3)) of a star-sensor attitude fix q_IS (covariance R_S in sensor axes)
    against the navigation state ``nav`` and the mounting estimate q_BS: z = δθ(q_IB, q_IS ⊗ q̂_BS⁻¹) in
    body axes (:func:`kernels.fix_residual`), H = A (+ R_BS in the mounting columns), R = R_BS R_S R_BSᵀ.
    With the refraction state ε_r, its column −R_BI ρ_I: ``rho_I`` (3,) [rad] the rotation vector by which the
    processing's model air raised the boresight (b × refract(b)), of which the real air leaves ε_r more
    (eq. 3 of :mod:`navsim.earth.refraction`): the corrected fix is turned by −ε_r ρ_I in ICRS axes."""
    q_IB = inertial_attitude(nav, q_ie)
    z, R_BS, R = fix_residual(q_IB, q_BS, q_IS, R_S)
    H_att = np.zeros((3, 6))
    for i in range(3):
        H_att[i, i] = 1.0
        for j in range(3):
            H_att[i, 3 + j] = R_BS[i, j]
    H = np.empty((3, layout.n))
    _chain(H_att, attitude_jacobian(nav, layout.n), layout.mounting, H)
    if layout.refraction >= 0:
        H[:, layout.refraction] = -(rk.quat_to_matrix(q_IB).T @ rho_I)
    return z, H, R


@njit
def fix_update(nav, calib, P, acc, model, q_ie, q_IS, R_S, gate, estimated, rho_I):
    """Flush the covariance, then the gated update with a star-sensor attitude fix q_IS (covariance
    R_S in sensor axes) of :func:`fix_terms`. Returns (z (3,) [rad], nis, accepted)."""
    flush(nav, P, acc, model)
    z, H, R = fix_terms(nav, calib[12:16], q_ie, q_IS, R_S, model.layout, rho_I)
    nis, accepted = gated_update(nav, calib, P, H, R, z, gate, estimated, model.layout)
    return z, nis, accepted


@njit
def star_terms(nav, q_BS, q_ie, ref_I, obs_S, cov_S, layout, shift_I):
    """(z (N, 2) [rad], H (N, 2, n), R (N, 2, 2)) of identified stars against the navigation state ``nav``
    and the mounting estimate q_BS: each star's tangent-plane residual (:func:`kernels.star_residuals`)
    with its H chained to the navigation error state; catalog directions ``ref_I`` (N, 3) (already
    apparent: aberrated and refracted as the processing sees them), measured ``obs_S`` (N, 3), covariances
    ``cov_S`` (N, 3, 3) [rad², sensor axes]. With the refraction state ε_r, its column T R_SI shift_I[k]:
    ``shift_I`` (N, 3) the refraction the processing's model air gave each star, of which the real air
    leaves ε_r more in the measured direction (eq. 3 of :mod:`navsim.earth.refraction`)."""
    q_IB = inertial_attitude(nav, q_ie)
    z, H_att, R = star_residuals(q_IB, q_BS, ref_I, obs_S, cov_S, 6, 3)
    A = attitude_jacobian(nav, layout.n)
    H = np.empty((z.shape[0], 2, layout.n))
    R_SI = rk.quat_to_matrix(q_BS).T @ rk.quat_to_matrix(q_IB).T
    for k in range(z.shape[0]):
        _chain(H_att[k], A, layout.mounting, H[k])
        if layout.refraction >= 0:
            e1, e2 = tangent_basis(R_SI @ ref_I[k])
            shift_S = R_SI @ shift_I[k]
            H[k, 0, layout.refraction], H[k, 1, layout.refraction] = np.sum(e1 * shift_S), np.sum(e2 * shift_S)
    return z, H, R


@njit
def stars_update(nav, calib, P, acc, model, q_ie, ref_I, obs_S, cov_S, gate, estimated, shift_I):
    """Flush the covariance, then the update with identified stars (:func:`star_terms`): each star gated
    alone by its 2-dof NIS; the accepted stars update together (Joseph), then the reset.
    Returns (z (N, 2), nis (N,), accepted (N,))."""
    flush(nav, P, acc, model)
    layout = model.layout
    z, H, R = star_terms(nav, calib[12:16], q_ie, ref_I, obs_S, cov_S, layout, shift_I)
    nis, accepted, Ha, za, Ra = gate_stars(H, P, z, R, gate)
    if za.shape[0] > 0:
        dx, P_next = joseph_update(P, Ha, Ra, za, estimated)
        P[:, :] = P_next
        reset(nav, calib, dx, layout)
    return z, nis, accepted
