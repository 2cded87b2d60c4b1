"""Apparent star directions: the aberration of light seen by an observer moving relative to the
solar-system barycentre, and the Earth's barycentric velocity that drives its annual part.

Frames (docs/design.md, "Apparent star directions"): catalog directions ``u`` are ICRS astrometric
unit vectors (BCRS, proper motion applied by the catalog), taken as the natural directions erfa.ab
expects; apparent directions are after aberration, in the observer's proper frame with ICRS axes
(the GCRS axes for an observer at the Earth). Velocities are barycentric [m/s], ICRS axes. Left
out: the Sun's light deflection (<= 4 mas at 90 deg from the Sun) and annual parallax (<= 0.8").

Equations: IERS/SOFA's relativistic aberration, pyerfa's ``erfa.ab`` (the Explanatory Supplement
to the Astronomical Almanac, 3rd ed., expr. 7.40, rigorously normalised, with the Sun's potential
term of Klioner 2003); Kaplan, USNO Circular 179, for the chain from catalog to apparent place.
"""

import erfa
import numpy as np

from startrack.base.errors import InputError

#: Speed of light [m/s] (IAU; erfa's CMPS).
SPEED_OF_LIGHT = erfa.CMPS
#: Sun-observer distance [au] passed to erfa.ab as ``s``. It enters only in the Sun's
#: gravitational-potential term (SRS/s)(β − (u·β)u), SRS = 1.97e-8 au, β = v/c: 0.4 µas at the
#: Earth's 30 km/s; 1 au instead of the Earth's 0.983-1.017 au changes it by < 0.01 µas.
SUN_DISTANCE_AU = 1.0
#: Directions whose norm differs from 1 by more than this are refused (they are not directions).
_UNIT_TOLERANCE = 1e-6
#: The span of erfa.epv00's series, Julian dates of 1900-01-01 and 2100-12-31 (TDB).
_EPV00_SPAN_JD = (2415020.5, 2488069.5)


def aberrate(u, v):
    """Apparent unit directions (..., 3) of catalog directions ``u`` (..., 3) seen by an observer
    moving at barycentric velocity ``v`` [m/s] (3,) or (..., 3), ICRS axes; broadcast together.

    The shift is towards the velocity (the apex), of size |v|/c sin θ to first order, θ the angle
    from the velocity: up to 20.5" for the Earth's orbital 29.8 km/s, 0.32" for the equator's
    465 m/s rotation, 5.3" for a satellite's 7.7 km/s. erfa.ab, relativistic, with
    bm1 = sqrt(1 − |v/c|²) and s = ``SUN_DISTANCE_AU``. Bad input (NaN, non-unit ``u``, |v| >= c)
    raises InputError.
    """
    u, beta = _checked("aberrate", u, v)
    return _ab(u, beta)


def unaberrate(u_apparent, v):
    """Catalog unit directions (..., 3) whose apparent directions are ``u_apparent`` (..., 3) for
    an observer at barycentric velocity ``v`` [m/s]: the inverse of :func:`aberrate`.

    The exact Lorentz inverse: erfa.ab is special-relativistic aberration, the boost of the light's
    direction into the observer's frame, and the inverse of the boost by v is the boost by −v, so
    ``unaberrate(u, v) = erfa.ab(u, −v/c)``. erfa's Sun-potential term, which acts like a velocity
    larger by SRS/s = 2e-8 across the line of sight, cancels the same way: the round trip is at the
    rounding level, 1e-10" (tested below 1e-6" from 465 m/s to 0.97 c).
    """
    u_apparent, beta = _checked("unaberrate", u_apparent, v)
    return _ab(u_apparent, -beta)


def earth_barycentric_velocity(jd1, jd2):
    """Velocity (..., 3) [m/s] of the Earth's centre relative to the solar-system barycentre, ICRS
    axes, at the two-part Julian date ``jd1 + jd2`` (TDB; TT is within 2 ms of it, 1e-5 m/s),
    broadcast over arrays of times.

    erfa.epv00 (a simplified VSOP2000 solution, Moisson & Bretagnon 2001; against JPL DE405 over
    1900-2100 its velocity is within 4.9 mm/s, < 4 µas of aberration); dates outside 1900-2100
    raise InputError.
    """
    jd1, jd2 = np.broadcast_arrays(np.asarray(jd1, dtype=float), np.asarray(jd2, dtype=float))
    jd = jd1 + jd2
    _require((jd >= _EPV00_SPAN_JD[0]) & (jd <= _EPV00_SPAN_JD[1]), jd,
             "earth_barycentric_velocity: Julian date {} is outside 1900-2100 "
             f"(JD {_EPV00_SPAN_JD[0]}-{_EPV00_SPAN_JD[1]}), the span of erfa.epv00's series.")
    _, barycentric = erfa.epv00(jd1, jd2)
    return barycentric["v"] * (erfa.DAU / erfa.DAYSEC)


def _ab(u, beta):
    """erfa.ab of unit directions ``u`` and velocities ``beta`` in units of c."""
    bm1 = np.sqrt(1.0 - np.sum(beta * beta, axis=-1))
    return erfa.ab(u, beta, SUN_DISTANCE_AU, bm1)


def _checked(name, u, v):
    """``u`` (float, unit, finite) and ``v`` / c, or InputError naming ``name``'s bad argument."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    if u.shape[-1:] != (3,) or v.shape[-1:] != (3,):
        raise InputError(f"{name}: directions and velocities need 3 components on their last axis, "
                         f"got shapes {u.shape} and {v.shape}.")
    norm = np.linalg.norm(u, axis=-1)
    _require(np.abs(norm - 1.0) <= _UNIT_TOLERANCE, norm,  # NaN and inf fail the comparison
             f"{name}: directions must be finite unit vectors (|u| within {_UNIT_TOLERANCE:g} of 1), got |u| = {{}}.")
    speed = np.linalg.norm(v, axis=-1)
    _require(speed < SPEED_OF_LIGHT, speed, f"{name}: the observer's velocity must be finite and below "
             f"the speed of light ({SPEED_OF_LIGHT:.0f} m/s), got |v| = {{}} m/s.")
    return u, v / SPEED_OF_LIGHT


def _require(ok, values, message):
    """InputError of ``message`` formatted with the first of ``values`` where ``ok`` is False."""
    if not np.all(ok):
        raise InputError(message.format(values[~ok].flat[0]))
