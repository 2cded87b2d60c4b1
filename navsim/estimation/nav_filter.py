"""Navigation error-state Kalman filter of the strapdown INS, aided here by position fixes and a baro.

The filter owns the nominal navigation state (the strapdown ``nav`` vector of
:mod:`navsim.ins.strapdown`: L, λ, h, v_n, q_nb), the IMU error estimates (gyro and accelerometer
biases, optional scale factors) and the covariance P of the error state
(:mod:`navsim.estimation.nav_kernels`, docs/design.md):

    x = [φ, δv_n, δL, δλ, δh, ε, ∇ (, δs_g, δs_a)],   C_nb,est = (I − [φ×]) C_nb,true.

``predict`` mechanizes the corrected IMU increments at the IMU rate and propagates P every
``covariance_interval`` increments with the discretised error dynamics (Φ, Q_d by series, tested
against expm and Van Loan); ``update_position`` and ``update_baro`` gate each measurement by its
chi-square NIS against the prior, update in Joseph form and reset the estimate into the nominal
state. Nobody else writes the state or P: read them through the properties.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.wgs84 import radii
from navsim.estimation import nav_kernels
from navsim.estimation.attitude_filter import UpdateResult
from navsim.estimation.consistency import chi2_quantile
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
    ``gyro_bias``/``accel_bias`` initial estimates [rad/s, m/s²].
    """

    def __init__(self, lat, lon, h, v_n, q_nb, P, noise, dt, estimate_scale_factors=False,
                 covariance_interval=20, gate_probability=0.9999, gyro_bias=(0.0, 0.0, 0.0),
                 accel_bias=(0.0, 0.0, 0.0)):
        self.n = SCALE_STATES if estimate_scale_factors else BASE_STATES
        if not dt > 0.0:
            raise InputError(f"imu.rate_hz: the IMU interval must be > 0, got {dt!r} s")
        if int(covariance_interval) < 1:
            raise InputError(f"filter.covariance_interval: must be >= 1 IMU interval, got {covariance_interval!r}")
        self.dt = float(dt)
        self.covariance_interval = int(covariance_interval)
        self.q_c = noise.spectral_densities(self.n)
        self.gate = {dof: float(chi2_quantile(gate_probability, dof)) for dof in (1, 3)}
        self._imu = np.zeros(12)
        self._imu[0:3], self._imu[3:6] = gyro_bias, accel_bias
        self.reset(lat, lon, h, v_n, q_nb, P)

    def reset(self, lat, lon, h, v_n, q_nb, P):
        """Re-initialise the navigation state and the covariance (the IMU error estimates are kept)."""
        P = np.array(P, dtype=float)
        if P.shape != (self.n, self.n):
            raise InputError(f"filter.P: must be {self.n}x{self.n} for the chosen states, got {P.shape}")
        self._nav = strapdown.initial_state(lat, lon, h, v_n, q_nb)
        self._P = 0.5 * (P + P.T)
        self._acc = np.zeros(nav_kernels.ACC_SIZE)

    def predict(self, dtheta, dv):
        """Mechanize IMU increments ``dtheta`` [rad], ``dv`` [m/s] (3,) or (m, 3), one interval each."""
        dtheta = np.ascontiguousarray(np.atleast_2d(dtheta), dtype=float)
        dv = np.ascontiguousarray(np.atleast_2d(dv), dtype=float)
        nav_kernels.predict(self._nav, self._imu, self._P, self._acc, dtheta, dv, self.dt, self.q_c,
                            self.covariance_interval)

    def update_position(self, lat, lon, h, sigma):
        """Update with a position fix (L, λ [rad], h [m]) of NED σ ``sigma`` (3,) [m], gated at 3 dof."""
        self._flush()
        r_m, r_n = radii(self._nav[0])
        sigma = np.broadcast_to(np.asarray(sigma, dtype=float), (3,))
        scale = np.array([r_m + self._nav[2], (r_n + self._nav[2]) * np.cos(self._nav[0]), 1.0])
        R = np.diag((sigma / scale) ** 2)
        z = self._nav[0:3] - np.array([lat, lon, h])
        nis, accepted = nav_kernels.position_update(self._nav, self._imu, self._P, z, R, self.gate[3])
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]))

    def update_baro(self, h, sigma):
        """Update with a baro height ``h`` [m] of σ ``sigma`` [m], gated at 1 dof."""
        self._flush()
        z = self._nav[2] - float(h)
        nis, accepted = nav_kernels.baro_update(self._nav, self._imu, self._P, z, float(sigma) ** 2, self.gate[1])
        return UpdateResult(z=np.array([[z]]), nis=np.array([nis]), accepted=np.array([accepted]))

    def _flush(self):
        nav_kernels.flush(self._nav, self._P, self._acc, self.q_c, self.dt)

    def snapshot(self):
        """What a run log keeps of the filter at an epoch: position, velocity, attitude, IMU error
        estimates and P (copies)."""
        return {"lat": self._nav[0], "lon": self._nav[1], "h": self._nav[2], "v_n": self.v_n, "q_nb": self.q_nb,
                "gyro_bias": self.gyro_bias, "accel_bias": self.accel_bias, "P": self.P}

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


def error_state(lat, lon, h, v_n, q_nb, gyro_bias, accel_bias, truth_lat, truth_lon, truth_h, truth_v_n,
                truth_q_nb, truth_gyro_bias, truth_accel_bias):
    """The filter's error (est − true in its definitions) (..., 15): φ from C_est C_trueᵀ = I − [φ×],
    δv, δL, δλ, δh, ε = b_g,true − b̂_g, ∇ = b_a,true − b̂_a. Inputs broadcast over a leading axis."""
    phi = -rot.to_rotation_vector(rot.multiply(q_nb, rot.conjugate(truth_q_nb)))
    dp = np.stack([np.asarray(lat) - truth_lat, np.asarray(lon) - truth_lon, np.asarray(h) - truth_h], axis=-1)
    return np.concatenate([phi, np.asarray(v_n) - truth_v_n, dp, np.asarray(truth_gyro_bias) - gyro_bias,
                           np.asarray(truth_accel_bias) - accel_bias], axis=-1)
