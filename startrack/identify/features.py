"""Star-pattern features of a frame: angular distances and their error bounds (001 §4.3.1).

The per-pair error gate is the bound e_ij of 001 §4.3.1.  A centroid (X_i, Y_i) [px] on a pinhole of
focal length f [px] has the direction v_i = (X_i, Y_i, f) / |(X_i, Y_i, f)|, whose Jacobian columns are

    dv_i/dX_i = (e_x - v_i v_ix) / rho_i,   dv_i/dY_i = (e_y - v_i v_iy) / rho_i,   rho_i = f / v_iz.

Differentiating cos(beta_ij) = v_i^T v_j gives (001 §4.3.1)

    -sin(beta_ij) d beta_ij = v_j^T dv_i + v_i^T dv_j,

so, with every centroid coordinate wrong by at most delta [px],

    |d beta_ij| <= e_ij = delta (|v_j^T dv_i/dX_i| + |v_j^T dv_i/dY_i|
                                 + |v_i^T dv_j/dX_j| + |v_i^T dv_j/dY_j|) / sin(beta_ij).

001 bounds each |v_jm| by 1 (the sum of the absolute Jacobian entries); keeping the factor v_j^T, as
here, gives the tight bound of the same linearisation (001's is 2-3 times wider for the pairs of a
16 deg field).  For a Gaussian centroid error of standard deviation sigma per axis, delta = 3 sigma
makes e_ij at least a 3-sigma gate on beta_ij (the 1-norm bounds the 2-norm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from startrack.jit import njit


@njit
def pair_features(obs, focal_px, delta_px):  # pragma: no cover  (compiled)
    """(beta (n, n) [rad], e (n, n) [rad]) of every pair of the unit vectors ``obs`` (n, 3).

    beta_ij = arccos(v_i . v_j); e_ij the bound of 001 §4.3.1 (tightened, module text) for centroid
    errors up to ``delta_px`` [px] per axis on a pinhole of focal length ``focal_px`` [px].  The
    diagonal holds beta = 0, e = +inf.
    """
    n = obs.shape[0]
    beta = np.zeros((n, n))
    gate = np.full((n, n), np.inf)
    # t[i, j, 0..1] = v_j^T dv_i/dX_i, v_j^T dv_i/dY_i
    for i in range(n):
        scale = obs[i, 2] / focal_px
        for j in range(i + 1, n):
            c = obs[i, 0] * obs[j, 0] + obs[i, 1] * obs[j, 1] + obs[i, 2] * obs[j, 2]
            c = min(1.0, max(-1.0, c))
            s_ij = abs(obs[j, 0] - c * obs[i, 0]) + abs(obs[j, 1] - c * obs[i, 1])
            s_ji = abs(obs[i, 0] - c * obs[j, 0]) + abs(obs[i, 1] - c * obs[j, 1])
            sine = np.sqrt(max(1.0 - c * c, 0.0))
            b = np.arccos(c)
            e = np.inf
            if sine > 0.0:
                e = delta_px * (s_ij * scale + s_ji * obs[j, 2] / focal_px) / sine
            beta[i, j] = b
            beta[j, i] = b
            gate[i, j] = e
            gate[j, i] = e
    return beta, gate


@dataclass(frozen=True, eq=False)
class FrameFeatures:
    """A frame prepared for identification.

    ``obs_S`` (n, 3) centroid directions in the sensor frame, brightest first; ``index`` (n,) their
    positions in the caller's list; ``beta`` and ``gate`` (m, m) the angular distances and bounds
    e_ij [rad] of the first m (brightest) stars; ``verify_gate`` the verification match radius [rad].
    """

    obs_S: np.ndarray
    index: np.ndarray
    beta: np.ndarray
    gate: np.ndarray
    verify_gate: float

    @classmethod
    def build(cls, obs_S, index, focal_px: float, delta_px: float, verify_gate: float, n_pattern: int):
        """Features of ``obs_S`` (already brightest first) for at most ``n_pattern`` pattern stars."""
        beta, gate = pair_features(np.ascontiguousarray(obs_S[:n_pattern]), float(focal_px), float(delta_px))
        return cls(obs_S, index, beta, gate, verify_gate)

    def __len__(self):
        return int(self.obs_S.shape[0])
