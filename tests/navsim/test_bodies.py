"""The Sun and the Moon from the vehicle (navsim.earth.bodies) against skyfield with JPL's DE421 (an
independent ephemeris and reduction): geometric topocentric directions (skyfield's vector from the observer to
the body at the same instant), the Moon's distance and illuminated fraction."""

import numpy as np
import pytest

from navsim.earth.bodies import SunMoon
from navsim.earth.orientation import EarthOrientation
from startrack.base import units
from startrack.geometry.sphere import angular_distance
from tests.sky_support import skyfield_vectors

EPOCH = "2025-09-07T18:00:00"  # a total lunar eclipse night: the Moon full, opposite the Sun
#: An aircraft over the Atlantic at 11 km and a ship in the Arctic.
SITES = [(45.0, -30.0, 11_000.0), (82.0, 150.0, 0.0)]


@pytest.mark.parametrize("site", SITES)
def test_topocentric_sun_and_moon_match_skyfield(site, skyfield_sky):
    """Every 3 h over 6 days: the Sun within 0.1" (erfa.epv00 against DE421; measured 0.003"), the Moon within
    10" (moon98's stated accuracy; measured 4.6" geocentric) and its distance within 5 km (measured 2.4 km; the
    parallax that topocentric adds is up to 57' and 6400 km); the illuminated fraction within 0.001 (measured
    7e-6)."""
    from skyfield.api import wgs84

    ts, eph = skyfield_sky
    lat, lon, h = site
    t = np.arange(0.0, 6 * 86_400.0, 3 * 3600.0)
    orientation = EarthOrientation.compute(EPOCH, t)
    F = t.size
    bodies = SunMoon.compute(EPOCH, orientation, np.full(F, np.radians(lat)), np.full(F, np.radians(lon)), np.full(F, h))
    when = ts.utc(2025, 9, 7, 18, 0, t)
    observer = eph["earth"] + wgs84.latlon(lat, lon, elevation_m=h)
    sun, moon = ((eph[name] - observer).at(when) for name in ("sun", "moon"))
    assert units.rad_to_arcsec(angular_distance(bodies.sun_I, skyfield_vectors(sun))).max() < 0.1
    assert units.rad_to_arcsec(angular_distance(bodies.moon_I, skyfield_vectors(moon))).max() < 10.0
    assert np.abs(bodies.moon_distance - moon.distance().m).max() < 5e3
    illuminated = observer.at(when).observe(eph["moon"]).apparent().fraction_illuminated(eph["sun"])
    assert np.abs(bodies.moon_illuminated - illuminated).max() < 0.001
    assert bodies.moon_illuminated[1] > 0.99  # 21:00 UTC: the eclipse's full Moon


def test_elevation_of_the_sun_at_noon_and_midnight():
    """On the equator at the March equinox the Sun culminates near the zenith (within the 0.4 deg of its
    declination and the equation of time's 7 min), and twelve hours later it is near the nadir."""
    t = np.array([12 * 3600.0, 24 * 3600.0])
    orientation = EarthOrientation.compute("2026-03-20T00:00:00", t)
    bodies = SunMoon.compute("2026-03-20T00:00:00", orientation, np.zeros(2), np.zeros(2), np.zeros(2))
    elevation = np.degrees(bodies.elevation(bodies.sun_I))
    assert elevation[0] > 87.5 and elevation[1] < -87.5
