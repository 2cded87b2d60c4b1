"""What the gyro and the accelerometer models share: one three-axis inertial-sensor error synthesis.

A model is a frozen dataclass with ``rate_hz`` and the error fields ``bias_turn_on_sigma``,
``bias_turn_on``, ``bias_instability_sigma``, ``bias_correlation_time``, ``scale_factor_sigma``,
``misalignment_sigma``, ``quantization``, ``saturation``, plus two properties: ``white_noise``
(σ of the white-noise density: ARW for a gyro, VRW for an accelerometer [unit/√s]) and
``random_walk`` (σ of the bias random walk: RRW or the accelerometer bias random walk
[unit/s/√s]). Sample k is the measured quantity averaged over its interval (an increment / Δt):

    ỹ_k = (I + S)(I + M) ȳ_k + b_c + ½(b_(k−1) + b_k) + ½(g_(k−1) + g_k) + n_k

(see :mod:`navsim.sensors.gyro` for each term and its exact discretisation), then saturation and
quantisation of the accumulated increment.
"""

from dataclasses import dataclass

import numpy as np

from startrack import njit, units

#: Ratio of the flicker-floor definition of bias instability B (ADEV floor = 0.664 B, IEEE 952)
#: to the peak Allan deviation of a first-order Gauss-Markov process of unit σ (0.6174 at τ ≈ 1.893 T,
#: the maximum of :func:`allan_variance` below).
GAUSS_MARKOV_PEAK_ADEV = 0.6174
FLICKER_FLOOR_FACTOR = 0.664


def draw_errors(model, rng):
    """Constant errors of one unit: (turn-on bias (3,), matrix (I+S)(I+M) (3, 3))."""
    if model.bias_turn_on is not None:
        bias = np.asarray(model.bias_turn_on, dtype=float)
        rng.standard_normal(3)  # keep the stream layout independent of the option
    else:
        bias = model.bias_turn_on_sigma * rng.standard_normal(3)
    scale = model.scale_factor_sigma * rng.standard_normal(3)
    misalignment = model.misalignment_sigma * rng.standard_normal((3, 3))
    np.fill_diagonal(misalignment, 0.0)
    return bias, np.diag(1.0 + scale) @ (np.eye(3) + misalignment)


def synthesize(model, mean, seed):
    """Samples of ``model`` for true interval means ``mean`` (M, 3): (samples (M, 3), total bias
    (M, 3) at each sample time, matrix (3, 3)). ``seed`` is a SeedSequence or an int; the constant
    errors and the noise come from two spawned sub-streams."""
    mean = np.asarray(mean, dtype=float)
    m = mean.shape[0]
    dt = 1.0 / model.rate_hz
    if not isinstance(seed, np.random.SeedSequence):
        seed = np.random.SeedSequence(seed)
    error_rng, noise_rng = (np.random.default_rng(s) for s in seed.spawn(2))
    bias_c, matrix = draw_errors(model, error_rng)
    n_white, n_walk, n_gm, gm0 = (
        noise_rng.standard_normal((m, 3)),
        noise_rng.standard_normal((m, 3)),
        noise_rng.standard_normal((m, 3)),
        noise_rng.standard_normal(3),
    )
    walk = np.vstack([np.zeros(3), np.cumsum(model.random_walk * np.sqrt(dt) * n_walk, axis=0)])
    phi = np.exp(-dt / model.bias_correlation_time)
    drive = model.bias_instability_sigma * np.sqrt(1.0 - phi * phi) * n_gm
    gm = gauss_markov(model.bias_instability_sigma * gm0, phi, drive)
    sigma_white = np.sqrt(model.white_noise**2 / dt + model.random_walk**2 * dt / 12.0)
    out = (
        mean @ matrix.T
        + bias_c
        + 0.5 * (walk[:-1] + walk[1:])
        + 0.5 * (gm[:-1] + gm[1:])
        + sigma_white * n_white
    )
    out = np.clip(out, -model.saturation, model.saturation)
    if model.quantization > 0.0:
        accumulated = np.cumsum(out * dt, axis=0)
        counts = np.round(accumulated / model.quantization)
        counts = np.diff(np.vstack([np.zeros(3), counts]), axis=0)
        out = counts * model.quantization / dt
    return out, bias_c + walk[1:] + gm[1:], matrix


@njit
def gauss_markov(g0, phi, drive):
    """The first-order Gauss-Markov sequence g_(k+1) = φ g_k + drive_k from g_0 (3,): (M+1, 3)."""
    g = np.empty((drive.shape[0] + 1, drive.shape[1]))
    g[0] = g0
    for k in range(drive.shape[0]):
        for i in range(drive.shape[1]):
            g[k + 1, i] = drive[k, i] + phi * g[k, i]
    return g


@dataclass(frozen=True)
class Grade:
    """One grade of an inertial sensor's datasheet (a preset) in the datasheet's units: the ``white`` noise and
    ``random_walk`` (the sensor's units, e.g. deg/√h and deg/h/√h), the ``bias`` figure (the turn-on 1σ and the
    bias-instability floor B), the Gauss-Markov ``correlation_time`` [s], ``scale_factor_ppm`` and
    ``misalignment_arcsec``."""

    white: float
    bias: float
    random_walk: float
    correlation_time: float
    scale_factor_ppm: float
    misalignment_arcsec: float


def preset_fields(sensor, grades, name, white, random_walk, bias):
    """The SI fields of the preset ``name`` of ``grades`` ({name: :class:`Grade`}) of a ``sensor`` (its name in the
    message): ``white`` and ``random_walk`` each (the model's field, the datasheet-to-SI conversion), ``bias`` the
    bias figure's conversion, used both as the turn-on 1σ and as the bias-instability floor B
    (σ_g = 0.664 B / 0.6174, :func:`bias_instability_to_sigma`)."""
    if name not in grades:
        raise ValueError(f"unknown {sensor} preset {name!r}; choose one of {', '.join(grades)}")
    grade = grades[name]
    b = bias(grade.bias)
    return {white[0]: float(white[1](grade.white)), random_walk[0]: float(random_walk[1](grade.random_walk)),
            "bias_turn_on_sigma": float(b), "bias_instability_sigma": float(bias_instability_to_sigma(b)),
            "bias_correlation_time": grade.correlation_time, "scale_factor_sigma": grade.scale_factor_ppm * units.PPM,
            "misalignment_sigma": float(units.arcsec_to_rad(grade.misalignment_arcsec))}


def filter_random_walk(model):
    """Random-walk σ a bias state of a Kalman filter should assume: the model's random walk plus the
    Gauss-Markov driving noise (2 σ_g²/τ)^½ [unit/s/√s]."""
    gm = 0.0
    if model.bias_instability_sigma > 0.0:
        gm = 2.0 * model.bias_instability_sigma**2 / model.bias_correlation_time
    return float(np.sqrt(model.random_walk**2 + gm))


def bias_instability_to_sigma(bias_instability):
    """Gauss-Markov σ_g whose peak Allan deviation equals the flicker floor 0.664 B."""
    return FLICKER_FLOOR_FACTOR * bias_instability / GAUSS_MARKOV_PEAK_ADEV


def allan_variance(tau, model):
    """Theoretical Allan variance [unit²] of the model's noise terms at cluster times tau [s].

    White noise N: N²/τ; random walk K: K² τ/3; Gauss-Markov of σ_g, T: with r = τ/T,
    σ_g² [2(r − 1 + e^(−r))/r² − (1 − e^(−r))²/r²] (IEEE Std 952-1997, annex C).
    """
    tau = np.asarray(tau, dtype=float)
    avar = model.white_noise**2 / tau + model.random_walk**2 * tau / 3.0
    if model.bias_instability_sigma > 0.0:
        r = tau / model.bias_correlation_time
        e = np.exp(-r)
        avar = avar + model.bias_instability_sigma**2 * (2.0 * (r - 1.0 + e) - (1.0 - e) ** 2) / r**2
    return avar
