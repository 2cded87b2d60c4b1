"""The Earth's shadow on a spacecraft: the fraction of the Sun's disc it sees, by the conical (two-disc) model of
Montenbruck & Gill, *Satellite Orbits* (2000), §3.4.2, eqs. 3.85-3.87.

Seen from the spacecraft at r (geocentric), the Sun's disc has the apparent radius a = asin(R_☉/|s − r|), the
Earth's b = asin(R_⊕/|r|) and their centres are c apart (the angle between −r and s − r). The two discs overlap
when c < a + b: the spacecraft is in the penumbra while c > |a − b|, in the umbra (b > a) or an annular eclipse
(a > b) inside; the sunlit fraction is 1 − A/(π a²) with A the overlap's area (eq. 3.87, the discs taken flat:
their radii are < 70 deg in any orbit, the error below 1 % of the penumbra's depth at 300 km). The Earth is the
WGS-84 ellipsoid: the shadow is computed in coordinates whose z (along the Earth's axis) is stretched by
a/b = 1/(1 − f), where the ellipsoid is the sphere of radius a (the limb's line of tangency is affine-invariant,
so the instant the Sun's centre meets the limb is exact; the discs' angular sizes are then off by up to f, 0.3 %).
``flattening=0`` gives a sphere.
"""

import numpy as np

from navsim.earth.wgs84 import A as R_EARTH
from navsim.earth.wgs84 import F as FLATTENING
from startrack import angular_distance

#: The Sun's radius [m] (IAU 2015 nominal R_☉).
R_SUN = 6.957e8
#: The shadow states of :func:`shadow`.
SUNLIT, PENUMBRA, UMBRA, ANNULAR = 0, 1, 2, 3


def stretched(x, pole, flattening):
    """Positions x (..., 3) with their component along the unit ``pole`` stretched by 1/(1 − f) (module docstring)."""
    along = np.sum(x * pole, axis=-1, keepdims=True)
    return x + along * (1.0 / (1.0 - flattening) - 1.0) * pole


def discs(r_I, sun_I, pole=(0.0, 0.0, 1.0), radius=R_EARTH, flattening=FLATTENING):
    """(a, b, c) (N,) [rad]: the apparent radii of the Sun's and the Earth's discs and their centres' separation, seen
    from spacecraft at the geocentric positions ``r_I`` (N, 3) [m] with the geocentric Sun at ``sun_I`` (N, 3) [m];
    ``pole`` the Earth's axis (GCRS), ``radius`` its equatorial radius [m], ``flattening`` its f (module docstring).
    c − b is the Sun's centre's angle above the Earth's limb."""
    pole = np.asarray(pole, dtype=float)
    r = stretched(np.atleast_2d(r_I), pole, flattening)
    to_sun = stretched(np.atleast_2d(sun_I), pole, flattening) - r
    a = np.arcsin(np.minimum(R_SUN / np.linalg.norm(to_sun, axis=-1), 1.0))
    b = np.arcsin(np.minimum(radius / np.linalg.norm(r, axis=-1), 1.0))
    c = angular_distance(-r / np.linalg.norm(r, axis=-1, keepdims=True),
                         to_sun / np.linalg.norm(to_sun, axis=-1, keepdims=True))
    return a, b, c


def shadow(r_I, sun_I, pole=(0.0, 0.0, 1.0), radius=R_EARTH, flattening=FLATTENING):
    """(sunlit fraction (N,) in [0, 1], state (N,): :data:`SUNLIT`, :data:`PENUMBRA`, :data:`UMBRA`, :data:`ANNULAR`)
    of spacecraft at ``r_I`` (N, 3) [m] with the geocentric Sun at ``sun_I`` (N, 3) [m] (:func:`discs`)."""
    a, b, c = discs(r_I, sun_I, pole, radius, flattening)
    fraction = np.ones(len(a))
    state = np.full(len(a), SUNLIT)
    inside = c <= np.abs(a - b)
    umbra = inside & (b >= a)
    fraction[umbra], state[umbra] = 0.0, UMBRA
    annular = inside & (b < a)
    fraction[annular], state[annular] = 1.0 - (b[annular] / a[annular]) ** 2, ANNULAR
    partial = (c < a + b) & ~inside
    state[partial] = PENUMBRA
    fraction[partial] = 1.0 - overlap_area(a[partial], b[partial], c[partial]) / (np.pi * a[partial] ** 2)
    return fraction, state


def overlap_area(a, b, c):
    """The area where two discs of radii a and b with centres c apart overlap (|a − b| < c < a + b; eq. 3.87):
    A = a² acos(x/a) + b² acos((c − x)/b) − c y, x = (c² + a² − b²)/(2c), y = √(a² − x²)."""
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = np.sqrt(np.maximum(a * a - x * x, 0.0))
    return a * a * np.arccos(np.clip(x / a, -1.0, 1.0)) + b * b * np.arccos(np.clip((c - x) / b, -1.0, 1.0)) - c * y


def crossings(t, value, level=0.0):
    """(entries, exits) [s]: the times ``value`` (N,) sampled at ``t`` (N,) [s] falls below, and rises back above,
    ``level``, each interpolated linearly between samples (an eclipse's: the Sun's angle above the limb c − b of
    :func:`discs` through 0, or the sunlit fraction through 0.5)."""
    below = value < level
    change = np.flatnonzero(below[1:] != below[:-1])
    w = (value[change] - level) / (value[change] - value[change + 1])
    times = t[change] + w * (t[change + 1] - t[change])
    return times[below[change + 1]], times[~below[change + 1]]
