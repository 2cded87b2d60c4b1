"""Compiled inner loops of the MEKF (numba): propagation, Joseph update, star residuals.

These are the scalar forms of :mod:`navsim.kinematics` and :mod:`navsim.estimation.attitude_filter`'s maths,
compiled because a filter step runs tens of thousands of times per simulated minute. Each is
tested against its numpy / filterpy counterpart. Conventions are those of DESIGN.md
(scalar-last Hamilton quaternions, error state δθ in body axes).
"""

import numpy as np

from navsim.kinematics_jit import rk4_hold
from startrack.jit import njit
from startrack.rotation_jit import quat_from_rotation_vector, quat_multiply, quat_to_matrix, rotation_vector, skew


@njit
def mm(A, B):
    """A @ B for small matrices with explicit loops (cheaper than a BLAS call below ~20x20)."""
    n, k = A.shape
    m = B.shape[1]
    C = np.zeros((n, m))
    for i in range(n):
        for p in range(k):
            a = A[i, p]
            if a != 0.0:
                for j in range(m):
                    C[i, j] += a * B[p, j]
    return C


@njit
def mm_t(A, B):
    """A @ B.T for small matrices with explicit loops."""
    n, k = A.shape
    m = B.shape[0]
    C = np.empty((n, m))
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for p in range(k):
                acc += A[i, p] * B[j, p]
            C[i, j] = acc
    return C


@njit
def inverse_small(S):
    """Inverse of a small symmetric positive-definite matrix: closed form for 2x2 and 3x3, else LAPACK."""
    n = S.shape[0]
    if n == 3:
        a, b, c = S[0, 0], S[0, 1], S[0, 2]
        d, e, f = S[1, 1], S[1, 2], S[2, 2]
        A = d * f - e * e
        B = c * e - b * f
        C = b * e - c * d
        det = a * A + b * B + c * C
        out = np.empty((3, 3))
        out[0, 0] = A / det
        out[0, 1] = B / det
        out[1, 0] = B / det
        out[0, 2] = C / det
        out[2, 0] = C / det
        out[1, 1] = (a * f - c * c) / det
        out[1, 2] = (b * c - a * e) / det
        out[2, 1] = out[1, 2]
        out[2, 2] = (a * d - b * b) / det
        return out
    if n == 2:
        det = S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]
        out = np.empty((2, 2))
        out[0, 0] = S[1, 1] / det
        out[1, 1] = S[0, 0] / det
        out[0, 1] = -S[0, 1] / det
        out[1, 0] = -S[1, 0] / det
        return out
    return np.linalg.inv(S)







@njit
def transition(omega, d_scale, dt, n, sf_start):
    """Closed-form transition matrix Φ (n x n) of the error state over dt (Crassidis & Junkins,
    *Optimal Estimation of Dynamic Systems*, 2nd ed., §7.2.1), w = |ω|:

    Φ11 = I − [ω×] sin(wΔt)/w + [ω×]² (1 − cos wΔt)/w²,
    Φ12 = −IΔt + [ω×](1 − cos wΔt)/w² − [ω×]²(wΔt − sin wΔt)/w³,
    Φ_θs = Φ12 diag(ω̃ − b) (δs enters like δb), all other blocks identity/zero.
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
    W = skew(omega)
    W2 = mm(W, W)
    F = np.eye(n)
    for i in range(3):
        for j in range(3):
            F[i, j] += -a * W[i, j] + b * W2[i, j]
            F[i, 3 + j] = b * W[i, j] - c * W2[i, j]
        F[i, 3 + i] -= dt
    if sf_start >= 0:
        for i in range(3):
            for j in range(3):
                F[i, sf_start + j] = F[i, 3 + j] * d_scale[j]
    return F


@njit
def process_noise(arw, rrw, sf_rw, dt, n, sf_start):
    """Discrete Q (n x n): Farrenkopf's attitude/bias blocks for ARW σ_v [rad/√s] and RRW σ_u
    [rad/s^(3/2)] — Q11 = (σ_v²Δt + σ_u²Δt³/3) I, Q12 = −σ_u²Δt²/2 I, Q22 = σ_u²Δt I — and a
    scale-factor random walk σ_s²Δt I."""
    Q = np.zeros((n, n))
    for i in range(3):
        Q[i, i] = arw * arw * dt + rrw * rrw * dt**3 / 3.0
        Q[i, 3 + i] = Q[3 + i, i] = -0.5 * rrw * rrw * dt * dt
        Q[3 + i, 3 + i] = rrw * rrw * dt
        if sf_start >= 0:
            Q[sf_start + i, sf_start + i] = sf_rw * sf_rw * dt
    return Q


@njit
def predict(q, P, b, s, omega_measured, dt, arw, rrw, sf_rw, q_scale, sf_start):
    """MEKF propagation over consecutive gyro samples ``omega_measured`` (m, 3), each held for dt:
    ω = (1 − s)(ω̃ − b), q by RK4 (eq. 9 of 000), P ← Φ P Φᵀ + q_scale Q. Returns (q, P).

    Φ = I + E with E non-zero only in the three attitude rows, so Φ P Φᵀ = P + E P + (E P)ᵀ
    + E P Eᵀ is formed from the 3 x n product E P alone.
    """
    n = P.shape[0]
    Q = q_scale * process_noise(arw, rrw, sf_rw, dt, n, sf_start)
    P = P.copy()
    EP = np.empty((3, n))
    for k in range(omega_measured.shape[0]):
        d_scale = omega_measured[k] - b
        omega = (1.0 - s) * d_scale
        F = transition(omega, d_scale, dt, n, sf_start)
        for i in range(3):
            F[i, i] -= 1.0  # E = Φ − I
        for i in range(3):
            for j in range(n):
                acc = 0.0
                for p in range(n):
                    acc += F[i, p] * P[p, j]
                EP[i, j] = acc
        for i in range(3):
            for j in range(3):
                acc = 0.0
                for p in range(n):
                    acc += EP[i, p] * F[j, p]
                P[i, j] += EP[i, j] + EP[j, i] + acc
            for j in range(3, n):
                P[i, j] += EP[i, j]
                P[j, i] = P[i, j]
        for i in range(n):
            for j in range(i, n):
                value = 0.5 * (P[i, j] + P[j, i]) + Q[i, j]
                P[i, j] = value
                P[j, i] = value
        q = rk4_hold(q, omega, dt)
    return q, P


@njit
def joseph_update(P, H, R, z):
    """Kalman update of a zero error state: returns (dx, P⁺) with the Joseph form
    P⁺ = (I − KH) P (I − KH)ᵀ + K R Kᵀ, K = P Hᵀ S⁻¹, S = H P Hᵀ + R, symmetrised.

    Formed as M = P − K (H P), P⁺ = M − (M Hᵀ) Kᵀ + K R Kᵀ: O(n² m) for m measurements.
    """
    HP = mm(H, P)
    S = mm_t(HP, H) + R
    K = mm(HP.T.copy(), inverse_small(S))
    dx = np.zeros(K.shape[0])
    for i in range(K.shape[0]):
        for j in range(z.shape[0]):
            dx[i] += K[i, j] * z[j]
    M = P - mm(K, HP)
    P_next = M - mm_t(mm_t(M, H), K) + mm_t(mm(K, R), K)
    return dx, 0.5 * (P_next + P_next.T)


@njit
def joseph_update_attitude(P, R, z):
    """:func:`joseph_update` for H = [I₃ 0] (an attitude fix, no mounting state), in O(n²):
    S = P₁₁ + R, K = P[:, :3] S⁻¹, M = P − K P[:3, :], P⁺ = M − M[:, :3] Kᵀ + K R Kᵀ."""
    n = P.shape[0]
    S = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            S[i, j] = P[i, j] + R[i, j]
    S_inv = inverse_small(S)
    K = np.zeros((n, 3))
    for i in range(n):
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
def star_residuals(q_IB, R_BS, ref_I, obs_S, n, mis_start):
    """Tangent-plane residuals of identified stars and their Jacobians.

    ŝ = R_SB R_IBᵀ r; T (2x3) spans the plane ⟂ ŝ; z = T (s − ŝ);
    H = T [R_SB [b̂×], 0, …, ([ŝ×] at ``mis_start`` if ≥ 0)]. Returns (z (N, 2), H (N, 2, n)).
    """
    m = ref_I.shape[0]
    R_IB = quat_to_matrix(q_IB)
    R_SB = R_BS.T
    z = np.empty((m, 2))
    H = np.zeros((m, 2, n))
    for k in range(m):
        b_hat = R_IB.T @ ref_I[k]
        s_hat = R_SB @ b_hat
        # tangent basis: e1 = s × (axis least aligned with s), e2 = s × e1
        axis = np.zeros(3)
        ax = np.abs(s_hat)
        if ax[0] <= ax[1] and ax[0] <= ax[2]:
            axis[0] = 1.0
        elif ax[1] <= ax[2]:
            axis[1] = 1.0
        else:
            axis[2] = 1.0
        e1 = np.cross(s_hat, axis)
        e1 /= np.sqrt(np.sum(e1 * e1))
        e2 = np.cross(s_hat, e1)
        d = obs_S[k] - s_hat
        z[k, 0] = np.sum(e1 * d)
        z[k, 1] = np.sum(e2 * d)
        A = R_SB @ skew(b_hat)
        for j in range(3):
            H[k, 0, j] = e1[0] * A[0, j] + e1[1] * A[1, j] + e1[2] * A[2, j]
            H[k, 1, j] = e2[0] * A[0, j] + e2[1] * A[1, j] + e2[2] * A[2, j]
        if mis_start >= 0:
            B = skew(s_hat)
            for j in range(3):
                H[k, 0, mis_start + j] = e1[0] * B[0, j] + e1[1] * B[1, j] + e1[2] * B[2, j]
                H[k, 1, mis_start + j] = e2[0] * B[0, j] + e2[1] * B[1, j] + e2[2] * B[2, j]
    return z, H


@njit
def block_nis(H, P, z, variance):
    """NIS z_kᵀ S_k⁻¹ z_k of each 2-dim star residual, S_k = H_k P H_kᵀ + σ_k² I₂."""
    m = z.shape[0]
    out = np.empty(m)
    for k in range(m):
        S = mm_t(mm(H[k], P), H[k])
        S[0, 0] += variance[k]
        S[1, 1] += variance[k]
        det = S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]
        out[k] = (S[1, 1] * z[k, 0] ** 2 - 2.0 * S[0, 1] * z[k, 0] * z[k, 1] + S[0, 0] * z[k, 1] ** 2) / det
    return out


@njit
def attitude_update(q, b, s, q_BS, P, q_IS, R_S, gate, sf_start, mis_start):
    """Gated update with an attitude fix q_IS (covariance R_S in sensor axes), then the reset.

    z = δθ(q, q_IS ⊗ q_BS⁻¹) in body axes, H = [I, 0, (0), (R_BS)], R = R_BS R_S R_BSᵀ.
    Returns (q, b, s, q_BS, P, z, nis, accepted); the state is unchanged when rejected.
    """
    n = P.shape[0]
    conj = np.array([-1.0, -1.0, -1.0, 1.0])
    q_IB_measured = quat_multiply(q_IS, q_BS * conj)
    z = rotation_vector(quat_multiply(q * conj, q_IB_measured))
    R_BS = quat_to_matrix(q_BS)
    H = np.zeros((3, n))
    for i in range(3):
        H[i, i] = 1.0
        if mis_start >= 0:
            for j in range(3):
                H[i, mis_start + j] = R_BS[i, j]
    R = mm_t(mm(R_BS, R_S), R_BS)
    S = mm_t(mm(H, P), H) + R
    S_inv = inverse_small(S)
    nis = 0.0
    for i in range(3):
        for j in range(3):
            nis += z[i] * S_inv[i, j] * z[j]
    if nis > gate:
        return q, b, s, q_BS, P, z, nis, False
    if mis_start >= 0:
        dx, P_next = joseph_update(P, H, R, z)
    else:
        dx, P_next = joseph_update_attitude(P, R, z)
    q, b, s, q_BS = reset(q, b, s, q_BS, dx, sf_start, mis_start)
    return q, b, s, q_BS, P_next, z, nis, True


@njit
def stars_update(q, b, s, q_BS, P, ref_I, obs_S, variance, gate, sf_start, mis_start):
    """Gated update with identified stars (see :func:`star_residuals`): each star's 2-dof NIS
    against the prior is compared with ``gate``; the accepted stars update together, then the
    reset. Returns (q, b, s, q_BS, P, z (N, 2), nis (N,), accepted (N,))."""
    n = P.shape[0]
    z, H = star_residuals(q, quat_to_matrix(q_BS), ref_I, obs_S, n, mis_start)
    nis = block_nis(H, P, z, variance)
    accepted = nis <= gate
    m = int(np.sum(accepted))
    if m == 0:
        return q, b, s, q_BS, P, z, nis, accepted
    Ha = np.empty((2 * m, n))
    za = np.empty(2 * m)
    Ra = np.zeros((2 * m, 2 * m))
    row = 0
    for k in range(z.shape[0]):
        if accepted[k]:
            for r in range(2):
                Ha[row] = H[k, r]
                za[row] = z[k, r]
                Ra[row, row] = variance[k]
                row += 1
    dx, P_next = joseph_update(P, Ha, Ra, za)
    q, b, s, q_BS = reset(q, b, s, q_BS, dx, sf_start, mis_start)
    return q, b, s, q_BS, P_next, z, nis, accepted


@njit
def reset(q, b, s, q_BS, dx, sf_start, mis_start):
    """Move the error estimate dx into the nominal state (first-order reset):
    q ← q ⊗ δq(δθ), b ← b + δb, s ← s + δs, q_BS ← q_BS ⊗ δq(δm). Returns (q, b, s, q_BS)."""
    q_next = quat_multiply(q, quat_from_rotation_vector(dx[0:3]))
    q_next /= np.sqrt(np.sum(q_next * q_next))
    b_next = b + dx[3:6]
    s_next = s.copy()
    if sf_start >= 0:
        s_next += dx[sf_start : sf_start + 3]
    q_BS_next = q_BS.copy()
    if mis_start >= 0:
        q_BS_next = quat_multiply(q_BS, quat_from_rotation_vector(dx[mis_start : mis_start + 3]))
        q_BS_next /= np.sqrt(np.sum(q_BS_next * q_BS_next))
    return q_next, b_next, s_next, q_BS_next



@njit
def run_filter(q, b, s, q_BS, P, omega, ratio, dt, arw, rrw, sf_rw, q_scale, sf_start, mis_start,
               fix_mode, q_meas, R_S, offsets, ref_I, obs_S, variance, gate, available):
    """The vector-fidelity filter loop of one run, compiled: for each frame f, ``ratio`` gyro
    samples of ``omega`` (M, 3) propagate the filter (:func:`predict`), then the frame's
    measurements update it — an attitude fix ``q_meas[f]`` with covariance ``R_S`` when
    ``fix_mode``, else the stars ``offsets[f]:offsets[f+1]`` of ``ref_I``/``obs_S``/``variance``
    (:func:`attitude_update`, :func:`stars_update`) — all gated at ``gate``; frames whose
    ``available`` is False (outage, dropped) only propagate.

    Returns per frame: q (F, 4), b (F, 3), P (F, n, n), measurements, accepted, NIS of the
    accepted, its degrees of freedom, and the RMS of the accepted innovations [rad].
    """
    n_frames = offsets.shape[0] - 1
    n = P.shape[0]
    q_log = np.empty((n_frames, 4))
    b_log = np.empty((n_frames, 3))
    P_log = np.empty((n_frames, n, n))
    n_meas = np.zeros(n_frames, dtype=np.int32)
    n_acc = np.zeros(n_frames, dtype=np.int32)
    nis_log = np.full(n_frames, np.nan)
    dof_log = np.zeros(n_frames, dtype=np.int32)
    innov_log = np.full(n_frames, np.nan)
    for f in range(n_frames):
        q, P = predict(q, P, b, s, omega[f * ratio : (f + 1) * ratio], dt, arw, rrw, sf_rw, q_scale, sf_start)
        if not available[f]:
            pass
        elif fix_mode:
            q, b, s, q_BS, P, z, nis, ok = attitude_update(q, b, s, q_BS, P, q_meas[f], R_S, gate, sf_start, mis_start)
            n_meas[f] = 1
            if ok:
                n_acc[f] = 1
                nis_log[f] = nis
                dof_log[f] = 3
                innov_log[f] = np.sqrt(np.sum(z * z) / 3.0)
        else:
            lo, hi = offsets[f], offsets[f + 1]
            if hi > lo:
                q, b, s, q_BS, P, z, nis, acc = stars_update(
                    q, b, s, q_BS, P, ref_I[lo:hi], obs_S[lo:hi], variance[lo:hi], gate, sf_start, mis_start
                )
                m = int(np.sum(acc))
                n_meas[f] = hi - lo
                n_acc[f] = m
                if m > 0:
                    total = 0.0
                    squares = 0.0
                    for k in range(hi - lo):
                        if acc[k]:
                            total += nis[k]
                            squares += z[k, 0] ** 2 + z[k, 1] ** 2
                    nis_log[f] = total
                    dof_log[f] = 2 * m
                    innov_log[f] = np.sqrt(squares / (2 * m))
        q_log[f] = q
        b_log[f] = b
        P_log[f] = P
    return q_log, b_log, P_log, n_meas, n_acc, nis_log, dof_log, innov_log


@njit
def quadratic_forms(P, e):
    """eᵢᵀ Pᵢ⁻¹ eᵢ for each i of P (N, m, m) symmetric positive definite and e (N, m), by
    Cholesky factorisation (NEES of the logged covariances)."""
    count, m = e.shape
    out = np.empty(count)
    L = np.empty((m, m))
    y = np.empty(m)
    for i in range(count):
        for r in range(m):
            for c in range(r + 1):
                acc = P[i, r, c]
                for k in range(c):
                    acc -= L[r, k] * L[c, k]
                if r == c:
                    L[r, r] = np.sqrt(acc)
                else:
                    L[r, c] = acc / L[c, c]
        total = 0.0
        for r in range(m):
            acc = e[i, r]
            for k in range(r):
                acc -= L[r, k] * y[k]
            y[r] = acc / L[r, r]
            total += y[r] * y[r]
        out[i] = total
    return out
