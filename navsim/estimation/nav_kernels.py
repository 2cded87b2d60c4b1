"""Compiled kernels of the navigation error-state filter (numba): the continuous error dynamics F,
their discretisation (Φ, Q_d), propagation over IMU increments, the position and baro updates and
the reset (the star sensor's updates are :mod:`navsim.estimation.celestial_kernels`).

Error state x (zero between updates; docs/design.md), each optional group where :class:`Layout`
puts it:

    [φ (3) | δv_n (3) | δL, δλ, δh | ε (3) | ∇ (3) | δs_g (3), δs_a (3) | μ (3) | δg (3) | ε_r]

with C_nb,est = (I − [φ×]) C_nb,true, δv = v_est − v_true, δL = L_est − L_true (…), ε = b_g,true −
b̂_g and ∇ = b_a,true − b̂_a (the residual biases of the corrected increments), δs = s_true − ŝ, the
star-sensor mounting error μ (q_BS,true = q̂_BS ⊗ δq(μ), μ in sensor axes) and the gravity
disturbance of the truth δg = [−ξγ, −ηγ, Δg] (NED) that the INS does not know: a first-order
Gauss-Markov process in travelled distance (σ, correlation length D: in time, 1/τ = V/D with V the
horizontal speed; a random constant when D is infinite), kept as consider states (Schmidt), and the fractional
error ε_r of the air the star sensor's processing corrects the refraction with (eq. 3 of
:mod:`navsim.earth.refraction`: a random constant, a consider state).
Corrected increments are (1 − ŝ)(Δθ̃ − b̂_g Δt) and (1 − ŝ_a)(Δṽ − b̂_a Δt).

The filter's estimates beside the strapdown ``nav`` vector are ``calib`` (:data:`CALIB_SIZE`):
[b̂_g (3), b̂_a (3), ŝ_g (3), ŝ_a (3), q̂_BS (4)].
"""

from collections import namedtuple

import numpy as np

from navsim.earth.frames import earth_rate_n, transport_rate_n
from navsim.earth.gravity import normal_gravity_height_gradient, normal_gravity_latitude_gradient
from navsim.earth.wgs84 import E2, radii
from navsim.estimation.linalg import inverse_small, joseph_update, mm, mm_t, van_loan
from navsim.ins.strapdown import step
from startrack.jit import njit
from startrack.rotation_jit import quat_from_rotation_vector, quat_multiply, quat_to_matrix, skew

#: First index of the position error (δL, δλ, δh) in the error state.
DP = 6
#: The 15 states every navigation filter carries (attitude, velocity, position, the two biases).
BASE_STATES = 15
#: Size of the ``calib`` vector: biases, scale factors, mounting quaternion q̂_BS.
CALIB_SIZE = 16
#: Where each optional group of the error state starts (−1: absent), and the state count n.
Layout = namedtuple("Layout", "n scale mounting gravity refraction")
#: What the kernels need of the filter's model: the constant continuous noise densities ``q_c`` (n,),
#: the gravity disturbance's ``gm`` = (σ_N², σ_E², σ_D² [m²/s⁴], 1/D [1/m]), the IMU interval ``dt``
#: [s], the covariance interval ``every`` [IMU intervals] and the :class:`Layout`.
NavModel = namedtuple("NavModel", "q_c gm dt every layout")


def layout(scale_factors=False, mounting=False, gravity=False, refraction=False):
    """The :class:`Layout` of an error state with the chosen optional groups, in their fixed order."""
    n, starts = BASE_STATES, []
    for present, size in ((scale_factors, 6), (mounting, 3), (gravity, 3), (refraction, 1)):
        starts.append(n if present else -1)
        n += size if present else 0
    return Layout(n, *starts)
#: The states a baro height updates by default: the vertical channel δv_D, δh and the body-z
#: accelerometer bias (down in level flight); for its update every other state is a consider state
#: (Schmidt), so a baro damps the vertical channel and tells the filter nothing of the horizontal ones.
#: (Estimating them all, the filter draws horizontal information from the height through the Coriolis
#: and v²/R couplings of the vertical channel and f^n × φ in manoeuvres, which no biased, lagging baro
#: really carries; a white-noise height reference does, and the filter may then update every state:
#: ``NavFilterConfig(baro_states="all")``, as PSINS's SINS/CNS height measurement.)
BARO_STATES = (5, DP + 2, 14)
#: Layout of the accumulator of one covariance interval: [count, Σ C_nb Δv (3), Σ C_nb (9),
#: Σ C_nb diag(Δθ) (9), Σ C_nb diag(Δv) (9)].
ACC_SIZE = 31


@njit
def continuous_f(lat, h, v, f_n, C, C_w, C_f, layout, inv_length):
    """Continuous error dynamics F (n x n) at (L, h, v_n) [rad, m, m/s] for the specific force f_n
    [m/s²] in n, the mean C_nb ``C``, and (for the scale-factor columns) C_nb diag(ω_b) ``C_w``
    [rad/s] and C_nb diag(f_b) ``C_f`` [m/s²], the states of ``layout`` and the gravity
    disturbance's 1/D [1/m] (Titterton & Weston, 2nd ed., ch. 12; Groves, 2nd ed., §14.2.4, with
    this φ sign):

    φ̇ = −ω_in × φ + δω_in − C_nb (ε + diag(ω_b) δs_g),
    δv̇ = f^n × φ + C_nb (∇ + diag(f_b) δs_a) − (2ω_ie + ω_en) × δv − (2δω_ie + δω_en) × v + δγ − δg,
    δL̇ = δv_N/(R_M+h) − v_N δh/(R_M+h)², δλ̇ = δv_E/((R_N+h) cos L) + v_E tan L δL/((R_N+h) cos L)
    − v_E δh/((R_N+h)² cos L), δḣ = −δv_D; δγ = [0, 0, ∂γ/∂L δL + ∂γ/∂h δh]; the mounting constant;
    the disturbance δ̇g = −(V/D) δg (the truth's gravity, so −δg in δv̇: the INS lacks it); and the terms of
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
    F = np.zeros((layout.n, layout.n))
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
    if layout.scale >= 0:
        F[0:3, layout.scale:layout.scale + 3] = -C_w
        F[3:6, layout.scale + 3:layout.scale + 6] = C_f
    if layout.gravity >= 0:
        decay = np.hypot(v[0], v[1]) * inv_length
        for i in range(3):
            F[3 + i, layout.gravity + i] = -1.0
            F[layout.gravity + i, layout.gravity + i] = -decay
    return F


@njit
def discretize(F, q_c, dt):
    """(Φ, Q_d) over dt [s] for F and the diagonal continuous noise ``q_c`` (n,): the fifth-order series
    of :func:`navsim.estimation.linalg.van_loan`."""
    Phi, Q = van_loan(F, q_c.reshape(1, q_c.shape[0]), dt)
    return Phi, Q[0]


@njit
def correct(sample, calib, dt, scale, a, b):
    """Write into ``a``, ``b`` the increments of one IMU ``sample`` (6,) (interval means: rate [rad/s],
    specific force [m/s²]) corrected by the estimates ``calib`` = [b̂_g, b̂_a, ŝ_g, ŝ_a, …]:
    (1 − ŝ_g)(ω̃ − b̂_g) Δt and (1 − ŝ_a)(f̃ − b̂_a) Δt (the scale factors when ``scale``)."""
    for i in range(3):
        a[i] = (sample[i] - calib[i]) * dt
        b[i] = (sample[3 + i] - calib[3 + i]) * dt
        if scale:
            a[i] *= 1.0 - calib[6 + i]
            b[i] *= 1.0 - calib[9 + i]


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
def noise_densities(nav, model):
    """The continuous noise densities (n,) at the current speed: ``model.q_c`` with, for the gravity
    disturbance, the Gauss-Markov drive 2σ²/τ = 2σ² V/D (zero at rest and for a constant field)."""
    q = model.q_c.copy()
    g = model.layout.gravity
    if g >= 0:
        rate = np.hypot(nav[3], nav[4]) * model.gm[3]
        for i in range(3):
            q[g + i] = 2.0 * model.gm[i] * rate
    return q


@njit
def flush(nav, P, acc, model):
    """Propagate P over the accumulated intervals (P ← Φ P Φᵀ + Q_d, F at the current position and
    velocity with the interval means of f^n and C_nb) and empty the accumulator."""
    count = acc[0]
    if count == 0.0:
        return
    span = count * model.dt
    C = acc[4:13].reshape(3, 3) / count
    C_w = acc[13:22].reshape(3, 3) / span
    C_f = acc[22:31].reshape(3, 3) / span
    F = continuous_f(nav[0], nav[2], nav[3:6], acc[1:4] / span, C, C_w, C_f, model.layout, model.gm[3])
    Phi, Q = discretize(F, noise_densities(nav, model), span)
    P_next = mm(Phi, mm(Phi, P).T.copy()) + Q  # Φ (Φ P)ᵀ = Φ P Φᵀ with sparse left factors
    P[:, :] = 0.5 * (P_next + P_next.T)
    acc[:] = 0.0


@njit
def predict(nav, calib, P, acc, samples, model):
    """Mechanize the corrected IMU samples (M, 6) and propagate P every ``model.every`` intervals
    (the remainder stays in ``acc`` until the next call or update). All arrays change in place."""
    a, b = np.empty(3), np.empty(3)
    scale = model.layout.scale >= 0
    for k in range(samples.shape[0]):
        correct(samples[k], calib, model.dt, scale, a, b)
        accumulate(acc, nav[6:10], a, b)
        step(nav, a, b, model.dt)
        if acc[0] >= model.every:
            flush(nav, P, acc, model)


@njit
def reset(nav, calib, dx, layout):
    """Fold the error estimate dx into the nominal state (in place): C_nb ← exp([φ×]) C_nb,
    v ← v − δv, (L, λ, h) ← − (δL, δλ, δh), b̂ ← b̂ + (ε, ∇), ŝ ← ŝ + δs, q̂_BS ← q̂_BS ⊗ δq(μ)
    (the gravity disturbance is a consider state: never estimated)."""
    q = quat_multiply(quat_from_rotation_vector(dx[0:3]), nav[6:10])
    nav[6:10] = q / np.sqrt(np.sum(q * q))
    nav[3:6] -= dx[3:6]
    nav[0:3] -= dx[6:9]
    calib[0:6] += dx[9:15]
    if layout.scale >= 0:
        calib[6:12] += dx[layout.scale:layout.scale + 6]
    if layout.mounting >= 0:
        m = layout.mounting
        q = quat_multiply(calib[12:16], quat_from_rotation_vector(dx[m:m + 3]))
        calib[12:16] = q / np.sqrt(np.sum(q * q))


@njit
def position_update(nav, calib, P, acc, model, fix, sigma, gate, estimated):
    """Flush the covariance, then the gated update with a position fix ``fix`` = (L, λ, h) [rad, rad, m]
    of NED σ ``sigma`` (3,) [m]: z = (L̂, λ̂, ĥ) − fix, H = [0 0 I 0 …],
    R = diag(σ_N²/(R_M+h)², σ_E²/((R_N+h) cos L)², σ_D²), the ``estimated`` states corrected.
    Returns (z in NED metres (3,), nis, accepted); the state, P and the nominal state change in place."""
    flush(nav, P, acc, model)
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
    nis, accepted = gated_update(nav, calib, P, H, R, z, gate, estimated, model.layout)
    return z_m, nis, accepted


@njit
def baro_update(nav, calib, P, acc, model, height, sigma, gate, estimated):
    """Flush the covariance, then the gated update of the ``estimated`` states (:data:`BARO_STATES`, or
    all) with a baro height [m] of σ [m]: z = ĥ − h_baro, H = e_h. Returns (z (1,) [m], nis, accepted)."""
    flush(nav, P, acc, model)
    H = np.zeros((1, P.shape[0]))
    H[0, DP + 2] = 1.0
    R = np.full((1, 1), sigma * sigma)
    z = np.array([nav[2] - height])
    nis, accepted = gated_update(nav, calib, P, H, R, z, gate, estimated, model.layout)
    return z, nis, accepted


@njit
def gated_update(nav, calib, P, H, R, z, gate, estimated, layout):
    """The update with one measurement vector z = H x + v (v ~ N(0, R)), gated as a whole by its NIS
    zᵀ S⁻¹ z against ``gate``: Joseph form with the ``estimated`` states corrected, then the reset.
    Returns (nis, accepted)."""
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
    reset(nav, calib, dx, layout)
    return nis, True


@njit
def run_record(nav, calib, P, acc, samples, ratio, model, position, position_sigma, baro, baro_sigma, gates, estimated,
               baro_estimated):
    """The whole-record loop of the fast path: for each frame f, ``ratio`` IMU samples of ``samples``
    (F*ratio, 6) propagate the filter (:func:`predict`), then the frame's position fix (a row of
    ``position`` (F, 3), NaN: none) and baro height (``baro`` (F,), NaN: none) update it in that
    order (the fix correcting the ``estimated`` states, the baro the ``baro_estimated``), with ``gates`` =
    (3-dof, 1-dof) NIS gates. Returns the per-frame logs of the step-by-step
    loop: nav[0:10] (F, 10), the estimates ``calib`` (F, 16), P (F, n, n) and the frame's update
    statistics (measurements, accepted, NIS sum, dof, innovation RMS [m])."""
    frames = position.shape[0]
    n = P.shape[0]
    nav_log, calib_log, P_log = np.empty((frames, 10)), np.empty((frames, CALIB_SIZE)), np.empty((frames, n, n))
    n_meas, n_acc, dof_log = np.zeros(frames, np.int32), np.zeros(frames, np.int32), np.zeros(frames, np.int32)
    nis_log, rms_log = np.full(frames, np.nan), np.full(frames, np.nan)
    for f in range(frames):
        predict(nav, calib, P, acc, samples[f * ratio:(f + 1) * ratio], model)
        count, accepted, nis_sum, dof, squares = 0, 0, 0.0, 0, 0.0
        if not np.isnan(position[f, 0]):
            z, nis, ok = position_update(nav, calib, P, acc, model, position[f], position_sigma, gates[0], estimated)
            count += 1
            if ok:
                accepted, nis_sum, dof, squares = accepted + 1, nis_sum + nis, dof + 3, squares + np.sum(z * z)
        if not np.isnan(baro[f]):
            z, nis, ok = baro_update(nav, calib, P, acc, model, baro[f], baro_sigma, gates[1], baro_estimated)
            count += 1
            if ok:
                accepted, nis_sum, dof, squares = accepted + 1, nis_sum + nis, dof + 1, squares + z[0] * z[0]
        nav_log[f], calib_log[f], P_log[f] = nav[0:10], calib, P
        n_meas[f], n_acc[f], dof_log[f] = count, accepted, dof
        if accepted:
            nis_log[f], rms_log[f] = nis_sum, np.sqrt(squares / dof)
    return nav_log, calib_log, P_log, n_meas, n_acc, nis_log, dof_log, rms_log
