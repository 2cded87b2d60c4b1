"""Three-axis integrating accelerometer model, the twin of :mod:`navsim.sensors.gyro`.

Output sample k is the measured specific force averaged over its interval (a velocity increment
divided by Δt), f = a − g in body axes (at rest on a level table, NED body axes: [0, 0, −g]):

    f̃_k = (I + S)(I + M) f̄_k + ∇_c + ½(∇_(k−1) + ∇_k) + ½(g_(k−1) + g_k) + n_k

- S, M: scale-factor and misalignment errors; ∇_c: turn-on bias (constant);
- ∇_k: bias random walk, ∇_k = ∇_(k−1) + σ_∇ √Δt N(0, I);
- n_k: velocity random walk plus the in-interval part of the bias walk,
  σ = (σ_VRW²/Δt + σ_∇² Δt/12)^½ (the same exact discretisation as the gyro's);
- g_k: bias instability, a first-order Gauss-Markov process (σ_g, τ);
- then saturation and quantisation of the accumulated velocity to the LSB.

The synthesis is :func:`navsim.sensors.inertial.synthesize`, shared with the gyro (same seeding).
Units: SI (m/s², m/s/√s) inside; datasheet conversions in :mod:`startrack.base.units` (µg, m/s/√h).
"""

from dataclasses import dataclass, field

import numpy as np

from navsim.sensors import inertial
from startrack import units

#: The datasheet presets: VRW [m/s/√h], bias [µg], bias random walk [µg/√h], τ [s], scale factor [ppm], misalignment
#: [arcsec]; bias random walk, scale factor and misalignment typical of each grade.
PRESETS = {
    "navigation": inertial.Grade(0.002, 25.0, 2.0, 3600.0, 20.0, 5.0),
    "tactical": inertial.Grade(0.05, 1000.0, 50.0, 300.0, 300.0, 60.0),
    "mems": inertial.Grade(0.06, 500.0, 100.0, 100.0, 1000.0, 300.0),
}


@dataclass(frozen=True)
class AccelerometerRecord:
    """One accelerometer record: ``force`` (M, 3) measured interval-mean specific force [m/s²];
    ``bias`` (M, 3) the true total bias at each sample time; ``matrix`` the true (I+S)(I+M)."""

    force: np.ndarray
    bias: np.ndarray
    matrix: np.ndarray


@dataclass(frozen=True)
class AccelerometerModel:
    """Accelerometer error parameters, SI units. A field set to 0 switches that error off."""

    rate_hz: float
    vrw: float = 0.0  # velocity random walk [m/s/√s]
    bias_rw: float = 0.0  # bias random walk [m/s²/√s]
    bias_turn_on_sigma: float = 0.0  # 1σ per axis of the constant bias [m/s²]
    bias_instability_sigma: float = 0.0  # steady σ_g of the Gauss-Markov bias [m/s²]
    bias_correlation_time: float = 300.0  # τ [s]
    scale_factor_sigma: float = 0.0  # 1σ per axis [-]
    misalignment_sigma: float = 0.0  # 1σ per off-diagonal element [rad]
    quantization: float = 0.0  # velocity-increment LSB [m/s]
    saturation: float = np.inf  # |specific force| limit [m/s²]
    bias_turn_on: tuple | None = field(default=None)  # fixed turn-on bias [m/s²] instead of a draw

    @property
    def dt(self):
        return 1.0 / self.rate_hz

    @property
    def white_noise(self):
        return self.vrw

    @property
    def random_walk(self):
        return self.bias_rw

    @classmethod
    def preset(cls, name, rate_hz):
        """A datasheet preset of :data:`PRESETS`, beside the gyro's (:func:`navsim.sensors.inertial.preset_fields`)."""
        return cls(rate_hz=rate_hz, **inertial.preset_fields("accelerometer", PRESETS, name, ("vrw", units.vrw_to_si),
                                                             ("bias_rw", units.micro_g_per_sqrt_h_to_si), units.micro_g_to_si))

    @property
    def filter_bias_rw(self):
        """Random-walk σ a bias state should assume: bias RW plus the Gauss-Markov driving noise."""
        return inertial.filter_random_walk(self)

    def measure(self, force_mean, seed) -> AccelerometerRecord:
        """Accelerometer samples for true interval-mean specific forces ``force_mean`` (M, 3) [m/s²]
        (Δv/Δt of a truth trajectory); ``seed`` a SeedSequence or an int."""
        force, bias, matrix = inertial.synthesize(self, force_mean, seed)
        return AccelerometerRecord(force=force, bias=bias, matrix=matrix)
