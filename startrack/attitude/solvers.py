"""Attitude from identified stars: TRIAD, 004's three-star optimal, 003's multi-vector, Wahba (SVD, q-method, QUEST).

Every solver is a strategy object with the same call::

    solution = solver.solve(ref_I, obs_S, sigma)

* ``ref_I`` (N, 3): catalog unit vectors in the inertial frame I;
* ``obs_S`` (N, 3): the measured unit vectors of the same stars in the star-sensor frame S;
* ``sigma``: per-axis angular noise of each measured direction [rad], scalar or (N,);
  the measurement model is ``obs_S = R_IS^T ref_I + dv`` with ``dv`` perpendicular to the direction
  and covariance ``sigma^2 (I - b b^T)`` (Shuster's QUEST measurement model).

Convention: ``q_IS`` (scalar-last, scipy's Hamilton convention) rotates S vectors into I, so
``obs_S = R_IS^T ref_I``; the documents' attitude matrix A (I -> S) is ``R_IS^T``.  The attitude
error ``dtheta`` is in S axes: ``R_true = R_est exp([dtheta x])``, i.e. ``q_true = q_est (x) dq``, the
filter's multiplicative error convention (docs/design.md).  Components x, y of ``dtheta`` are the
cross-boresight errors, z the roll about the boresight.

Each solution carries the first-order covariance of *that* estimator:

* Wahba solvers (SVD, q-method, QUEST) are efficient: ``P = [sum sigma_i^-2 (I - b_i b_i^T)]^-1``,
  the Cramer-Rao bound (:func:`cramer_rao_covariance`).
* TRIAD, 004's three-star algorithm and 003's multi-vector algorithm are not; their ``P`` is their
  own linearised error propagation (derived in each class), which is >= the Cramer-Rao bound.
  Using the bound for them would understate their error (TRIAD's cross-boresight variance is twice
  the bound for two equally good stars).

``solution.residuals`` are the angles [rad] between each measured direction and the estimated
attitude's prediction ``R_IS^T ref_I``.
"""

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError
from startrack.geometry.rotation import from_matrix, nearest_rotation, skew, to_matrix

_UNIT_NORM_TOLERANCE = 1e-6


@dataclass(frozen=True)
class AttitudeSolution:
    """Result of an attitude solve.

    q_IS: (4,) scalar-last quaternion rotating S vectors into I (w >= 0).
    P: (3, 3) covariance [rad^2] of the attitude error in S axes (x, y cross-boresight, z roll).
    residuals: (N,) angle [rad] between each measured direction and its prediction.
    method: name of the solver.
    """

    q_IS: np.ndarray
    P: np.ndarray
    residuals: np.ndarray
    method: str

    @property
    def R_IS(self):
        """(3, 3) rotation matrix taking S vectors into I."""
        return to_matrix(self.q_IS)


def cramer_rao_covariance(obs_S, sigma):
    """Cramer-Rao covariance [rad^2] in S axes: P = [sum_i sigma_i^-2 (I - b_i b_i^T)]^-1.

    obs_S (N, 3) unit vectors in S, sigma scalar or (N,) [rad].  Requires two non-parallel vectors.
    """
    obs_S = np.asarray(obs_S, dtype=float)
    weights = np.broadcast_to(np.asarray(sigma, dtype=float) ** -2, obs_S.shape[:1])
    return _inverse_fisher((obs_S * weights[:, None]).T @ obs_S, float(weights.sum()))


def _inverse_fisher(weighted_scatter, weight_sum):
    """[w I - C]^-1 for the symmetric 3x3 C = sum w_i b_i b_i^T, by the adjugate (scalar arithmetic)."""
    (c11, c12, c13), (_, c22, c23), (_, _, c33) = weighted_scatter.tolist()
    f11, f22, f33 = weight_sum - c11, weight_sum - c22, weight_sum - c33
    a11, a22, a33 = f22 * f33 - c23 * c23, f11 * f33 - c13 * c13, f11 * f22 - c12 * c12
    a12, a13, a23 = c12 * f33 + c13 * c23, c12 * c23 + c13 * f22, f11 * c23 + c12 * c13
    det = f11 * a11 - c12 * a12 - c13 * a13
    if not det > 0.0:
        raise InputError("the observed directions are all parallel; the attitude is not observable.")
    return np.array([[a11, a12, a13], [a12, a22, a23], [a13, a23, a33]]) / det


def _propagated_covariance(jacobians, obs, sigma2):
    """P = sum_i J_i sigma_i^2 (I - b_i b_i^T) J_i^T for linear error maps dtheta = sum_i J_i db_i."""
    tangent = np.eye(3) - obs[:, :, None] * obs[:, None, :]
    return np.einsum("nij,njk,nlk,n->il", jacobians, tangent, jacobians, sigma2)


def _validated(ref_I, obs_S, sigma, min_stars, name):
    """Arrays (ref, obs, sigma (N,)) after checking shapes, finiteness, unit norms and sigma > 0."""
    ref = np.asarray(ref_I, dtype=float)
    obs = np.asarray(obs_S, dtype=float)
    if ref.ndim != 2 or ref.shape[1] != 3 or obs.shape != ref.shape:
        raise InputError(f"{name}: ref_I and obs_S must both have shape (N, 3); got {ref.shape} and {obs.shape}.")
    n = ref.shape[0]
    if n < min_stars:
        raise InputError(f"{name}: needs at least {min_stars} stars, got {n}.")
    for label, vectors in (("ref_I", ref), ("obs_S", obs)):
        norm_error = np.abs(np.einsum("ij,ij->i", vectors, vectors) - 1.0).max()
        if not norm_error <= 2.0 * _UNIT_NORM_TOLERANCE:                # also catches NaN and inf
            raise InputError(f"{name}: {label} must hold finite unit vectors; a squared norm is off by "
                             f"{norm_error:.3g}.")
    sig = np.asarray(sigma, dtype=float)
    if sig.ndim == 0:
        if not (math.isfinite(sig) and sig > 0.0):
            raise InputError(f"{name}: sigma must be finite and > 0 rad; got {float(sig)}.")
        return ref, obs, np.full(n, float(sig))
    if sig.shape != (n,):
        raise InputError(f"{name}: sigma must be a scalar or have shape ({n},); got shape {sig.shape}.")
    if not (np.isfinite(sig).all() and (sig > 0.0).all()):
        raise InputError(f"{name}: sigma must be finite and > 0 rad; got {sig}.")
    return ref, obs, sig


def _residuals(ref, obs, R_IS):
    """Angle [rad] between obs_i and R_IS^T ref_i: 2 asin(|chord| / 2), accurate near 0."""
    chord = obs - ref @ R_IS
    return 2.0 * np.arcsin(np.minimum(0.5 * np.sqrt(np.einsum("ij,ij->i", chord, chord)), 1.0))


class AttitudeSolver(ABC):
    """Common validating front end; subclasses implement ``_solve`` -> (q_IS, P)."""

    name: str            # registry key and AttitudeSolution.method
    min_stars: int       # fewest stars the method accepts

    def solve(self, ref_I, obs_S, sigma=1.0):
        """Attitude of S in I from N >= ``min_stars`` star pairs; returns an :class:`AttitudeSolution`.

        ref_I, obs_S (N, 3) unit vectors [-]; sigma [rad] scalar or (N,).  Bad input raises
        :class:`InputError`; a degenerate geometry (all stars collinear with the origin) too.
        """
        ref, obs, sig = _validated(ref_I, obs_S, sigma, self.min_stars, self.name)
        q, P = self._solve(ref, obs, sig)
        return AttitudeSolution(q_IS=q, P=P, residuals=_residuals(ref, obs, to_matrix(q)),
                                method=self.name)

    @abstractmethod
    def _solve(self, ref, obs, sigma):
        """(q_IS (4,), P (3, 3)) from validated ref (N, 3), obs (N, 3), sigma (N,) [rad]."""


class _LinearisedSolver(AttitudeSolver):
    """An inefficient estimator: its covariance is its own first-order error propagation."""

    def _solve(self, ref, obs, sigma):
        q = self._estimate(ref, obs, sigma)
        return q, self._covariance(ref, obs, sigma, to_matrix(q))

    @abstractmethod
    def _estimate(self, ref, obs, sigma):
        """Unit quaternion q_IS (4,)."""

    @abstractmethod
    def _covariance(self, ref, obs, sigma, R_IS):
        """Covariance [rad^2] of the attitude error in S axes."""


def _two_best(sigma):
    """Indices of the two most accurate stars (smallest sigma; ties keep input order)."""
    order = np.argsort(sigma, kind="stable")
    return int(order[0]), int(order[1])


def _cross(a, b):
    """Cross product of two 3-vectors (scalar arithmetic; np.cross is slow on single vectors)."""
    a1, a2, a3 = a.tolist()
    b1, b2, b3 = b.tolist()
    return np.array([a2 * b3 - a3 * b2, a3 * b1 - a1 * b3, a1 * b2 - a2 * b1])


def _unit_cross(a, b, name):
    """(a x b / |a x b|, |a x b|); InputError for parallel vectors."""
    c = _cross(a, b)
    norm = math.sqrt(c @ c)
    if norm < 1e-12:
        raise InputError(f"{name}: the two anchor stars are parallel; their cross product vanishes.")
    return c / norm, norm


class Triad(_LinearisedSolver):
    """TRIAD (Black 1964; Shuster & Oh 1981) on the two most accurate stars (the first two for equal sigma).

    Triads t1 = b1, t2 = b1 x b2 / |b1 x b2|, t3 = t1 x t2 in S and the same from r1, r2 in I;
    R_IS = [r-triad][b-triad]^T.  Covariance (Shuster & Oh 1981, anchor b1):
    P = sigma1^2 I + |b1 x b2|^-2 [(sigma2^2 - sigma1^2) b1 b1^T + sigma1^2 (b1.b2)(b1 b2^T + b2 b1^T)].
    Other stars only contribute to the residuals.
    """

    name = "triad"
    min_stars = 2

    def _estimate(self, ref, obs, sigma):
        i, j = _two_best(sigma)
        return from_matrix(self._triad(ref[i], ref[j]) @ self._triad(obs[i], obs[j]).T)

    def _triad(self, v1, v2):
        t2, _ = _unit_cross(v1, v2, self.name)
        return np.column_stack([v1, t2, _cross(v1, t2)])

    def _covariance(self, ref, obs, sigma, R_IS):
        i, j = _two_best(sigma)
        b1, b2 = obs[i], obs[j]
        s1, s2 = sigma[i] ** 2, sigma[j] ** 2
        _, sin_angle = _unit_cross(b1, b2, self.name)
        outer = np.outer(b1, b2)
        return s1 * np.eye(3) + ((s2 - s1) * np.outer(b1, b1)
                                 + s1 * (b1 @ b2) * (outer + outer.T)) / sin_angle ** 2


class ThreeStarOptimal(_LinearisedSolver):
    """Three-star optimal attitude of 004 eq. 8-12 (generalised to N >= 3 stars).

    U_ij = U_i x U_j / |.| (eq. 8) and V_ij likewise (eq. 9) from the two most accurate stars
    (004: the two brightest); U = [U_1 .. U_N U_ij], V = [V_1 .. V_N V_ij] (eq. 10);
    M = U V^T (V V^T)^-1 (eq. 11, maps S -> I); M_s* = 1/2 (3 I - M^T M) M^T (eq. 12, one
    orthogonalising step, I -> S).  The quaternion is Shepperd's of M_s*^T, normalised.  Unweighted
    as in 004 (sigma only picks the anchor pair).

    Covariance: with g_k = (V V^T)^-1 V_k, dtheta = 1/2 sum_k dV_k x g_k (first order of eq. 11-12),
    and dV_ij = (I - V_ij V_ij^T)/|V_i x V_j| (dV_i x V_j + V_i x dV_j).
    """

    name = "three_star"
    min_stars = 3

    def _estimate(self, ref, obs, sigma):
        i, j = _two_best(sigma)
        u_ij, _ = _unit_cross(ref[i], ref[j], self.name)            # eq. 8
        v_ij, _ = _unit_cross(obs[i], obs[j], self.name)            # eq. 9
        U = np.vstack([ref, u_ij]).T                                # eq. 10
        V = np.vstack([obs, v_ij]).T
        M = _solve_spd(V @ V.T, V @ U.T, self.name).T               # eq. 11: U V^T (V V^T)^-1
        M_s = 0.5 * (3.0 * np.eye(3) - M.T @ M) @ M.T               # eq. 12
        return from_matrix(M_s.T)

    def _covariance(self, ref, obs, sigma, R_IS):
        i, j = _two_best(sigma)
        v_ij, cross_norm = _unit_cross(obs[i], obs[j], self.name)
        V = np.vstack([obs, v_ij])
        G = np.linalg.solve(V.T @ V, V.T).T                         # rows g_k = (V V^T)^-1 V_k
        J = -0.5 * skew(G[:-1])                                     # dV_k x g_k = -[g_k x] dV_k
        D = (np.eye(3) - np.outer(v_ij, v_ij)) / cross_norm
        G_ij = -0.5 * skew(G[-1]) @ D
        J[i] += G_ij @ -skew(obs[j])
        J[j] += G_ij @ skew(obs[i])
        return _propagated_covariance(J, obs, sigma ** 2)


class MultiVector(_LinearisedSolver):
    """Multi-reference-vector attitude of 003 eq. 1: B* = B (B^T B)^-1/2 with B the least-squares B.

    With R = [S_1 .. S_N]^T (references) and G = [P_1 .. P_N]^T (observations), the observation
    equation R B = G has the least-squares solution B = (R^T W R)^-1 R^T W G (003: W = I; here
    W = diag(sigma^-2), identical for equal sigma); B* = B (B^T B)^-1/2 = U V^T (SVD B = U S V^T)
    is its orthogonal polar factor and R_IS = B* (003's A = B*^-1 = B*^T, I -> S); should the polar
    factor be a reflection (only for absurd noise) the nearest rotation is used.

    Covariance: c_i = sigma_i^-2 R_IS^T (R^T W R)^-1 S_i, dtheta = 1/2 sum_i dP_i x c_i.
    """

    name = "multi_vector"
    min_stars = 3

    def _estimate(self, ref, obs, sigma):
        root_w = (1.0 / sigma)[:, None]
        B, _, _, singular = np.linalg.lstsq(ref * root_w, obs * root_w, rcond=None)   # SVD, not normal eq.
        if singular[-1] <= 1e-12 * singular[0]:
            raise InputError(f"{self.name}: the reference vectors are coplanar with the origin; R^T R is "
                             "singular (use a Wahba solver).")
        return from_matrix(nearest_rotation(B))                      # eq. 1: the polar factor U V^T

    def _covariance(self, ref, obs, sigma, R_IS):
        w = sigma ** -2
        C = R_IS.T @ np.linalg.inv(ref.T @ (ref * w[:, None]))
        c = (ref @ C.T) * w[:, None]
        return _propagated_covariance(-0.5 * skew(c), obs, sigma ** 2)


def _solve_spd(A, B, name):
    """A^-1 B for a 3x3 normal matrix A, raising InputError when the star geometry is degenerate."""
    eigenvalues = np.linalg.eigvalsh(A)
    if eigenvalues[0] <= 1e-12 * eigenvalues[-1]:
        raise InputError(f"{name}: the observed star directions are degenerate; the normal matrix is singular.")
    return np.linalg.solve(A, B)


class _WahbaSolver(AttitudeSolver):
    """Wahba's problem: min sum a_i |b_i - A r_i|^2 (A = R_IS^T: I -> S), a_i = sigma_i^-2 / sum sigma^-2.

    The attitude profile B = sum a_i b_i r_i^T and the Cramer-Rao covariance share one weighting:
    P = [sum_i sigma_i^-2 (I - b_i b_i^T)]^-1 = [I - sum a_i b_i b_i^T]^-1 / sum sigma^-2.
    """

    def _solve(self, ref, obs, sigma):
        w = sigma ** -2
        w_sum = float(w.sum())
        weighted = obs * (w / w_sum)[:, None]
        return self._from_profile(weighted.T @ ref), _inverse_fisher(weighted.T @ obs, 1.0) / w_sum

    @abstractmethod
    def _from_profile(self, B):
        """Unit quaternion q_IS (4,) maximising tr(A B^T) for the attitude profile B (3, 3)."""


class SvdWahba(_WahbaSolver):
    """Wahba's problem by singular value decomposition (Markley 1988).

    B = sum a_i b_i r_i^T = U S V^T; A = U diag(1, 1, det U det V) V^T minimises
    sum a_i |b_i - A r_i|^2 (A: I -> S); R_IS = A^T.  Efficient: P is the Cramer-Rao bound.
    """

    name = "svd"
    min_stars = 2

    def _from_profile(self, B):
        return from_matrix(nearest_rotation(B.T))


def _davenport_parts(B):
    """S = B + B^T, z = (B23 - B32, B31 - B13, B12 - B21), sigma = tr B of Davenport's K."""
    z = np.array([B[1, 2] - B[2, 1], B[2, 0] - B[0, 2], B[0, 1] - B[1, 0]])
    return B + B.T, z, np.trace(B)


class QMethod(_WahbaSolver):
    """Davenport's q-method: q_IS is the eigenvector of K = [[S - sigma I, z], [z^T, sigma]] for its
    largest eigenvalue (Shuster's scalar-last q of A = R_IS^T equals scipy's q_IS).  P = Cramer-Rao."""

    name = "q_method"
    min_stars = 2

    def _from_profile(self, B):
        S, z, trace = _davenport_parts(B)
        K = np.empty((4, 4))
        K[:3, :3] = S - trace * np.eye(3)
        K[:3, 3] = K[3, :3] = z
        K[3, 3] = trace
        q = np.linalg.eigh(K)[1][:, 3]
        return q if q[3] >= 0.0 else -q


class Quest(_WahbaSolver):
    """QUEST (Shuster & Oh 1981) with the method of sequential rotations, in scalar arithmetic.

    The largest eigenvalue of K solves lambda^4 - (a + b) lambda^2 - c lambda + (a b + c sigma - d) = 0
    with a = sigma^2 - kappa, b = sigma^2 + z.z, c = det S + z.S z, d = z.S^2 z, kappa = tr adj S;
    Newton's method from lambda = sum a_i = 1.  q_IS is the null vector of H = lambda I - K, i.e. any
    non-zero column of adj H = (product of the other eigen-gaps) q q^T; QUEST's x = (alpha I + beta S
    + S^2) z, gamma = det((lambda + sigma) I - S) is its fourth column.  The diagonal of adj H is
    proportional to (q_x^2, q_y^2, q_z^2, q_w^2); when q_w^2 is not the largest (rotation near 180 deg,
    gamma -> 0) the references are turned by 180 deg about the axis k of the largest component
    (B -> B R_k), solved again, and turned back: q_IS = (e_k, 0) (x) q'_IS.  P = Cramer-Rao bound.
    """

    name = "quest"
    min_stars = 2
    max_newton_iterations = 20

    def _from_profile(self, B):
        q, k = self._quest(B.tolist())
        if q is not None:
            return np.array(q)
        flipped = -B
        flipped[:, k] = B[:, k]                                      # B R_k: references turned about axis k
        (x, y, z, w), _ = self._quest(flipped.tolist(), rotate=False)
        v = (x, y, z)
        # (e_k, 0) (x) q': vector w e_k + e_k x v, scalar -v_k
        e_cross_v = ((0.0, -z, y), (z, 0.0, -x), (-y, x, 0.0))[k]
        q = np.array([w * (i == k) + e_cross_v[i] for i in range(3)] + [-v[k]])
        return q if q[3] >= 0.0 else -q

    def _quest(self, B, rotate=True):
        """(q, None) from the attitude profile B (nested lists), or (None, k) if axis k must be turned."""
        (b11, b12, b13), (b21, b22, b23), (b31, b32, b33) = B
        s11, s22, s33 = 2.0 * b11, 2.0 * b22, 2.0 * b33
        s12, s13, s23 = b12 + b21, b13 + b31, b23 + b32
        z1, z2, z3 = b23 - b32, b31 - b13, b12 - b21
        sig = b11 + b22 + b33
        kappa = s22 * s33 - s23 * s23 + s11 * s33 - s13 * s13 + s11 * s22 - s12 * s12
        det_s = s11 * (s22 * s33 - s23 * s23) - s12 * (s12 * s33 - s23 * s13) + s13 * (s12 * s23 - s22 * s13)
        sz1 = s11 * z1 + s12 * z2 + s13 * z3
        sz2 = s12 * z1 + s22 * z2 + s23 * z3
        sz3 = s13 * z1 + s23 * z2 + s33 * z3
        a = sig * sig - kappa
        b = sig * sig + z1 * z1 + z2 * z2 + z3 * z3
        c = det_s + z1 * sz1 + z2 * sz2 + z3 * sz3
        d = sz1 * sz1 + sz2 * sz2 + sz3 * sz3
        constant = a * b + c * sig - d
        lam = 1.0
        for _ in range(self.max_newton_iterations):
            lam2 = lam * lam
            step = (lam2 * lam2 - (a + b) * lam2 - c * lam + constant) / (4.0 * lam2 * lam - 2.0 * (a + b) * lam - c)
            lam -= step
            if abs(step) < 1e-15:
                break
        alpha = lam * lam - sig * sig + kappa
        beta = lam - sig
        gamma = (lam + sig) * alpha - det_s                           # adj(H)_ww = det((lam + sig) I - S)
        if rotate:
            e = lam - sig
            t11, t22, t33 = lam + sig - s11, lam + sig - s22, lam + sig - s33
            cofactors = (_minor(t22, s23, t33, z2, z3, e), _minor(t11, s13, t33, z1, z3, e),
                         _minor(t11, s12, t22, z1, z2, e))
            k = max(range(3), key=cofactors.__getitem__)
            if cofactors[k] > gamma:
                return None, k
        # x = alpha z + beta S z + S (S z)
        x1 = alpha * z1 + beta * sz1 + s11 * sz1 + s12 * sz2 + s13 * sz3
        x2 = alpha * z2 + beta * sz2 + s12 * sz1 + s22 * sz2 + s23 * sz3
        x3 = alpha * z3 + beta * sz3 + s13 * sz1 + s23 * sz2 + s33 * sz3
        norm = math.sqrt(x1 * x1 + x2 * x2 + x3 * x3 + gamma * gamma)
        if gamma < 0.0:
            norm = -norm
        return (x1 / norm, x2 / norm, x3 / norm, gamma / norm), None


def _minor(t_a, s_b, t_c, z_p, z_r, e):
    """Principal 3x3 minor det [[t_a, -s_b, -z_p], [-s_b, t_c, -z_r], [-z_p, -z_r, e]] of lambda I - K."""
    return e * (t_a * t_c - s_b * s_b) - t_a * z_r * z_r - t_c * z_p * z_p - 2.0 * s_b * z_p * z_r


SOLVERS = {solver.name: solver for solver in (Triad(), ThreeStarOptimal(), MultiVector(),
                                              SvdWahba(), QMethod(), Quest())}


def get_solver(name):
    """The solver registered under ``name`` (one of ``SOLVERS``); unknown names raise InputError."""
    try:
        return SOLVERS[name]
    except KeyError:
        raise InputError(f"unknown attitude solver {name!r}; choose one of {', '.join(SOLVERS)}.") from None
