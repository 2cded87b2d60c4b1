"""The Sun and the Moon seen from the vehicle: where they are at the frames of a run, for the exclusion
angles of the star sensor and the sky's background.

Geocentric positions in ICRS (GCRS) axes from pyerfa: the Sun from ``erfa.epv00`` (the Earth's
heliocentric position, VSOP2000-based; within 0.05" of JPL DE405 over 1900-2100) and the Moon from
``erfa.moon98`` (Meeus's abridged ELP, *Astronomical Algorithms* 2nd ed. ch. 47; about 10" in longitude,
3" in latitude); topocentric for the observer at r_I = C_ie r_e (parallax: up to 57' for the Moon).
Directions are geometric: the light time and the aberration move the Sun by ≤ 21" and the Moon by ≤ 1",
nothing for an exclusion angle. The Moon's phase angle i is the Sun-Moon-observer angle, its illuminated
fraction (1 + cos i)/2 (Meeus eq. 48.1); TDB is taken as TT (< 2 ms).
"""

from dataclasses import dataclass

import erfa
import numpy as np

from navsim.earth.frames import local_up, slowly, tt_epoch
from navsim.earth.wgs84 import geodetic_to_ecef
from startrack import angular_distance

#: The astronomical unit [m] (IAU 2012).
AU = erfa.DAU


@dataclass(frozen=True)
class SunMoon:
    """At the frame times ``t`` (F,) [s after the epoch]: unit directions from the observer to the Sun
    (``sun_I``) and the Moon (``moon_I``) (F, 3) in ICRS axes, the observer's local vertical ``up_I`` (F, 3),
    the Moon's distance ``moon_distance`` (F,) [m], phase angle ``moon_phase_angle`` (F,) [rad] and
    illuminated fraction ``moon_illuminated`` (F,)."""

    t: np.ndarray
    sun_I: np.ndarray
    moon_I: np.ndarray
    up_I: np.ndarray
    moon_distance: np.ndarray
    moon_phase_angle: np.ndarray
    moon_illuminated: np.ndarray

    @classmethod
    def compute(cls, epoch_utc, orientation, lat, lon, h):
        """The Sun and the Moon at the frames of an :class:`~navsim.earth.orientation.EarthOrientation`
        (its ``t`` and C_ie) for the observer at geodetic (L, λ, h) (F,) [rad, rad, m]."""
        r_I = np.einsum("fij,fj->fi", orientation.c_ie, np.stack(geodetic_to_ecef(lat, lon, h), axis=-1))
        return cls.seen_from(orientation.t, *geocentric(epoch_utc, orientation.t), r_I, local_up(orientation.c_ie, lat, lon))

    @classmethod
    def seen_from(cls, t, sun, moon, r_I, up_I):
        """The Sun and the Moon at the geocentric positions ``sun``, ``moon`` (F, 3) [m] (:func:`geocentric`) seen by
        the observer at the geocentric ``r_I`` (F, 3) [m] whose vertical is ``up_I`` (F, 3), at times ``t`` (F,) [s]."""
        to_sun, to_moon = sun - r_I, moon - r_I
        distance = np.linalg.norm(to_moon, axis=-1)
        phase = angular_distance(sun - moon, r_I - moon)
        return cls(t=t, sun_I=_unit(to_sun), moon_I=to_moon / distance[:, None], up_I=up_I, moon_distance=distance,
                   moon_phase_angle=phase, moon_illuminated=0.5 * (1.0 + np.cos(phase)))

    def elevation(self, u_I):
        """Elevation [rad] above the observer's horizontal plane of unit directions ``u_I`` (F, 3)."""
        return np.arcsin(np.clip(np.sum(u_I * self.up_I, axis=-1), -1.0, 1.0))


def geocentric(epoch_utc, t):
    """(sun (F, 3), moon (F, 3)) [m]: the geocentric positions of the Sun (``erfa.epv00``) and the Moon
    (``erfa.moon98``) in GCRS axes at ``t`` (F,) [s after the UTC epoch] (module docstring), evaluated on the 60 s grid
    of :func:`navsim.earth.frames.slowly` and interpolated (the curvature of their paths leaves < 3 m: 2e-11 rad of the
    Sun's direction, 3e-9 of the Moon's)."""
    def positions(s):
        tt = tt_epoch(epoch_utc, s)
        return np.stack([-erfa.epv00(*tt)[0]["p"] * AU, erfa.moon98(*tt)["p"] * AU], axis=-2)

    both = slowly(positions, np.asarray(t, dtype=float))
    return both[..., 0, :], both[..., 1, :]


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)
