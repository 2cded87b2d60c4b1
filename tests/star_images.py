"""Star images made without the project's renderer, for the centroid tests and the image-chain benchmark:
numpy and scipy's erf only.

A star of N_e photoelectrons is a Gaussian PSF of radius ``sigma`` [px] integrated over each unit pixel and
averaged over ``steps`` points of a uniform track of length ``smear`` = (Δu, Δv) [px] about its centre
(u, v) (u the column, v the row); the sky adds ``sky_e`` per pixel; the charge is drawn from the Poisson
law, the read noise from the Gaussian, then divided by the gain [e-/DN], offset by the bias and rounded to
whole DN (no saturation: the tests that need it clip themselves).
"""

import numpy as np
from scipy.special import erf


def expected_electrons(shape, stars, sigma, steps=256):
    """The noise-free star charge [e-] of an image (rows, cols) of the stars [(u, v, N_e, (Δu, Δv)), ...]."""
    rows, cols = np.arange(shape[0]), np.arange(shape[1])
    image = np.zeros(shape)
    a = 1.0 / (np.sqrt(2.0) * sigma)
    s = (np.arange(steps) + 0.5) / steps - 0.5
    for u, v, electrons, (du, dv) in stars:
        for point in s:
            cu, cv = u + point * du, v + point * dv
            fx = 0.5 * (erf((cols - cu + 0.5) * a) - erf((cols - cu - 0.5) * a))
            fy = 0.5 * (erf((rows - cv + 0.5) * a) - erf((rows - cv - 0.5) * a))
            image += np.outer(fy, fx) * (electrons / steps)
    return image


def noisy_frame(rng, shape, stars, sigma, sky_e=100.0, read_e=5.0, gain=1.0, bias=100.0):
    """A frame [DN] (float, whole numbers) of the stars with the noise of the module docstring."""
    charge = rng.poisson(expected_electrons(shape, stars, sigma) + sky_e) + rng.normal(0.0, read_e, shape)
    return np.rint(charge / gain + bias)
