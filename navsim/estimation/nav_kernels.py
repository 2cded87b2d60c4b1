"""Compiled kernels of the navigation error-state filter (numba): the continuous error dynamics F,
their discretisation (Φ, Q_d), propagation over IMU increments, the position, velocity, body-velocity
(a land vehicle's non-holonomic constraint) and baro updates and the reset (the star sensor's updates are :mod:`navsim.estimation.celestial_kernels`).

Error state x (zero between updates; docs/design.md), each optional group where :class:`Layout`
puts it:

    [φ (3) | δv_w (3) | δθ_x, δθ_y, δh | ε (3) | ∇ (3) | δs_g (3), δs_a (3) | μ (3) | δg (3) | ε_r]

resolved in the wander-azimuth frame w of the INS (:mod:`navsim.earth.wander`; issue 31: no latitude or
longitude in it, so it holds at the poles), with C_ew,est = C_ew,true (I + [δθ×]), δθ = [δθ_x, δθ_y, 0] horizontal
(the true w frame is the local-level frame at the true position that the minimal rotation turns into the
estimated one), C_wb,est = (I − [φ×]) C_wb,true, δv = v_w,est − v_w,true (each in its own w frame), δh = h_est −
h_true, ε = b_g,true − b̂_g and ∇ = b_a,true − b̂_a (the residual biases of the corrected increments), δs = s_true − ŝ,
the star-sensor mounting error μ (q_BS,true = q̂_BS ⊗ δq(μ), μ in sensor axes) and the gravity
disturbance of the truth δg = [−ξγ, −ηγ, Δg] (in w) that the INS does not know: a first-order
Gauss-Markov process in travelled distance (σ, correlation length D: in time, 1/τ = V/D with V the
horizontal speed; a random constant when D is infinite), kept as consider states (Schmidt), and the fractional
error ε_r of the air the star sensor's processing corrects the refraction with (eq. 3 of
:mod:`navsim.earth.refraction`: a random constant, a consider state).
Corrected increments are (1 − ŝ)(Δθ̃ − b̂_g Δt) and (1 − ŝ_a)(Δṽ − b̂_a Δt).

The filter's estimates beside the strapdown ``nav`` vector are ``calib`` (:data:`CALIB_SIZE`):
[b̂_g (3), b̂_a (3), ŝ_g (3), ŝ_a (3), q̂_BS (4)].

What the filter shows (its ``P``, a run's error state) is this state turned into NED with the position in metres
(:func:`public_jacobian`): [φ_n | δv_n | δN, δE, δh | … | δg_n | …], defined wherever NED is.
"""

from collections import namedtuple

import numpy as np

from navsim.earth.gravity import normal_gravity_height_gradient, normal_gravity_sine_gradient
from navsim.earth.wander import curvature, earth_rate_w, frame_angles, radii_of_sine, transport_rate_w
from navsim.earth.wgs84 import E2, radii
from navsim.estimation.linalg import inverse_small, joseph_update, mm, mm_t, van_loan
from navsim.ins.strapdown import ROW, step
from startrack import njit
from startrack import rotation_kernels as rk

#: First index of the position error (δθ_x, δθ_y, δh) in the error state.
DP = 6
#: The 15 states every navigation filter carries (attitude, velocity, position, the two biases).
BASE_STATES = 15
#: Size of the ``calib`` vector: biases, scale factors, mounting quaternion q̂_BS ...
CALIB_SIZE = 16
#: ... and its parts: b̂_g, b̂_a, ŝ_g, ŝ_a, q̂_BS.
GYRO_BIAS, ACCEL_BIAS, GYRO_SCALE, ACCEL_SCALE, MOUNTING = slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 16)
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
#: Layout of the accumulator of one covariance interval: [count, Σ C_wb Δv (3), Σ C_wb (9),
#: Σ C_wb diag(Δθ) (9), Σ C_wb diag(Δv) (9)].
ACC_SIZE = 31


@njit
def _rho_derivatives(C_ew, h, v):
    """(ρ (3,), ∂δρ/∂δv (3, 3), ∂δρ/∂(δθ_x, δθ_y, δh) (3, 3)) of the transport rate ρ = ω_ew^w (eq. 2 of
    :mod:`navsim.earth.wander`, g = D v_h, ρ = [g_y, −g_x, 0]), δρ = ρ_est − ρ_true each in its own frame. The true
    frame turns about the vertical at −(ρ × δθ)_z (it keeps δθ horizontal), hence δρ_z = ρ_x δθ_y − ρ_y δθ_x.
    Through the position: δs = c_1 δθ_x − c_0 δθ_y, δc = s [δθ_y, −δθ_x] (from C_ew,est = C_ew,true (I + [δθ×]))."""
    D, k, s, c = curvature(C_ew, h)
    r_m, r_n, dr_m, dr_n = radii_of_sine(s)
    rm, rn = r_m + h, r_n + h
    rho = transport_rate_w(C_ew, h, v)
    cv = c[0] * v[0] + c[1] * v[1]
    dg_dh = np.empty(2)
    dg_ds = np.empty(2)
    dk_dh = -k * (1.0 / rm + 1.0 / rn)
    dk_ds = k * (dr_n / r_n + 2.0 * E2 * s / (1.0 - E2 * s * s) - dr_m / rm - dr_n / rn)
    for i in range(2):
        dg_dh[i] = -v[i] / rn**2 + dk_dh * c[i] * cv
        dg_ds[i] = -v[i] * dr_n / rn**2 + dk_ds * c[i] * cv
    # ∂g/∂θ = ∂g/∂s [c_1, −c_0] + k (cv I + c v_hᵀ) [[0, s], [−s, 0]]
    dg_dt = np.empty((2, 2))
    for i in range(2):
        m0, m1 = k * (cv * (i == 0) + c[i] * v[0]), k * (cv * (i == 1) + c[i] * v[1])
        dg_dt[i, 0] = dg_ds[i] * c[1] - m1 * s
        dg_dt[i, 1] = -dg_ds[i] * c[0] + m0 * s
    d_v = np.zeros((3, 3))
    d_p = np.zeros((3, 3))
    for j in range(2):
        d_v[0, j], d_v[1, j] = D[1, j], -D[0, j]
        d_p[0, j], d_p[1, j] = dg_dt[1, j], -dg_dt[0, j]
    d_p[0, 2], d_p[1, 2] = dg_dh[1], -dg_dh[0]
    d_p[2, 0], d_p[2, 1] = -rho[1], rho[0]
    return rho, d_v, d_p


@njit
def continuous_f(C_ew, h, v, f_w, C, C_w, C_f, layout, inv_length):
    """Continuous error dynamics F (n x n) at the position C_ew (3, 3), h [m] and ground velocity v (3,) [m/s] in w
    for the specific force f_w [m/s²] in w, the mean C_wb ``C``, and (for the scale-factor columns) C_wb diag(ω_b)
    ``C_w`` [rad/s] and C_wb diag(f_b) ``C_f`` [m/s²], the states of ``layout`` and the gravity disturbance's 1/D
    [1/m] (Titterton & Weston, 2nd ed., §12.3.2 with w for n; Groves, 2nd ed., §14.2.4, with this φ sign):

    φ̇ = −ω_iw × φ + δω_ie + δρ − C_wb (ε + diag(ω_b) δs_g),  δω_ie = ω_ie^w × δθ,
    δv̇ = f^w × φ + C_wb (∇ + diag(f_b) δs_a) − (2ω_ie + ρ) × δv − (2δω_ie + δρ) × v + δγ − δg,
    δθ̇_x,y = δρ_x,y,  δḣ = −δv_z;  δγ = [0, 0, ∂γ/∂s δs + ∂γ/∂h δh];

    δρ of :func:`_rho_derivatives` (the exact derivatives of the ellipsoid's curvature, finite at the poles); the
    mounting constant; the disturbance δ̇g = −(V/D) δg (the truth's gravity, so −δg in δv̇: the INS lacks it).
    """
    w_ie = earth_rate_w(C_ew)
    rho, d_v, d_p = _rho_derivatives(C_ew, h, v)
    d_ie = np.zeros((3, 3))
    W = rk.skew(w_ie)
    for i in range(3):
        d_ie[i, 0], d_ie[i, 1] = W[i, 0], W[i, 1]
    V = rk.skew(v)
    F = np.zeros((layout.n, layout.n))
    F[0:3, 0:3] = -rk.skew(w_ie + rho)
    F[0:3, 3:6] = d_v
    F[0:3, 6:9] = d_ie + d_p
    F[0:3, 9:12] = -C
    F[3:6, 0:3] = rk.skew(f_w)
    F[3:6, 3:6] = -rk.skew(2.0 * w_ie + rho) + mm(V, d_v)
    F[3:6, 6:9] = mm(V, 2.0 * d_ie + d_p)
    s = -C_ew[2, 2]
    dgamma = normal_gravity_sine_gradient(s, h)
    F[5, 6] += dgamma * C_ew[2, 1]
    F[5, 7] -= dgamma * C_ew[2, 0]
    F[5, 8] += normal_gravity_height_gradient(np.arcsin(min(1.0, max(-1.0, s))), h)
    F[3:6, 12:15] = C
    F[6:8, 3:6] = d_v[0:2]
    F[6:8, 6:9] = d_p[0:2]
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
def public_jacobian(nav, n, gravity):
    """T (n, n): the error state in w turned into what the filter shows (module docstring): φ_n = C_nw φ,
    δv_n = C_nw δv, (δN, δE) = −diag(R_M + h, R_N + h) R(α) J (δθ_x, δθ_y) (J = [[0, 1], [−1, 0]], the inverse of the
    position map of :func:`navsim.earth.wander.ned_offset`), δh, δg_n = C_nw δg (``gravity`` its first index, −1:
    none); the other states as they are. α from :func:`navsim.earth.wander.frame_angles`."""
    C_ew = rk.quat_to_matrix(nav[0:4])
    lat, _, alpha = frame_angles(C_ew)
    ca, sa = np.cos(alpha), np.sin(alpha)
    r_m, r_n = radii(lat)
    T = np.eye(n)
    for b in (0, 3, gravity):
        if b >= 0:
            T[b, b], T[b, b + 1], T[b + 1, b], T[b + 1, b + 1] = ca, -sa, sa, ca
    h = nav[4]
    T[DP, DP], T[DP, DP + 1] = -(r_m + h) * sa, -(r_m + h) * ca
    T[DP + 1, DP], T[DP + 1, DP + 1] = (r_n + h) * ca, -(r_n + h) * sa
    return T


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
    C = rk.quat_to_matrix(q_nb)
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
        rate = np.hypot(nav[5], nav[6]) * model.gm[3]
        horizontal = 0.5 * (model.gm[0] + model.gm[1])  # the w frame turns: an isotropic horizontal field
        for i in range(3):
            q[g + i] = 2.0 * (horizontal if i < 2 else model.gm[2]) * rate
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
    F = continuous_f(rk.quat_to_matrix(nav[0:4]), nav[4], nav[5:8], acc[1:4] / span, C, C_w, C_f, model.layout, model.gm[3])
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
        accumulate(acc, nav[8:12], a, b)
        step(nav, a, b, model.dt)
        if acc[0] >= model.every:
            flush(nav, P, acc, model)


@njit
def reset(nav, calib, dx, layout):
    """Fold the error estimate dx into the nominal state (in place): C_wb ← exp([φ×]) C_wb,
    v ← v − δv, C_ew ← C_ew exp(−[δθ×]), h ← h − δh, b̂ ← b̂ + (ε, ∇), ŝ ← ŝ + δs, q̂_BS ← q̂_BS ⊗ δq(μ)
    (the gravity disturbance is a consider state: never estimated)."""
    q = rk.quat_multiply(rk.quat_from_rotation_vector(dx[0:3]), nav[8:12])
    nav[8:12] = q / np.sqrt(np.sum(q * q))
    nav[5:8] -= dx[3:6]
    q = rk.quat_multiply(nav[0:4], rk.quat_from_rotation_vector(np.array([-dx[DP], -dx[DP + 1], 0.0])))
    nav[0:4] = q / np.sqrt(np.sum(q * q))
    nav[4] -= dx[DP + 2]
    calib[0:6] += dx[9:15]
    if layout.scale >= 0:
        calib[6:12] += dx[layout.scale:layout.scale + 6]
    if layout.mounting >= 0:
        m = layout.mounting
        q = rk.quat_multiply(calib[12:16], rk.quat_from_rotation_vector(dx[m:m + 3]))
        calib[12:16] = q / np.sqrt(np.sum(q * q))


@njit
def position_terms(nav, fix, sigma, n):
    """(z (3,) [m, w axes], H (3, n), R (3, 3), C_nw (3, 3)) of a position fix ``fix`` = (L, λ, h) [rad, rad, m] of
    NED σ ``sigma`` (3,) [m]: z = the estimate's offset from the fix, horizontal −D⁻¹ J δθ (δθ the rotation that
    turns the fix's normal into the estimate's, in w; D of eq. 2 of :mod:`navsim.earth.wander`), then −δh (down);
    H = [−D⁻¹ J, −e_h] in the position columns, R = C_wn diag(σ²) C_nw."""
    C_ew = rk.quat_to_matrix(nav[0:4])
    cl = np.cos(fix[0])
    up_fix = np.array([cl * np.cos(fix[1]), cl * np.sin(fix[1]), np.sin(fix[0])])
    up = np.array([-C_ew[0, 2], -C_ew[1, 2], -C_ew[2, 2]])
    axis = np.cross(up_fix, up)
    sine = np.sqrt(np.sum(axis * axis))
    theta_e = axis * (np.arctan2(sine, np.sum(up_fix * up)) / sine if sine > 0.0 else 1.0)
    theta = C_ew.T @ theta_e
    D, _, _, _ = curvature(C_ew, nav[4])
    D_inv = inverse_small(D)
    z = np.empty(3)
    H = np.zeros((3, n))
    for i in range(2):
        z[i] = -(D_inv[i, 0] * theta[1] - D_inv[i, 1] * theta[0])
        H[i, DP], H[i, DP + 1] = D_inv[i, 1], -D_inv[i, 0]
    z[2] = -(nav[4] - fix[2])
    H[2, DP + 2] = -1.0
    _, _, alpha = frame_angles(C_ew)
    ca, sa = np.cos(alpha), np.sin(alpha)
    C_nw = np.array([[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]])
    R = C_nw.T @ np.diag(sigma * sigma) @ C_nw
    return z, H, R, C_nw


@njit
def position_update(nav, calib, P, acc, model, fix, sigma, gate, estimated):
    """Flush the covariance, then the gated update with a position fix ``fix`` = (L, λ, h) [rad, rad, m]
    of NED σ ``sigma`` (3,) [m] (:func:`position_terms`), the ``estimated`` states corrected.
    Returns (z in NED metres (3,), nis, accepted); the state, P and the nominal state change in place."""
    flush(nav, P, acc, model)
    z, H, R, C_nw = position_terms(nav, fix, sigma, P.shape[0])
    z_n = C_nw @ z
    nis, accepted = gated_update(nav, calib, P, H, R, z, gate, estimated, model.layout)
    return z_n, nis, accepted


@njit
def velocity_update(nav, calib, P, acc, model, v_n, sigma, gate, estimated):
    """Flush the covariance, then the gated update of the ``estimated`` states with a NED velocity ``v_n`` (3,) [m/s]
    of NED σ ``sigma`` (3,) [m/s] (a GNSS velocity, or zero at a stop): z = v̂_w − C_wn v_n, H = [0 I 0] on δv (the
    error state's δv = v̂_w − v_w, :func:`reset`), R = C_wn diag(σ²) C_nw (Groves, 2nd ed., §14.4.1, loosely
    coupled velocity measurement, in w). Returns (z in NED (3,) [m/s], nis, accepted)."""
    flush(nav, P, acc, model)
    _, _, alpha = frame_angles(rk.quat_to_matrix(nav[0:4]))
    ca, sa = np.cos(alpha), np.sin(alpha)
    C_nw = np.array([[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]])
    z = nav[5:8] - C_nw.T @ v_n
    H = np.zeros((3, P.shape[0]))
    for i in range(3):
        H[i, 3 + i] = 1.0
    R = C_nw.T @ np.diag(sigma * sigma) @ C_nw
    nis, accepted = gated_update(nav, calib, P, H, R, z, gate, estimated, model.layout)
    return C_nw @ z, nis, accepted


@njit
def body_velocity_terms(nav, n):
    """(ŷ (2,) [m/s], H (2, n)) of the body's lateral and vertical velocity ŷ = (C_bw v̂_w)_y,z, the non-holonomic
    constraint of a land vehicle (Groves, 2nd ed., §15.3.1; Shin 2001, §4.3). With C_wb,est = (I − [φ×]) C_wb,true and
    δv = v̂_w − v_w (:func:`reset`), C_bw,est v̂ = C_bw,true (I + [φ×]) (v + δv), so to first order
    z = ŷ − y = C_bw δv − C_bw [v̂×] φ: H_v = (C_bw)_y,z, H_φ = −(C_bw [v̂×])_y,z."""
    C_wb = rk.quat_to_matrix(nav[8:12])
    V = rk.skew(nav[5:8])
    y = np.zeros(2)
    H = np.zeros((2, n))
    for r in range(2):
        for k in range(3):  # row 1 + r of C_bw is column 1 + r of C_wb
            c = C_wb[k, 1 + r]
            y[r] += c * nav[5 + k]
            H[r, 3 + k] = c
            for j in range(3):
                H[r, j] -= c * V[k, j]
    return y, H


@njit
def body_velocity_update(nav, calib, P, acc, model, v_yz, sigma, gate, estimated):
    """Flush the covariance, then the gated update of the ``estimated`` states with the body's lateral and vertical
    velocity ``v_yz`` (2,) [m/s] (zero: the non-holonomic constraint) of σ ``sigma`` (2,) [m/s]: z = ŷ − v_yz, H of
    :func:`body_velocity_terms`, R = diag(σ²). Returns (z in body y, z (2,) [m/s], nis, accepted)."""
    flush(nav, P, acc, model)
    y, H = body_velocity_terms(nav, P.shape[0])
    z = y - v_yz
    R = np.diag(sigma * sigma)
    nis, accepted = gated_update(nav, calib, P, H, R, z, gate, estimated, model.layout)
    return z, nis, accepted


@njit
def baro_update(nav, calib, P, acc, model, height, sigma, gate, estimated):
    """Flush the covariance, then the gated update of the ``estimated`` states (:data:`BARO_STATES`, or
    all) with a baro height [m] of σ [m]: z = ĥ − h_baro, H = e_h. Returns (z (1,) [m], nis, accepted)."""
    flush(nav, P, acc, model)
    H = np.zeros((1, P.shape[0]))
    H[0, DP + 2] = 1.0
    R = np.full((1, 1), sigma * sigma)
    z = np.array([nav[4] - height])
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
    loop: nav[0:ROW] (F, ROW), the estimates ``calib`` (F, 16), P (F, n, n) and the frame's update
    statistics (measurements, accepted, NIS sum, dof, innovation RMS [m])."""
    frames = position.shape[0]
    n = P.shape[0]
    nav_log, calib_log, P_log = np.empty((frames, ROW)), np.empty((frames, CALIB_SIZE)), np.empty((frames, n, n))
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
        nav_log[f], calib_log[f], P_log[f] = nav[0:ROW], calib, P
        n_meas[f], n_acc[f], dof_log[f] = count, accepted, dof
        if accepted:
            nis_log[f], rms_log[f] = nis_sum, np.sqrt(squares / dof)
    return nav_log, calib_log, P_log, n_meas, n_acc, nis_log, dof_log, rms_log


@njit
def public_covariances(nav_rows, P_rows, gravity):
    """:func:`to_public` of each logged P (F, n, n) at its solution row (F, ROW)."""
    out = np.empty_like(P_rows)
    for f in range(P_rows.shape[0]):
        out[f] = to_public(P_rows[f], nav_rows[f], gravity)
    return out


@njit
def to_public(P, nav, gravity):
    """T P Tᵀ for T = :func:`public_jacobian` (n, n) of the solution row ``nav``, using its structure: T differs from
    the identity only on the leading nine states and the gravity disturbance's three."""
    n = P.shape[0]
    T = public_jacobian(nav, n, gravity)
    count = 9 if gravity < 0 else 12
    idx = np.empty(count, np.int64)
    for a in range(9):
        idx[a] = a
    for a in range(count - 9):
        idx[9 + a] = gravity + a
    out = P.copy()
    for a in range(count):  # rows: (T P)[i, :] = Σ_b T[i, b] P[b, :] over the turned states
        for j in range(n):
            total = 0.0
            for b in range(count):
                total += T[idx[a], idx[b]] * P[idx[b], j]
            out[idx[a], j] = total
    rows = out.copy()
    for i in range(n):  # columns: (T P Tᵀ)[:, j] = Σ_b (T P)[:, b] T[j, b]
        for a in range(count):
            total = 0.0
            for b in range(count):
                total += rows[i, idx[b]] * T[idx[a], idx[b]]
            out[i, idx[a]] = total
    return out


@njit
def to_public_vector(x, nav, gravity):
    """T x (n,) for T = :func:`public_jacobian` of the solution row ``nav``."""
    return public_jacobian(nav, x.shape[0], gravity) @ x
