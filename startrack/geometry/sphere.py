"""Directions on the celestial sphere: RA/Dec <-> unit vectors, angular distance, the azimuthal equidistant map.

Conventions (docs/design.md): inertial frame I = ICRS; RA = atan2(y, x) in [0, 2 pi),
Dec = asin(z); radians everywhere.
"""

import numpy as np


def radec_to_vector(ra, dec):
    """Unit vectors (..., 3) from right ascension and declination [rad]."""
    ra = np.asarray(ra, dtype=float)
    dec = np.asarray(dec, dtype=float)
    cos_dec = np.cos(dec)
    return np.stack([cos_dec * np.cos(ra), cos_dec * np.sin(ra), np.sin(dec)], axis=-1)


def vector_to_radec(v):
    """(RA in [0, 2 pi), Dec in [-pi/2, pi/2]) [rad] of vectors (..., 3); need not be unit."""
    v = np.asarray(v, dtype=float)
    norm = np.linalg.norm(v, axis=-1)
    ra = np.mod(np.arctan2(v[..., 1], v[..., 0]), 2.0 * np.pi)
    dec = np.arcsin(np.clip(v[..., 2] / norm, -1.0, 1.0))
    return ra, dec


def angular_distance(a, b):
    """Angle [rad] between direction arrays (..., 3), accurate at 0 and pi: atan2(|a x b|, a . b), the cross
    product written out (np.cross costs ~20 us a call, most of a small array's time)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    cross = np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                      a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)
    return np.arctan2(np.sqrt(np.sum(cross * cross, axis=-1)), np.sum(a * b, axis=-1))


def local_frame(ra, dec):
    """Unit vectors (..., 3) of the local frame at (ra, dec) [rad]: the direction u, east (increasing
    RA along the parallel) and north (increasing Dec along the meridian)."""
    ra = np.asarray(ra, dtype=float)
    dec = np.asarray(dec, dtype=float)
    sin_a, cos_a = np.sin(ra), np.cos(ra)
    sin_d, cos_d = np.sin(dec), np.cos(dec)
    u = np.stack([cos_d * cos_a, cos_d * sin_a, sin_d], axis=-1)
    east = np.stack([-sin_a, cos_a, np.zeros_like(ra)], axis=-1)
    north = np.stack([-sin_d * cos_a, -sin_d * sin_a, cos_d], axis=-1)
    return u, east, north


def tangent_basis(s):
    """Two orthonormal rows (N, 2, 3) spanning the plane perpendicular to each unit vector s (N, 3)."""
    helper = np.zeros_like(s)
    helper[np.arange(len(s)), np.argmin(np.abs(s), axis=1)] = 1.0
    e1 = np.cross(s, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return np.stack([e1, np.cross(s, e1)], axis=1)


def azimuthal_equidistant(ra, dec, centre_ra, centre_dec):
    """(x, y) (...,) [rad] of the directions at (ra, dec) [rad] on the azimuthal equidistant map centred at
    (centre_ra, centre_dec) (Snyder 1987, ch. 25): each at its angular distance from the centre, in its bearing there,
    x towards east (increasing ra), y towards north. No point is singular but the centre's antipode; the poles and the
    180° meridian are ordinary points (a map of any route on the Earth, longitude and latitude for ra and dec)."""
    centre, east, north = local_frame(centre_ra, centre_dec)
    u = radec_to_vector(ra, dec)
    distance = angular_distance(centre, u)
    e, n = u @ east, u @ north
    norm = np.hypot(e, n)
    scale = np.divide(distance, norm, out=np.zeros_like(distance), where=norm > 0.0)
    return e * scale, n * scale
