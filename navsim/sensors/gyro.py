"""Three-axis rate-integrating gyro model.

Output sample k is the measured rate averaged over its interval [t_(k-1), t_k] of length Δt
(a delta-angle divided by Δt):

    ω̃_k = (I + S)(I + M) ω̄_k + b_c + ½(b_(k-1) + b_k) + ½(g_(k-1) + g_k) + n_k

- ω̄_k: true mean body rate over the interval; S = diag(scale-factor errors); M: small
  misalignment / non-orthogonality (off-diagonal) matrix; b_c: turn-on bias (constant).
- b_k: rate random walk, b_k = b_(k-1) + σ_u √Δt N(0, I).
- n_k: angle random walk plus the in-interval part of the bias walk,
  σ = (σ_v²/Δt + σ_u² Δt/12)^½ — the exact discretisation of the continuous model
  ω̃ = ω + β + η_v, β̇ = η_u (Farrenkopf 1978; Crassidis & Junkins, *Optimal Estimation of
  Dynamic Systems*, 2nd ed., §7.2.1).
- g_k: bias instability as a first-order Gauss-Markov process with steady σ_g and correlation
  time τ: g_k = φ g_(k-1) + σ_g (1 − φ²)^½ N(0, I), φ = exp(−Δt/τ).
- then saturation (clip to ± saturation) and quantisation of the accumulated angle to the
  LSB (so quantisation error does not accumulate).

Units: SI (rad, s) inside; conversions from datasheet units are in :mod:`startrack.base.units`.
"""

from dataclasses import dataclass, field

import numpy as np

from navsim.sensors import inertial
from navsim.sensors.inertial import allan_variance, bias_instability_to_sigma  # noqa: F401  (the gyro's API)
from startrack import units

#: The datasheet presets: ARW [deg/√h], bias [deg/h], RRW [deg/h/√h], τ [s], scale factor [ppm], misalignment
#: [arcsec]; RRW, scale factor and misalignment typical of each grade.
PRESETS = {
    "navigation": inertial.Grade(0.002, 0.0035, 0.0003, 3600.0, 5.0, 5.0),
    "tactical": inertial.Grade(0.125, 1.0, 0.05, 300.0, 100.0, 60.0),
    "mems": inertial.Grade(0.15, 0.5, 0.3, 100.0, 500.0, 300.0),
}


@dataclass(frozen=True)
class GyroRecord:
    """One gyro record: ``omega`` (M, 3) measured rates [rad/s]; ``bias`` (M, 3) the true total
    bias (turn-on + random walk + Gauss-Markov) at each sample time, the filter's target;
    ``matrix`` the true (I+S)(I+M)."""

    omega: np.ndarray
    bias: np.ndarray
    matrix: np.ndarray


@dataclass(frozen=True)
class GyroModel:
    """Gyro error parameters, SI units. A field set to 0 switches that error off."""

    rate_hz: float
    arw: float = 0.0  # σ_v, angle random walk [rad/√s]
    rrw: float = 0.0  # σ_u, rate random walk [rad/s^(3/2)]
    bias_turn_on_sigma: float = 0.0  # 1σ per axis of the constant bias [rad/s]
    bias_instability_sigma: float = 0.0  # steady σ_g of the Gauss-Markov bias [rad/s]
    bias_correlation_time: float = 300.0  # τ [s]
    scale_factor_sigma: float = 0.0  # 1σ per axis [-]
    misalignment_sigma: float = 0.0  # 1σ per off-diagonal element [rad]
    quantization: float = 0.0  # delta-angle LSB [rad]
    saturation: float = np.inf  # |rate| limit [rad/s]
    bias_turn_on: tuple | None = field(default=None)  # fixed turn-on bias [rad/s] instead of a draw

    @property
    def dt(self):
        return 1.0 / self.rate_hz

    @classmethod
    def preset(cls, name, rate_hz):
        """A datasheet preset of :data:`PRESETS` (:func:`navsim.sensors.inertial.preset_fields`)."""
        return cls(rate_hz=rate_hz, **inertial.preset_fields("gyro", PRESETS, name, ("arw", units.arw_to_si),
                                                             ("rrw", units.rrw_to_si), units.deg_per_h_to_rad_per_s))

    @property
    def white_noise(self):
        return self.arw

    @property
    def random_walk(self):
        return self.rrw

    @property
    def filter_rrw(self):
        """Random-walk σ_u a 6-state filter should assume: RRW plus the Gauss-Markov driving
        noise (2 σ_g²/τ)^½ [rad/s^(3/2)]."""
        return inertial.filter_random_walk(self)

    def draw_errors(self, rng):
        """Constant errors of one unit: (turn-on bias (3,), matrix (I+S)(I+M) (3, 3))."""
        return inertial.draw_errors(self, rng)

    def measure(self, omega_mean, seed) -> "GyroRecord":
        """Gyro samples for true interval-mean rates ``omega_mean`` (M, 3) [rad/s].

        ``seed`` is a :class:`numpy.random.SeedSequence` (or an int); the constant errors and
        the noise come from two spawned sub-streams (:func:`navsim.sensors.inertial.synthesize`).
        """
        omega, bias, matrix = inertial.synthesize(self, omega_mean, seed)
        return GyroRecord(omega=omega, bias=bias, matrix=matrix)
