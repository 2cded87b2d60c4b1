"""Optical-axis (boresight) solves of the contest paper 001, chapters 2-3.

The point D where the optical axis meets the celestial sphere is the unit vector ``w`` in the
inertial frame I ("^0w" of 001).  Inputs, for stars already identified:

* ``ref_I`` (n, 3): catalog unit vectors p_i of the stars in I (001: ^0p_i);
* scalar image data (001 ch. 2): ``radii_px`` (n,) the distance a_i [px] of each star image from the
  principal point; with the focal length f [px], cos(gamma_i) = f / sqrt(f^2 + a_i^2) is the cosine of
  the angle between the star and the boresight (eq. 2-1);
* vector image data (001 ch. 3): ``xy_px`` (n, 2) the image coordinates (X_i, Y_i) [px] relative to the
  principal point, X = u - cx, Y = v - cy; c_i = (X_i, Y_i, f)/|.| is the star direction in the sensor
  frame S of docs/design.md (+z boresight, +x along u, +y along v), so the sensor attitude follows too.

001's rotation R maps I into S (R = R_IS^T); ``BoresightSolution.q_IS`` is docs/design.md's quaternion.
Matrices below are written with stars as columns: Pc = [p_1 .. p_n], Cc = [c_1 .. c_n] and
R Pc = Cc (001 eq. 3-1); the row matrix ^0P of eq. 2-2 is Pc^T.

Every solve is vectorised over a batch of star triples (the ``*_batch`` kernels: stacked arrays, no
input validation, for inner loops such as the best-triple search of 2.3.1/3.3.1 and the contest
experiment); the other public functions validate their input and call the same kernels.
"""

from dataclasses import dataclass
from functools import lru_cache
from itertools import combinations

import numpy as np
from scipy.optimize import brentq

from startrack.base.errors import InputError
from startrack.geometry.rotation import from_matrix, nearest_rotation

_RANK_TOLERANCE = 1e-9          # relative singular value below which ^0P counts as rank deficient
_COLLINEAR_TOLERANCE = 1e-4     # 1 - |P^+ b|^2 down to -this counts as tangent (noise in b), not a miss
_FOCAL_GRID_POINTS = 256        # grid that brackets the roots of |P^-1 b(f)|^2 = 1 before bisection


@dataclass(frozen=True)
class BoresightSolution:
    """Result of a boresight solve.

    boresight_I: (3,) unit vector of D in I (the first candidate).
    candidates: (k, 3) all admissible solutions (k = 2 for the collinear case 2.1.2 (二)).
    focal_px: focal length used or estimated [px].
    q_IS: (4,) sensor attitude (vector image data only), else None.
    method: name of the model and equation.
    """

    boresight_I: np.ndarray
    candidates: np.ndarray
    focal_px: float
    q_IS: np.ndarray | None
    method: str


# ----------------------------------------------------------------------------------------- checks

def _as_unit_vectors(ref_I, min_count, what):
    ref = np.asarray(ref_I, dtype=float)
    if ref.ndim != 2 or ref.shape[1] != 3 or ref.shape[0] < min_count:
        raise InputError(f"{what}: ref_I must have shape (n, 3) with n >= {min_count}; got {ref.shape}.")
    error = np.abs(np.einsum("ij,ij->i", ref, ref) - 1.0).max()
    if not error <= 1e-6:
        raise InputError(f"{what}: ref_I must hold finite unit vectors (squared norm off by {error:.3g}).")
    return ref


def _as_radii(radii_px, n, what):
    radii = np.asarray(radii_px, dtype=float)
    if radii.shape != (n,) or not np.isfinite(radii).all() or (radii < 0.0).any():
        raise InputError(f"{what}: radii_px must be {n} finite values >= 0 px; got {radii_px!r}.")
    return radii


def _as_xy(xy_px, n, what):
    xy = np.asarray(xy_px, dtype=float)
    if xy.shape != (n, 2) or not np.isfinite(xy).all():
        raise InputError(f"{what}: xy_px must be a finite array of shape ({n}, 2) px; got shape {xy.shape}.")
    return xy


def _as_focal(focal_px, what):
    f = float(focal_px)
    if not (np.isfinite(f) and f > 0.0):
        raise InputError(f"{what}: focal_px must be finite and > 0 px; got {focal_px!r}.")
    return f


def _as_bounds(focal_bounds_px, what):
    try:
        low, high = (float(v) for v in focal_bounds_px)
    except (TypeError, ValueError):
        raise InputError(f"{what}: focal_bounds_px must be a pair (f_min, f_max) in px; got {focal_bounds_px!r}.") from None
    if not (np.isfinite(low) and np.isfinite(high) and 0.0 < low < high):
        raise InputError(f"{what}: focal_bounds_px must satisfy 0 < f_min < f_max; got {focal_bounds_px!r}.")
    return low, high


def _one_triple(ref, what):
    if ref.shape[0] != 3:
        raise InputError(f"{what}: this model uses exactly 3 stars; got {ref.shape[0]}.")


# ------------------------------------------------------------------------ scalar model, known f

def cos_gamma(radii_px, focal_px):
    """b_i = cos(gamma_i) = f / sqrt(f^2 + a_i^2) (001 eq. 2-1); radii and f in px."""
    return focal_px / np.sqrt(focal_px ** 2 + np.asarray(radii_px) ** 2)


def scalar_known_f_batch(P_rows, b):
    """w = P^-1 b / |P^-1 b| (001 eq. 2-3) for stacks P_rows (K, 3, 3) (rows p_i^T) and b (K, 3)."""
    w = np.linalg.solve(P_rows, b[..., None])[..., 0]
    return w / np.linalg.norm(w, axis=-1, keepdims=True)


def _scalar_known_f(P_rows, radii, f, what):
    """One triple: rank test of ^0P (001 2.1.2) and eq. 2-3 (rank 3) or the collinear line (rank 2)."""
    U, s, Vt = np.linalg.svd(P_rows)
    b = cos_gamma(radii, f)
    rank = int(np.sum(s > _RANK_TOLERANCE * s[0]))
    if rank == 3:
        return scalar_known_f_batch(P_rows[None], b[None])
    if rank == 1:
        raise InputError(f"{what}: the three stars coincide (rank(^0P) = 1, 001 2.1.2 (三)); "
                         "the boresight is not determined.")
    # rank 2 (001 2.1.2 (二)): w = P^+ b + k t with P t = 0 and |P^+ b|^2 + k^2 = 1
    w0 = Vt[:2].T @ ((U[:, :2].T @ b) / s[:2])
    t = Vt[2]
    k2 = 1.0 - w0 @ w0
    if k2 < -_COLLINEAR_TOLERANCE:
        raise InputError(f"{what}: collinear stars and the measured radii give a line that misses the "
                         f"unit sphere (1 - |P^+ b|^2 = {k2:.3g}); no boresight satisfies eq. 2-1.")
    if k2 <= 0.0:
        return (w0 / np.linalg.norm(w0))[None]
    k = np.sqrt(k2)
    return np.stack([w0 + k * t, w0 - k * t])


def _linearised_error_term(P_rows, radii, f, what):
    """001 2.1.2 (一)(II): min |da|^2 s.t. |P^-1 (b - A da)|^2 = 1, A = diag(d cos(gamma_i)/d a_i).

    With c = P^-1 b, G = P^-1 A = U S V^T, d = U^T c and da = V y this is min |y|^2 s.t.
    |d - S y|^2 = 1; Lagrange gives y_i = mu s_i d_i / (1 + mu s_i^2) and the secular equation
    sum_i d_i^2 / (1 + mu s_i^2)^2 = 1, monotone on 1 + mu s_max^2 > 0 (the global minimum), solved
    by Brent's method in nu = mu s_max^2.  Returns w = P^-1 (b - A da) (unit by construction).
    """
    b = cos_gamma(radii, f)
    slope = -f * radii / (f ** 2 + radii ** 2) ** 1.5
    c = np.linalg.solve(P_rows, b)
    G = np.linalg.solve(P_rows, np.diag(slope))
    U, s, Vt = np.linalg.svd(G)
    d = U.T @ c
    if s[0] == 0.0:
        raise InputError(f"{what}: all three stars sit on the principal point; no error term can be fitted.")
    r = (s / s[0]) ** 2

    def excess(nu):
        return np.sum(d ** 2 / (1.0 + nu * r) ** 2) - 1.0

    if excess(0.0) > 0.0:
        high = 1.0
        while excess(high) > 0.0:
            high *= 4.0
            if high > 1e18:
                raise InputError(f"{what}: the linearised error term cannot reach the unit sphere.")
        nu = brentq(excess, 0.0, high, xtol=1e-15, rtol=1e-15)
    else:
        low = -0.5
        while excess(low) < 0.0:
            low = -1.0 + (1.0 + low) / 16.0
            if 1.0 + low < 1e-15:
                raise InputError(f"{what}: the linearised error term cannot reach the unit sphere.")
        nu = brentq(excess, low, 0.0, xtol=1e-15, rtol=1e-15)
    mu = nu / s[0] ** 2
    da = Vt.T @ (mu * s * d / (1.0 + mu * s ** 2))
    w = c - G @ da
    return w / np.linalg.norm(w)


def solve_scalar_known_f(ref_I, radii_px, focal_px, method="normalised"):
    """Boresight from 3 stars, their image radii a_i [px] and a known focal length f [px] (001 2.1).

    ^0P w = b (eq. 2-2).  method "normalised": w = P^-1 b/|P^-1 b| (eq. 2-3); "linearised": the
    constrained linearised-error-term solution of 2.1.2 (一)(II).  Stars on one great circle
    (rank ^0P = 2, 2.1.2 (二)) give up to two candidates; coincident stars (rank 1) raise InputError.
    """
    what = "solve_scalar_known_f"
    ref = _as_unit_vectors(ref_I, 3, what)
    _one_triple(ref, what)
    radii = _as_radii(radii_px, 3, what)
    f = _as_focal(focal_px, what)
    if method == "normalised":
        candidates = _scalar_known_f(ref, radii, f, what)
    elif method == "linearised":
        if np.linalg.matrix_rank(ref, tol=_RANK_TOLERANCE) < 3:
            raise InputError(f"{what}: the linearised variant needs three non-collinear stars (rank ^0P = 3).")
        candidates = _linearised_error_term(ref, radii, f, what)[None]
    else:
        raise InputError(f"{what}: method must be 'normalised' or 'linearised'; got {method!r}.")
    return BoresightSolution(candidates[0], candidates, f, None, f"scalar_known_f_{method}")


# ---------------------------------------------------------------------- scalar model, unknown f

def _focal_grid(bounds):
    return np.geomspace(bounds[0], bounds[1], _FOCAL_GRID_POINTS)


def scalar_unknown_f_batch(P_rows, radii, bounds):
    """001 2.2.1: f* with |P^-1 b(f)|^2 = 1 inside bounds, for stacks P_rows (K, 3, 3), radii (K, 3).

    h(f) = |P^-1 b(f)|^2 - 1 is sampled on a geometric grid; the sign change nearest the geometric
    centre of the bounds is refined by 60 bisection steps.  Returns (f (K,), w (K, 3)); f is NaN where
    h has no sign change inside the bounds.
    """
    P_inv = np.linalg.inv(P_rows)

    def h(f):                                   # f (K, m) -> (K, m)
        b = f[..., None] / np.sqrt(f[..., None] ** 2 + radii[:, None, :] ** 2)
        x = np.einsum("kij,kmj->kmi", P_inv, b)
        return np.einsum("kmi,kmi->km", x, x) - 1.0

    grid = _focal_grid(bounds)
    values = h(np.broadcast_to(grid, (P_rows.shape[0], grid.size)))
    change = np.signbit(values[:, :-1]) != np.signbit(values[:, 1:])
    centre = 0.5 * (grid.size - 2)
    distance = np.where(change, np.abs(np.arange(grid.size - 1) - centre), np.inf)
    j = np.argmin(distance, axis=1)
    found = np.isfinite(distance[np.arange(j.size), j])
    low, high = grid[j], grid[j + 1]
    h_low = values[np.arange(j.size), j]
    for _ in range(60):
        mid = np.sqrt(low * high)
        h_mid = h(mid[:, None])[:, 0]
        same = np.signbit(h_mid) == np.signbit(h_low)
        low, h_low = np.where(same, mid, low), np.where(same, h_mid, h_low)
        high = np.where(same, high, mid)
    f = np.where(found, np.sqrt(low * high), np.nan)
    b = f[:, None] / np.sqrt(f[:, None] ** 2 + radii ** 2)
    w = np.einsum("kij,kj->ki", P_inv, b)
    return f, w / np.linalg.norm(w, axis=-1, keepdims=True)


def solve_scalar_unknown_f(ref_I, radii_px, focal_bounds_px):
    """Boresight and focal length from 3 stars and their image radii, f unknown (001 2.2.1).

    f* solves |^0P^-1 b(f)|^2 = 1 within focal_bounds_px = (f_min, f_max) [px] (001 notes the solve is
    only stable with such a prior range); w = ^0P^-1 b(f*), normalised.  InputError when no root lies
    inside the bounds.
    """
    what = "solve_scalar_unknown_f"
    ref = _as_unit_vectors(ref_I, 3, what)
    _one_triple(ref, what)
    radii = _as_radii(radii_px, 3, what)
    bounds = _as_bounds(focal_bounds_px, what)
    if np.linalg.matrix_rank(ref, tol=_RANK_TOLERANCE) < 3:
        raise InputError(f"{what}: needs three non-collinear stars (rank ^0P = 3, 001 2.2.1).")
    f, w = scalar_unknown_f_batch(ref[None], radii[None], bounds)
    if not np.isfinite(f[0]):
        raise InputError(f"{what}: no focal length in {bounds} px makes |P^-1 b(f)| = 1; "
                         "the radii do not match the stars or the bounds are wrong.")
    return BoresightSolution(w[0], w, float(f[0]), None, "scalar_unknown_f_numeric")


# ------------------------------------------------------------------------ vector model, known f

def sensor_directions(xy_px, focal_px):
    """c_i = (X_i, Y_i, f)/|.| (001 3.1.1): unit star directions in S from image coordinates [px]."""
    xy = np.asarray(xy_px, dtype=float)
    f = np.broadcast_to(np.asarray(focal_px, dtype=float)[..., None], xy.shape[:-1] + (1,))
    c = np.concatenate([xy, f], axis=-1)
    return c / np.linalg.norm(c, axis=-1, keepdims=True)


def vector_known_f_batch(P_rows, C_rows):
    """001 3.1.1: R = Cc Pc^-1 projected onto the rotations by SVD; w = R^T e_3.  Stacks (K, 3, 3)."""
    R_raw = np.swapaxes(np.linalg.solve(P_rows, C_rows), -1, -2)   # Cc Pc^-1 = (P_rows^-1 C_rows)^T
    R = nearest_rotation(R_raw)
    return R, R[..., 2, :]


def _solution_from_R(R, f, method):
    return BoresightSolution(R[2].copy(), R[2][None].copy(), float(f), from_matrix(R.T), method)


def solve_vector_known_f(ref_I, xy_px, focal_px):
    """Boresight and attitude from 3 stars with image coordinates (X_i, Y_i) [px], f known (001 3.1.1).

    R ^0P = c (eq. 3-1) gives R = c ^0P^-1, projected onto the rotations by SVD (U V^T); w = R^T e_3.
    """
    what = "solve_vector_known_f"
    ref = _as_unit_vectors(ref_I, 3, what)
    _one_triple(ref, what)
    xy = _as_xy(xy_px, 3, what)
    f = _as_focal(focal_px, what)
    if np.linalg.matrix_rank(ref, tol=_RANK_TOLERANCE) < 3:
        raise InputError(f"{what}: needs three non-collinear stars (rank ^0P = 3, 001 3.1.1).")
    R, _ = vector_known_f_batch(ref, sensor_directions(xy, f))
    return _solution_from_R(R, f, "vector_known_f_svd")


# --------------------------------------------------------------------- vector model, unknown f

def _pair_indices(n):
    return np.array(list(combinations(range(n), 2))).reshape(-1, 2)


def focal_cubic_batch(ref, xy):
    """001 3.2.1 (二): t = f^2 minimising |e|^2, e = D (t^2, t, 1)^T, for stacks ref (K, n, 3), xy (K, n, 2).

    For each star pair the law of cosines cos(beta_ij) = (|OQ_i|^2 + |OQ_j|^2 - |Q_iQ_j|^2) /
    (2 |OQ_i| |OQ_j|) with |OQ_i|^2 = t + rho_i^2 becomes, after squaring,
    (cos^2 b - 1) t^2 + (cos^2 b (rho_i^2 + rho_j^2) - 2 m_ij) t + cos^2 b rho_i^2 rho_j^2 - m_ij^2 = 0,
    m_ij = X_i X_j + Y_i Y_j.  d|e|^2/dt = 0 is a cubic in t, solved through its companion matrix
    (t scaled by the largest rho^2 for conditioning); among its real positive roots the one of least
    |e|^2 is kept.  Returns (f (K,) [px], loss (K,) = |e|^2 in scaled units); f = NaN where no real
    positive root exists.
    """
    pairs = _pair_indices(ref.shape[1])
    i, j = pairs[:, 0], pairs[:, 1]
    cos2 = np.einsum("kpi,kpi->kp", ref[:, i], ref[:, j]) ** 2
    rho2 = np.einsum("kni,kni->kn", xy, xy)
    scale = np.maximum(rho2.max(axis=1), 1.0)[:, None]
    ri, rj = rho2[:, i] / scale, rho2[:, j] / scale
    m = np.einsum("kpi,kpi->kp", xy[:, i], xy[:, j]) / scale
    D = np.stack([cos2 - 1.0, cos2 * (ri + rj) - 2.0 * m, cos2 * ri * rj - m ** 2], axis=-1)  # (K, p, 3)
    G = np.einsum("kpa,kpb->kab", D, D)                       # |e|^2 = v^T G v, v = (t^2, t, 1)
    # d/dt v^T G v = 2 v^T G dv/dt with dv/dt = (2t, 1, 0): cubic coefficients (highest first)
    c3 = 2.0 * G[:, 0, 0]
    c2 = 3.0 * G[:, 0, 1]
    c1 = G[:, 1, 1] + 2.0 * G[:, 0, 2]
    c0 = G[:, 1, 2]
    companion = np.zeros((ref.shape[0], 3, 3))
    companion[:, 0, :] = -np.stack([c2, c1, c0], axis=-1) / c3[:, None]
    companion[:, 1, 0] = companion[:, 2, 1] = 1.0
    roots = np.linalg.eigvals(companion)
    real = np.abs(roots.imag) <= 1e-9 * np.maximum(1.0, np.abs(roots.real))
    t = np.where(real & (roots.real > 0.0), roots.real, np.nan)
    v = np.stack([t ** 2, t, np.ones_like(t)], axis=-1)
    loss = np.einsum("kra,kab,krb->kr", v, G, v)
    best = np.argmin(np.where(np.isnan(loss), np.inf, loss), axis=1)
    k = np.arange(t.shape[0])
    t_best, loss_best = t[k, best], loss[k, best]
    return np.sqrt(t_best * scale[:, 0]), loss_best


def focal_from_angular_distances(ref_I, xy_px):
    """Focal length [px] from n >= 2 stars' catalog angular distances and image coordinates (001 3.2.1 (二)).

    Returns (f, loss) where loss = |e|^2 of the pair equations (dimensionless, t scaled by the largest
    rho^2).  InputError when the cubic has no real positive root (the data do not match).
    """
    what = "focal_from_angular_distances"
    ref = _as_unit_vectors(ref_I, 2, what)
    xy = _as_xy(xy_px, ref.shape[0], what)
    f, loss = focal_cubic_batch(ref[None], xy[None])
    if not np.isfinite(f[0]):
        raise InputError(f"{what}: the cubic in t = f^2 has no real positive root; the image coordinates "
                         "do not match the stars' angular distances.")
    return float(f[0]), float(loss[0])


def solve_vector_unknown_f(ref_I, xy_px, method="analytic", focal_bounds_px=None):
    """Boresight, attitude and f from 3 stars with image coordinates, f unknown (001 3.2.1).

    method "analytic": f from the cubic in t = f^2 (3.2.1 (二)); "numeric": f from
    |(c(f) P^-1)^T e_3|^2 = 1 within focal_bounds_px (3.2.1 (一); the third row of c(f) P^-1 only
    involves cos(gamma_i), so this is the scalar equation of 2.2.1).  Then R by SVD as with known f.
    """
    what = "solve_vector_unknown_f"
    ref = _as_unit_vectors(ref_I, 3, what)
    _one_triple(ref, what)
    xy = _as_xy(xy_px, 3, what)
    if np.linalg.matrix_rank(ref, tol=_RANK_TOLERANCE) < 3:
        raise InputError(f"{what}: needs three non-collinear stars (rank ^0P = 3, 001 3.2.1).")
    if method == "analytic":
        f, _ = focal_from_angular_distances(ref, xy)
    elif method == "numeric":
        if focal_bounds_px is None:
            raise InputError(f"{what}: method 'numeric' needs focal_bounds_px = (f_min, f_max).")
        f = solve_scalar_unknown_f(ref, np.hypot(xy[:, 0], xy[:, 1]), focal_bounds_px).focal_px
    else:
        raise InputError(f"{what}: method must be 'analytic' or 'numeric'; got {method!r}.")
    R, _ = vector_known_f_batch(ref, sensor_directions(xy, f))
    return _solution_from_R(R, f, f"vector_unknown_f_{method}")


# ------------------------------------------------------------------------ best triple (‖M‖)

def _scalar_bound_norms(P_rows, radii, f):
    """001 2.3.1: |M| (spectral) with M = (I - w w^T) P^-1 A, A = diag(d cos(gamma_i)/d a_i)."""
    b = f / np.sqrt(f ** 2 + radii ** 2)
    slope = -f * radii / (f ** 2 + radii ** 2) ** 1.5
    P_inv = np.linalg.inv(P_rows)
    w = np.einsum("kij,kj->ki", P_inv, b)
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    G = P_inv * slope[:, None, :]
    M = G - w[:, :, None] * np.einsum("ki,kij->kj", w, G)[:, None, :]
    return np.linalg.norm(M, ord=2, axis=(1, 2))


def _vector_bound_norms(P_rows, xy, f):
    """001 3.3.1: |(^0P^-1)^T N_3| (spectral); N_3 (3 x 6) holds d c_i3/d X_i, d c_i3/d Y_i on its rows.

    With the row matrix ^0P = Pc^T, w = Pc^-T (c_13, c_23, c_33)^T = P_rows^-1 zeta, hence the map is
    P_rows^-1 N_3.
    """
    rho2 = np.einsum("kni,kni->kn", xy, xy)
    grad = -f * xy / ((f ** 2 + rho2) ** 1.5)[..., None]            # (K, 3, 2)
    K = P_rows.shape[0]
    N3 = np.zeros((K, 3, 6))
    for i in range(3):
        N3[:, i, 2 * i:2 * i + 2] = grad[:, i]
    return np.linalg.norm(np.linalg.inv(P_rows) @ N3, ord=2, axis=(1, 2))


def all_triples(n):
    """(C(n, 3), 3) index array of all star triples."""
    return np.array(list(combinations(range(n), 3))).reshape(-1, 3)


def error_bound_norms(ref_I, focal_px, radii_px=None, xy_px=None):
    """|M| of every triple (001 2.3.1 with radii_px, 3.3.1 with xy_px); returns (triples, norms).

    Triples whose stars are collinear (singular ^0P) get an infinite norm.
    """
    what = "error_bound_norms"
    ref = _as_unit_vectors(ref_I, 3, what)
    f = _as_focal(focal_px, what)
    triples = all_triples(ref.shape[0])
    P_rows = ref[triples]
    singular = np.linalg.svd(P_rows, compute_uv=False)
    ok = singular[:, 2] > _RANK_TOLERANCE * singular[:, 0]
    norms = np.full(len(triples), np.inf)
    if (radii_px is None) == (xy_px is None):
        raise InputError(f"{what}: give exactly one of radii_px (scalar model) or xy_px (vector model).")
    if radii_px is not None:
        radii = _as_radii(radii_px, ref.shape[0], what)
        norms[ok] = _scalar_bound_norms(P_rows[ok], radii[triples[ok]], f)
    else:
        xy = _as_xy(xy_px, ref.shape[0], what)
        norms[ok] = _vector_bound_norms(P_rows[ok], xy[triples[ok]], f)
    return triples, norms


def best_triple(ref_I, focal_px, radii_px=None, xy_px=None):
    """Indices (3,) of the triple with the smallest error-bound norm |M| (001 2.3.1, 3.3.1)."""
    triples, norms = error_bound_norms(ref_I, focal_px, radii_px=radii_px, xy_px=xy_px)
    if not np.isfinite(norms).any():
        raise InputError("best_triple: every triple of stars is collinear; no boresight can be solved.")
    return triples[int(np.argmin(norms))]


# ---------------------------------------------------------------------- all stars (OLS, CLS)

def _constrained_unit_ls(P_rows, b):
    """001 2.3.2 (二): min |P' w - b'|^2 s.t. |w| = 1 by the 6th-degree polynomial and its companion matrix.

    P'^T P' = U diag(l_1, l_2, l_3) U^T, d = U^T P'^T b'; stationarity (P'^T P' + lam I) w = P'^T b'
    with |w| = 1 gives sum_i d_i^2 / (lam + l_i)^2 = 1, i.e. sum_i d_i^2 prod_{j != i} (lam + l_j)^2 -
    prod_j (lam + l_j)^2 = 0.  Its roots are the eigenvalues of the companion matrix; every real root,
    polished by Newton steps on the secular equation, gives w = U d/(lam + l) (renormalised); the one
    of least cost is returned.
    """
    lam_i, U = np.linalg.eigh(P_rows.T @ P_rows)
    d = U.T @ (P_rows.T @ b)
    factors = [np.poly1d([1.0, l]) ** 2 for l in lam_i]
    poly = -(factors[0] * factors[1] * factors[2])
    for i in range(3):
        others = [factors[j] for j in range(3) if j != i]
        poly = poly + d[i] ** 2 * others[0] * others[1]
    c = poly.coeffs                                              # c_6 .. c_0, c_6 = -1
    companion = np.zeros((6, 6))
    companion[0] = -c[1:] / c[0]
    companion[np.arange(1, 6), np.arange(5)] = 1.0
    roots = np.linalg.eigvals(companion)
    scale = max(1.0, float(np.abs(lam_i).max()))
    lam = roots.real[np.abs(roots.imag) <= 1e-6 * scale]
    if lam.size == 0:
        lam = roots.real[np.argsort(np.abs(roots.imag))[:1]]
    def secular(value):                                         # sum d_i^2 / (lam + l_i)^2 - 1
        return np.sum(d ** 2 / (value + lam_i) ** 2) - 1.0

    best_w, best_cost = None, np.inf
    with np.errstate(divide="ignore", invalid="ignore"):
        for value in lam:
            for _ in range(8):                                  # Newton polish while |secular| decreases
                step = secular(value) / (2.0 * np.sum(d ** 2 / (value + lam_i) ** 3))
                if not abs(secular(value + step)) < abs(secular(value)):
                    break
                value += step
            w = U @ (d / (value + lam_i))
            norm = np.linalg.norm(w)
            if not (np.isfinite(norm) and norm > 0.0):
                continue
            w /= norm
            cost = np.sum((P_rows @ w - b) ** 2)
            if cost < best_cost:
                best_w, best_cost = w, cost
    return best_w


def solve_scalar_all_stars(ref_I, radii_px, focal_px, method="ols"):
    """Boresight from all n >= 3 stars' radii with known f (001 2.3.2).

    ^0P' w = b'.  method "ols": w = (P'^T P')^-1 P'^T b' normalised (2.3.2 (一)); "constrained": least
    squares on the unit sphere through the 6th-degree polynomial (2.3.2 (二)).
    """
    what = "solve_scalar_all_stars"
    ref = _as_unit_vectors(ref_I, 3, what)
    radii = _as_radii(radii_px, ref.shape[0], what)
    f = _as_focal(focal_px, what)
    if np.linalg.matrix_rank(ref, tol=_RANK_TOLERANCE) < 3:
        raise InputError(f"{what}: ^0P' must have full column rank (stars not all on one great circle).")
    b = cos_gamma(radii, f)
    if method == "ols":
        w = np.linalg.lstsq(ref, b, rcond=None)[0]
        w /= np.linalg.norm(w)
    elif method == "constrained":
        w = _constrained_unit_ls(ref, b)
    else:
        raise InputError(f"{what}: method must be 'ols' or 'constrained'; got {method!r}.")
    return BoresightSolution(w, w[None], f, None, f"scalar_all_stars_{method}")


def _vector_ols(ref, c):
    """001 3.3.2 (一): R_hat = argmin |R Pc' - Cc'|^2 = Cc' Pc'^T (Pc' Pc'^T)^-1, projected by SVD."""
    R_raw = np.linalg.solve(ref.T @ ref, ref.T @ c).T
    return nearest_rotation(R_raw)


def solve_vector_all_stars(ref_I, xy_px, focal_px=None):
    """Boresight and attitude from all n >= 3 stars' image coordinates by OLS then SVD (001 3.3.2 (一)).

    With focal_px None, f comes first from the cubic of 3.2.1 (二) over all star pairs.
    """
    what = "solve_vector_all_stars"
    ref = _as_unit_vectors(ref_I, 3, what)
    xy = _as_xy(xy_px, ref.shape[0], what)
    if np.linalg.matrix_rank(ref, tol=_RANK_TOLERANCE) < 3:
        raise InputError(f"{what}: ^0P' must have full column rank (stars not all on one great circle).")
    f = focal_from_angular_distances(ref, xy)[0] if focal_px is None else _as_focal(focal_px, what)
    R = _vector_ols(ref, sensor_directions(xy, f))
    return _solution_from_R(R, f, "vector_all_stars_ols")


@lru_cache(maxsize=32)
def _constrained_fit_solver(n):
    """casadi/Ipopt NLP: min sum |R p_i - c_i(f)|^2 s.t. R R^T = I (upper triangle), f > 0; n stars."""
    import casadi as ca

    R = ca.SX.sym("R", 3, 3)
    f = ca.SX.sym("f")
    P = ca.SX.sym("P", 3, n)           # reference directions as columns
    XY = ca.SX.sym("XY", 2, n)         # image coordinates [px]
    scale = ca.SX.sym("scale")         # f is optimised as f / scale (order 1)
    fs = f * scale
    cost = 0
    for i in range(n):
        c = ca.vertcat(XY[0, i], XY[1, i], fs)
        c = c / ca.norm_2(c)
        cost += ca.sumsqr(R @ P[:, i] - c)
    RRt = R @ R.T
    g = ca.vertcat(*[RRt[a, b] - (1.0 if a == b else 0.0) for a in range(3) for b in range(a, 3)])
    nlp = {"x": ca.vertcat(ca.vec(R), f), "p": ca.vertcat(ca.vec(P), ca.vec(XY), scale), "f": cost, "g": g}
    options = {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes", "tol": 1e-14,
                                              "max_iter": 200}}
    return ca.nlpsol("boresight_constrained_fit", "ipopt", nlp, options)


def solve_vector_constrained(ref_I, xy_px, focal_px=None, focal_bounds_px=None):
    """Constrained fit min |R Pc' - c'(f)|^2 s.t. R R^T = I over all n >= 3 stars (001 3.3.2 (二)).

    With focal_px given, this is the orthogonal Procrustes (Wahba) problem and its SVD closed form
    (R = U diag(1, 1, det) V^T of Cc' Pc'^T) is exact.  With f unknown, R and f are optimised together
    with casadi/Ipopt, started from the closed form (f from the cubic of 3.2.1 (二), R by SVD), f within
    focal_bounds_px (default: half to twice the starting f).  Milliseconds per solve: for offline and
    calibration use, not per frame.  InputError if Ipopt does not converge.
    """
    what = "solve_vector_constrained"
    ref = _as_unit_vectors(ref_I, 3, what)
    xy = _as_xy(xy_px, ref.shape[0], what)
    if focal_px is not None:
        f = _as_focal(focal_px, what)
        R = nearest_rotation(sensor_directions(xy, f).T @ ref)
        return _solution_from_R(R, f, "vector_constrained_procrustes")
    f0 = focal_from_angular_distances(ref, xy)[0]
    low, high = _as_bounds(focal_bounds_px, what) if focal_bounds_px is not None else (0.5 * f0, 2.0 * f0)
    f0 = min(max(f0, low), high)
    R0 = nearest_rotation(sensor_directions(xy, f0).T @ ref)
    solver = _constrained_fit_solver(ref.shape[0])
    x0 = np.concatenate([R0.T.ravel(), [1.0]])                 # casadi vec() is column-major
    params = np.concatenate([ref.ravel(), xy.ravel(), [f0]])   # vec(P) of 3 x n columns = ref rows
    bounds_x = np.full(10, np.inf)
    result = solver(x0=x0, p=params, lbx=np.concatenate([-bounds_x[:9], [low / f0]]),
                    ubx=np.concatenate([bounds_x[:9], [high / f0]]), lbg=0.0, ubg=0.0)
    if not solver.stats()["success"]:
        raise InputError(f"{what}: Ipopt did not converge ({solver.stats()['return_status']}).")
    x = np.asarray(result["x"]).ravel()
    R = nearest_rotation(x[:9].reshape(3, 3).T)
    return _solution_from_R(R, x[9] * f0, "vector_constrained_ipopt")
