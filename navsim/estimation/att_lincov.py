"""Compiled linear covariance analysis of the attitude filter (the MEKF of
:mod:`navsim.estimation.attitude_filter`; numba): the pass along a nominal attitude profile that drives the
primitives of :mod:`navsim.estimation.lincov` with the filter's model beside the truth's.

The truth's error state has the MEKF's layout with every group the truth has (its own
:data:`~navsim.estimation.kernels.FilterModel`, the mounting always last):

    [δθ (3), e_b (3), e_g (3), δs (3), δk (6), δm (3)],

e_b = b_true − b̂ the total bias error (the filter's δb), e_g = g_true − ĝ the Gauss-Markov part's (ĝ = 0 when
the filter carries none: then b̂ does not decay and ė_b = −g/τ + noise, the truth's own; when it does, b̂ decays
by ĝ and ė_b = −e_g/τ + noise: one Φ, :func:`kernels.transition`, for both). The truth's Q is
:func:`kernels.process_noise` of its model, one per error source.
"""

from collections import namedtuple

import numpy as np

from navsim.estimation.kernels import fix_residual, star_residuals, transition
from navsim.estimation.lincov import allocate_log, keep, propagate, trimmed, update
from startrack import njit

#: The measurements of a pass, per frame f of F: identified stars (rows ``star_offsets[f]:star_offsets[f+1]`` of
#: the catalog directions ``star_ref`` (M, 3) in I, the noise-free directions ``star_obs`` (M, 3) in S through the
#: nominal mounting and their covariances ``star_cov`` (M, 3, 3) [rad²]), attitude fixes (``fix_mask`` (F,),
#: noise-free ``fix_q`` (F, 4), ``fix_R`` (3, 3) [rad²]); ``r_scale2`` the filter's measurement_noise_scale²;
#: the stack's source of the star sensor's noise.
Measurements = namedtuple("Measurements", "star_offsets star_ref star_obs star_cov fix_mask fix_q fix_R r_scale2 star_source")
#: The leading block kept in full at every output frame: δθ, e_b.
BLOCK = 6


@njit
def _update_frame(P, mean, P_f, q_IB, q_BS, f, meas, n_t, W, estimated):
    """The frame's stars (one measurement) or its attitude fix."""
    lo, hi = meas.star_offsets[f], meas.star_offsets[f + 1]
    if hi > lo:
        z, H, R = star_residuals(q_IB, q_BS, meas.star_ref[lo:hi], meas.star_obs[lo:hi], meas.star_cov[lo:hi], n_t, n_t - 3)
        m = z.shape[0]
        H_t, R_t, d = np.zeros((2 * m, n_t)), np.zeros((2 * m, 2 * m)), np.empty(2 * m)
        for k in range(m):
            for r in range(2):
                H_t[2 * k + r] = H[k, r]
                d[2 * k + r] = z[k, r]
                for c in range(2):
                    R_t[2 * k + r, 2 * k + c] = R[k, r, c]
        update(P, mean, P_f, W, H_t, R_t, meas.r_scale2 * R_t, d, estimated, meas.star_source, meas.star_source)
    if meas.fix_mask[f]:
        z, R_BS, R = fix_residual(q_IB, q_BS, meas.fix_q[f], meas.fix_R)
        H_t = np.zeros((3, n_t))
        for i in range(3):
            H_t[i, i] = 1.0
            for j in range(3):
                H_t[i, n_t - 3 + j] = R_BS[i, j]
        update(P, mean, P_f, W, H_t, R, meas.r_scale2 * R, z, estimated, meas.star_source, meas.star_source)


@njit
def run(omega, q_IB, dt, ratio, stride, truth_model, Q_t, filter_model, Q_f, W, T, estimated, P, mean, P_f, q_BS, meas,
        step_frames, step_values, step_source, nees_dof):
    """The pass along the nominal (true mean body rates ``omega`` (N, 3) [rad/s] of the gyro intervals of ``dt``
    [s], attitudes ``q_IB`` (N+1, 4)): per gyro interval the truth's stacks P (S, n_t, n_t) and ``mean`` (S, n_t)
    by the truth's Φ and each source's Q_t (S, n_t, n_t), the filter's P_f by its own Φ and Q_f; at the end of
    each frame of ``ratio`` intervals the gyro bias steps due (``step_frames`` (J,), ``step_values`` (J, 3)
    [rad/s] into source ``step_source``'s mean) and its measurements (``meas``). Every ``stride`` frames (and at the
    last) it keeps the time, the means, each source's diagonal in the truth's and (T P Tᵀ) the filter's
    coordinates and leading :data:`BLOCK` x BLOCK, the filter's diagonal and block, and its expected NEES over its
    first ``nees_dof`` states."""
    frames = omega.shape[0] // ratio
    S, n_t, n_f = P.shape[0], P.shape[1], P_f.shape[0]
    log = allocate_log((frames + stride - 1) // stride, S, n_t, n_f, BLOCK)
    out = 0
    for f in range(frames):
        for k in range(f * ratio, (f + 1) * ratio):
            propagate(P, mean, transition(omega[k], dt, n_t, truth_model), Q_t)
            Phi_f = transition(omega[k], dt, n_f, filter_model)
            P_next = Phi_f @ P_f @ Phi_f.T + Q_f
            P_f[:, :] = 0.5 * (P_next + P_next.T)
        for s in range(step_frames.shape[0]):
            if step_frames[s] == f:
                mean[step_source, 3:6] += step_values[s]
        end = (f + 1) * ratio
        _update_frame(P, mean, P_f, q_IB[end], q_BS, f, meas, n_t, W, estimated)
        if (f + 1) % stride == 0 or f == frames - 1:
            keep(log, out, end * dt, P, mean, P_f, T, nees_dof)
            out += 1
    return trimmed(log, out)
