"""Linear covariance analysis of a closed-loop error-state filter whose model differs from the truth
(compiled primitives; each run kind builds its truth model and drives them).

The truth's error state x (n_t: the filter's states and the ones it ignores — a Gauss-Markov bias part,
axis misalignments, a baro bias...) and the filter's error state (n_f), related by ``W`` (n_t x n_f):
column j of W is where the filter's state j sits in the truth (its correction goes there), and
``T`` (n_f x n_t) the filter's states as the truth's combinations (x_f = T x; T W = I). The filter
resets its estimate into the nominal state after every update, so between updates its estimate is zero
and the navigation error *is* the estimation error; its gains come from its own P_f along the nominal
trajectory. With each error source s driving x alone (its share of the initial covariance, of the
process noise Q_s and of the measurement noise R_s) the truth's covariance is the sum of the sources'
P_s, each propagated by the same linear recursion (Gelb, *Applied Optimal Estimation*, 1974, §7.1-7.2,
error budgets and the sensitivity of suboptimal filters; Maybeck vol. 1, 1979, §6.8; Geller 2006):

    propagation      P_s ← Φ P_s Φᵀ + Q_s,                      m ← Φ m                         (1)
    the filter       K = P_f H_fᵀ (H_f P_f H_fᵀ + R_f)⁻¹, H_f = H_t W, rows of consider states 0,
                     P_f ← (I − K H_f) P_f (I − K H_f)ᵀ + K R_f Kᵀ (Joseph)                        (2)
    update           A = I − W K H_t,  B = W K:  P_s ← A P_s Aᵀ + B R_s Bᵀ,  m ← A m − B d          (3)

for a measurement z = H_t x + d + v, v ~ N(0, Σ_s R_s), d a deterministic offset (a baro's lag, an
uncorrected aberration); m is the mean error of the fixed (not drawn) truth errors. When the filter's
model is the truth's (W = T = I, the same Φ, Q, H, R) eq. (3) is eq. (2) and Σ_s P_s = P_f.
"""

import numpy as np

from navsim.estimation.linalg import schmidt_gain
from startrack import njit


@njit
def propagate(P, mean, Phi, Q):
    """Eq. (1) in place for each source of the stacks P (S, n, n) and ``mean`` (S, n) with its Q (S, n, n)."""
    for s in range(P.shape[0]):
        P_next = Phi @ P[s] @ Phi.T + Q[s]
        P[s] = 0.5 * (P_next + P_next.T)
        mean[s] = Phi @ mean[s]


@njit
def filter_update(P_f, H_f, R_f, estimated):
    """Eq. (2) in place: the filter's Schmidt-Joseph update of P_f (n_f, n_f) with H_f (m, n_f) and its R_f
    (m, m); returns its gain K (n_f, m)."""
    K, HP = schmidt_gain(P_f, H_f, R_f, estimated)
    M = P_f - K @ HP
    P_next = M - (M @ H_f.T) @ K.T + K @ R_f @ K.T
    P_f[:, :] = 0.5 * (P_next + P_next.T)
    return K


@njit
def true_update(P, mean, W, K, H_t, R_t, d, source, offset_source):
    """Eq. (3) in place for the stacks P (S, n_t, n_t) and ``mean`` (S, n_t) of the sources: the filter's gain K
    applied to the truth's measurement H_t (m, n_t) whose noise R_t (m, m) is source ``source``'s and whose
    deterministic offset d (m,) is source ``offset_source``'s (the other sources see only A)."""
    B = W @ K
    A = np.eye(W.shape[0]) - B @ H_t
    for s in range(P.shape[0]):
        P_next = A @ P[s] @ A.T
        if s == source:
            P_next += B @ R_t @ B.T
        P[s] = 0.5 * (P_next + P_next.T)
        mean[s] = A @ mean[s]
        if s == offset_source:
            mean[s] -= B @ d


@njit
def update(P, mean, P_f, W, H_t, R_t, R_f, d, estimated, source, offset_source):
    """One measurement through the filter (eq. 2) and the truth (eq. 3); H_f = H_t W. Returns W K, the gain
    in the truth's coordinates (a second source's offset d' moves its mean by −W K d')."""
    H_f = np.ascontiguousarray(H_t @ W)
    K = filter_update(P_f, H_f, R_f, estimated)
    true_update(P, mean, W, K, H_t, R_t, d, source, offset_source)
    return W @ K


@njit
def expected_nees(P_f, C):
    """E[NEES] = tr(P_f⁻¹ C) of an error of second moment C (n_f, n_f) (covariance plus m mᵀ)."""
    return np.trace(np.linalg.solve(P_f, C))


@njit
def allocate_log(kept, S, n_t, n_f, block):
    """The arrays a pass keeps at ``kept`` frames (:func:`keep`): times (K,), means (S, K, n_t), each source's
    diagonal in the truth's (S, K, n_t) and the filter's coordinates (S, K, n_f) and leading ``block`` x block,
    the filter's own diagonal (K, n_f) and block, its expected NEES (K,)."""
    return (np.empty(kept), np.empty((S, kept, n_t)), np.empty((S, kept, n_t)), np.empty((S, kept, n_f)),
            np.empty((S, kept, block, block)), np.empty((kept, n_f)), np.empty((kept, block, block)), np.empty(kept))


@njit
def keep(log, out, t, P, mean, P_f, T, nees_dof):
    """Write row ``out`` of ``log`` (:func:`allocate_log`) at time ``t`` [s]: the sources' means and covariances,
    the filter's own, and its expected NEES over its first ``nees_dof`` states, tr(P_f⁻¹ T (Σ P + m mᵀ) Tᵀ)
    (m the summed mean)."""
    t_out, mean_out, diag_t, diag_f, block, filter_diag, filter_block, nees_out = log
    B = block.shape[2]
    n_t = P.shape[1]
    t_out[out] = t
    total = np.zeros(n_t)
    second = np.zeros((n_t, n_t))
    for s in range(P.shape[0]):
        mean_out[s, out] = mean[s]
        total += mean[s]
        second += P[s]
        diag_t[s, out] = np.diag(P[s])
        diag_f[s, out] = np.diag(T @ P[s] @ T.T)
        block[s, out] = P[s, :B, :B]
    second += np.outer(total, total)
    filter_diag[out], filter_block[out] = np.diag(P_f), P_f[:B, :B]
    C = T @ second @ T.T
    nees_out[out] = expected_nees(np.ascontiguousarray(P_f[:nees_dof, :nees_dof]), np.ascontiguousarray(C[:nees_dof, :nees_dof]))


@njit
def trimmed(log, rows):
    """The first ``rows`` kept frames of ``log``."""
    t_out, mean_out, diag_t, diag_f, block, filter_diag, filter_block, nees_out = log
    return (t_out[:rows], mean_out[:, :rows], diag_t[:, :rows], diag_f[:, :rows], block[:, :rows], filter_diag[:rows],
            filter_block[:rows], nees_out[:rows])
