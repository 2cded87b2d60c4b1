"""Navigation error-state Kalman filter of the strapdown INS, aided here by position fixes and a baro.

The filter owns the nominal navigation state (the strapdown ``nav`` vector of
:mod:`navsim.ins.strapdown`: L, λ, h, v_n, q_nb), the IMU error estimates (gyro and accelerometer
biases, optional scale factors) and the covariance P of the error state
(:mod:`navsim.estimation.nav_kernels`, docs/design.md):

    x = [φ, δv_n, δL, δλ, δh, ε, ∇ (, δs_g, δs_a)],   C_nb,est = (I − [φ×]) C_nb,true.

``predict(samples, dt)`` mechanizes the corrected IMU samples at the IMU rate and propagates P every
``covariance_interval`` intervals with the discretised error dynamics (Φ, Q_d by series, tested
against expm and Van Loan); ``update_position`` and ``update_baro`` gate each measurement by its
chi-square NIS against the prior, update in Joseph form and reset the estimate into the nominal
state; ``process_record`` is the compiled fast path over a whole aiding record, tested equal to the
step-by-step loop of :mod:`navsim.closed_loop`. Nobody else writes the state or P: read them
through the properties.
"""

from dataclasses import dataclass

import numpy as np

from navsim.estimation import nav_kernels
from navsim.estimation.consistency import chi2_quantile
from navsim.estimation.updates import UpdateResult
from navsim.ins import strapdown
from startrack import rotation as rot
from startrack.errors import InputError

BASE_STATES = 15
SCALE_STATES = 21


@dataclass(frozen=True)
class ImuNoise:
    """Noise the filter assumes (SI): ``arw`` [rad/√s], ``vrw`` [m/s/√s], ``gyro_bias_rw``
    [rad/s/√s], ``accel_bias_rw`` [m/s²/√s], ``scale_factor_rw`` [1/√s] (both sensors)."""

    arw: float
    vrw: float
    gyro_bias_rw: float = 0.0
    accel_bias_rw: float = 0.0
    scale_factor_rw: float = 0.0

    def spectral_densities(self, n):
        """Diagonal continuous noise q_c (n,) of the error state."""
        q = np.zeros(n)
        q[0:3], q[3:6] = self.arw**2, self.vrw**2
        q[9:12], q[12:15] = self.gyro_bias_rw**2, self.accel_bias_rw**2
        q[15:] = self.scale_factor_rw**2
        return q


class NavFilter:
    """Error-state filter with textbook names: error state x (zero between updates), covariance P;
    F, Φ, Q, H, R, K inside each compiled step.

    Parameters: the initial navigation state ``lat``, ``lon`` [rad], ``h`` [m], ``v_n`` (3,)
    [m/s], ``q_nb``; ``P`` (15x15, or 21x21 with ``estimate_scale_factors``); ``noise``
    (:class:`ImuNoise`); ``dt`` the IMU interval [s]; ``covariance_interval`` the number of
    increments per covariance propagation; ``gate_probability`` of the chi-square gates;
    ``process_noise_scale`` (multiplies Q) and ``measurement_noise_scale`` (multiplies each
    measurement's σ) for tuning; ``gyro_bias``/``accel_bias`` initial estimates [rad/s, m/s²].
    """

    def __init__(self, lat, lon, h, v_n, q_nb, P, noise, dt, estimate_scale_factors=False,
                 covariance_interval=20, gate_probability=0.9999, process_noise_scale=1.0,
                 measurement_noise_scale=1.0, gyro_bias=(0.0, 0.0, 0.0), accel_bias=(0.0, 0.0, 0.0)):
        self.n = SCALE_STATES if estimate_scale_factors else BASE_STATES
        if not dt > 0.0:
            raise InputError(f"imu.rate_hz: the IMU interval must be > 0, got {dt!r} s")
        if int(covariance_interval) < 1:
            raise InputError(f"filter.covariance_interval: must be >= 1 IMU interval, got {covariance_interval!r}")
        P = np.array(P, dtype=float)
        if P.shape != (self.n, self.n):
            raise InputError(f"filter.P: must be {self.n}x{self.n} for the chosen states, got {P.shape}")
        self.dt = float(dt)
        self.covariance_interval = int(covariance_interval)
        self.q_c = float(process_noise_scale) * noise.spectral_densities(self.n)
        self.sigma_scale = float(measurement_noise_scale)
        self.gates = np.array([chi2_quantile(gate_probability, dof) for dof in (3, 1)], dtype=float)
        self._imu = np.zeros(12)
        self._imu[0:3], self._imu[3:6] = gyro_bias, accel_bias
        self._nav = strapdown.initial_state(lat, lon, h, v_n, q_nb)
        self._P = 0.5 * (P + P.T)
        self._acc = np.zeros(nav_kernels.ACC_SIZE)

    def predict(self, samples, dt):
        """Mechanize IMU samples (m, 6) of the filter's interval ``dt`` [s]: each row the interval means
        of the measured rate [rad/s] and specific force [m/s²] (an increment divided by dt)."""
        if dt != self.dt:
            raise ValueError(f"IMU interval {dt} s, the filter was built for {self.dt} s")
        samples = np.ascontiguousarray(np.atleast_2d(samples), dtype=float)
        nav_kernels.predict(self._nav, self._imu, self._P, self._acc, samples, self.dt, self.q_c,
                            self.covariance_interval)

    def update_position(self, lat, lon, h, sigma):
        """Update with a position fix (L, λ [rad], h [m]) of NED σ ``sigma`` (3,) [m], gated at 3 dof;
        the innovation is reported in NED metres."""
        sigma = np.broadcast_to(np.asarray(sigma, dtype=float), (3,)) * self.sigma_scale
        z, nis, accepted = nav_kernels.position_update(self._nav, self._imu, self._P, self._acc, self.q_c, self.dt,
                                                       np.array([lat, lon, h], dtype=float), sigma, self.gates[0])
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]))

    def update_baro(self, h, sigma):
        """Update with a baro height ``h`` [m] of σ ``sigma`` [m], gated at 1 dof."""
        z, nis, accepted = nav_kernels.baro_update(self._nav, self._imu, self._P, self._acc, self.q_c, self.dt,
                                                   float(h), float(sigma) * self.sigma_scale, self.gates[1])
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]))

    def process_record(self, samples, ratio, dt, record):
        """The compiled fast path: the whole :class:`~navsim.sensors.aiding.AidingRecord` at once
        (:func:`nav_kernels.run_record`), returning the per-frame log the step-by-step loop of
        :mod:`navsim.closed_loop` would have written. ``samples`` (F*ratio, 6) IMU samples."""
        if dt != self.dt:
            raise ValueError(f"IMU interval {dt} s, the filter was built for {self.dt} s")
        out = nav_kernels.run_record(self._nav, self._imu, self._P, self._acc, np.ascontiguousarray(samples, dtype=float),
                                     int(ratio), self.dt, self.q_c, self.covariance_interval,
                                     np.ascontiguousarray(record.position), record.position_sigma * self.sigma_scale,
                                     np.ascontiguousarray(record.baro), record.baro_sigma * self.sigma_scale, self.gates)
        nav_log, imu_log, P_log = out[0], out[1], out[2]
        log = dict(zip(("n_measurements", "n_accepted", "nis", "nis_dof", "innovation_rms"), out[3:]))
        return {**_snapshot_arrays(nav_log, imu_log, self.n), "P": P_log, **log}

    def snapshot(self):
        """What a run log keeps of the filter at an epoch: position, velocity, attitude, IMU error
        estimates and P (copies)."""
        return {**_snapshot_arrays(self._nav[0:10], self._imu, self.n), "P": self.P}

    @property
    def P(self):
        """Covariance of the error state at the last propagation (a copy)."""
        return self._P.copy()

    @property
    def position(self):
        """(L, λ, h) [rad, rad, m]."""
        return tuple(float(x) for x in self._nav[0:3])

    @property
    def v_n(self):
        return self._nav[3:6].copy()

    @property
    def q_nb(self):
        return self._nav[6:10].copy()

    @property
    def gyro_bias(self):
        return self._imu[0:3].copy()

    @property
    def accel_bias(self):
        return self._imu[3:6].copy()

    @property
    def scale_factors(self):
        """(ŝ_g, ŝ_a) estimates [-] (zero unless estimated)."""
        return self._imu[6:9].copy(), self._imu[9:12].copy()


def _snapshot_arrays(nav, imu, n):
    """The snapshot's named parts (copies) of nav[0:10] and the IMU estimates, one row or (F, ·) rows:
    lat, lon, h, v_n, q_nb, gyro_bias, accel_bias and, with scale-factor states, gyro_scale_factor
    and accel_scale_factor."""
    out = {"lat": nav[..., 0].copy(), "lon": nav[..., 1].copy(), "h": nav[..., 2].copy(), "v_n": nav[..., 3:6].copy(),
           "q_nb": nav[..., 6:10].copy(), "gyro_bias": imu[..., 0:3].copy(), "accel_bias": imu[..., 3:6].copy()}
    if n > BASE_STATES:
        out["gyro_scale_factor"], out["accel_scale_factor"] = imu[..., 6:9].copy(), imu[..., 9:12].copy()
    return out


def error_state(lat, lon, h, v_n, q_nb, gyro_bias, accel_bias, truth_lat, truth_lon, truth_h, truth_v_n,
                truth_q_nb, truth_gyro_bias, truth_accel_bias):
    """The filter's error (est − true in its definitions) (..., 15): φ from C_est C_trueᵀ = I − [φ×],
    δv, δL, δλ, δh, ε = b_g,true − b̂_g, ∇ = b_a,true − b̂_a. Inputs broadcast over a leading axis."""
    phi = -rot.to_rotation_vector(rot.multiply(q_nb, rot.conjugate(truth_q_nb)))
    dp = np.stack([np.asarray(lat) - truth_lat, np.asarray(lon) - truth_lon, np.asarray(h) - truth_h], axis=-1)
    return np.concatenate([phi, np.asarray(v_n) - truth_v_n, dp, np.asarray(truth_gyro_bias) - gyro_bias,
                           np.asarray(truth_accel_bias) - accel_bias], axis=-1)
