"""The compiled linear algebra every filter kernel shares (numba): small products, inverses, the
Joseph-form Kalman update with consider states, and the quadratic forms of NEES.

Small explicit loops beat a BLAS call below ~20 x 20; each function is tested against numpy.
"""

import numpy as np

from startrack import njit


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
def solve3(A, d):
    """A⁻¹ d for a general 3x3 A (Cramer's rule)."""
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    out = np.empty(3)
    out[0] = (c00 * d[0] + (A[0, 2] * A[2, 1] - A[0, 1] * A[2, 2]) * d[1] + (A[0, 1] * A[1, 2] - A[0, 2] * A[1, 1]) * d[2]) / det
    out[1] = (c01 * d[0] + (A[0, 0] * A[2, 2] - A[0, 2] * A[2, 0]) * d[1] + (A[0, 2] * A[1, 0] - A[0, 0] * A[1, 2]) * d[2]) / det
    out[2] = (c02 * d[0] + (A[0, 1] * A[2, 0] - A[0, 0] * A[2, 1]) * d[1] + (A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]) * d[2]) / det
    return out


@njit
def schmidt_gain(P, H, R, estimated):
    """(K, H P): the Kalman gain K = P Hᵀ (H P Hᵀ + R)⁻¹ with the rows of consider states (not
    ``estimated``) zero (Schmidt 1966)."""
    HP = mm(H, P)
    S = mm_t(HP, H) + R
    K = mm(HP.T.copy(), inverse_small(S))
    for i in range(K.shape[0]):
        if not estimated[i]:
            K[i, :] = 0.0
    return K, HP


@njit
def joseph_update(P, H, R, z, estimated):
    """Kalman update of a zero error state: returns (dx, P⁺) with the Joseph form
    P⁺ = (I − KH) P (I − KH)ᵀ + K R Kᵀ, K = P Hᵀ S⁻¹, S = H P Hᵀ + R, symmetrised; the rows of K of
    consider states (not ``estimated``) are zero (Schmidt), for which the Joseph form stays exact.

    Formed as M = P − K (H P), P⁺ = M − (M Hᵀ) Kᵀ + K R Kᵀ: O(n² m) for m measurements.
    """
    K, HP = schmidt_gain(P, H, R, estimated)
    dx = np.zeros(K.shape[0])
    for i in range(K.shape[0]):
        for j in range(z.shape[0]):
            dx[i] += K[i, j] * z[j]
    M = P - mm(K, HP)
    P_next = M - mm_t(mm_t(M, H), K) + mm_t(mm(K, R), K)
    return dx, 0.5 * (P_next + P_next.T)


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


@njit
def _sparse_times(rows, cols, values, B, out):
    """out = S B for S given by its non-zero triplets (rows, cols, values)."""
    out[:, :] = 0.0
    for k in range(values.shape[0]):
        i, p, a = rows[k], cols[k], values[k]
        for j in range(B.shape[1]):
            out[i, j] += a * B[p, j]


@njit
def van_loan(F, q_c, dt):
    """(Φ, Q_d (S, n, n)) over dt [s] for F and S diagonal continuous noises ``q_c`` (S, n) (one per error
    source: Q_d is linear in q_c) by their Taylor series to fifth order: Φ = Σ (FΔt)^k/k! and Van Loan's
    integral Q_d = ∫₀^Δt e^(Fs) Q e^(Fᵀs) ds = Σ L_k Δt^(k+1)/(k+1)!, L_0 = Q, L_k = F L_(k−1) + L_(k−1) Fᵀ
    (Van Loan 1978). F is sparse: each product runs over its non-zeros only."""
    n, sources = F.shape[0], q_c.shape[0]
    rows, cols = np.nonzero(F)
    values = np.empty(rows.shape[0])
    for k in range(rows.shape[0]):
        values[k] = F[rows[k], cols[k]]
    Phi, term, product = np.eye(n), np.eye(n), np.empty((n, n))
    for k in range(1, 6):
        _sparse_times(rows, cols, values * (dt / k), term, product)
        term[:, :] = product
        Phi += term
    Q = np.zeros((sources, n, n))
    L = np.zeros((n, n))
    for s in range(sources):
        L[:, :] = 0.0
        for i in range(n):
            L[i, i] = q_c[s, i]
            Q[s, i, i] = q_c[s, i] * dt
        coefficient = dt
        for k in range(1, 6):
            _sparse_times(rows, cols, values, L, product)
            coefficient *= dt / (k + 1)
            for i in range(n):
                for j in range(n):
                    L[i, j] = product[i, j] + product[j, i]
                    Q[s, i, j] += coefficient * L[i, j]
    return Phi, Q
