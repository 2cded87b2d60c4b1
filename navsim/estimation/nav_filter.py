"""Navigation error-state Kalman filter of the strapdown INS, aided by position fixes, a baro and a
star sensor (SINS/CNS).

The filter owns the nominal navigation state (the strapdown ``nav`` vector of
:mod:`navsim.ins.strapdown`: q_ew, h, v_w, q_wb in the wander-azimuth frame w), its estimates beside it (gyro and
accelerometer biases, optional scale factors, the star sensor's mounting q̂_BS) and the covariance P of the error
state (:mod:`navsim.estimation.nav_kernels`, docs/design.md), which it shows in NED with the position in metres:

    x = [φ, δv_n, δN, δE, δh, ε, ∇ (, δs_g, δs_a) (, μ) (, δg) (, ε_r)],   C_nb,est = (I − [φ×]) C_nb,true,

μ the star-sensor mounting error (estimated or a consider state), δg the gravity disturbance the
INS does not know and ε_r the fractional error of the air its star processing corrects the refraction with
(consider states: Schmidt). ``predict(samples, dt)`` mechanizes the corrected IMU
samples at the IMU rate and propagates P every ``covariance_interval`` intervals (Φ, Q_d by series,
tested against expm and Van Loan); the updates — ``update_position``, ``update_velocity``, ``update_body_velocity`` (a land vehicle's
non-holonomic constraint), ``update_baro``,
``update_attitude`` (a star-sensor fix) and ``update_stars`` (identified stars one by one,
:mod:`navsim.estimation.celestial_kernels`) — gate each measurement by its chi-square NIS against
the prior, update in Joseph form and reset the estimate into the nominal state. With a star sensor
the filter also serves it (``sensor_prediction``: q̂_IS = q_ie ⊗ q_ew ⊗ q_wb ⊗ q̂_BS and the rate in
sensor axes) and takes its faults (``reinitialise`` from a fix after a lost track, ``disturb``).
``process_record`` is the compiled fast path over a whole position/baro record, tested equal to the
step-by-step loop of :mod:`navsim.closed_loop`. Nobody else writes the state or P: read them
through the properties.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.apparent import ApparentPlace
from navsim.earth.frames import c_en, local_up
from navsim.earth.orientation import observer_velocity
from navsim.earth.wander import ned_offset, normal, normal_turn, to_ned
from navsim.estimation import celestial_kernels, nav_kernels
from navsim.estimation.consistency import chi2_quantile
from navsim.estimation.nav_kernels import ACCEL_BIAS, ACCEL_SCALE, CALIB_SIZE, GYRO_BIAS, GYRO_SCALE, MOUNTING, NavModel
from navsim.estimation.treatments import TREATMENTS
from navsim.estimation.updates import UpdateResult, star_covariances
from navsim.ins import strapdown
from navsim.ins.strapdown import HEIGHT, Q_EW, Q_WB, V_W
from navsim.sensors.star_sensor import SensorPrior
from startrack import InputError
from startrack import rotation as rot

#: Which states a baro height updates: the vertical channel (:data:`nav_kernels.BARO_STATES`), or every
#: estimated state (a white-noise height reference).
BARO_CHOICES = ("vertical", "all")


@dataclass(frozen=True)
class ImuNoise:
    """Noise the filter assumes (SI): ``arw`` [rad/√s], ``vrw`` [m/s/√s], ``gyro_bias_rw``
    [rad/s/√s], ``accel_bias_rw`` [m/s²/√s], ``scale_factor_rw`` [1/√s] (both sensors)."""

    arw: float
    vrw: float
    gyro_bias_rw: float = 0.0
    accel_bias_rw: float = 0.0
    scale_factor_rw: float = 0.0

    def spectral_densities(self, layout):
        """Diagonal continuous noise q_c (n,) of the error state of ``layout`` (the mounting constant;
        the gravity disturbance's drive depends on the speed: :func:`nav_kernels.noise_densities`)."""
        q = np.zeros(layout.n)
        q[0:3], q[3:6] = self.arw**2, self.vrw**2
        q[9:12], q[12:15] = self.gyro_bias_rw**2, self.accel_bias_rw**2
        if layout.scale >= 0:
            q[layout.scale:layout.scale + 6] = self.scale_factor_rw**2
        return q


@dataclass(frozen=True)
class StarSensorModel:
    """What the filter knows of its star sensor: the nominal mounting ``q_BS`` (S -> B), how it treats
    the mounting error μ (``mounting``: estimate, consider or ignore), the Earth's orientation at the
    frames (:class:`~navsim.earth.orientation.EarthOrientation`), whether its processing
    corrects the aberration of the stars (``correct_aberration``, :mod:`navsim.earth.apparent`) and the air
    it corrects their refraction with at the INS's height (``refraction``, a
    :class:`navsim.earth.refraction.Air`; None: no correction) and the σ of that air's fractional error
    (``refraction_sigma``, eq. 3 of :mod:`navsim.earth.refraction`; > 0: the consider state ε_r)."""

    q_BS: np.ndarray
    mounting: str
    orientation: object
    correct_aberration: bool = True
    refraction: object = None
    refraction_sigma: float = 0.0

    @property
    def refraction_state(self):
        """Whether the filter carries ε_r."""
        return self.refraction is not None and self.refraction_sigma > 0.0


@dataclass(frozen=True)
class GravityUncertainty:
    """The filter's model of the gravity disturbance it does not know: σ (3,) of (δg_N, δg_E, δg_D)
    [m/s²] and the correlation length along the track [m] (inf: constant)."""

    sigma: np.ndarray
    correlation_length: float


@dataclass(frozen=True, eq=False)
class NavFilterConfig:
    """Everything the navigation filter is built from but its initial estimate, validated here: ``P0`` (its
    initial covariance, n x n in the state order of the module docstring: the initial σ of every state);
    ``noise`` (:class:`ImuNoise`); ``dt`` the IMU interval [s]; ``estimate_scale_factors``; ``star_sensor``
    (:class:`StarSensorModel`, or None without one; its ``mounting`` one of
    :data:`~navsim.estimation.treatments.TREATMENTS`); ``gravity`` (:class:`GravityUncertainty` for the three
    consider states, or None); ``covariance_interval`` the number of increments per covariance propagation;
    ``gate_probability`` of the chi-square gates; ``process_noise_scale`` (multiplies Q) and
    ``measurement_noise_scale`` (multiplies each measurement's σ) for tuning; ``baro_states``
    (:data:`BARO_CHOICES`)."""

    P0: np.ndarray
    noise: ImuNoise
    dt: float
    estimate_scale_factors: bool = False
    star_sensor: StarSensorModel | None = None
    gravity: GravityUncertainty | None = None
    covariance_interval: int = 20
    gate_probability: float = 0.9999
    process_noise_scale: float = 1.0
    measurement_noise_scale: float = 1.0
    baro_states: str = "vertical"

    def __post_init__(self):
        if self.mounting not in TREATMENTS:
            raise InputError(f"filter.mounting: must be one of {', '.join(TREATMENTS)}, got {self.mounting!r}")
        if not self.dt > 0.0:
            raise InputError(f"imu.rate_hz: the IMU interval must be > 0, got {self.dt!r} s")
        if int(self.covariance_interval) < 1:
            raise InputError(f"filter.covariance_interval: must be >= 1 IMU interval, got {self.covariance_interval!r}")
        if self.baro_states not in BARO_CHOICES:
            raise InputError(f"filter.baro_states: must be one of {', '.join(BARO_CHOICES)}, got {self.baro_states!r}")
        if not 0.0 < self.gate_probability < 1.0:
            raise InputError(f"filter.gate_probability: must be in (0, 1), got {self.gate_probability!r}")
        for name in ("process_noise_scale", "measurement_noise_scale"):
            if not float(getattr(self, name)) > 0.0:
                raise InputError(f"filter.{name}: must be > 0, got {getattr(self, name)!r}")
        P0 = np.array(self.P0, dtype=float)
        if P0.shape != (self.layout.n, self.layout.n):
            raise InputError(f"filter.P: must be {self.layout.n}x{self.layout.n} for the chosen states, got {P0.shape}")
        P0 = 0.5 * (P0 + P0.T)
        P0.flags.writeable = False
        object.__setattr__(self, "P0", P0)

    @property
    def mounting(self):
        """How the star sensor's mounting error is treated ("ignore" without a star sensor)."""
        return "ignore" if self.star_sensor is None else self.star_sensor.mounting

    @property
    def layout(self):
        """The error state's layout (:func:`navsim.estimation.nav_kernels.layout`)."""
        return nav_kernels.layout(self.estimate_scale_factors, self.mounting != "ignore", self.gravity is not None,
                                  self.star_sensor is not None and self.star_sensor.refraction_state)


class NavFilter:
    """Error-state filter with textbook names: error state x (zero between updates), covariance P;
    F, Φ, Q, H, R, K inside each compiled step.

    Built from the initial navigation state ``lat``, ``lon`` [rad], ``h`` [m], ``v_n`` (3,) [m/s],
    ``q_nb`` (the IMU error estimates start at zero) and its :class:`NavFilterConfig`.
    """

    def __init__(self, lat, lon, h, v_n, q_nb, config):
        self.config = config
        self.layout = config.layout
        self.n = self.layout.n
        gm = np.zeros(4)
        if config.gravity is not None:
            gm[0:3], gm[3] = np.square(config.gravity.sigma), 1.0 / config.gravity.correlation_length
        self.model = NavModel(q_c=float(config.process_noise_scale) * config.noise.spectral_densities(self.layout), gm=gm,
                              dt=float(config.dt), every=int(config.covariance_interval), layout=self.layout)
        self.star_sensor = config.star_sensor
        self.estimated = np.ones(self.n, dtype=np.bool_)
        if config.mounting == "consider":
            self.estimated[self.layout.mounting:self.layout.mounting + 3] = False
        if config.gravity is not None:
            self.estimated[self.layout.gravity:self.layout.gravity + 3] = False
        if self.layout.refraction >= 0:
            self.estimated[self.layout.refraction] = False
        self.baro_estimated = self.estimated.copy()
        if config.baro_states == "vertical":
            self.baro_estimated[:] = False
            self.baro_estimated[list(nav_kernels.BARO_STATES)] = True
        self.sigma_scale = float(config.measurement_noise_scale)
        self.gates = np.array([chi2_quantile(config.gate_probability, dof) for dof in (3, 1, 2)], dtype=float)
        self._calib = np.zeros(CALIB_SIZE)
        self._calib[MOUNTING] = (0.0, 0.0, 0.0, 1.0) if config.star_sensor is None else rot.normalize(config.star_sensor.q_BS)
        self._nav = strapdown.initial_state(lat, lon, h, v_n, q_nb)
        T_inv = np.linalg.inv(nav_kernels.public_jacobian(self._nav, self.n, self.layout.gravity))
        self._P = T_inv @ np.array(config.P0) @ T_inv.T
        self._P0_attitude = self._P[0:3, 0:3].copy()
        self._acc = np.zeros(nav_kernels.ACC_SIZE)
        self._intervals = 0

    @property
    def dt(self):
        return self.model.dt

    @property
    def t(self):
        """Time of the filter's state [s since the start]: the IMU intervals it has mechanized."""
        return self._intervals * self.model.dt

    def predict(self, samples, dt):
        """Mechanize IMU samples (m, 6) of the filter's interval ``dt`` [s]: each row the interval means
        of the measured rate [rad/s] and specific force [m/s²] (an increment divided by dt)."""
        if dt != self.dt:
            raise ValueError(f"IMU interval {dt} s, the filter was built for {self.dt} s")
        samples = np.ascontiguousarray(np.atleast_2d(samples), dtype=float)
        nav_kernels.predict(self._nav, self._calib, self._P, self._acc, samples, self.model)
        self._intervals += samples.shape[0]

    def update_position(self, lat, lon, h, sigma):
        """Update with a position fix (L, λ [rad], h [m]) of NED σ ``sigma`` (3,) [m], gated at 3 dof;
        the innovation is reported in NED metres."""
        sigma = np.broadcast_to(np.asarray(sigma, dtype=float), (3,)) * self.sigma_scale
        z, nis, accepted = nav_kernels.position_update(self._nav, self._calib, self._P, self._acc, self.model,
                                                       np.array([lat, lon, h], dtype=float), sigma, self.gates[0],
                                                       self.estimated)
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]), unit="m")

    def update_velocity(self, v_n, sigma):
        """Update with a NED velocity ``v_n`` (3,) [m/s] of NED σ ``sigma`` (3,) [m/s], gated at 3 dof
        (:func:`nav_kernels.velocity_update`); the innovation is reported in NED m/s."""
        sigma = np.broadcast_to(np.asarray(sigma, dtype=float), (3,)) * self.sigma_scale
        z, nis, accepted = nav_kernels.velocity_update(self._nav, self._calib, self._P, self._acc, self.model,
                                                       np.asarray(v_n, dtype=float), np.ascontiguousarray(sigma),
                                                       self.gates[0], self.estimated)
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]), unit="m/s")

    def update_body_velocity(self, v_yz, sigma):
        """Update with the body's lateral and vertical velocity ``v_yz`` (2,) [m/s] (zero for a land vehicle: the
        non-holonomic constraint) of σ ``sigma`` (2,) [m/s], gated at 2 dof (:func:`nav_kernels.body_velocity_update`,
        attitude and velocity coupled); the innovation is reported in body m/s."""
        sigma = np.broadcast_to(np.asarray(sigma, dtype=float), (2,)) * self.sigma_scale
        z, nis, accepted = nav_kernels.body_velocity_update(self._nav, self._calib, self._P, self._acc, self.model,
                                                            np.asarray(v_yz, dtype=float), np.ascontiguousarray(sigma),
                                                            self.gates[2], self.estimated)
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]), unit="m/s")

    def update_baro(self, h, sigma):
        """Update with a baro height ``h`` [m] of σ ``sigma`` [m], gated at 1 dof; it corrects the
        vertical channel, or every estimated state (``baro_states``)."""
        z, nis, accepted = nav_kernels.baro_update(self._nav, self._calib, self._P, self._acc, self.model,
                                                   float(h), float(sigma) * self.sigma_scale, self.gates[1],
                                                   self.baro_estimated)
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]), unit="m")

    def update_attitude(self, q_IS, R_S):
        """Update with a star-sensor attitude fix q_IS and its covariance R_S (3, 3) in sensor axes, gated
        at 3 dof (:func:`celestial_kernels.fix_update`); the fix is first turned back by the aberration
        rotation of its boresight when the processing corrects aberration."""
        j = self._frame()
        q_IS = np.asarray(q_IS, dtype=float)
        place = self._apparent_place(j)
        rho = self._refraction_rotation(place, q_IS) if self.layout.refraction >= 0 else np.zeros(3)
        q_IS = place.turn_back(q_IS)
        R = self.sigma_scale**2 * np.asarray(R_S, dtype=float)
        z, nis, accepted = celestial_kernels.fix_update(self._nav, self._calib, self._P, self._acc, self.model,
                                                        self.star_sensor.orientation.q_ie[j], q_IS, R, self.gates[0],
                                                        self.estimated, rho)
        return UpdateResult(z=z[None, :], nis=np.array([nis]), accepted=np.array([accepted]))

    def update_stars(self, ref_I, obs_S, cov_S):
        """Update with identified stars: catalog unit vectors ``ref_I`` (N, 3) in ICRS, measured unit
        vectors ``obs_S`` (N, 3) in S and their covariances ``cov_S`` (N, 3, 3) [rad², S]; each star a 2-dof
        residual gated alone (:func:`celestial_kernels.stars_update`). The catalog directions are made
        apparent with the filter's own velocity and the ephemeris when the processing corrects aberration, and
        refracted by its model air at the INS's position when it corrects refraction."""
        j = self._frame()
        aberrated, ref_I = self._apparent_place(j).directions(np.asarray(ref_I, dtype=float))
        z, nis, accepted = celestial_kernels.stars_update(self._nav, self._calib, self._P, self._acc, self.model,
                                                          self.star_sensor.orientation.q_ie[j], ref_I,
                                                          np.ascontiguousarray(obs_S, dtype=float),
                                                          star_covariances(cov_S, ref_I.shape[0], self.sigma_scale**2),
                                                          self.gates[2], self.estimated, ref_I - aberrated)
        return UpdateResult(z=z, nis=nis, accepted=accepted, per_row=True)

    def sensor_prediction(self, last_sample):
        """(q̂_IS, ω̂_S): the star sensor's attitude the INS predicts, q_ie ⊗ q_en ⊗ q_nb ⊗ q̂_BS, and the
        inertial body rate of the corrected IMU sample ``last_sample`` (6,) in sensor axes [rad/s]."""
        j = self._frame()
        q_IB = celestial_kernels.inertial_attitude(self._nav, self.star_sensor.orientation.q_ie[j])
        a, b = np.empty(3), np.empty(3)
        nav_kernels.correct(np.asarray(last_sample, dtype=float), self._calib, 1.0, self.layout.scale >= 0, a, b)
        return rot.multiply(q_IB, self._calib[MOUNTING]), rot.to_matrix(self._calib[MOUNTING]).T @ a

    def reinitialise(self, q_IS):
        """Restart the attitude from a star-sensor fix q_IS after a lost track: q_wb = q_ew⁻¹ ⊗ q_ie⁻¹ ⊗
        q_IS ⊗ q̂_BS⁻¹ (the fix corrected like an update's), the attitude block of P back to its
        initial value and its correlations cleared."""
        j = self._frame()
        q_IS = self._apparent_place(j).turn_back(np.asarray(q_IS, dtype=float))
        q_wi = rot.conjugate(rot.multiply(self.star_sensor.orientation.q_ie[j], self._nav[Q_EW]))
        self._nav[Q_WB] = rot.normalize(rot.multiply(rot.multiply(q_wi, q_IS), rot.conjugate(self._calib[MOUNTING])))
        self._P[0:3, :] = 0.0
        self._P[:, 0:3] = 0.0
        self._P[0:3, 0:3] = self._P0_attitude

    def disturb(self, rotation_vector):
        """The attitude-jump fault: the estimate is knocked off by ``rotation_vector`` [rad] (body axes),
        as by a disturbance the filter is not told about; P is left as it was."""
        self._nav[Q_WB] = rot.normalize(rot.multiply(self._nav[Q_WB], rot.from_rotation_vector(rotation_vector)))

    def _frame(self):
        if self.star_sensor is None:
            raise ValueError("this navigation filter has no star sensor")
        return self.star_sensor.orientation.index(self.t)

    def _observer_velocity(self, j, ned):
        """v_I (3,) [m/s]: the INS's velocity relative to the barycentre at frame ``j``, of its NED solution ``ned``
        (:meth:`_ned`)."""
        o = self.star_sensor.orientation
        lat, lon, v_n, _ = ned
        return observer_velocity(o.c_ie[j], o.v_earth[j], lat, lon, self._nav[HEIGHT], v_n)

    def sensor_prior(self):
        """The star sensor's :class:`~navsim.sensors.star_sensor.SensorPrior` at this frame: q̂_IS (as
        :meth:`sensor_prediction`), the covariance of its error in sensor axes, δθ_S = R_SB A x + μ (A of eq. 1 of
        :mod:`navsim.estimation.celestial_kernels`, μ when the mounting is a state, the turn of the field by the
        refraction state's −ε_r R_SI ρ when it has one), the processing that makes catalog stars apparent
        (:meth:`update_stars`'s), and the gyro's ARW and bias-error covariance (ε, in sensor axes) by which its
        attitude drifts between frames."""
        j = self._frame()
        nav_kernels.flush(self._nav, self._P, self._acc, self.model)
        R_SB = rot.to_matrix(self._calib[MOUNTING]).T
        G = R_SB @ celestial_kernels.attitude_jacobian(self._nav, self.layout.n)
        if self.layout.mounting >= 0:
            G[:, self.layout.mounting:self.layout.mounting + 3] += np.eye(3)
        q_IB = celestial_kernels.inertial_attitude(self._nav, self.star_sensor.orientation.q_ie[j])
        q_IS = rot.multiply(q_IB, self._calib[MOUNTING])
        place = self._apparent_place(j)
        if self.layout.refraction >= 0:  # the field turned by ε_r ρ: an attitude error −ε_r R_SI ρ (fix_terms)
            G[:, self.layout.refraction] = -(rot.to_matrix(q_IS).T @ self._refraction_rotation(place, q_IS))
        bias = R_SB @ self._P[9:12, 9:12] @ R_SB.T
        return SensorPrior(q_IS=q_IS, P_theta=G @ self._P @ G.T, apparent=place.apparent,
                           arw=self.config.noise.arw * np.sqrt(self.config.process_noise_scale), P_bias=bias)

    @staticmethod
    def _refraction_rotation(place, q_IS):
        """ρ (3,) [rad, ICRS axes]: the rotation vector by which the processing's model air raises the (aberrated)
        boresight of the sensor attitude ``q_IS`` (:meth:`ApparentPlace.refraction_rotation`)."""
        return place.refraction_rotation(rot.rotate(q_IS, np.array([0.0, 0.0, 1.0]))[None, :])[0]

    def _apparent_place(self, j):
        """The processing's :class:`~navsim.earth.apparent.ApparentPlace` at frame ``j`` (the state of now, held):
        aberration with the INS's velocity when it corrects aberration, refraction by its model air at the INS's
        position when it corrects refraction."""
        ned = self._ned()
        v = self._observer_velocity(j, ned) if self.star_sensor.correct_aberration else None
        return ApparentPlace(v, self._air(j, ned))

    def _air(self, j, ned):
        """(up_I (3,), A, B) of the processing's refraction correction at frame ``j`` and the INS's position (of its NED
        solution ``ned``, :meth:`_ned`), or None."""
        air = self.star_sensor.refraction
        if air is None:
            return None
        lat, lon, _, _ = ned
        a, b = air.coefficients(self._nav[HEIGHT])
        return local_up(self.star_sensor.orientation.c_ie[j], lat, lon), a, b

    def process_record(self, samples, ratio, dt, record):
        """The compiled fast path: the whole :class:`~navsim.sensors.aiding.AidingRecord` at once
        (:func:`nav_kernels.run_record`), returning the per-frame log the step-by-step loop of
        :mod:`navsim.closed_loop` would have written. ``samples`` (F*ratio, 6) IMU samples."""
        if dt != self.dt:
            raise ValueError(f"IMU interval {dt} s, the filter was built for {self.dt} s")
        out = nav_kernels.run_record(self._nav, self._calib, self._P, self._acc, np.ascontiguousarray(samples, dtype=float),
                                     int(ratio), self.model, np.ascontiguousarray(record.position),
                                     record.position_sigma * self.sigma_scale, np.ascontiguousarray(record.baro),
                                     record.baro_sigma * self.sigma_scale, self.gates, self.estimated,
                                     self.baro_estimated)
        self._intervals += samples.shape[0]
        nav_log, calib_log = out[0], out[1]
        P_log = nav_kernels.public_covariances(nav_log, out[2], self.layout.gravity)
        log = dict(zip(("n_measurements", "n_accepted", "nis", "nis_dof", "innovation_rms"), out[3:]))
        return {**self._snapshot_arrays(nav_log, calib_log), "P": P_log, **log}

    def snapshot(self):
        """What a run log keeps of the filter at an epoch: position, velocity, attitude, the estimates
        beside them and P (copies)."""
        return {**self._snapshot_arrays(self._nav[0:strapdown.ROW], self._calib), "P": self.P}

    def _snapshot_arrays(self, nav, calib):
        """The snapshot's named parts (copies) of solution rows nav[0:ROW] and the estimates ``calib``, one row or
        (F, ·) rows: lat, lon, h, v_n, q_nb (in NED, :func:`navsim.earth.wander.to_ned`), q_ew (the wander-azimuth
        frame), gyro_bias, accel_bias and, with scale-factor states, gyro_scale_factor and accel_scale_factor, with a
        star sensor q_bs."""
        lat, lon, v_n, q_nb = to_ned(nav[..., 0:4], nav[..., 5:8], nav[..., 8:12])
        out = {"lat": lat, "lon": lon, "h": nav[..., 4].copy(), "v_n": v_n, "q_nb": q_nb, "q_ew": nav[..., 0:4].copy(),
               "gyro_bias": calib[..., 0:3].copy(),
               "accel_bias": calib[..., 3:6].copy()}
        if self.layout.scale >= 0:
            out["gyro_scale_factor"], out["accel_scale_factor"] = calib[..., 6:9].copy(), calib[..., 9:12].copy()
        if self.star_sensor is not None:
            out["q_bs"] = calib[..., 12:16].copy()
        return out

    @property
    def P(self):
        """Covariance of the error state at the last propagation, in NED with the position in metres (module
        docstring; :func:`nav_kernels.public_jacobian`)."""
        return nav_kernels.to_public(self._P, self._nav[0:strapdown.ROW], self.layout.gravity)

    @property
    def position(self):
        """(L, λ, h) [rad, rad, m]."""
        lat, lon, _, _ = self._ned()
        return float(lat), float(lon), float(self._nav[HEIGHT])

    @property
    def v_n(self):
        return self._ned()[2]

    @property
    def q_nb(self):
        return self._ned()[3]

    def _ned(self):
        """(L, λ, v_n, q_nb) of the wander-azimuth solution (:func:`navsim.earth.wander.to_ned`)."""
        return to_ned(self._nav[Q_EW], self._nav[V_W], self._nav[Q_WB])

    @property
    def gyro_bias(self):
        return self._calib[GYRO_BIAS].copy()

    @property
    def accel_bias(self):
        return self._calib[ACCEL_BIAS].copy()

    @property
    def scale_factors(self):
        """(ŝ_g, ŝ_a) estimates [-] (zero unless estimated)."""
        return self._calib[GYRO_SCALE].copy(), self._calib[ACCEL_SCALE].copy()

    @property
    def q_BS(self):
        """The star-sensor mounting estimate q̂_BS (identity without a star sensor)."""
        return self._calib[MOUNTING].copy()


def state_names(layout):
    """The names of the error state's components in order (timeseries ``state_names``)."""
    names = ["phi_N", "phi_E", "phi_D", "dv_N", "dv_E", "dv_D", "dN", "dE", "dh", "eps_x", "eps_y", "eps_z",
             "nabla_x", "nabla_y", "nabla_z"]
    if layout.scale >= 0:
        names += ["dsg_x", "dsg_y", "dsg_z", "dsa_x", "dsa_y", "dsa_z"]
    if layout.mounting >= 0:
        names += ["mu_x", "mu_y", "mu_z"]
    if layout.gravity >= 0:
        names += ["dg_N", "dg_E", "dg_D"]
    if layout.refraction >= 0:
        names += ["refraction"]
    return names


def error_state(lat, lon, h, v_n, q_nb, gyro_bias, accel_bias, truth_lat, truth_lon, truth_h, truth_v_n,
                truth_q_nb, truth_gyro_bias, truth_accel_bias):
    """The filter's error (est − true in its definitions, as it shows them: NED axes of the estimate, position in
    metres) (..., 15). With δθ_e the turn of the true normal into the estimated one
    (:func:`navsim.earth.wander.normal_turn`; the true local-level frame is the estimated one turned back by it):
    φ from C_eb,est C_be,true exp(−[δθ_e×]) = I − [φ_e×], δv from v_e,est − exp([δθ_e×]) v_e,true, both resolved by
    C_ne,est; (δN, δE) the estimate's offset from the truth in its own NED (minus :func:`navsim.earth.wander.ned_offset`
    of the truth from it); δh; ε = b_g,true − b̂_g,
    ∇ = b_a,true − b̂_a. Inputs broadcast over a leading axis."""
    C_en, C_en_true = c_en(lat, lon), c_en(truth_lat, truth_lon)
    C_ne = np.swapaxes(C_en, -1, -2)
    turn = normal_turn(normal(truth_lat, truth_lon), normal(lat, lon))
    q_turn = rot.from_rotation_vector(turn)
    q_eb = rot.multiply(rot.from_matrix(C_en), q_nb)
    q_eb_true = rot.multiply(rot.multiply(q_turn, rot.from_matrix(C_en_true)), truth_q_nb)
    phi_e = -rot.to_rotation_vector(rot.multiply(q_eb, rot.conjugate(q_eb_true)))
    v_e = np.einsum("...ij,...j->...i", C_en, v_n)
    v_e_true = rot.rotate(q_turn, np.einsum("...ij,...j->...i", C_en_true, truth_v_n))
    rows = lambda x: np.einsum("...ij,...j->...i", C_ne, x)  # noqa: E731
    dp = -ned_offset(truth_lat, truth_lon, truth_h, lat, lon, h)  # the truth from the estimate, in its NED; δh = −(−δD)
    dp[..., 2] *= -1.0
    return np.concatenate([rows(phi_e), rows(v_e - v_e_true), dp, np.asarray(truth_gyro_bias) - gyro_bias,
                           np.asarray(truth_accel_bias) - accel_bias], axis=-1)


def mounting_error(q_bs, truth_q_bs):
    """μ (..., 3) [rad] of the mounting estimate: q_BS,true = q̂_BS ⊗ δq(μ) (sensor axes)."""
    return rot.to_rotation_vector(rot.multiply(rot.conjugate(q_bs), truth_q_bs))

