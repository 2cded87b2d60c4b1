"""The compile-ahead tasks of startrack (:mod:`startrack.compiled.compile_ahead`; the run kinds' ``lanes`` name
them ``"startrack.compile_tasks:<task>"``): each calls the kernels of one part of a run through the public
constructors a run uses, on small made-up inputs (so with a run's argument types)."""

import numpy as np

#: The camera of the compile-ahead tasks (the kernels' argument types do not depend on it).
_TASK_FOV_DEG, _TASK_SIZE_PX, _TASK_MAG = 16.0, 1024, 6.0


def _task_identifier(methods):
    from startrack.camera.model import Camera
    from startrack.catalog.navigation import NavigationCatalogParams, load_navigation_catalog
    from startrack.identify.identifier import StarIdentifier

    fov = np.radians(_TASK_FOV_DEG)
    catalog = load_navigation_catalog(NavigationCatalogParams(mag_limit=_TASK_MAG, fov=fov), progress=False)
    StarIdentifier(catalog, Camera.from_fov(fov, _TASK_SIZE_PX, _TASK_SIZE_PX), methods=methods)  # loads its kernels


def pattern_search():
    """Task: the kernels of the sub-catalog and lost-in-space searches (the pattern look-ups, the pyramid,
    verification) and of a whole solve."""
    _task_identifier(("subcatalog", "lost_in_space"))


def star_tracking():
    """Task: the kernels of tracking (verification around a prediction) and of a whole solve; after
    :func:`pattern_search` in another lane, it loads the verification that lane compiled."""
    _task_identifier(("tracking",))


def plate_solver():
    """Task: the kernels of the plate solver (an unknown camera's pattern search and self-calibration)."""
    from startrack.identify.plate_solver import PlateSolver

    PlateSolver()  # loads its kernels


def psf_fit():
    """Task: the kernels of the PSF fit, on a uint16 frame with a saturation level, as the image chain reads it:
    a star inside a larger frame (its window a strided slice) and one in a frame the size of its window (a
    contiguous one, as a tracking window's readout gives)."""
    from startrack.image.psf_fit import PixelNoise, fit_stars, half_width

    sigma, smear = 0.7, (2.0, 1.0)
    for size, centre in ((32, (15.3, 16.6)), (2 * half_width(sigma, smear) + 1, (half_width(sigma, smear),) * 2)):
        rows, cols = np.mgrid[0:size, 0:size]
        frame = 100.0 + 1000.0 * np.exp(-((cols - centre[0]) ** 2 + (rows - centre[1]) ** 2) / (2 * sigma**2))
        fit_stars(frame.astype(np.uint16), [[round(centre[0]), round(centre[1])]], sigma,
                  PixelNoise(10.0, gain_e_per_dn=2.0), 100.0, smear_px=[list(smear)], saturation_dn=4095.0)
