"""Compiled kernels of the navigation error-state filter (numba): the continuous error dynamics F,
their discretisation (Φ, Q_d), propagation over IMU increments, the measurement updates and the reset.

Error state x (zero between updates; docs/design.md):

    [φ (3) | δv_n (3) | δL, δλ, δh | ε (3) | ∇ (3) | δs_g (3), δs_a (3) if scale factors]

with C_nb,est = (I − [φ×]) C_nb,true, δv = v_est − v_true, δL = L_est − L_true (…), ε = b_g,true −
b̂_g and ∇ = b_a,true − b̂_a (the residual biases of the corrected increments), δs = s_true − ŝ.
Corrected increments are (1 − ŝ)(Δθ̃ − b̂_g Δt) and (1 − ŝ_a)(Δṽ − b̂_a Δt).
"""

import numpy as np

from navsim.earth.frames import earth_rate_n, transport_rate_n
from navsim.earth.gravity import normal_gravity_height_gradient, normal_gravity_latitude_gradient
from navsim.earth.wgs84 import E2, radii
from navsim.estimation.kernels import inverse_small, joseph_update, mm, mm_t
from navsim.ins.strapdown import step
from startrack.jit import njit
from startrack.rotation_jit import quat_from_rotation_vector, quat_multiply, quat_to_matrix, skew

#: First index of the position error (δL, δλ, δh) in the error state.
DP = 6
#: The states a baro height updates: the vertical channel δv_D, δh and the body-z accelerometer bias
#: (down in level flight); for its update every other state is a consider state (Schmidt), so a baro
#: damps the vertical channel and tells the filter nothing of the horizontal ones. (Estimating them
#: all, the filter would draw horizontal information from a white-noise height through the Coriolis
#: and v²/R couplings of the vertical channel, which no biased, lagging baro really carries.)
BARO_STATES = (5, DP + 2, 14)
#: Layout of the accumulator of one covariance interval: [count, Σ C_nb Δv (3), Σ C_nb (9),
#: Σ C_nb diag(Δθ) (9), Σ C_nb diag(Δv) (9)].
ACC_SIZE = 31


@njit
def continuous_f(lat, h, v, f_n, C, C_w, C_f, n):
    """Continuous error dynamics F (n x n) at (L, h, v_n) [rad, m, m/s] for the specific force f_n
    [m/s²] in n, the mean C_nb ``C``, and (for the scale-factor columns) C_nb diag(ω_b) ``C_w``
    [rad/s] and C_nb diag(f_b) ``C_f`` [m/s²] (Titterton & Weston, 2nd ed., ch. 12; Groves,
    2nd ed., §14.2.4, with this φ sign):

    φ̇ = −ω_in × φ + δω_in − C_nb (ε + diag(ω_b) δs_g),
    δv̇ = f^n × φ + C_nb (∇ + diag(f_b) δs_a) − (2ω_ie + ω_en) × δv − (2δω_ie + δω_en) × v + δg,
    δL̇ = δv_N/(R_M+h) − v_N δh/(R_M+h)², δλ̇ = δv_E/((R_N+h) cos L) + v_E tan L δL/((R_N+h) cos L)
    − v_E δh/((R_N+h)² cos L), δḣ = −δv_D; δg = [0, 0, ∂γ/∂L δL + ∂γ/∂h δh]; and the terms of
    dR_M/dL = 3 R_M e² sin L cos L/(1 − e² sin²L), dR_N/dL = R_N e² sin L cos L/(1 − e² sin²L)
    in every δL column (usually neglected; kept so that F is the exact Jacobian).
    """
    r_m, r_n = radii(lat)
    rm, rn = r_m + h, r_n + h
    s, c, t = np.sin(lat), np.cos(lat), np.tan(lat)
    k = E2 * s * c / (1.0 - E2 * s * s)
    dr_m, dr_n = 3.0 * r_m * k, r_n * k  # dR_M/dL, dR_N/dL
    w_ie = np.array(earth_rate_n(lat))
    w_en = np.array(transport_rate_n(lat, h, v[0], v[1]))
    # ∂ω_en/∂v, ∂ω_ie/∂p and ∂ω_en/∂p (p = L, λ, h)
    d_en_v = np.zeros((3, 3))
    d_en_v[0, 1], d_en_v[1, 0], d_en_v[2, 1] = 1.0 / rn, -1.0 / rm, -t / rn
    d_ie_p = np.zeros((3, 3))
    d_ie_p[0, 0], d_ie_p[2, 0] = w_ie[2], -w_ie[0]  # Ω(−sin L, 0, −cos L)
    d_en_p = np.zeros((3, 3))
    d_en_p[0, 0], d_en_p[1, 0] = -v[1] * dr_n / rn**2, v[0] * dr_m / rm**2
    d_en_p[2, 0] = -v[1] / (rn * c * c) + v[1] * t * dr_n / rn**2
    d_en_p[0, 2], d_en_p[1, 2], d_en_p[2, 2] = -v[1] / rn**2, v[0] / rm**2, v[1] * t / rn**2
    V = skew(v)
    F = np.zeros((n, n))
    F[0:3, 0:3] = -skew(w_ie + w_en)
    F[0:3, 3:6] = d_en_v
    F[0:3, 6:9] = d_ie_p + d_en_p
    F[0:3, 9:12] = -C
    F[3:6, 0:3] = skew(f_n)
    F[3:6, 3:6] = -skew(2.0 * w_ie + w_en) + mm(V, d_en_v)
    F[3:6, 6:9] = mm(V, 2.0 * d_ie_p + d_en_p)
    F[5, 6] += normal_gravity_latitude_gradient(lat, h)
    F[5, 8] += normal_gravity_height_gradient(lat, h)
    F[3:6, 12:15] = C
    F[6, 3], F[6, 6], F[6, 8] = 1.0 / rm, -v[0] * dr_m / rm**2, -v[0] / rm**2
    F[7, 4], F[7, 8] = 1.0 / (rn * c), -v[1] / (rn * rn * c)
    F[7, 6] = v[1] * s / (rn * c * c) - v[1] * dr_n / (rn * rn * c)
    F[8, 5] = -1.0
    if n > 15:
        F[0:3, 15:18] = -C_w
        F[3:6, 18:21] = C_f
    return F


@njit
def _sparse_times(rows, cols, values, B, out):
    """out = S B for S given by its non-zero triplets (rows, cols, values)."""
    out[:, :] = 0.0
    for k in range(values.shape[0]):
        i, p, a = rows[k], cols[k], values[k]
        for j in range(B.shape[1]):
            out[i, j] += a * B[p, j]


@njit
def discretize(F, q_c, dt):
    """(Φ, Q_d) over dt [s] for F and the diagonal continuous noise ``q_c`` (n,) by their Taylor
    series to fifth order: Φ = Σ (FΔt)^k/k! and Van Loan's integral
    Q_d = ∫₀^Δt e^(Fs) Q e^(Fᵀs) ds = Σ L_k Δt^(k+1)/(k+1)!, L_0 = Q, L_k = F L_(k−1) + L_(k−1) Fᵀ
    (Van Loan 1978). F is sparse: each product runs over its non-zeros only."""
    n = F.shape[0]
    rows, cols = np.nonzero(F)
    values = np.empty(rows.shape[0])
    for k in range(rows.shape[0]):
        values[k] = F[rows[k], cols[k]]
    Phi, term, product = np.eye(n), np.eye(n), np.empty((n, n))
    L = np.zeros((n, n))
    Q = np.zeros((n, n))
    for i in range(n):
        L[i, i] = q_c[i]
        Q[i, i] = q_c[i] * dt
    coefficient = dt
    for k in range(1, 6):
        _sparse_times(rows, cols, values * (dt / k), term, product)
        term[:, :] = product
        Phi += term
        _sparse_times(rows, cols, values, L, product)
        coefficient *= dt / (k + 1)
        for i in range(n):
            for j in range(n):
                L[i, j] = product[i, j] + product[j, i]
                Q[i, j] += coefficient * L[i, j]
    return Phi, Q


@njit
def correct(sample, imu, dt, n, a, b):
    """Write into ``a``, ``b`` the increments of one IMU ``sample`` (6,) (interval means: rate [rad/s],
    specific force [m/s²]) corrected by the estimates ``imu`` = [b̂_g, b̂_a, ŝ_g, ŝ_a]:
    (1 − ŝ_g)(ω̃ − b̂_g) Δt and (1 − ŝ_a)(f̃ − b̂_a) Δt."""
    for i in range(3):
        a[i] = (sample[i] - imu[i]) * dt
        b[i] = (sample[3 + i] - imu[3 + i]) * dt
        if n > 15:
            a[i] *= 1.0 - imu[6 + i]
            b[i] *= 1.0 - imu[9 + i]


@njit
def accumulate(acc, q_nb, dtheta, dv):
    """Add one interval's corrected increments to the covariance accumulator, resolved with the
    attitude q_nb at the start of the interval."""
    C = quat_to_matrix(q_nb)
    acc[0] += 1.0
    for i in range(3):
        for j in range(3):
            acc[1 + i] += C[i, j] * dv[j]
            acc[4 + 3 * i + j] += C[i, j]
            acc[13 + 3 * i + j] += C[i, j] * dtheta[j]
            acc[22 + 3 * i + j] += C[i, j] * dv[j]


@njit
def flush(nav, P, acc, q_c, dt):
    """Propagate P over the accumulated intervals (P ← Φ P Φᵀ + Q_d, F at the current position and
    velocity with the interval means of f^n and C_nb) and empty the accumulator."""
    count = acc[0]
    if count == 0.0:
        return
    span = count * dt
    n = P.shape[0]
    C = acc[4:13].reshape(3, 3) / count
    C_w = acc[13:22].reshape(3, 3) / span
    C_f = acc[22:31].reshape(3, 3) / span
    F = continuous_f(nav[0], nav[2], nav[3:6], acc[1:4] / span, C, C_w, C_f, n)
    Phi, Q = discretize(F, q_c, span)
    P_next = mm(Phi, mm(Phi, P).T.copy()) + Q  # Φ (Φ P)ᵀ = Φ P Φᵀ with sparse left factors
    P[:, :] = 0.5 * (P_next + P_next.T)
    acc[:] = 0.0


@njit
def predict(nav, imu, P, acc, samples, dt, q_c, every):
    """Mechanize the corrected IMU samples (M, 6) and propagate P every ``every`` intervals
    (the remainder stays in ``acc`` until the next call or update). All arrays change in place."""
    n = P.shape[0]
    a, b = np.empty(3), np.empty(3)
    for k in range(samples.shape[0]):
        correct(samples[k], imu, dt, n, a, b)
        accumulate(acc, nav[6:10], a, b)
        step(nav, a, b, dt)
        if acc[0] >= every:
            flush(nav, P, acc, q_c, dt)


@njit
def reset(nav, imu, dx, n):
    """Fold the error estimate dx into the nominal state (in place): C_nb ← exp([φ×]) C_nb,
    v ← v − δv, (L, λ, h) ← − (δL, δλ, δh), b̂ ← b̂ + (ε, ∇), ŝ ← ŝ + δs."""
    q = quat_multiply(quat_from_rotation_vector(dx[0:3]), nav[6:10])
    nav[6:10] = q / np.sqrt(np.sum(q * q))
    nav[3:6] -= dx[3:6]
    nav[0:3] -= dx[6:9]
    imu[0:6] += dx[9:15]
    if n > 15:
        imu[6:12] += dx[15:21]


@njit
def position_update(nav, imu, P, acc, q_c, dt, fix, sigma, gate):
    """Flush the covariance, then the gated update with a position fix ``fix`` = (L, λ, h) [rad, rad, m]
    of NED σ ``sigma`` (3,) [m]: z = (L̂, λ̂, ĥ) − fix, H = [0 0 I 0 …],
    R = diag(σ_N²/(R_M+h)², σ_E²/((R_N+h) cos L)², σ_D²). Returns (z in NED metres (3,), nis,
    accepted); the state, P and the nominal state change in place."""
    flush(nav, P, acc, q_c, dt)
    n = P.shape[0]
    r_m, r_n = radii(nav[0])
    scale = np.array([r_m + nav[2], (r_n + nav[2]) * np.cos(nav[0]), -1.0])
    H = np.zeros((3, n))
    R = np.zeros((3, 3))
    z = np.empty(3)
    for i in range(3):
        H[i, DP + i] = 1.0
        R[i, i] = (sigma[i] / scale[i]) ** 2
        z[i] = nav[i] - fix[i]
    z_m = z * scale
    nis, accepted = _gated_update(nav, imu, P, H, R, z, gate, np.ones(n, dtype=np.bool_))  # every state estimated
    return z_m, nis, accepted


@njit
def baro_update(nav, imu, P, acc, q_c, dt, height, sigma, gate):
    """Flush the covariance, then the gated update of the vertical channel (:data:`BARO_STATES`) with
    a baro height [m] of σ [m]: z = ĥ − h_baro, H = e_h. Returns (z (1,) [m], nis, accepted)."""
    flush(nav, P, acc, q_c, dt)
    n = P.shape[0]
    H = np.zeros((1, n))
    H[0, DP + 2] = 1.0
    R = np.full((1, 1), sigma * sigma)
    z = np.array([nav[2] - height])
    estimated = np.zeros(n, dtype=np.bool_)
    for i in BARO_STATES:
        estimated[i] = True
    nis, accepted = _gated_update(nav, imu, P, H, R, z, gate, estimated)
    return z, nis, accepted


@njit
def _gated_update(nav, imu, P, H, R, z, gate, estimated):
    S = mm_t(mm(H, P), H) + R
    S_inv = inverse_small(S)
    nis = 0.0
    for i in range(z.shape[0]):
        for j in range(z.shape[0]):
            nis += z[i] * S_inv[i, j] * z[j]
    if nis > gate:
        return nis, False
    dx, P_next = joseph_update(P, H, R, z, estimated)
    P[:, :] = P_next
    reset(nav, imu, dx, P.shape[0])
    return nis, True


@njit
def run_record(nav, imu, P, acc, samples, ratio, dt, q_c, every, position, position_sigma, baro, baro_sigma, gates):
    """The whole-record loop of the fast path: for each frame f, ``ratio`` IMU samples of ``samples``
    (F*ratio, 6) propagate the filter (:func:`predict`), then the frame's position fix (a row of
    ``position`` (F, 3), NaN: none) and baro height (``baro`` (F,), NaN: none) update it in that
    order, with ``gates`` = (3-dof, 1-dof) NIS gates. Returns the per-frame logs of the step-by-step
    loop: nav[0:10] (F, 10), the IMU estimates (F, 12), P (F, n, n) and the frame's update
    statistics (measurements, accepted, NIS sum, dof, innovation RMS [m])."""
    frames = position.shape[0]
    n = P.shape[0]
    nav_log, imu_log, P_log = np.empty((frames, 10)), np.empty((frames, 12)), np.empty((frames, n, n))
    n_meas, n_acc, dof_log = np.zeros(frames, np.int32), np.zeros(frames, np.int32), np.zeros(frames, np.int32)
    nis_log, rms_log = np.full(frames, np.nan), np.full(frames, np.nan)
    for f in range(frames):
        predict(nav, imu, P, acc, samples[f * ratio:(f + 1) * ratio], dt, q_c, every)
        count, accepted, nis_sum, dof, squares = 0, 0, 0.0, 0, 0.0
        if not np.isnan(position[f, 0]):
            z, nis, ok = position_update(nav, imu, P, acc, q_c, dt, position[f], position_sigma, gates[0])
            count += 1
            if ok:
                accepted, nis_sum, dof, squares = accepted + 1, nis_sum + nis, dof + 3, squares + np.sum(z * z)
        if not np.isnan(baro[f]):
            z, nis, ok = baro_update(nav, imu, P, acc, q_c, dt, baro[f], baro_sigma, gates[1])
            count += 1
            if ok:
                accepted, nis_sum, dof, squares = accepted + 1, nis_sum + nis, dof + 1, squares + z[0] * z[0]
        nav_log[f], imu_log[f], P_log[f] = nav[0:10], imu, P
        n_meas[f], n_acc[f], dof_log[f] = count, accepted, dof
        if accepted:
            nis_log[f], rms_log[f] = nis_sum, np.sqrt(squares / dof)
    return nav_log, imu_log, P_log, n_meas, n_acc, nis_log, dof_log, rms_log
