"""Multiplicative error-state Kalman filter (MEKF) for attitude and gyro bias, with optional gyro
calibration and star-sensor mounting states.

Nominal state: attitude q_IB (scalar-last), the total gyro bias b [rad/s] and its Gauss-Markov part
g (the bias instability, σ_g and τ from the gyro's datasheet), the gyro error matrix K of
ω̃ = (I + K) ω + b + noise (scale factors on the diagonal, the six misalignment/non-orthogonality
terms off it, as in the alignment-calibration filter of Pittelkau 2001) and the star-sensor mounting
q_BS of each of its H star-sensor heads (a spacecraft's 2-3; one otherwise). Error state x (zero between updates):

    x = [δθ (3), δb (3), δg (3), δs (3) scale factors, δk (6) off-diagonal terms, δm (3 per head) mounting]

each of the last four groups present when asked for, with q_true = q ⊗ δq(δθ) (δθ in body axes),
δb = b_true − b (the total bias, so the attitude/bias NEES is over the first six states whatever the
groups), δg = g_true − g, δK = K_true − K and q_BS,true = q_BS ⊗ δq(δm) for each head (δm in its sensor axes), as
docs/design.md fixes. Without δg the bias instability is folded into an equivalent random walk. A group is estimated, or kept as consider states (Schmidt-Kalman: in P and Φ,
never corrected, so the filter accounts for an error it does not estimate), or ignored.

Propagation at the gyro rate: q by RK4 (eq. 9 of 000) with ω = (I + K)⁻¹(ω̃ − b) held over the
interval; P ← Φ P Φᵀ + Q with the closed-form Φ and Farrenkopf's discrete Q
(:func:`navsim.estimation.kernels.transition`, :func:`~navsim.estimation.kernels.process_noise`).
Updates: an attitude fix (3-dim) of a head or one 2-dim tangent-plane residual per identified star, each
through its head's mounting; each is gated by its chi-square NIS against the prior, the accepted ones update together in Joseph form,
and the error estimate is reset into the nominal state.

The filter owns its state: q, b, K, q_BS and P are read-only views; only its methods change them
(predict, the updates, :meth:`AttitudeFilter.reinitialise` after a lost track and
:meth:`AttitudeFilter.disturb` for the attitude-jump fault). :meth:`AttitudeFilter.process_record`
is the compiled fast path over a whole record, tested equal to the step-by-step path.
The linear algebra is compiled (:mod:`navsim.estimation.kernels`); it is tested equal to
filterpy's ``KalmanFilter.predict``/``update`` (Joseph form), which is the reference engine.
"""

from dataclasses import dataclass

import numpy as np

from navsim.estimation import kernels
from navsim.estimation.consistency import chi2_quantile
from navsim.estimation.kernels import FilterModel
from navsim.estimation.treatments import TREATMENTS
from navsim.estimation.updates import UpdateResult, star_covariances
from startrack import InputError
from startrack import rotation as rot

#: The groups of extra states in error-state order, with their sizes.
GROUPS = (("bias_instability", 3), ("scale_factor", 3), ("gyro_misalignment", 6), ("mounting", 3))


def _read_only(array):
    view = array.view()
    view.flags.writeable = False
    return view


@dataclass(frozen=True, eq=False)
class AttitudeFilterConfig:
    """Everything the MEKF is built from but its initial estimate, validated here: ``P0`` (its initial
    covariance, n x n in the state order of the module docstring: the initial σ of every state),
    ``arw``/``rrw`` (gyro noise the filter assumes, SI), ``q_BS`` (nominal sensor mounting, rotating S
    vectors into B: one quaternion (4,), or one per head (H, 4)), ``bias_instability``, ``scale_factor``,
    ``gyro_misalignment``, ``mounting`` (each one of :data:`~navsim.estimation.treatments.TREATMENTS`; the mounting
    one for every head or a tuple of one per head: when any head carries its mounting, every head has its three
    states, an ignored head's with a zero initial σ in P0, so they never move), ``bias_instability_sigma`` σ_g [rad/s] and
    ``bias_correlation_time`` τ [s] of the Gauss-Markov bias, ``calibration_rw`` (σ of a random walk of the
    calibration terms, 1/√s), ``process_noise_scale`` (multiplies Q) and ``measurement_noise_scale``
    (multiplies the sensor's σ) for tuning studies, and ``gate_probability`` (chi-square gate)."""

    P0: np.ndarray
    arw: float
    rrw: float
    q_BS: tuple = (0.0, 0.0, 0.0, 1.0)
    bias_instability: str = "ignore"
    scale_factor: str = "ignore"
    gyro_misalignment: str = "ignore"
    mounting: str | tuple = "ignore"
    bias_instability_sigma: float = 0.0
    bias_correlation_time: float = np.inf
    calibration_rw: float = 0.0
    process_noise_scale: float = 1.0
    measurement_noise_scale: float = 1.0
    gate_probability: float = 0.9999

    def __post_init__(self):
        q_BS = np.atleast_2d(np.array(self.q_BS, dtype=float))
        if q_BS.ndim != 2 or q_BS.shape[1] != 4 or len(q_BS) < 1:
            raise InputError(f"filter: q_BS must be a quaternion or one per head, got shape {np.shape(self.q_BS)}")
        object.__setattr__(self, "q_BS", tuple(map(tuple, q_BS)))
        mounting = (self.mounting,) * len(q_BS) if isinstance(self.mounting, str) else tuple(self.mounting)
        if len(mounting) != len(q_BS):
            raise InputError(f"filter.mounting: one treatment per head ({len(q_BS)}), got {len(mounting)}")
        for group in dict(GROUPS):
            for treatment in (mounting if group == "mounting" else (getattr(self, group),)):
                if treatment not in TREATMENTS:
                    raise InputError(f"filter.{group}: must be one of {', '.join(TREATMENTS)}, got {treatment!r}")
        for name in ("arw", "rrw", "bias_instability_sigma", "calibration_rw"):
            if not 0.0 <= float(getattr(self, name)) < np.inf:
                raise InputError(f"filter: {name} must be a finite number >= 0, got {getattr(self, name)!r}")
        for name in ("bias_correlation_time", "process_noise_scale", "measurement_noise_scale"):
            if not float(getattr(self, name)) > 0.0:
                raise InputError(f"filter: {name} must be > 0, got {getattr(self, name)!r}")
        if not 0.0 < self.gate_probability < 1.0:
            raise InputError(f"filter.gate_probability: must be in (0, 1), got {self.gate_probability!r}")
        P0 = np.array(self.P0, dtype=float)
        if P0.shape != (self.n, self.n):
            raise InputError(f"filter: P0 must be {self.n}x{self.n} for the chosen states, got {P0.shape}")
        P0.flags.writeable = False
        object.__setattr__(self, "P0", P0)

    @property
    def model(self):
        """The :data:`~navsim.estimation.kernels.FilterModel` the compiled kernels take."""
        return FilterModel(arw=float(self.arw), rrw=float(self.rrw), gm_sigma=float(self.bias_instability_sigma),
                           gm_tau=float(self.bias_correlation_time), cal_rw=float(self.calibration_rw),
                           q_scale=float(self.process_noise_scale), n_bi=3 * int(self.bias_instability != "ignore"),
                           n_sf=3 * int(self.scale_factor != "ignore"), n_gm=6 * int(self.gyro_misalignment != "ignore"),
                           mounting=self._carried("mounting"), heads=self.heads)

    @property
    def heads(self):
        """The number of star-sensor heads."""
        return len(self.q_BS)

    @property
    def mountings(self):
        """The mounting treatment of each head (H,)."""
        return (self.mounting,) * self.heads if isinstance(self.mounting, str) else self.mounting

    def _carried(self, group):
        """Whether the filter carries the group's states (the mounting's: when any head does)."""
        if group == "mounting":
            return any(t != "ignore" for t in self.mountings)
        return getattr(self, group) != "ignore"

    @property
    def estimated(self):
        """(n,) True for the states the updates correct, False for consider states (and an ignored head's mounting)."""
        flags = [True] * 6
        for group, size in GROUPS:
            if self._carried(group):
                treatments = self.mountings if group == "mounting" else (getattr(self, group),)
                flags += [t == "estimate" for t in treatments for _ in range(size)]
        return np.array(flags)

    @property
    def n(self):
        """The size of the error state."""
        return 6 + sum(size * (self.heads if group == "mounting" else 1) for group, size in GROUPS if self._carried(group))


class AttitudeFilter:
    """MEKF with textbook names: error state x, covariance P; Φ, Q, H, R, K inside each step.

    Built from ``q`` (q_IB estimate), ``b`` (bias estimate, rad/s) and its :class:`AttitudeFilterConfig`
    (P0, noise, state treatments, tuning).
    """

    def __init__(self, q, b, config):
        self.config = config
        self.model = config.model
        self.estimated = config.estimated
        self.n = config.n
        q = np.asarray(q, dtype=float)
        q_BS = np.array(config.q_BS, dtype=float)
        self._x = np.concatenate([q / np.linalg.norm(q), np.asarray(b, dtype=float), np.zeros(12), q_BS.ravel()])
        self._P = np.array(config.P0)
        self._P0_attitude = self._P[0:3, 0:3].copy()
        self.variance_scale = float(config.measurement_noise_scale) ** 2
        self.gate = {dof: float(chi2_quantile(config.gate_probability, dof)) for dof in (2, 3)}

    q = property(lambda self: _read_only(self._x[0:4]), doc="q_IB estimate (4,)")
    b = property(lambda self: _read_only(self._x[4:7]), doc="total gyro bias estimate (3,) [rad/s]")
    g = property(lambda self: _read_only(self._x[kernels.X_G : kernels.X_G + 3]),
                 doc="Gauss-Markov part of the bias estimate (3,) [rad/s]")
    K = property(lambda self: _read_only(self._x[7:16].reshape(3, 3)), doc="gyro error matrix estimate (3, 3)")
    q_BS = property(lambda self: _read_only(self._x[kernels.X_BS :].reshape(-1, 4)),
                    doc="mounting estimate q_BS of each head (H, 4)")
    P = property(lambda self: _read_only(self._P), doc="error covariance (n, n)")

    @property
    def R_BS(self):
        """Mounting estimate of each head as a matrix (H, 3, 3) (S -> B)."""
        return rot.to_matrix(self.q_BS)

    def calibration_slices(self):
        """{group: slice of the error state} of the extra states the filter carries."""
        out, start = {}, 6
        sizes = {"bias_instability": self.model.n_bi, "scale_factor": self.model.n_sf, "gyro_misalignment": self.model.n_gm,
                 "mounting": 3 * self.model.mounting * self.model.heads}
        for group, _ in GROUPS:
            if sizes[group]:
                out[group] = slice(start, start + sizes[group])
                start += sizes[group]
        return out

    def predict(self, omega_measured, dt):
        """Propagate q (RK4) and P (Φ P Φᵀ + Q) over one gyro sample (3,) or several
        consecutive samples (m, 3), each held for dt [s] (:func:`navsim.estimation.kernels.predict`)."""
        if np.ndim(omega_measured) != 2:
            omega_measured = np.atleast_2d(np.asarray(omega_measured, dtype=float))
        self._x, self._P = kernels.predict(self._x, self._P, omega_measured, dt, self.model)

    def sensor_prediction(self, omega_measured, head=0):
        """(q_IS, ω_S): the predicted attitude q_IB ⊗ q_BS of head ``head`` and the body rate the filter
        believes from the gyro sample ``omega_measured`` (3,), in that head's axes [rad/s]."""
        omega = kernels.corrected_rate(self._x, np.asarray(omega_measured, dtype=float), self.model)
        return rot.multiply(self._x[0:4], self.q_BS[head]), self.R_BS[head].T @ omega

    def update_attitude(self, q_IS, R_S, head=0):
        """Update with head ``head``'s attitude fix q_IS and its 3x3 covariance R_S in sensor axes
        (:func:`navsim.estimation.kernels.attitude_update`: z = δθ(q, q_IS ⊗ q_BS⁻¹) in body axes,
        H = [I, 0, (0), (R_BS)], R = R_BS R_S R_BSᵀ), gated at 3 dof."""
        R = self.variance_scale * np.asarray(R_S, dtype=float)
        self._x, self._P, z, nis, accepted = kernels.attitude_update(
            self._x, self._P, np.asarray(q_IS, dtype=float), R, int(head), self.gate[3], self.model, self.estimated)
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]))

    def update_stars(self, ref_I, obs_S, cov_S, heads=None):
        """Update with identified stars: catalog unit vectors ref_I (N, 3) in I, measured unit
        vectors obs_S (N, 3) in S and the covariance of each measured direction cov_S (N, 3, 3) [rad², S], star k
        seen by head ``heads[k]`` (None: all by head 0).

        Each star gives z_i = T_i (s_i − ŝ_i) with T_i (2x3) spanning the plane ⟂ ŝ_i,
        H_i = T_i [R_SB [b̂_i×], 0, (0), ([ŝ_i×])], R_i = T_i C_i T_iᵀ (:func:`kernels.star_residuals`).
        Stars whose NIS against the prior exceeds the 2-dof gate are rejected; the rest update
        together (:func:`kernels.stars_update`).
        """
        ref_I = np.ascontiguousarray(ref_I, dtype=float)
        obs_S = np.ascontiguousarray(obs_S, dtype=float)
        heads = np.zeros(len(ref_I), dtype=np.int64) if heads is None else np.ascontiguousarray(heads, dtype=np.int64)
        self._x, self._P, z, nis, accepted = kernels.stars_update(
            self._x, self._P, heads, ref_I, obs_S, star_covariances(cov_S, ref_I.shape[0], self.variance_scale), self.gate[2], self.model,
            self.estimated)
        return UpdateResult(z=z, nis=nis, accepted=accepted, per_row=True)

    def reinitialise(self, q_IS, head=0):
        """Restart the attitude from head ``head``'s fix q_IS after a lost track: q_IB = q_IS ⊗ q_BS⁻¹, the
        attitude block of P back to its initial value and its correlations cleared."""
        self._x[0:4] = rot.normalize(rot.multiply(q_IS, rot.conjugate(self.q_BS[head])))
        self._P[0:3, :] = 0.0
        self._P[:, 0:3] = 0.0
        self._P[0:3, 0:3] = self._P0_attitude

    def disturb(self, rotation_vector):
        """The attitude-jump fault: the estimate is knocked off by ``rotation_vector`` [rad] (body
        axes), as by a disturbance the filter is not told about; P is left as it was."""
        self._x[0:4] = rot.normalize(rot.multiply(self._x[0:4], rot.from_rotation_vector(rotation_vector)))

    def snapshot(self):
        """What the run log keeps of the filter at a frame: q_est, bias_est, the gyro error matrix
        (flat, K_est) and P."""
        return {"q_est": self._x[0:4].copy(), "bias_est": self._x[4:7].copy(), "K_est": self._x[7:16].copy(),
                "P": self._P.copy()}

    def process_record(self, omega, ratio, dt, record):
        """The compiled fast path: run the whole record at once (:func:`kernels.run_fixes` or
        :func:`kernels.run_stars`) and return the per-frame log that the step-by-step loop of
        :mod:`navsim.closed_loop` would have written.

        ``omega`` (F*ratio, 3) gyro samples; ``record`` a :class:`navsim.sensors.star_vector.Record`
        (fixes q_IS (F, 4) with R_S (3, 3), or (F, H, 4) with (H, 3, 3) for H heads; or the stars of every frame with
        their heads) with the frames ``available`` ((F,), or (F, H) for the fixes of H heads).
        """
        omega = np.ascontiguousarray(omega)
        available = np.asarray(record.available, dtype=np.bool_)
        if record.fixes is not None:
            fixes = np.asarray(record.fixes, dtype=float)
            heads = 1 if fixes.ndim == 2 else fixes.shape[1]
            out = kernels.run_fixes(self._x, self._P, omega, ratio, dt, self.model, self.estimated,
                                    np.ascontiguousarray(fixes.reshape(len(fixes), heads, 4)),
                                    self.variance_scale * np.reshape(record.R_S, (heads, 3, 3)), self.gate[3],
                                    np.ascontiguousarray(available.reshape(len(fixes), heads)))
        else:
            stars = record.stars
            out = kernels.run_stars(self._x, self._P, omega, ratio, dt, self.model, self.estimated,
                                    stars.offsets.astype(np.int64), stars.head_index(),
                                    np.ascontiguousarray(stars.ref_I), np.ascontiguousarray(stars.obs_S),
                                    star_covariances(record.covariances(), len(stars.ref_I), self.variance_scale), self.gate[2], available)
        x_log, P_log = out[0], out[1]
        self._x, self._P = x_log[-1].copy(), P_log[-1].copy()
        log = dict(zip(("n_measurements", "n_accepted", "nis", "nis_dof", "innovation_rms"), out[2:]))
        return {"q_est": x_log[:, 0:4], "bias_est": x_log[:, 4:7], "K_est": x_log[:, 7:16], "P": P_log, **log}
