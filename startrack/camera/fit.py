"""Least-squares fit of the attitude and the camera's intrinsics to matched stars (compiled).

Model (:mod:`startrack.camera.model`, docs/design.md): a catalog direction v_I is seen at
v_S = R_IS^T v_I with the ideal coordinates (x, y) of the camera's projection -- pinhole x = v_x / v_z,
y = v_y / v_z; fisheye (equidistant, Kannala & Brandt 2006) (x, y) = theta (v_x, v_y) / rho, rho =
hypot(v_x, v_y), theta = atan2(rho, v_z) -- r^2 = x^2 + y^2, d = 1 + k1 r^2 + k2 r^4 and

    u = cx + f x d,   v = cy + f y d.

Parameters: the attitude error dtheta (rotation vector in S, R_IS <- R_IS exp([dtheta x]), the
convention of the filter's error state) and the intrinsics p = (f, cx, cy, k1, k2), each free or held.
The Jacobian: dv_S/d dtheta = [v_S x]; pinhole dx/dv_S = (1/v_z, 0, -x/v_z), dy/dv_S = (0, 1/v_z, -y/v_z);
fisheye, with s = theta / rho, dtheta/dv_S = (v_x v_z / rho, v_y v_z / rho, -rho) / |v|^2,
dx/dv_S = s e_x + v_x (dtheta/dv_S - s (v_x, v_y, 0) / rho) / rho (and y alike);
du/dx = f (d + 2 x^2 (k1 + 2 k2 r^2)), du/dy = dv/dx = 2 f x y (k1 + 2 k2 r^2),
dv/dy = f (d + 2 y^2 (k1 + 2 k2 r^2)); du/df = x d, du/dcx = 1, du/dk1 = f x r^2, du/dk2 = f x r^4
(and likewise for v).

Gauss-Newton (Gauss-Markov weights 1/sigma_i^2 per star and axis) with Gaussian priors on the
intrinsics (maximum a posteriori: a free principal point of a narrow field is held near the image
centre by its prior instead of drifting along its near-degeneracy with the attitude; Gauss-Newton as in
Hartley & Zisserman §A6, docs/references.md); the normal matrix is scaled to unit diagonal before it is
solved (Cholesky: a singular one -- too few or degenerate stars -- is reported, not raised).
The covariance of the estimate is the inverse normal matrix (Hartley & Zisserman ch. 5) times
max(1, chi^2 / dof): the stated sigma_i are a lower bound of the real centroid errors of a real camera.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from startrack.camera.model import width_angle
from startrack.camera.projection_kernels import FISHEYE, INTRINSICS, project_one
from startrack.compiled.numba_setup import njit
from startrack.geometry.rotation_kernels import quat_from_rotation_vector, quat_to_matrix

#: Names of the fitted parameters, in the order of :func:`fit` 's covariance.
PARAMETERS = ("dtheta_x", "dtheta_y", "dtheta_z", "f", "cx", "cy", "k1", "k2")


@njit(_nrt=False)
def _ideal_jacobian(v, projection, J):  # pragma: no cover  (compiled)
    """(x, y) of the direction v (3,) in S, with J (2, 3) = d(x, y)/dv_S filled (module text)."""
    vx, vy, vz = v[0], v[1], v[2]
    rho = math.sqrt(vx * vx + vy * vy)
    if projection != FISHEYE or rho <= 1e-9 * abs(vz):  # the fisheye is the pinhole to first order on its axis
        x, y = vx / vz, vy / vz
        J[0, 0], J[0, 1], J[0, 2] = 1.0 / vz, 0.0, -x / vz
        J[1, 0], J[1, 1], J[1, 2] = 0.0, 1.0 / vz, -y / vz
        return x, y
    n2 = rho * rho + vz * vz
    theta = math.atan2(rho, vz)
    s = theta / rho
    d_theta = (vx * vz / (rho * n2), vy * vz / (rho * n2), -rho / n2)
    d_rho = (vx / rho, vy / rho, 0.0)
    for c in range(3):
        d_s = (d_theta[c] - s * d_rho[c]) / rho
        J[0, c] = vx * d_s
        J[1, c] = vy * d_s
    J[0, 0] += s
    J[1, 1] += s
    return s * vx, s * vy


@njit(_nrt=False)
def _jacobian_rows(v, camera_params, rows, J):  # pragma: no cover  (compiled)
    """rows (2, 8): d(u, v)/d(dtheta, f, cx, cy, k1, k2) at the direction v (3,) in S (module text), with
    d(x, y)/d dtheta = J [v x] (J (2, 3) scratch for d(x, y)/dv_S)."""
    f, k1, k2 = camera_params[0], camera_params[5], camera_params[6]
    x, y = _ideal_jacobian(v, camera_params[8], J)
    r2 = x * x + y * y
    d = 1.0 + k1 * r2 + k2 * r2 * r2
    g = 2.0 * (k1 + 2.0 * k2 * r2)
    du_dx, du_dy = f * (d + x * x * g), f * x * y * g
    dv_dx, dv_dy = du_dy, f * (d + y * y * g)
    # [v x] = ((0, -v_z, v_y), (v_z, 0, -v_x), (-v_y, v_x, 0))
    dx0, dx1, dx2 = J[0, 1] * v[2] - J[0, 2] * v[1], -J[0, 0] * v[2] + J[0, 2] * v[0], J[0, 0] * v[1] - J[0, 1] * v[0]
    dy0, dy1, dy2 = J[1, 1] * v[2] - J[1, 2] * v[1], -J[1, 0] * v[2] + J[1, 2] * v[0], J[1, 0] * v[1] - J[1, 1] * v[0]
    rows[0, 0], rows[1, 0] = du_dx * dx0 + du_dy * dy0, dv_dx * dx0 + dv_dy * dy0
    rows[0, 1], rows[1, 1] = du_dx * dx1 + du_dy * dy1, dv_dx * dx1 + dv_dy * dy1
    rows[0, 2], rows[1, 2] = du_dx * dx2 + du_dy * dy2, dv_dx * dx2 + dv_dy * dy2
    rows[0, 3], rows[1, 3] = x * d, y * d
    rows[0, 4], rows[1, 4] = 1.0, 0.0
    rows[0, 5], rows[1, 5] = 0.0, 1.0
    rows[0, 6], rows[1, 6] = f * x * r2, f * y * r2
    rows[0, 7], rows[1, 7] = f * x * r2 * r2, f * y * r2 * r2


@njit
def _normal_equations(uv, weight, ref_I, R_IS, camera_params, free, prior_mean, prior_sigma):  # pragma: no cover
    """(N (8, 8), b (8,), chi^2 of the data) of one Gauss-Newton step; held parameters get N_ii = 1, b_i = 0."""
    N = np.zeros((8, 8))
    b = np.zeros(8)
    rows = np.empty((2, 8))
    J = np.empty((2, 3))
    chi2 = 0.0
    v = np.empty(3)
    for i in range(uv.shape[0]):
        for c in range(3):
            v[c] = R_IS[0, c] * ref_I[i, 0] + R_IS[1, c] * ref_I[i, 1] + R_IS[2, c] * ref_I[i, 2]
        u_model, v_model = project_one(v[0], v[1], v[2], camera_params)
        res = (uv[i, 0] - u_model, uv[i, 1] - v_model)
        _jacobian_rows(v, camera_params, rows, J)
        for a in range(2):
            chi2 += weight[i] * res[a] * res[a]
            for p in range(8):
                wr = weight[i] * rows[a, p]
                b[p] += wr * res[a]
                for q in range(p, 8):
                    N[p, q] += wr * rows[a, q]
    for p in range(8):
        for q in range(p):
            N[p, q] = N[q, p]
    for p in range(3, 8):
        k = INTRINSICS[p - 3]
        if free[p - 3] and prior_sigma[p - 3] < np.inf:
            N[p, p] += 1.0 / prior_sigma[p - 3] ** 2
            b[p] += (prior_mean[p - 3] - camera_params[k]) / prior_sigma[p - 3] ** 2
    for p in range(3, 8):
        if not free[p - 3]:
            N[p, :] = 0.0
            N[:, p] = 0.0
            N[p, p] = 1.0
            b[p] = 0.0
    return N, b, chi2


@njit
def _cholesky_inverse(A):  # pragma: no cover  (compiled)
    """(ok, A^-1) of a symmetric positive-definite matrix by Cholesky factorisation; ok is False when a
    pivot is not positive (singular: too few or degenerate stars)."""
    n = A.shape[0]
    L = np.zeros((n, n))
    for j in range(n):
        d = A[j, j] - np.sum(L[j, :j] ** 2)
        if not d > 1e-12 * max(A[j, j], 1e-300):
            return False, np.zeros((n, n))
        L[j, j] = np.sqrt(d)
        for i in range(j + 1, n):
            L[i, j] = (A[i, j] - np.sum(L[i, :j] * L[j, :j])) / L[j, j]
    inverse_L = np.zeros((n, n))
    for j in range(n):  # forward substitution for the columns of L^-1
        inverse_L[j, j] = 1.0 / L[j, j]
        for i in range(j + 1, n):
            inverse_L[i, j] = -np.sum(L[i, j:i] * inverse_L[j:i, j]) / L[i, i]
    return True, inverse_L.T @ inverse_L


@njit
def _solve_scaled(N, b):  # pragma: no cover  (compiled)
    """(ok, N^-1 b, N^-1) with N scaled to unit diagonal first (conditioning of pixels against k's)."""
    diagonal = np.diag(N)
    if not np.all(diagonal > 0.0):
        return False, np.zeros(b.size), np.zeros(N.shape)
    scale = 1.0 / np.sqrt(diagonal)
    ok, inverse = _cholesky_inverse(N * np.outer(scale, scale))
    inverse = inverse * np.outer(scale, scale)
    return ok, inverse @ b, inverse


#: A Gauss-Newton fit has converged when no step exceeds this fraction of its parameter's sigma.
CONVERGED = 1e-3


@njit
def fit(uv, sigma_px, ref_I, R_IS, camera_params, free, prior_mean, prior_sigma, iterations=8):  # pragma: no cover
    """Gauss-Newton fit of the attitude and the free intrinsics (module text).

    uv (m, 2) [px] observed; sigma_px (m,) per-axis noise [px]; ref_I (m, 3) catalog directions; R_IS
    and camera_params (:func:`startrack.camera.projection_kernels.camera_array`) the start; free (5,) bool for (f, cx, cy,
    k1, k2); prior_mean, prior_sigma (5,) (inf: no prior).  Returns (ok, R_IS, camera_params, covariance
    (8, 8) of (dtheta, f, cx, cy, k1, k2) [rad, px, -], chi^2 / dof) -- zero rows for held parameters;
    ok is False when the stars do not determine the parameters (singular normal matrix).
    """
    R = R_IS.copy()
    params = camera_params.copy()
    weight = 1.0 / sigma_px**2
    n_free = 3 + int(np.sum(free))
    dof = max(2 * uv.shape[0] - n_free, 1)
    for _ in range(iterations):
        N, b, chi2 = _normal_equations(uv, weight, ref_I, R, params, free, prior_mean, prior_sigma)
        ok, step, inverse = _solve_scaled(N, b)
        if not ok:
            return False, R_IS, camera_params, np.zeros((8, 8)), 0.0
        R = R @ quat_to_matrix(quat_from_rotation_vector(step[:3]))
        for p in range(5):
            params[INTRINSICS[p]] += step[3 + p]
        if np.max(np.abs(step) / np.sqrt(np.diag(inverse))) < CONVERGED:
            break
    N, b, chi2 = _normal_equations(uv, weight, ref_I, R, params, free, prior_mean, prior_sigma)
    ok, _, inverse = _solve_scaled(N, b)
    for p in range(3, 8):
        if not free[p - 3]:
            inverse[p, :] = 0.0
            inverse[:, p] = 0.0
    reduced = chi2 / dof
    return ok, R, params, inverse * max(1.0, reduced), reduced


@dataclass(frozen=True, eq=False)
class CameraCalibration:
    """The camera a frame's stars calibrated: ``camera`` (:class:`startrack.camera.model.Camera`) and the
    ``covariance`` (8, 8) of (dtheta, f, cx, cy, k1, k2) from :func:`fit`, with the fit's
    ``reduced_chi2``, ``rms_px`` (per-axis residual RMS), ``matched`` and ``predicted`` stars and
    ``mag_limit`` (the faintest predicted star, V mag)."""

    camera: object
    covariance: np.ndarray
    reduced_chi2: float
    rms_px: float
    matched: int
    predicted: int
    mag_limit: float

    @property
    def sigma(self) -> dict:
        """1-sigma of f [px], cx, cy [px], k1, k2 and of the angle the width subtends
        (:attr:`startrack.camera.model.Camera.angular_width`) [deg], the latter propagated through the covariance
        of (f, cx, cy, k1, k2) with its numerical Jacobian."""
        covariance = self.covariance[3:, 3:]
        spread = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
        out = dict(zip(("focal_px", "cx", "cy", "k1", "k2"), (float(s) for s in spread)))
        camera = self.camera
        base = np.array([camera.focal_px, camera.cx, camera.cy, camera.k1, camera.k2])
        step = 1e-3 * spread
        moved = base + np.diag(step)
        widths = width_angle(*moved.T, camera.width, camera.height, camera.projection)
        gradient = np.where(step > 0.0, (widths - camera.angular_width) / np.where(step > 0.0, step, 1.0), 0.0)
        out["fov_deg"] = math.degrees(math.sqrt(max(gradient @ covariance @ gradient, 0.0)))
        return out

    def to_dict(self) -> dict:
        """JSON-ready 1-sigma and fit statistics (with the camera's geometry, the ``camera`` entry of
        ``startrack solve --json``)."""
        return {"sigma": self.sigma, "rms_px": self.rms_px, "reduced_chi2": self.reduced_chi2,
                "matched": self.matched, "predicted": self.predicted, "mag_limit": self.mag_limit}
