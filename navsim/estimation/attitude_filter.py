"""Multiplicative error-state Kalman filter (MEKF) for attitude and gyro bias.

Nominal state: attitude q_IB (scalar-last), gyro bias b [rad/s], optionally gyro scale-factor
errors s [-] and the star-sensor mounting q_BS. Error state x (zero between updates):

    x = [δθ (3), δb (3), δs (3) if scale factors, δm (3) if misalignment]

with q_true = q ⊗ δq(δθ) (δθ in body axes), δb = b_true − b, δs = s_true − s, and
q_BS,true = q_BS ⊗ δq(δm) (δm in sensor axes), as DESIGN.md fixes.

Propagation at the gyro rate: q by RK4 (eq. 9 of 000) with ω = (I − diag s)(ω̃ − b) held over
the interval; P ← Φ P Φᵀ + Q with the closed-form Φ and Farrenkopf's discrete Q
(:func:`navsim.estimation.kernels.transition`, :func:`navsim.estimation.kernels.process_noise`). Updates: an attitude
fix (3-dim) or one 2-dim tangent-plane residual per identified star; each is gated by its
chi-square NIS against the prior, the accepted ones update together in Joseph form, and the
error estimate is reset into the nominal state.

The linear algebra is compiled (:mod:`navsim.estimation.kernels`); it is tested equal to filterpy's
``KalmanFilter.predict``/``update`` (Joseph form), which is the reference engine.
"""

from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from navsim.estimation import kernels


@dataclass(frozen=True)
class UpdateResult:
    """Outcome of one measurement update: innovations z (one row per measurement), NIS per
    measurement against the prior, and the accepted mask."""

    z: np.ndarray
    nis: np.ndarray
    accepted: np.ndarray

    @property
    def n_accepted(self):
        return int(np.count_nonzero(self.accepted))

    @property
    def n_rejected(self):
        return self.accepted.size - self.n_accepted


class AttitudeFilter:
    """MEKF with textbook names: error state x, covariance P; Φ, Q, H, R, K inside each step.

    Parameters: ``q`` (q_IB estimate), ``b`` (bias estimate, rad/s), ``P`` (initial covariance,
    n x n), ``arw``/``rrw`` (gyro noise the filter assumes, SI), ``q_BS`` (nominal sensor mounting,
    rotating S vectors into B; identity by default), ``estimate_scale_factor``/``estimate_misalignment`` (extra states; their initial σ
    are in P), ``scale_factor_rw`` (σ of a scale-factor random walk, 1/√s),
    ``process_noise_scale`` (multiplies Q, for tuning) and ``gate_probability`` (chi-square gate).
    """

    def __init__(
        self,
        q,
        b,
        P,
        arw,
        rrw,
        q_BS=None,
        estimate_scale_factor=False,
        estimate_misalignment=False,
        scale_factor_rw=0.0,
        process_noise_scale=1.0,
        gate_probability=0.9999,
    ):
        self.n = 6 + 3 * int(estimate_scale_factor) + 3 * int(estimate_misalignment)
        P = np.array(P, dtype=float)
        if P.shape != (self.n, self.n):
            raise ValueError(f"P must be {self.n}x{self.n} for the chosen states, got {P.shape}")
        q = np.asarray(q, dtype=float)
        self.q = q / np.linalg.norm(q)
        self.b = np.array(b, dtype=float)
        self.s = np.zeros(3)
        self.P = P
        self.q_BS = np.array([0.0, 0.0, 0.0, 1.0] if q_BS is None else q_BS, dtype=float)
        self.R_BS = kernels.quat_to_matrix(self.q_BS)
        self.arw = float(arw)
        self.rrw = float(rrw)
        self.scale_factor_rw = float(scale_factor_rw)
        self.process_noise_scale = float(process_noise_scale)
        self.gate = {dof: float(chi2.ppf(gate_probability, dof)) for dof in (2, 3)}
        self.sf_start = 6 if estimate_scale_factor else -1
        self.mis_start = self.n - 3 if estimate_misalignment else -1

    def predict(self, omega_measured, dt):
        """Propagate q (RK4) and P (Φ P Φᵀ + Q) over one gyro sample (3,) or several
        consecutive samples (m, 3), each held for dt [s] (:func:`navsim.estimation.kernels.predict`)."""
        if np.ndim(omega_measured) != 2:
            omega_measured = np.atleast_2d(np.asarray(omega_measured, dtype=float))
        self.q, self.P = kernels.predict(
            self.q, self.P, self.b, self.s, omega_measured, dt,
            self.arw, self.rrw, self.scale_factor_rw, self.process_noise_scale, self.sf_start,
        )

    def update_attitude(self, q_IS, R_S):
        """Update with a star-sensor attitude fix q_IS and its 3x3 covariance R_S in sensor axes
        (:func:`navsim.estimation.kernels.attitude_update`: z = δθ(q, q_IS ⊗ q_BS⁻¹) in body axes,
        H = [I, 0, (0), (R_BS)], R = R_BS R_S R_BSᵀ), gated at 3 dof."""
        self.q, self.b, self.s, q_BS, self.P, z, nis, accepted = kernels.attitude_update(
            self.q, self.b, self.s, self.q_BS, self.P, np.asarray(q_IS, dtype=float), R_S,
            self.gate[3], self.sf_start, self.mis_start,
        )
        self._set_mounting(q_BS)
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]))

    def update_stars(self, ref_I, obs_S, sigma):
        """Update with identified stars: catalog unit vectors ref_I (N, 3) in I, measured unit
        vectors obs_S (N, 3) in S, direction σ (N,) or scalar [rad].

        Each star gives z_i = T_i (s_i − ŝ_i) with T_i (2x3) spanning the plane ⟂ ŝ_i,
        H_i = T_i [R_SB [b̂_i×], 0, (0), ([ŝ_i×])], R_i = σ_i² I₂ (:func:`kernels.star_residuals`).
        Stars whose NIS against the prior exceeds the 2-dof gate are rejected; the rest update
        together (:func:`kernels.stars_update`).
        """
        ref_I = np.ascontiguousarray(ref_I, dtype=float)
        obs_S = np.ascontiguousarray(obs_S, dtype=float)
        variance = np.broadcast_to(np.asarray(sigma, dtype=float) ** 2, (ref_I.shape[0],)).copy()
        self.q, self.b, self.s, q_BS, self.P, z, nis, accepted = kernels.stars_update(
            self.q, self.b, self.s, self.q_BS, self.P, ref_I, obs_S, variance, self.gate[2],
            self.sf_start, self.mis_start,
        )
        self._set_mounting(q_BS)
        return UpdateResult(z=z, nis=nis, accepted=accepted)

    def _set_mounting(self, q_BS):
        if self.mis_start >= 0:
            self.q_BS = q_BS
            self.R_BS = kernels.quat_to_matrix(q_BS)
