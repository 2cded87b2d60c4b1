"""Star images made without the project's renderer, for the centroid and trailed-detection tests and their
benchmarks: numpy and scipy's erf only.

A star of N_e photoelectrons is a Gaussian PSF of radius ``sigma`` [px] integrated over each unit pixel and
averaged over ``steps`` points of a uniform track of length ``smear`` = (Δu, Δv) [px] about its centre
(u, v) (u the column, v the row); the sky adds ``sky_e`` per pixel; the charge is drawn from the Poisson
law, the read noise from the Gaussian, then divided by the gain [e-/DN], offset by the bias and rounded to
whole DN (no saturation: the tests that need it clip themselves).  The Poisson sky is skewed, which lifts a
matched filter's false detections above eq. 4 of :mod:`startrack.image.trail_detection` (Gaussian noise):
:func:`poisson_sky_lift`.
"""

import numpy as np
from scipy.special import erf
from scipy.stats import norm


#: Reach of a star's light beyond its track [PSF radii]: beyond 8.3 σ erf rounds to 1 and the profile is exactly 0.
_REACH_SIGMA = 10.0


def expected_electrons(shape, stars, sigma, steps=256):
    """The noise-free star charge [e-] of an image (rows, cols) of the stars [(u, v, N_e, (Δu, Δv)), ...], each
    drawn on the pixels within 10 σ + 1 px of its track (the others' share is exactly 0 in double precision)."""
    image = np.zeros(shape)
    a = 1.0 / (np.sqrt(2.0) * sigma)
    s = (np.arange(steps) + 0.5) / steps - 0.5
    for u, v, electrons, (du, dv) in stars:
        reach = _REACH_SIGMA * sigma + 1.0
        r0, r1 = (int(np.clip(x, 0, shape[0])) for x in (v - abs(dv) / 2 - reach, v + abs(dv) / 2 + reach + 1))
        c0, c1 = (int(np.clip(x, 0, shape[1])) for x in (u - abs(du) / 2 - reach, u + abs(du) / 2 + reach + 1))
        rows, cols = np.arange(r0, r1), np.arange(c0, c1)
        for point in s:
            cu, cv = u + point * du, v + point * dv
            fx = 0.5 * (erf((cols - cu + 0.5) * a) - erf((cols - cu - 0.5) * a))
            fy = 0.5 * (erf((rows - cv + 0.5) * a) - erf((rows - cv - 0.5) * a))
            image[r0:r1, c0:c1] += np.outer(fy, fx) * (electrons / steps)
    return image


def noisy_frame(rng, shape, stars, sigma, sky_e=100.0, read_e=5.0, gain=1.0, bias=100.0):
    """A frame [DN] (float, whole numbers) of the stars with the noise of the module docstring."""
    charge = rng.poisson(expected_electrons(shape, stars, sigma) + sky_e) + rng.normal(0.0, read_e, shape)
    return np.rint(charge / gain + bias)


def poisson_sky_lift(template, threshold, sky_e, pixel_variance_dn2, gain=1.0):
    """The factor by which these frames' Poisson sky lifts the false detections of a matched filter of
    ``template`` at the SNR ``threshold`` above its Gaussian-noise rate: the filter's skewness
    γ = κ₃ Σt³ / (v Σt²)^(3/2) (κ₃ = sky_e / g³ [DN³] the sky's third cumulant, v the pixel variance [DN²]) in the
    Edgeworth tail 1 + γ (u² − 1) φ(u) / (6 Q(u))."""
    skew = sky_e / gain**3 * np.sum(template**3) / (pixel_variance_dn2 * np.sum(template**2)) ** 1.5
    return float(1.0 + skew * (threshold**2 - 1.0) * norm.pdf(threshold) / (6.0 * norm.sf(threshold)))
