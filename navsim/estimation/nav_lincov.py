"""Compiled linear covariance analysis of the navigation filter (numba): the truth's error dynamics
(the filter's states plus the errors it ignores) and the pass along a nominal trajectory that drives
the primitives of :mod:`navsim.estimation.lincov` with the filter's own model beside the truth's.

The truth's error state is the navigation error state of :mod:`navsim.estimation.nav_kernels` with every
group the truth has (scale factors, mounting, gravity disturbance: its ``base`` layout), then the
truth-only groups of :data:`TruthLayout`: the Gauss-Markov parts g of the gyro and accelerometer
biases (the filter's ε is ε_t + g_g, its ∇ is ∇_t + g_a: it carries them as random walks), the six
axis misalignments of each sensor (ω̃ = (I + S)(I + M) ω: M's off-diagonal terms, :data:`MISALIGNMENT_PAIRS`)
and the baro's bias (a white-noise height to the filter).
"""

from collections import namedtuple

import numpy as np

from navsim.earth.wander import frame_angles
from navsim.estimation.celestial_kernels import fix_terms, star_terms
from navsim.estimation.linalg import van_loan
from navsim.estimation.lincov import allocate_log, keep, propagate, trimmed, update
from navsim.estimation.nav_kernels import (
    DP,
    continuous_f,
    discretize,
    noise_densities,
    position_terms,
    public_jacobian,
    to_public,
    to_public_vector,
)
from startrack import njit
from startrack import rotation_kernels as rk

#: Where the truth's groups start (−1: absent): ``base`` the :class:`nav_kernels.Layout` of the states the
#: filter may carry; the Gauss-Markov bias parts (3 each), the misalignments (6 each), the baro bias (1);
#: ``n`` the truth's state count.
TruthLayout = namedtuple("TruthLayout", "base gyro_gm accel_gm gyro_mis accel_mis baro n")
#: The measurements of a pass, per frame f of F: identified stars (rows ``star_offsets[f]:star_offsets[f+1]``
#: of the filter's catalog directions ``star_ref`` (M, 3) in I, the noise-free measured directions
#: ``star_obs`` (M, 3) in S through the nominal mounting and their covariances ``star_cov`` (M, 3, 3)
#: [rad²]); attitude fixes (``fix_mask`` (F,), noise-free ``fix_q`` (F, 4) as the filter's processing
#: sees them, ``fix_R`` (3, 3) [rad²]); position fixes (``position_mask`` (F,), NED σ ``position_sigma``
#: (3,) [m]); baro heights (``baro_mask`` (F,), the truth's white-noise variance ``baro_var`` and the
#: filter's ``baro_filter_var`` [m²], the deterministic offset ``baro_offset`` (F,) [m] of its lag);
#: ``r_scale2`` the filter's measurement_noise_scale²; the stack's sources of the star sensor's noise
#: (``star_source``) and of the aiding sensors' (``aiding_source``), and of the stars' deterministic offsets:
#: the refraction's (``refraction_source``: the real air against the processing's model, or all of it
#: uncorrected) is the difference between the residuals against ``star_ref`` and against ``star_ref_real``
#: (``fix_q``, ``fix_q_real``: the processing with the real air's refraction), the rest (an uncorrected
#: aberration: ``offset_source``) the residual against ``star_ref_real``. When the filter carries the refraction
#: state ε_r (the truth's then holds the real air's as its mean), the refraction is that state's, through the
#: columns of ``star_shift`` (M, 3) (the refraction of each star the processing corrects) and ``fix_rho`` (F, 3) (the
#: rotation vector of the fixes' boresights) (:func:`navsim.estimation.celestial_kernels.star_terms`, ``fix_terms``).
Measurements = namedtuple("Measurements", "star_offsets star_ref star_ref_real star_shift star_obs star_cov fix_mask "
                                          "fix_q fix_q_real fix_rho fix_R position_mask position_sigma baro_mask baro_var "
                                          "baro_filter_var baro_offset r_scale2 star_source aiding_source offset_source "
                                          "refraction_source")
#: The off-diagonal terms (i, j) of a misalignment matrix M, in the order of its six states.
MISALIGNMENT_PAIRS = ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))
#: The leading block kept in full at every output frame: φ, δv, δN, δE, δh.
BLOCK = 9


@njit
def truth_f(C_ew, h, v, f_n, C, G_w, G_f, tl, inv_length, inv_tau):
    """The truth's continuous error dynamics (n_t, n_t): :func:`nav_kernels.continuous_f` of its ``base``
    layout (1/D ``inv_length`` of its gravity disturbance), then φ̇ −= C_wb g_g, δv̇ += C_wb g_a with
    ġ = −g/τ (``inv_tau`` = (1/τ_g, 1/τ_a)), and the misalignment columns φ̇ −= C_wb M_g ω_b,
    δv̇ += C_wb M_a f_b: column (i, j) is −G_w[:, i, j] (G_w[a, i, j] the interval mean of C_wb[a, i] ω_j,
    [rad/s]) and G_f[:, i, j] [m/s²]."""
    C_w, C_f = np.empty((3, 3)), np.empty((3, 3))
    for a in range(3):
        for i in range(3):
            C_w[a, i], C_f[a, i] = G_w[a, i, i], G_f[a, i, i]
    F = np.zeros((tl.n, tl.n))
    F[:tl.base.n, :tl.base.n] = continuous_f(C_ew, h, v, f_n, C, C_w, C_f, tl.base, inv_length)
    if tl.gyro_gm >= 0:
        F[0:3, tl.gyro_gm:tl.gyro_gm + 3] = -C
        for i in range(3):
            F[tl.gyro_gm + i, tl.gyro_gm + i] = -inv_tau[0]
    if tl.accel_gm >= 0:
        F[3:6, tl.accel_gm:tl.accel_gm + 3] = C
        for i in range(3):
            F[tl.accel_gm + i, tl.accel_gm + i] = -inv_tau[1]
    for p in range(6):
        i, j = MISALIGNMENT_PAIRS[p]
        if tl.gyro_mis >= 0:
            F[0:3, tl.gyro_mis + p] = -G_w[:, i, j]
        if tl.accel_mis >= 0:
            F[3:6, tl.accel_mis + p] = G_f[:, i, j]
    return F


@njit
def _to_frame(P, mean, P_f, nav, tl, model, inward):
    """Turn the truth's stacks P (S, n_t, n_t), ``mean`` (S, n_t) and the filter's P_f between the public coordinates
    and the wander-azimuth frame of the solution row ``nav`` (``inward``: public to w; else w to public), in place
    (:func:`nav_kernels.to_public`)."""
    if inward:
        T_t = np.linalg.inv(public_jacobian(nav, tl.n, tl.base.gravity))
        T_f = np.linalg.inv(public_jacobian(nav, P_f.shape[0], model.layout.gravity))
        for s in range(P.shape[0]):
            P[s] = T_t @ P[s] @ T_t.T
            mean[s] = T_t @ mean[s]
        P_f[:, :] = T_f @ P_f @ T_f.T
        return
    for s in range(P.shape[0]):
        P[s] = to_public(P[s], nav, tl.base.gravity)
        mean[s] = to_public_vector(mean[s], nav, tl.base.gravity)
    P_f[:, :] = to_public(P_f, nav, model.layout.gravity)


@njit
def _interval_means(q_wb, dtheta, dv, k0, k1, dt):
    """(C, f_w, G_w, G_f) over IMU intervals k0..k1−1 with C_wb at the start of each interval, as the
    filter's accumulator has them: the mean C_wb, the mean specific force in w [m/s²], and
    G_w[a, i, j] = mean C_wb[a, i] ω_j [rad/s], G_f likewise with f_b [m/s²]."""
    C, f_n = np.zeros((3, 3)), np.zeros(3)
    G_w, G_f = np.zeros((3, 3, 3)), np.zeros((3, 3, 3))
    for k in range(k0, k1):
        Ck = rk.quat_to_matrix(q_wb[k])
        for a in range(3):
            for i in range(3):
                C[a, i] += Ck[a, i]
                f_n[a] += Ck[a, i] * dv[k, i]
                for j in range(3):
                    G_w[a, i, j] += Ck[a, i] * dtheta[k, j]
                    G_f[a, i, j] += Ck[a, i] * dv[k, j]
    span = (k1 - k0) * dt
    return C / (k1 - k0), f_n / span, G_w / span, G_f / span


@njit
def _nav(rows, k):
    """The strapdown state's solution row (q_ew, h, v_w, q_wb) of the nominal at sample k."""
    return rows[k].copy()


@njit
def _embed(H, n_t):
    """H (m, n) of the truth's base layout padded with zero columns to (m, n_t)."""
    out = np.zeros((H.shape[0], n_t))
    out[:, :H.shape[1]] = H
    return out


@njit
def _propagate_interval(P, mean, P_f, nav, C, f_n, G_w, G_f, span, tl, truth_q, inv_length, inv_tau, gravity_drive,
                        gravity_source, model):
    """Eq. (1) of :mod:`navsim.estimation.lincov` for the truth and the filter over ``span`` [s]; the
    truth's gravity disturbance driven by 2σ² V/D at the current speed (``gravity_drive`` = 2σ²/D)."""
    speed = np.hypot(nav[5], nav[6])
    q = truth_q.copy()
    if tl.base.gravity >= 0:  # an isotropic horizontal field in the turning w frame, as the filter's
        for i in range(3):
            drive = 0.5 * (gravity_drive[0] + gravity_drive[1]) if i < 2 else gravity_drive[2]
            q[gravity_source, tl.base.gravity + i] += drive * speed
    C_ew = rk.quat_to_matrix(nav[0:4])
    F_t = truth_f(C_ew, nav[4], nav[5:8], f_n, C, G_w, G_f, tl, inv_length, inv_tau)
    Phi, Q = van_loan(F_t, q, span)
    propagate(P, mean, Phi, Q)
    C_w, C_f = np.empty((3, 3)), np.empty((3, 3))
    for a in range(3):
        for i in range(3):
            C_w[a, i], C_f[a, i] = G_w[a, i, i], G_f[a, i, i]
    F_f = continuous_f(C_ew, nav[4], nav[5:8], f_n, C, C_w, C_f, model.layout, model.gm[3])
    Phi_f, Q_f = discretize(F_f, noise_densities(nav, model), span)
    P_next = Phi_f @ P_f @ Phi_f.T + Q_f
    P_f[:, :] = 0.5 * (P_next + P_next.T)


@njit
def _update_stars(P, mean, P_f, nav, q_ie, q_BS, rows, meas, tl, W, estimated):
    """All stars of a frame as one measurement (the filter fuses the accepted stars together)."""
    obs, cov, shift = meas.star_obs[rows[0]:rows[1]], meas.star_cov[rows[0]:rows[1]], meas.star_shift[rows[0]:rows[1]]
    z, H, R = star_terms(nav, q_BS, q_ie, meas.star_ref[rows[0]:rows[1]], obs, cov, tl.base, shift)
    z_real = star_terms(nav, q_BS, q_ie, meas.star_ref_real[rows[0]:rows[1]], obs, cov, tl.base, shift)[0]
    m = z.shape[0]
    H_t, R_t, d, d_real = np.zeros((2 * m, tl.n)), np.zeros((2 * m, 2 * m)), np.empty(2 * m), np.empty(2 * m)
    for k in range(m):
        for r in range(2):
            H_t[2 * k + r, :tl.base.n] = H[k, r]
            d[2 * k + r], d_real[2 * k + r] = z[k, r], z_real[k, r]
            for c in range(2):
                R_t[2 * k + r, 2 * k + c] = R[k, r, c]
    _offset_update(P, mean, P_f, W, H_t, R_t, meas, d, d_real, estimated, tl)


@njit
def _offset_update(P, mean, P_f, W, H_t, R_t, meas, d, d_real, estimated, tl):
    """A star-sensor measurement whose deterministic offset d splits into the refraction's d − d_real and the
    rest's d_real (:data:`Measurements`); the refraction's is the truth's state ε_r when it has one."""
    B = update(P, mean, P_f, W, H_t, R_t, meas.r_scale2 * R_t, d_real, estimated, meas.star_source, meas.offset_source)
    if meas.refraction_source >= 0 and tl.base.refraction < 0:
        mean[meas.refraction_source] -= B @ (d - d_real)


@njit
def _update_aiding(P, mean, P_f, nav, f, meas, tl, W, estimated, baro_estimated):
    """The frame's position fix (H and R of :func:`nav_kernels.position_terms` at the nominal) and baro height
    (H = e_δh − e_baro bias, R the white noise; the filter's R its σ with the bias), in that order."""
    if meas.position_mask[f]:
        lat, lon, _ = frame_angles(rk.quat_to_matrix(nav[0:4]))
        _, H, R_t, _ = position_terms(nav, np.array([lat, lon, nav[4]]), meas.position_sigma, tl.base.n)
        H_t = _embed(H, tl.n)
        update(P, mean, P_f, W, H_t, R_t, meas.r_scale2 * R_t, np.zeros(3), estimated, meas.aiding_source,
               meas.aiding_source)
    if meas.baro_mask[f]:
        H_t = np.zeros((1, tl.n))
        H_t[0, DP + 2] = 1.0
        if tl.baro >= 0:
            H_t[0, tl.baro] = -1.0
        R_t = np.full((1, 1), meas.baro_var)
        R_f = np.full((1, 1), meas.r_scale2 * meas.baro_filter_var)
        update(P, mean, P_f, W, H_t, R_t, R_f, np.array([meas.baro_offset[f]]), baro_estimated, meas.aiding_source,
               meas.aiding_source)


@njit
def run(rows, dtheta, dv, dt, ratio, every, stride, tl, truth_q, inv_length, inv_tau, gravity_drive,
        gravity_source, model, W, T, estimated, baro_estimated, P, mean, P_f, q_ie, q_BS, meas, step_frames, step_values,
        step_source):
    """The pass along the nominal (its wander-azimuth solution rows (q_ew, h, v_w, q_wb) (N+1, ROW); increments
    Δθ, Δv (N, 3) on IMU
    intervals of ``dt`` [s]): per frame of ``ratio`` intervals, the truth's stacks P (S, n_t, n_t) and
    ``mean`` (S, n_t) (one per error source) and the filter's P_f propagated every ``every`` intervals and at the frame's end
    (:func:`_propagate_interval`; the truth's noise densities ``truth_q`` (S, n_t)), the gyro bias steps of
    the frame added to source ``step_source``'s mean (``step_frames`` (J,), ``step_values`` (J, 3) [rad/s]), then the frame's
    measurements (``meas``: stars or a fix, then the position fix and the baro). Every ``stride`` frames
    (and at the last) it keeps: the time, the mean, the diagonal of each source's P in the truth's and
    (T P Tᵀ) the filter's coordinates, each source's leading :data:`BLOCK` x BLOCK, the filter's own
    diagonal and block, and the filter's expected NEES tr(P_f⁻¹ (T (Σ P + m mᵀ) Tᵀ)). The stacks come and go in
    the public coordinates (NED, position in metres: :func:`nav_kernels.to_public`); the pass runs in w."""
    frames = (rows.shape[0] - 1) // ratio
    _to_frame(P, mean, P_f, rows[0], tl, model, True)
    S, n_t, n_f = P.shape[0], tl.n, P_f.shape[0]
    log = allocate_log((frames + stride - 1) // stride, S, n_t, n_f, BLOCK)
    out = 0
    for f in range(frames):
        for s in range(step_frames.shape[0]):
            if step_frames[s] == f:
                mean[step_source, 9:12] += step_values[s]
        k0, end = f * ratio, (f + 1) * ratio
        while k0 < end:
            k1 = min(k0 + every, end)
            C, f_n, G_w, G_f = _interval_means(rows[:, 8:12], dtheta, dv, k0, k1, dt)
            nav = _nav(rows, k1)
            _propagate_interval(P, mean, P_f, nav, C, f_n, G_w, G_f, (k1 - k0) * dt, tl, truth_q, inv_length, inv_tau,
                                gravity_drive, gravity_source, model)
            k0 = k1
        nav = _nav(rows, end)
        span = (meas.star_offsets[f], meas.star_offsets[f + 1])
        if span[1] > span[0]:
            _update_stars(P, mean, P_f, nav, q_ie[f], q_BS, span, meas, tl, W, estimated)
        if meas.fix_mask[f]:
            z, H, R = fix_terms(nav, q_BS, q_ie[f], meas.fix_q[f], meas.fix_R, tl.base, meas.fix_rho[f])
            z_real = fix_terms(nav, q_BS, q_ie[f], meas.fix_q_real[f], meas.fix_R, tl.base, meas.fix_rho[f])[0]
            _offset_update(P, mean, P_f, W, _embed(H, n_t), R, meas, z, z_real, estimated, tl)
        _update_aiding(P, mean, P_f, nav, f, meas, tl, W, estimated, baro_estimated)
        if (f + 1) % stride == 0 or f == frames - 1:
            Pp, mp, Pfp = P.copy(), mean.copy(), P_f.copy()
            _to_frame(Pp, mp, Pfp, nav, tl, model, False)
            keep(log, out, end * dt, Pp, mp, Pfp, T, n_f)
            out += 1
    return trimmed(log, out)
