"""The compile-ahead task of the image chain's position fit (:mod:`startrack.precompile`; the run kinds'
``lanes``): it calls :func:`startrack.psf_fit.fit_stars` as a run does, on a made-up frame of one star."""

import numpy as np


def psf_fit():
    """Task: the kernels of the PSF fit, on a uint16 frame with a saturation level, as the image chain reads it."""
    from startrack.psf_fit import PixelNoise, fit_stars

    rows, cols = np.mgrid[0:32, 0:32]
    frame = 100.0 + 1000.0 * np.exp(-((cols - 15.3) ** 2 + (rows - 16.6) ** 2) / (2 * 0.7**2))
    fit_stars(frame.astype(np.uint16), [[15.0, 17.0]], 0.7, PixelNoise(10.0, gain_e_per_dn=2.0), 100.0,
              smear_px=[[2.0, 1.0]], saturation_dn=4095.0)
