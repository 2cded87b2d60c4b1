"""The Earth's disc seen from a spacecraft: which directions it hides and how near a sensor's boresight its limb is.

The Earth is the WGS-84 ellipsoid raised by a ``height`` [m] — the atmosphere that a star sensor counts as part of
the bright limb (a star behind it is refracted, extinguished or drowned; 50-100 km is the usual bright-limb
allowance). As in :mod:`navsim.orbit.eclipse`, stretching the coordinates along the Earth's axis by 1/(1 − f) turns
the ellipsoid into a sphere of radius a + h: a line of sight meets the ellipsoid exactly when its stretched image
meets the sphere, so what the disc hides is exact; the limb's angle from a direction is the stretched frame's (off
by up to f = 0.3 % of it).

The sunlit Earth's light at the spacecraft (:meth:`EarthDisc.albedo_irradiance`), the stray light a baffle lets
through when the limb is near a field: the Earth as a Lambert sphere of Bond albedo A (its geometric albedo 2A/3)
seen at the phase angle α (Sun-Earth-spacecraft) from the distance r,

    E_⊕ / E_☉ = (2A/3) (R/r)² Φ(α),   Φ(α) = (sin α + (π − α) cos α)/π   (Russell 1916; Lester et al. 1979),

0 over the night side (α = π): its irradiance normal to the line of sight as a fraction of the Sun's.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.wgs84 import A as R_EARTH
from navsim.earth.wgs84 import F as FLATTENING
from navsim.orbit.eclipse import stretched
from startrack import angular_distance


@dataclass(frozen=True)
class EarthDisc:
    """The Earth seen from the spacecraft's geocentric positions ``r_I`` (F, 3) [m] at F frames, its ellipsoid raised
    by ``height`` [m], the Earth's axis ``pole`` (3,) in GCRS (module docstring)."""

    r_I: np.ndarray
    height: float = 0.0
    pole: tuple = (0.0, 0.0, 1.0)

    def _centre_and_radius(self, frame):
        r = stretched(np.atleast_2d(self.r_I[frame]), np.asarray(self.pole), FLATTENING)
        distance = np.linalg.norm(r, axis=-1)
        return -r / distance[:, None], np.arcsin(np.minimum((R_EARTH + self.height) / distance, 1.0))

    def _stretched_directions(self, u_I):
        u = stretched(np.atleast_2d(u_I), np.asarray(self.pole), FLATTENING)
        return u / np.linalg.norm(u, axis=-1, keepdims=True)

    def limb_angle(self, u_I, frame=None):
        """The angle [rad] of the unit directions ``u_I`` (N, 3) above the Earth's limb at frames ``frame`` (N,)
        (default: u_I holds one direction per frame): negative on the disc."""
        frame = np.arange(len(self.r_I)) if frame is None else np.asarray(frame)
        centre, radius = self._centre_and_radius(frame)
        return angular_distance(self._stretched_directions(u_I), centre) - radius

    def hides(self, u_I, frame):
        """True for the directions ``u_I`` (N, 3) at frames ``frame`` (N,) that meet the raised ellipsoid."""
        return self.limb_angle(u_I, frame) < 0.0

    def albedo_irradiance(self, sun, albedo=0.3):
        """E_⊕ / E_☉ (F,) at every frame (module docstring) with the geocentric Sun at ``sun`` (F, 3) [m]."""
        r = np.atleast_2d(self.r_I)
        distance = np.linalg.norm(r, axis=-1)
        alpha = angular_distance(r / distance[:, None], sun / np.linalg.norm(sun, axis=-1, keepdims=True))
        phase = (np.sin(alpha) + (np.pi - alpha) * np.cos(alpha)) / np.pi
        return 2.0 * albedo / 3.0 * (R_EARTH / distance) ** 2 * phase

    def angular_radius(self):
        """The disc's angular radius (F,) [rad] at every frame (in the stretched frame)."""
        return self._centre_and_radius(np.arange(len(self.r_I)))[1]
