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
        """Datasheet presets beside the gyro's: 'navigation' (VRW 0.002 m/s/√h, bias 25 µg),
        'tactical' (0.05, 1000) and 'mems' (0.06, 500). The bias figure is the turn-on 1σ and the
        bias-instability floor B (σ_g = 0.664 B / 0.6174); bias random walk, scale factor and
        misalignment are typical of each grade."""
        table = {
            # vrw m/s/√h, bias µg, bias rw µg/√h, τ s, scale ppm, misalignment arcsec
            "navigation": (0.002, 25.0, 2.0, 3600.0, 20.0, 5.0),
            "tactical": (0.05, 1000.0, 50.0, 300.0, 300.0, 60.0),
            "mems": (0.06, 500.0, 100.0, 100.0, 1000.0, 300.0),
        }
        if name not in table:
            raise ValueError(f"unknown accelerometer preset {name!r}; choose one of {', '.join(table)}")
        vrw, bias, bias_rw, tau, scale_ppm, misalignment_arcsec = table[name]
        return cls(
            rate_hz=rate_hz,
            vrw=float(units.vrw_to_si(vrw)),
            bias_rw=float(units.micro_g_per_sqrt_h_to_si(bias_rw)),
            bias_turn_on_sigma=float(units.micro_g_to_si(bias)),
            bias_instability_sigma=float(inertial.bias_instability_to_sigma(units.micro_g_to_si(bias))),
            bias_correlation_time=tau,
            scale_factor_sigma=scale_ppm * units.PPM,
            misalignment_sigma=float(units.arcsec_to_rad(misalignment_arcsec)),
        )

    @property
    def filter_bias_rw(self):
        """Random-walk σ a bias state should assume: bias RW plus the Gauss-Markov driving noise."""
        return inertial.filter_random_walk(self)

    def measure(self, force_mean, seed) -> AccelerometerRecord:
        """Accelerometer samples for true interval-mean specific forces ``force_mean`` (M, 3) [m/s²]
        (Δv/Δt of a truth trajectory); ``seed`` a SeedSequence or an int."""
        force, bias, matrix = inertial.synthesize(self, force_mean, seed)
        return AccelerometerRecord(force=force, bias=bias, matrix=matrix)
