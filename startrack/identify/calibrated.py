"""Identification of frames from a calibrated camera, as a star tracker runs (``startrack solve --camera
FILE`` or ``--fov-deg F``): the navigation catalog of 000 and a :class:`StarIdentifier` built once for
the camera, and the attitude of *that* camera's frame S -- +z through its principal point -- with the
Cramér-Rao covariance of the matched stars (the SVD solution of Wahba's problem attains it; Markley
1988, docs/references.md).

:class:`CalibratedSolver` takes a frame as :class:`startrack.identify.plate_solver.PlateSolver` does
(``solve(uv, width, height, flux, sigma_px, boresight)``), so the command line holds either.  The
identifier's gates use one centroid sigma (``centroid_sigma_px``), and the covariance is the bound for
it; when a frame's stars come with sigmas estimated from the image (its detections), the attitude is
refitted with those weights and the covariance is the bound for them, scaled by max(1, chi^2 / dof) of
the residuals (estimated sigmas are a lower bound of a real camera's errors).

Catalog depth: ``mag_limit``, or by default the shallowest of :data:`_DEPTHS` at which the camera's field
holds :data:`_FIELD_STARS` catalog stars on average, N(V <= m) Omega / (4 pi) (16 deg: V 6; 5 deg: V 7.5).
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from startrack.attitude.solvers import SvdWahba
from startrack.geometry.sphere import vector_to_radec
from startrack.identify.identifier import StarIdentifier
from startrack.identify.prior import Prior
from startrack.identify.result import IdentificationResult
from startrack.identify.verify import DEFAULT_FALSE_MATCH_THRESHOLD, field_solid_angle

#: Catalog stars the field holds on average at the default depth.
_FIELD_STARS = 15.0
#: Catalog depths [V mag] the default is chosen from.
_DEPTHS = (6.0, 6.5, 7.0, 7.5, 8.0)


def _default_mag_limit(camera, v_mag) -> float:
    """The shallowest of :data:`_DEPTHS` at which ``camera``'s field holds :data:`_FIELD_STARS` of the stars
    of magnitudes ``v_mag`` on average (the deepest when none does)."""
    fraction = field_solid_angle(camera) / (4.0 * math.pi)
    for depth in _DEPTHS:
        if np.count_nonzero(np.asarray(v_mag) <= depth) * fraction >= _FIELD_STARS:
            return depth
    return _DEPTHS[-1]


class CalibratedSolver:
    """Star identification of frames from one calibrated ``camera`` (:class:`startrack.camera.model.Camera`).

    mag_limit: depth of the navigation catalog [V mag] (default :func:`_default_mag_limit`); epoch: of the
    star positions [Julian year]; centroid_sigma_px: the centroid noise the identifier's gates assume
    [px]; threshold: largest accepted false-match probability.
    """

    def __init__(self, camera, mag_limit=None, epoch=2000.0, centroid_sigma_px=0.3,
                 threshold=DEFAULT_FALSE_MATCH_THRESHOLD, progress=False):
        from startrack.catalog.hipparcos import load_star_catalog
        from startrack.catalog.navigation import NavigationCatalogParams, load_navigation_catalog

        stars = load_star_catalog(epoch)
        self.mag_limit = _default_mag_limit(camera, stars.v_mag) if mag_limit is None else float(mag_limit)
        params = NavigationCatalogParams(mag_limit=self.mag_limit, fov=camera.angular_width, epoch=epoch)
        self.camera = camera
        self.identifier = StarIdentifier(load_navigation_catalog(params, progress=progress), camera,
                                         centroid_sigma_px=centroid_sigma_px, false_match_threshold=threshold)

    def solve(self, uv, width, height, flux=None, sigma_px=None, boresight=None) -> IdentificationResult:
        """Identify the centroids ``uv`` (n, 2) [px] of a ``width`` x ``height`` frame; ``flux`` (n,) orders
        them (brightest first; else given order); ``sigma_px`` (n,) their centroid sigma estimated from the
        image [px] (default: the identifier's, as stated); ``boresight`` = (axis (3,), radius [rad]) a prior
        boresight, searched first.  Never raises for the frame's content."""
        start = time.perf_counter()
        cam = self.camera
        if (width, height) != (cam.width, cam.height):
            return _failed(f"the camera is {cam.width} x {cam.height} px, the frame {width} x {height} px", start)
        sigma = _checked_sigma(sigma_px, np.shape(uv)[0] if np.ndim(uv) else 0)
        if isinstance(sigma, str):
            return _failed(sigma, start)
        prior = None if boresight is None else Prior(boresight=tuple(float(x) for x in vector_to_radec(boresight[0])))
        result = self.identifier.solve(uv, flux, prior)
        if not result.ok or sigma is None:
            return result
        return self._weighted(result, sigma[result.matches[:, 0]] / cam.focal_px, start)

    @staticmethod
    def _weighted(result, sigma, start):
        """``result`` with the stars' own angular sigma (M,) [rad]: the attitude refitted with their weights
        (SVD, efficient), the sigma scaled by sqrt(max(1, chi^2 / dof)) of its residuals (dof = 2 M - 3):
        estimated sigmas are a lower bound of a real camera's errors, as in :mod:`startrack.camera.fit`."""
        solution = SvdWahba().solve(result.ref_I, result.obs_S, sigma)
        chi2 = float(np.sum((solution.residuals / sigma) ** 2))
        scale = math.sqrt(max(1.0, chi2 / max(2 * len(sigma) - 3, 1)))
        return dataclasses.replace(result, q_IS=solution.q_IS, sigma=sigma * scale,
                                   solve_ms=1e3 * (time.perf_counter() - start))


def _checked_sigma(sigma_px, n):
    """``sigma_px`` as an (n,) array of positive numbers, None when not given, or the reason it is not one."""
    if sigma_px is None:
        return None
    try:
        sigma = np.asarray(sigma_px, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        return "centroid sigma must be numbers"
    if sigma.shape != (n,) or not np.all(np.isfinite(sigma) & (sigma > 0.0)):
        return f"centroid sigma needs one finite value > 0 per centroid ({n})"
    return sigma


def _failed(reason, start):
    return IdentificationResult(status="error", reason=reason + ".", solve_ms=1e3 * (time.perf_counter() - start))
