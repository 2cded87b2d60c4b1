"""Compiled inner loops of the attitude filter (numba): propagation, gated Joseph updates, star
residuals and the whole-record loops of the fast path.

These are the scalar forms of :mod:`navsim.estimation.attitude_filter`'s maths, compiled because a
filter step runs tens of thousands of times per simulated minute; each is tested against its
numpy / filterpy counterpart. Conventions are those of docs/design.md (scalar-last Hamilton
quaternions, error state δθ in body axes).

Nominal state ``x`` (19 + 4 H,): q_IB [0:4], total gyro bias b [4:7] (rad/s), the gyro error matrix K
[7:16] (row-major 3x3, ω̃ = (I + K) ω + b + noise: scale factors on the diagonal, misalignment and
non-orthogonality off it), the Gauss-Markov part g of the bias [16:19] (rad/s), then the mounting q_BS of each
of the ``model.heads`` = H star-sensor heads [19 + 4h : 23 + 4h]. Error state (n,): δθ [0:3], δb [3:6] (the total
bias), then optional groups in this order: δg [6:9] (``model.n_bi`` = 3: the bias instability as a first-order
Gauss-Markov process of σ_g and τ, inside the total bias), the calibration states δk — the 3 scale factors
(``model.n_sf`` = 3) followed by the 6 off-diagonal terms k_xy, k_xz, k_yx, k_yz, k_zx, k_zy (``model.n_gm`` = 6) —
and, with ``model.mounting``, δm of each head [n − 3H + 3h : n − 3H + 3h + 3]. ``estimated`` (n,) marks the states
the updates correct; the others are consider states (Schmidt): they stay in P and in Φ, their gain is zero. A
measurement of head h (a fix, a star) sees the body through that head's mounting and mounting error.
"""

from collections import namedtuple

import numpy as np

from navsim.estimation.linalg import inverse_small, joseph_update, mm, mm_t, solve3
from navsim.kinematics_jit import rk4_hold
from startrack import njit
from startrack import rotation_kernels as rk

#: What the filter assumes of the gyro and which states it carries: ARW σ_v [rad/√s], RRW σ_u
#: [rad/s^(3/2)], the bias instability's σ_g [rad/s] and correlation time τ [s], random walk of the
#: calibration terms σ_k [1/√s], the factor on Q, the number of Gauss-Markov states (0 or 3), of
#: scale-factor states (0 or 3) and of misalignment states (0 or 6), whether δm is a state, the star-sensor heads.
FilterModel = namedtuple("FilterModel", "arw rrw gm_sigma gm_tau cal_rw q_scale n_bi n_sf n_gm mounting heads", defaults=(1,))
#: Where the Gauss-Markov bias and the first head's mounting start in the nominal state.
X_G, X_BS = 16, 19
#: Flat index in K of each calibration state: the scale factors, then the off-diagonal terms.
K_FLAT = np.array([0, 4, 8, 1, 2, 3, 5, 6, 7])


@njit
def calibration_flat(model):
    """Flat index in K of each calibration state, in state order."""
    first = 0 if model.n_sf else 3
    return K_FLAT[first : first + model.n_sf + model.n_gm]


@njit
def corrected_rate(x, omega_measured, model):
    """The body rate the filter believes, ω = (I + K)⁻¹ (ω̃ − b) [rad/s] (ω̃ − b without calibration states)."""
    d = omega_measured - x[4:7]
    if model.n_sf + model.n_gm == 0:
        return d
    A = np.eye(3) + x[7:16].reshape(3, 3)
    return solve3(A, d)


@njit
def transition(omega, dt, n, model):
    """Closed-form transition matrix Φ (n x n) of the error state over dt (Crassidis & Junkins,
    *Optimal Estimation of Dynamic Systems*, 2nd ed., §7.2.1), w = |ω|:

    Φ11 = I − [ω×] sin(wΔt)/w + [ω×]² (1 − cos wΔt)/w²,
    Φ12 = −IΔt + [ω×](1 − cos wΔt)/w² − [ω×]²(wΔt − sin wΔt)/w³,
    Φ_θk = Φ12 D(ω), D(ω) δk = δK ω (a gyro-matrix error enters like a bias: ω̃ = (I + K) ω + b,
    Pittelkau 2001), all other blocks identity/zero.
    """
    w = np.sqrt(omega[0] ** 2 + omega[1] ** 2 + omega[2] ** 2)
    wt = w * dt
    if wt < 1e-3:  # series, error O((wΔt)^4)
        a = dt * (1.0 - wt * wt / 6.0)
        b = dt * dt * (0.5 - wt * wt / 24.0)
        c = dt**3 * (1.0 / 6.0 - wt * wt / 120.0)
    else:
        a = np.sin(wt) / w
        b = (1.0 - np.cos(wt)) / (w * w)
        c = (wt - np.sin(wt)) / w**3
    W = rk.skew(omega)
    W2 = mm(W, W)
    F = np.eye(n)
    for i in range(3):
        for j in range(3):
            F[i, j] += -a * W[i, j] + b * W2[i, j]
            F[i, 3 + j] = b * W[i, j] - c * W2[i, j]
        F[i, 3 + i] -= dt
    if model.n_bi:
        # θ integrates the bias decay −g(1 − e^(−s/τ)): Φ_θg = ∫ Φ11(Δt − s)(1 − e^(−s/τ)) ds, to O(Δt⁴)
        tau = model.gm_tau
        decay = np.exp(-dt / tau)
        for i in range(3):
            for j in range(3):
                F[i, 6 + j] = -W[i, j] * dt**3 / (6.0 * tau)
            F[i, 6 + i] += 0.5 * dt * dt / tau - dt**3 / (6.0 * tau * tau)
            F[3 + i, 6 + i] = decay - 1.0  # b(t + Δt) = b − (1 − e^(−Δt/τ)) g
            F[6 + i, 6 + i] = decay
    flat = calibration_flat(model)
    start = 6 + model.n_bi
    for c in range(flat.shape[0]):
        row, col = flat[c] // 3, flat[c] % 3  # δK[row, col] ω adds ω[col] to the rate error's row
        for i in range(3):
            F[i, start + c] = F[i, 3 + row] * omega[col]
    return F


@njit
def process_noise(model, dt, n):
    """Discrete Q (n x n), before ``model.q_scale``: Farrenkopf's attitude/bias blocks for ARW σ_v and
    RRW σ_u — Q11 = (σ_v²Δt + σ_u²Δt³/3) I, Q12 = −σ_u²Δt²/2 I, Q22 = σ_u²Δt I —, the Gauss-Markov
    drive of the bias instability, q_g = 2σ_g²/τ, which enters the total bias like a rate random
    walk and the g state with its exact variance σ_g²(1 − e^(−2Δt/τ)), and a random walk σ_k²Δt of
    each calibration state."""
    arw, rrw = model.arw, model.rrw
    Q = np.zeros((n, n))
    for i in range(3):
        Q[i, i] = arw * arw * dt + rrw * rrw * dt**3 / 3.0
        Q[i, 3 + i] = Q[3 + i, i] = -0.5 * rrw * rrw * dt * dt
        Q[3 + i, 3 + i] = rrw * rrw * dt
    if model.n_bi:
        q_g = 2.0 * model.gm_sigma**2 / model.gm_tau
        drive = model.gm_sigma**2 * (1.0 - np.exp(-2.0 * dt / model.gm_tau))
        for i in range(3):
            Q[i, i] += q_g * dt**3 / 3.0
            Q[i, 3 + i] -= 0.5 * q_g * dt * dt
            Q[3 + i, i] = Q[i, 3 + i]
            Q[i, 6 + i] = Q[6 + i, i] = -0.5 * q_g * dt * dt
            Q[3 + i, 3 + i] += drive
            Q[3 + i, 6 + i] = Q[6 + i, 3 + i] = drive
            Q[6 + i, 6 + i] = drive
    start = 6 + model.n_bi
    for c in range(model.n_sf + model.n_gm):
        Q[start + c, start + c] = model.cal_rw * model.cal_rw * dt
    return Q


@njit
def predict(x, P, omega_measured, dt, model):
    """Propagation over consecutive gyro samples ``omega_measured`` (m, 3), each held for dt:
    q by RK4 (eq. 9 of 000) with the corrected rate (:func:`corrected_rate`), P ← Φ P Φᵀ + q_scale Q.
    Returns (x, P).

    Φ = I + E with E non-zero only in the r leading rows (the attitude's, and the bias and
    Gauss-Markov rows when g is a state), so Φ P Φᵀ = P + E P + (E P)ᵀ + E P Eᵀ is formed from the
    r x n product E P alone. The nominal bias decays with ĝ: b ← b − (1 − e^(−Δt/τ)) ĝ, ĝ ← e^(−Δt/τ) ĝ.
    """
    n = P.shape[0]
    r = 3 + 2 * model.n_bi
    Q = model.q_scale * process_noise(model, dt, n)
    decay = np.exp(-dt / model.gm_tau) if model.n_bi else 1.0
    P = P.copy()
    x = x.copy()
    EP = np.empty((r, n))
    for k in range(omega_measured.shape[0]):
        omega = corrected_rate(x, omega_measured[k], model)
        F = transition(omega, dt, n, model)
        for i in range(r):
            F[i, i] -= 1.0  # E = Φ − I
        for i in range(r):
            for j in range(n):
                acc = 0.0
                for p in range(n):
                    acc += F[i, p] * P[p, j]
                EP[i, j] = acc
        for i in range(r):
            for j in range(r):
                acc = 0.0
                for p in range(n):
                    acc += EP[i, p] * F[j, p]
                P[i, j] += EP[i, j] + EP[j, i] + acc
            for j in range(r, n):
                P[i, j] += EP[i, j]
                P[j, i] = P[i, j]
        for i in range(n):
            for j in range(i, n):
                value = 0.5 * (P[i, j] + P[j, i]) + Q[i, j]
                P[i, j] = value
                P[j, i] = value
        x[0:4] = rk4_hold(x[0:4], omega, dt)
        if model.n_bi:
            x[4:7] -= (1.0 - decay) * x[X_G : X_G + 3]
            x[X_G : X_G + 3] *= decay
    return x, P


@njit
def joseph_update_attitude(P, R, z, estimated):
    """:func:`joseph_update` for H = [I₃ 0] (an attitude fix, no mounting state), in O(n²):
    S = P₁₁ + R, K = P[:, :3] S⁻¹ (zero rows for consider states), M = P − K P[:3, :],
    P⁺ = M − M[:, :3] Kᵀ + K R Kᵀ."""
    n = P.shape[0]
    S = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            S[i, j] = P[i, j] + R[i, j]
    S_inv = inverse_small(S)
    K = np.zeros((n, 3))
    for i in range(n):
        if estimated[i]:
            for j in range(3):
                for m in range(3):
                    K[i, j] += P[i, m] * S_inv[m, j]
    dx = np.zeros(n)
    for i in range(n):
        dx[i] = K[i, 0] * z[0] + K[i, 1] * z[1] + K[i, 2] * z[2]
    M = P.copy()
    for i in range(n):
        for j in range(n):
            M[i, j] -= K[i, 0] * P[0, j] + K[i, 1] * P[1, j] + K[i, 2] * P[2, j]
    KR = np.zeros((n, 3))
    for i in range(n):
        for j in range(3):
            for m in range(3):
                KR[i, j] += K[i, m] * R[m, j]
    P_next = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            acc = M[i, j]
            for m in range(3):
                acc += (KR[i, m] - M[i, m]) * K[j, m]
            P_next[i, j] = acc
    for i in range(n):
        for j in range(i + 1, n):
            value = 0.5 * (P_next[i, j] + P_next[j, i])
            P_next[i, j] = value
            P_next[j, i] = value
    return dx, P_next


@njit
def tangent_basis(s):
    """(e1, e2): the basis of the plane ⟂ the unit vector s of a star residual, e1 = s × (the axis least aligned
    with s) normalised, e2 = s × e1."""
    axis = np.zeros(3)
    ax = np.abs(s)
    if ax[0] <= ax[1] and ax[0] <= ax[2]:
        axis[0] = 1.0
    elif ax[1] <= ax[2]:
        axis[1] = 1.0
    else:
        axis[2] = 1.0
    e1 = np.cross(s, axis)
    e1 /= np.sqrt(np.sum(e1 * e1))
    return e1, np.cross(s, e1)


@njit
def mounting_column(model, n, head):
    """The first error-state column of head ``head``'s mounting error δm, or −1 when the filter carries none."""
    return n - 3 * model.heads + 3 * head if model.mounting else -1


@njit
def q_BS_of(x, head):
    """The mounting estimate q_BS (4,) of head ``head`` in the nominal state x."""
    return x[X_BS + 4 * head : X_BS + 4 * head + 4]


@njit
def star_residuals(q_IB, q_BS, ref_I, obs_S, cov_S, n, mount_col):
    """Tangent-plane residuals of identified stars against the estimates q_IB, q_BS, their Jacobians and
    their measurement covariances.

    ŝ = R_SB R_IBᵀ r; T (2x3) spans the plane ⟂ ŝ; z = T (s − ŝ); R = T C Tᵀ of the measured direction's
    covariance C (3x3, sensor axes: ``cov_S``, correlated along a smear trail);
    H = T [R_SB [b̂×], 0, …, ([ŝ×] in the three columns from ``mount_col``, when it is ≥ 0)] for the body-axes
    attitude error δθ (first three columns) and the mounting error δm.
    Returns (z (N, 2), H (N, 2, n), R (N, 2, 2)).
    """
    m = ref_I.shape[0]
    z = np.empty((m, 2))
    H = np.zeros((m, 2, n))
    R = np.empty((m, 2, 2))
    R_IB = rk.quat_to_matrix(q_IB)
    R_SB = rk.quat_to_matrix(q_BS).T
    for k in range(m):
        _star_row(R_IB, R_SB, ref_I[k], obs_S[k], cov_S[k], z[k], H[k], R[k], mount_col)
    return z, H, R


@njit
def _star_row(R_IB, R_SB, ref_I, obs_S, cov_S, z, H, R, mount_col):
    """One star's z (2,), H (2, n) and R (2, 2) of :func:`star_residuals`, written in place."""
    b_hat = R_IB.T @ ref_I
    s_hat = R_SB @ b_hat
    e1, e2 = tangent_basis(s_hat)
    d = obs_S - s_hat
    z[0] = np.sum(e1 * d)
    z[1] = np.sum(e2 * d)
    c1, c2 = cov_S @ e1, cov_S @ e2
    R[0, 0] = np.sum(e1 * c1)
    R[0, 1] = R[1, 0] = 0.5 * (np.sum(e1 * c2) + np.sum(e2 * c1))
    R[1, 1] = np.sum(e2 * c2)
    A = R_SB @ rk.skew(b_hat)
    for j in range(3):
        H[0, j] = e1[0] * A[0, j] + e1[1] * A[1, j] + e1[2] * A[2, j]
        H[1, j] = e2[0] * A[0, j] + e2[1] * A[1, j] + e2[2] * A[2, j]
    if mount_col >= 0:
        B = rk.skew(s_hat)
        for j in range(3):
            H[0, mount_col + j] = e1[0] * B[0, j] + e1[1] * B[1, j] + e1[2] * B[2, j]
            H[1, mount_col + j] = e2[0] * B[0, j] + e2[1] * B[1, j] + e2[2] * B[2, j]


@njit
def head_residuals(x, heads, ref_I, obs_S, cov_S, n, model):
    """:func:`star_residuals` of stars seen by several heads: star k through head ``heads[k]``'s mounting estimate
    and mounting columns."""
    m = ref_I.shape[0]
    z = np.empty((m, 2))
    H = np.zeros((m, 2, n))
    R = np.empty((m, 2, 2))
    R_IB = rk.quat_to_matrix(x[0:4])
    for k in range(m):
        h = heads[k]
        _star_row(R_IB, rk.quat_to_matrix(q_BS_of(x, h)).T, ref_I[k], obs_S[k], cov_S[k], z[k], H[k], R[k],
                  mounting_column(model, n, h))
    return z, H, R


@njit
def block_nis(H, P, z, R):
    """NIS z_kᵀ S_k⁻¹ z_k of each 2-dim star residual, S_k = H_k P H_kᵀ + R_k."""
    m = z.shape[0]
    out = np.empty(m)
    for k in range(m):
        S = mm_t(mm(H[k], P), H[k]) + R[k]
        det = S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]
        out[k] = (S[1, 1] * z[k, 0] ** 2 - 2.0 * S[0, 1] * z[k, 0] * z[k, 1] + S[0, 0] * z[k, 1] ** 2) / det
    return out


@njit
def fix_residual(q_IB, q_BS, q_IS, R_S):
    """An attitude fix q_IS (covariance R_S in sensor axes) against the estimates q_IB and q_BS:
    z = δθ(q_IB, q_IS ⊗ q_BS⁻¹), the rotation vector of q_IB⁻¹ ⊗ q_IS ⊗ q_BS⁻¹ in body axes, with
    z = δθ + R_BS δm to first order for q_IB,true = q_IB ⊗ δq(δθ) and q_BS,true = q_BS ⊗ δq(δm);
    R = R_BS R_S R_BSᵀ. Returns (z (3,), R_BS, R)."""
    conj = np.array([-1.0, -1.0, -1.0, 1.0])
    z = rk.rotation_vector(rk.quat_multiply(q_IB * conj, rk.quat_multiply(q_IS, q_BS * conj)))
    R_BS = rk.quat_to_matrix(q_BS)
    return z, R_BS, mm_t(mm(R_BS, R_S), R_BS)


@njit
def attitude_update(x, P, q_IS, R_S, head, gate, model, estimated):
    """Gated update with head ``head``'s attitude fix q_IS (covariance R_S in sensor axes), then the reset.

    z = δθ(q, q_IS ⊗ q_BS⁻¹) in body axes, H = [I, 0, (0), (R_BS in the head's mounting columns)],
    R = R_BS R_S R_BSᵀ. Returns (x, P, z, nis, accepted); the state is unchanged when rejected.
    """
    n = P.shape[0]
    z, R_BS, R = fix_residual(x[0:4], q_BS_of(x, head), q_IS, R_S)
    H = np.zeros((3, n))
    col = mounting_column(model, n, head)
    for i in range(3):
        H[i, i] = 1.0
        if col >= 0:
            for j in range(3):
                H[i, col + j] = R_BS[i, j]
    S = mm_t(mm(H, P), H) + R
    S_inv = inverse_small(S)
    nis = 0.0
    for i in range(3):
        for j in range(3):
            nis += z[i] * S_inv[i, j] * z[j]
    if nis > gate:
        return x, P, z, nis, False
    if col >= 0:
        dx, P_next = joseph_update(P, H, R, z, estimated)
    else:
        dx, P_next = joseph_update_attitude(P, R, z, estimated)
    return reset(x, dx, model), P_next, z, nis, True


@njit
def stars_update(x, P, heads, ref_I, obs_S, cov_S, gate, model, estimated):
    """Gated update with identified stars, star k seen by head ``heads[k]``, and their covariances in S (see
    :func:`star_residuals`): each star's 2-dof NIS against the prior is compared with ``gate``; the accepted stars
    update together, then the reset. Returns (x, P, z (N, 2), nis (N,), accepted (N,))."""
    z, H, R = head_residuals(x, heads, ref_I, obs_S, cov_S, P.shape[0], model)
    nis, accepted, Ha, za, Ra = gate_stars(H, P, z, R, gate)
    if za.shape[0] == 0:
        return x, P, z, nis, accepted
    dx, P_next = joseph_update(P, Ha, Ra, za, estimated)
    return reset(x, dx, model), P_next, z, nis, accepted


@njit
def gate_stars(H, P, z, R, gate):
    """Each star's 2-dof NIS against the prior (:func:`block_nis`) compared with ``gate``; the accepted
    stars stacked into one measurement. Returns (nis (N,), accepted (N,), H (2m, n), z (2m,),
    R (2m, 2m): the accepted stars' 2x2 blocks) for the m accepted stars."""
    n = P.shape[0]
    nis = block_nis(H, P, z, R)
    accepted = nis <= gate
    m = int(np.sum(accepted))
    Ha = np.empty((2 * m, n))
    za = np.empty(2 * m)
    Ra = np.zeros((2 * m, 2 * m))
    row = 0
    for k in range(z.shape[0]):
        if accepted[k]:
            for r in range(2):
                Ha[row + r] = H[k, r]
                za[row + r] = z[k, r]
                for c in range(2):
                    Ra[row + r, row + c] = R[k, r, c]
            row += 2
    return nis, accepted, Ha, za, Ra


@njit
def reset(x, dx, model):
    """Move the error estimate dx into the nominal state (first-order reset):
    q ← q ⊗ δq(δθ), b ← b + δb, g ← g + δg, K ← K + δK, each head's q_BS ← q_BS ⊗ δq(δm). Returns the new x."""
    n = dx.shape[0]
    out = x.copy()
    q_next = rk.quat_multiply(x[0:4], rk.quat_from_rotation_vector(dx[0:3]))
    out[0:4] = q_next / np.sqrt(np.sum(q_next * q_next))
    out[4:7] = x[4:7] + dx[3:6]
    if model.n_bi:
        out[X_G : X_G + 3] = x[X_G : X_G + 3] + dx[6:9]
    flat = calibration_flat(model)
    for c in range(flat.shape[0]):
        out[7 + flat[c]] = x[7 + flat[c]] + dx[6 + model.n_bi + c]
    if model.mounting:
        for h in range(model.heads):
            col = mounting_column(model, n, h)
            q_BS_next = rk.quat_multiply(q_BS_of(x, h), rk.quat_from_rotation_vector(dx[col : col + 3]))
            out[X_BS + 4 * h : X_BS + 4 * h + 4] = q_BS_next / np.sqrt(np.sum(q_BS_next * q_BS_next))
    return out


@njit
def star_statistics(z, nis, accepted):
    """(accepted, NIS sum of the accepted, its dof, RMS of their innovations [rad]) of one star frame."""
    m = 0
    total = 0.0
    squares = 0.0
    for k in range(z.shape[0]):
        if accepted[k]:
            m += 1
            total += nis[k]
            squares += z[k, 0] ** 2 + z[k, 1] ** 2
    if m == 0:
        return 0, np.nan, 0, np.nan
    return m, total, 2 * m, np.sqrt(squares / (2 * m))


@njit
def _allocate_logs(n_frames, x_size, n):
    return (np.empty((n_frames, x_size)), np.empty((n_frames, n, n)), np.zeros(n_frames, dtype=np.int32),
            np.zeros(n_frames, dtype=np.int32), np.full(n_frames, np.nan), np.zeros(n_frames, dtype=np.int32),
            np.full(n_frames, np.nan))


@njit
def run_fixes(x, P, omega, ratio, dt, model, estimated, q_meas, R_S, gate, available):
    """The whole-record loop of the fast path with attitude fixes: for each frame f, ``ratio`` gyro
    samples of ``omega`` (F*ratio, 3) propagate the filter (:func:`predict`), then the fix of each head h
    ``q_meas[f, h]`` (covariance R_S[h]) that is ``available[f, h]`` updates it, head after head
    (:func:`attitude_update`). Returns per frame: x (F, 19 + 4H), P (F, n, n), measurements, accepted, NIS of the
    accepted (summed over the heads), its dof and the RMS of the accepted innovations [rad]."""
    n_frames, n_heads = available.shape
    x_log, P_log, n_meas, n_acc, nis_log, dof_log, innov_log = _allocate_logs(n_frames, x.shape[0], P.shape[0])
    for f in range(n_frames):
        x, P = predict(x, P, omega[f * ratio : (f + 1) * ratio], dt, model)
        nis_sum, squares = 0.0, 0.0
        for h in range(n_heads):
            if available[f, h]:
                x, P, z, nis, ok = attitude_update(x, P, q_meas[f, h], R_S[h], h, gate, model, estimated)
                n_meas[f] += 1
                if ok:
                    n_acc[f] += 1
                    nis_sum += nis
                    squares += np.sum(z * z)
        if n_acc[f]:
            nis_log[f] = nis_sum
            dof_log[f] = 3 * n_acc[f]
            innov_log[f] = np.sqrt(squares / (3.0 * n_acc[f]))
        x_log[f] = x
        P_log[f] = P
    return x_log, P_log, n_meas, n_acc, nis_log, dof_log, innov_log


@njit
def run_stars(x, P, omega, ratio, dt, model, estimated, offsets, heads, ref_I, obs_S, cov_S, gate, available):
    """:func:`run_fixes` with star vectors: frame f updates with the stars offsets[f]:offsets[f+1]
    of ``heads``/``ref_I``/``obs_S``/``cov_S`` (:func:`stars_update`)."""
    n_frames = available.shape[0]
    x_log, P_log, n_meas, n_acc, nis_log, dof_log, innov_log = _allocate_logs(n_frames, x.shape[0], P.shape[0])
    for f in range(n_frames):
        x, P = predict(x, P, omega[f * ratio : (f + 1) * ratio], dt, model)
        lo, hi = offsets[f], offsets[f + 1]
        if available[f] and hi > lo:
            x, P, z, nis, accepted = stars_update(x, P, heads[lo:hi], ref_I[lo:hi], obs_S[lo:hi], cov_S[lo:hi], gate,
                                                  model, estimated)
            n_meas[f] = hi - lo
            n_acc[f], nis_log[f], dof_log[f], innov_log[f] = star_statistics(z, nis, accepted)
        x_log[f] = x
        P_log[f] = P
    return x_log, P_log, n_meas, n_acc, nis_log, dof_log, innov_log
