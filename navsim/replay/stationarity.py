"""Whether a land vehicle is at rest, from its IMU alone: the acceleration-moving variance detector of Skog et al. 2010
(§III, the MV detector of its likelihood-ratio family; the accelerometers, not the gyros: idling, the car drive's
gyros shake by 0.8-2.8 deg/s RMS, as much as while driving, its accelerometers' RMS deviation |y − ȳ| is under
0.16 m/s² at rest against 0.37-2.2 m/s² moving). Smooth motion without vibration looks like rest to it.

Over the W samples y_k (specific force [m/s²]) of a window, with ȳ their mean and σ_a the accelerometers' white noise
per sample [m/s²],

    T = (1 / (σ_a² W)) Σ_k |y_k − ȳ|²,                                                  (1)

and the window is at rest when T < γ. At rest y_k = f + n_k with n_k ~ N(0, σ_a² I), so σ_a² W T is σ_a² times a
chi-square of 3 (W − 1) degrees of freedom (the sample variance of 3 axes), and γ = χ²_p(3 (W − 1)) / W keeps a window
at rest with probability p. σ_a is the stated velocity random walk over the IMU interval, VRW / √Δt.
"""

import numpy as np

from navsim.estimation.consistency import chi2_quantile


def statistic(specific_force, ends, window, sigma):
    """T (E,) of eq. (1) over the ``window`` samples before each index of ``ends`` (E,) of the specific force
    ``specific_force`` (M, 3) [m/s²] of white noise ``sigma`` [m/s²] per sample (NaN where fewer samples precede)."""
    ends = np.asarray(ends, dtype=int)
    out = np.full(ends.size, np.nan)
    full = ends >= window
    if full.any():
        frames = np.lib.stride_tricks.sliding_window_view(specific_force, window, axis=0)[ends[full] - window]
        deviation = frames - frames.mean(axis=2, keepdims=True)  # (E, 3, W)
        out[full] = np.sum(deviation**2, axis=(1, 2)) / (sigma**2 * window)
    return out


def threshold(window, probability):
    """γ of eq. (1): the statistic a window at rest stays under with ``probability`` (module docstring)."""
    return chi2_quantile(probability, 3 * (window - 1)) / window


def at_rest(specific_force, ends, window, sigma, probability):
    """(E,) whether the vehicle is at rest over the ``window`` samples before each of ``ends``: T < γ (eq. 1)."""
    return statistic(specific_force, ends, window, sigma) < threshold(window, probability)
