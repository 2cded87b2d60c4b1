"""Barometric altimeter: the height a baro reports for the vertical channel of the INS.

    h̃_k = y_k + b + n_k,   y_k = ρ y_(k−1) + (1 − ρ) h_k,   ρ = exp(−Δt/τ_lag),

a first-order lag of time constant τ_lag on the true height h (exact for a height held over each
sample interval; y_0 = h_0), a constant bias b (turn-on, 1σ ``bias_sigma``) plus a bias random walk
(``bias_rw``), and white noise n of σ ``noise_sigma``.
"""

from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter

from startrack import InputError


@dataclass(frozen=True)
class BaroRecord:
    """``h`` (M,) measured heights [m]; ``bias`` (M,) the true bias at each sample [m]."""

    h: np.ndarray
    bias: np.ndarray


@dataclass(frozen=True)
class BaroModel:
    """Baro error parameters: ``rate_hz``, ``noise_sigma`` [m], ``bias_sigma`` [m] (turn-on 1σ),
    ``bias_rw`` [m/√s], ``lag_time_constant`` [s] (0: no lag)."""

    rate_hz: float
    noise_sigma: float = 0.0
    bias_sigma: float = 0.0
    bias_rw: float = 0.0
    lag_time_constant: float = 0.0

    def __post_init__(self):
        if not self.rate_hz > 0.0:
            raise InputError(f"baro.rate_hz: must be > 0, got {self.rate_hz!r}")
        for key in ("noise_sigma", "bias_sigma", "bias_rw", "lag_time_constant"):
            if not getattr(self, key) >= 0.0:
                raise InputError(f"baro.{key}: must be >= 0, got {getattr(self, key)!r}")

    def measure(self, h_true, seed) -> BaroRecord:
        """Baro samples of the true heights ``h_true`` (M,) at the baro's rate; ``seed`` a
        SeedSequence or an int (constant bias and noise from two spawned sub-streams)."""
        h_true = np.asarray(h_true, dtype=float)
        if not isinstance(seed, np.random.SeedSequence):
            seed = np.random.SeedSequence(seed)
        bias_rng, noise_rng = (np.random.default_rng(s) for s in seed.spawn(2))
        dt = 1.0 / self.rate_hz
        bias = self.bias_sigma * bias_rng.standard_normal() + np.cumsum(
            self.bias_rw * np.sqrt(dt) * noise_rng.standard_normal(h_true.size))
        lagged = h_true
        if self.lag_time_constant > 0.0:
            rho = np.exp(-dt / self.lag_time_constant)
            lagged = lfilter([1.0 - rho], [1.0, -rho], h_true, zi=[rho * h_true[0]])[0]
        return BaroRecord(h=lagged + bias + self.noise_sigma * noise_rng.standard_normal(h_true.size), bias=bias)
