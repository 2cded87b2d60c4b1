"""Apparent star directions (startrack.catalog.apparent_place) against skyfield, an independent implementation
(NOVAS's aberration, JPL's DE421 ephemeris from the skyfield-data package: nothing is downloaded),
and against the closed forms of relativistic aberration and the annual aberration figures."""

import erfa
import numpy as np
import pytest

from startrack.base import units
from startrack.base.errors import InputError
from startrack.catalog import apparent_place as aberration
from startrack.geometry import sphere
from tests.sky_support import deflected_by_the_sun, random_directions, skyfield_stars, skyfield_vectors

DATES = [(2000, 1, 1, 12.0), (2015, 3, 20, 0.0), (2019, 7, 15, 3.5), (2026, 3, 1, 12.0), (2045, 9, 1, 0.0)]
C = aberration.SPEED_OF_LIGHT


def near_the_sun(jd1, jd2):
    """Directions 1, 5, 20, 45, 90, 135 and 180 deg from the Sun seen from the Earth at the date."""
    sun = -erfa.epv00(jd1, jd2)[0]["p"]
    sun /= np.linalg.norm(sun)
    side = np.cross(sun, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    angle = np.radians([1.0, 5.0, 20.0, 45.0, 90.0, 135.0, 180.0])[:, None]
    return np.cos(angle) * sun + np.sin(angle) * side


@pytest.mark.parametrize("date", DATES)
def test_geocentric_apparent_places_against_skyfield(skyfield_sky, date):
    """Apparent places of 300 random stars and 7 at 1-180 deg from the Sun for the geocentre:
    skyfield's ``earth.at(t).observe(star).apparent(deflectors=(10,))`` (deflection by the Sun,
    then aberration, ICRS axes) against ours: the Sun's deflection applied here on our side with
    erfa.ldsun, then ``aberrate(u, earth_barycentric_velocity(t))``. Within 0.01" (measured
    <= 1.4 µas over the 5 dates, 1535 places); without the deflection the stars near the Sun
    miss by 0.47"."""
    ts, ephemeris = skyfield_sky
    t = ts.utc(*date)
    jd = (t.whole, t.tdb_fraction)
    u = np.concatenate([random_directions(300), near_the_sun(*jd)])
    theirs = skyfield_vectors(ephemeris["earth"].at(t).observe(skyfield_stars(u)).apparent(deflectors=(10,)))
    v = aberration.earth_barycentric_velocity(*jd)
    ours = aberration.aberrate(deflected_by_the_sun(u, *jd), v)
    assert sphere.angular_distance(ours, theirs).max() < 0.01 * units.ARCSEC
    assert sphere.angular_distance(aberration.aberrate(u, v), theirs).max() > 0.3 * units.ARCSEC


@pytest.mark.parametrize("date", DATES[1::2])
@pytest.mark.parametrize("site", [None, (0.0, 30.0, 0.0), (45.0, -70.0, 3000.0), (-33.9, 151.2, 11000.0)])
def test_aberration_step_against_skyfield(skyfield_sky, date, site):
    """The aberration step alone, the same velocity on both sides (skyfield's barycentric velocity of
    the geocentre or of a site on the WGS-84 ellipsoid, so the Earth's rotation enters, up to
    465 m/s, 0.32"): skyfield's ``relativity.add_aberration`` of the astrometric position
    against ``aberrate``. Within 1 µas: the difference is erfa's Sun-potential term (0.4 µas)."""
    from skyfield.api import wgs84
    from skyfield.relativity import add_aberration

    ts, ephemeris = skyfield_sky
    t = ts.utc(*date)
    observer = ephemeris["earth"] if site is None else ephemeris["earth"] + wgs84.latlon(*site)
    at = observer.at(t)
    u = random_directions(200, seed=1)
    astrometric = at.observe(skyfield_stars(u))
    position = astrometric.xyz.au.copy()
    add_aberration(position, at.velocity.au_per_d[:, None], astrometric.light_time)
    theirs = (position / np.linalg.norm(position, axis=0)).T
    ours = aberration.aberrate(u, at.velocity.m_per_s)
    assert sphere.angular_distance(ours, theirs).max() < 1e-6 * units.ARCSEC


def test_earth_barycentric_velocity_against_de421(skyfield_sky):
    """erfa.epv00 against JPL DE421 through skyfield, every 10 days of 2000-2049: within 0.01 m/s
    (measured < 4 mm/s over the 1827 dates; 0.01 m/s is 7 µas of aberration)."""
    ts, ephemeris = skyfield_sky
    t = ts.tdb_jd(2451544.5 + np.arange(0.0, 50 * 365.25, 10.0))
    theirs = ephemeris["earth"].at(t).velocity.m_per_s.T
    ours = aberration.earth_barycentric_velocity(t.whole, t.tdb_fraction)
    assert ours.shape == theirs.shape
    assert np.linalg.norm(ours - theirs, axis=-1).max() < 0.01


@pytest.mark.parametrize("speed", [465.0, 7.7e3, 29.78e3, 3e6])
def test_size_is_the_relativistic_closed_form(speed):
    """At angle θ from the velocity the apparent angle θ' has tan θ' = sin θ sqrt(1 − β²)/(cos θ + β)
    (special relativity) and the shift is β sin θ to first order: the closed form within erfa's
    Sun-potential term (SRS/s) β sin θ (0.4 µas at 29.78 km/s), towards the apex, and 20.49" at
    θ = 90 deg for 29.78 km/s."""
    theta = np.radians(np.linspace(0.0, 180.0, 37))
    direction = np.array([0.6, -0.48, 0.64])
    side = np.cross(direction, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    u = np.cos(theta)[:, None] * direction + np.sin(theta)[:, None] * side
    beta = speed / C
    apparent = aberration.aberrate(u, speed * direction)
    shift = theta - np.arctan2(np.sin(theta) * np.sqrt(1.0 - beta**2), np.cos(theta) + beta)
    sun_term = erfa.SRS / aberration.SUN_DISTANCE_AU * beta
    np.testing.assert_allclose(sphere.angular_distance(u, apparent), shift, rtol=0, atol=sun_term + 1e-15)
    np.testing.assert_allclose(shift, beta * np.sin(theta), rtol=0, atol=beta**2)
    assert np.all(sphere.angular_distance(apparent, direction) <= theta + 1e-15)
    if speed == 29.78e3:
        assert shift[18] / units.ARCSEC == pytest.approx(20.48939, abs=1e-5)  # the figure's last digit


def test_constant_of_aberration():
    """The IAU constant of aberration κ = 20.49552" is the shift at 90 deg for |v| = c sin κ."""
    kappa = 20.49552 * units.ARCSEC
    u = np.array([1.0, 0.0, 0.0])
    shifted = aberration.aberrate(u, [0.0, C * np.sin(kappa), 0.0])
    # exact but for erfa's Sun-potential term, SRS/s β = 0.4 µas (and rounding): 1 µas
    assert sphere.angular_distance(u, shifted) / units.ARCSEC == pytest.approx(20.49552, abs=1e-6)


def test_no_shift_along_the_velocity():
    v = np.array([2e4, -1e4, 5e3])
    u = np.stack([v, -v]) / np.linalg.norm(v)
    np.testing.assert_allclose(aberration.aberrate(u, v), u, rtol=0, atol=1e-15)  # rounding level: exact


@pytest.mark.parametrize("speed", [465.0, 29.78e3, 3e6, 1.5e8, 2.9e8])
def test_round_trip(speed):
    """unaberrate(aberrate(u)) and aberrate(unaberrate(u)) return u within 1e-6", up to 0.97 c."""
    u = random_directions(2000, seed=2)
    v = speed * random_directions(1, seed=3)[0]
    # 1 µas: the exact Lorentz inverse, at the rounding level (1e-10", unaberrate's docstring)
    back = aberration.unaberrate(aberration.aberrate(u, v), v)
    assert sphere.angular_distance(back, u).max() < 1e-6 * units.ARCSEC
    there = aberration.aberrate(aberration.unaberrate(u, v), v)
    assert sphere.angular_distance(there, u).max() < 1e-6 * units.ARCSEC


@pytest.mark.parametrize("function", [aberration.aberrate, aberration.unaberrate])
@pytest.mark.parametrize("u_shape, v_shape, out_shape", [
    ((3,), (3,), (3,)), ((7, 3), (3,), (7, 3)), ((3,), (5, 3), (5, 3)), ((2, 4, 3), (2, 4, 3), (2, 4, 3)),
    ((4, 1, 3), (6, 3), (4, 6, 3)),
])
def test_vectorised_shapes(function, u_shape, v_shape, out_shape):
    """Directions and velocities broadcast together; each element as if computed alone."""
    u = random_directions(int(np.prod(u_shape[:-1])), seed=4).reshape(u_shape)
    v = 3e4 * random_directions(int(np.prod(v_shape[:-1])), seed=5).reshape(v_shape)
    out = function(u, v)
    assert out.shape == out_shape
    u_b, v_b = np.broadcast_to(u, out_shape), np.broadcast_to(v, out_shape)
    for index in np.ndindex(out_shape[:-1]):
        np.testing.assert_array_equal(out[index], function(u_b[index], v_b[index]))


def test_earth_velocity_shapes():
    assert aberration.earth_barycentric_velocity(2451545.0, 0.0).shape == (3,)
    assert aberration.earth_barycentric_velocity(2451545.0, np.arange(5.0)).shape == (5, 3)
    assert aberration.earth_barycentric_velocity(np.full((2, 3), 2451545.0), 0.5).shape == (2, 3, 3)


def ecliptic_basis():
    """The vernal equinox x, the ecliptic's own 90 deg point and its pole, ICRS axes (J2000 obliquity)."""
    obliquity = erfa.obl06(2451545.0, 0.0)
    pole = np.array([0.0, -np.sin(obliquity), np.cos(obliquity)])
    x = np.array([1.0, 0.0, 0.0])
    return x, np.cross(pole, x), pole


def yearly_shift(u, east, north, year=2026):
    """The aberration displacement [arcsec] of direction u along (east, north) every day of a year."""
    jd1, jd2 = erfa.cal2jd(year, 1, 1)
    v = aberration.earth_barycentric_velocity(jd1, jd2 + np.arange(366.0))
    shift = aberration.aberrate(u, v) - u
    return shift @ east / units.ARCSEC, shift @ north / units.ARCSEC


def test_annual_circle_at_the_ecliptic_pole():
    """A star at the ecliptic pole runs, over a year, a circle of radius κ = 20.49552" (the hodograph
    of the Earth's Kepler orbit) whose centre is off by e κ = 0.34" (the elliptic terms): its radius
    lies in [20.2, 20.8]" and within 0.02" of κ (the Moon's and planets' pull stay below 0.01")."""
    x, y, pole = ecliptic_basis()
    a, b = yearly_shift(pole, x, y)
    # Least-squares circle: a² + b² = 2 a0 a + 2 b0 b + k.
    design = np.column_stack([2 * a, 2 * b, np.ones_like(a)])
    (a0, b0, k), *_ = np.linalg.lstsq(design, a**2 + b**2, rcond=None)
    radius = np.sqrt(k + a0**2 + b0**2)
    assert 20.2 <= radius <= 20.8
    assert radius == pytest.approx(20.49552, abs=0.02)
    assert np.hypot(a0, b0) == pytest.approx(0.0167 * 20.49552, abs=0.02)
    assert np.ptp(np.hypot(a - a0, b - b0)) < 0.05


def test_annual_segment_on_the_ecliptic():
    """A star on the ecliptic swings along it by ±κ over a year (half the range in [20.2, 20.8]")
    and stays on it within 0.01" (the Earth's velocity lies in the ecliptic)."""
    x, y, pole = ecliptic_basis()
    along, across = yearly_shift(x, y, pole)
    assert 20.2 <= np.ptp(along) / 2 <= 20.8
    assert np.abs(across).max() < 0.01


@pytest.mark.parametrize("function", [aberration.aberrate, aberration.unaberrate])
@pytest.mark.parametrize("u, v, message", [
    ([np.nan, 0.0, 1.0], [0.0, 3e4, 0.0], r"directions must be finite unit vectors .*got \|u\| = nan"),
    ([1.0, 1.0, 0.0], [0.0, 3e4, 0.0], r"directions must be finite unit vectors .*got \|u\| = 1.414"),
    ([[0.0, 0.0, 1.0], [0.0, 0.0, 1.01]], [0.0, 3e4, 0.0], r"got \|u\| = 1.01"),
    ([0.0, 0.0, 1.0], [0.0, 3e8, 0.0], r"velocity must be finite and below the speed of light .*got \|v\| = 3"),
    ([0.0, 0.0, 1.0], [C, 0.0, 0.0], r"below the speed of light"),
    ([0.0, 0.0, 1.0], [np.inf, 0.0, 0.0], r"got \|v\| = inf m/s"),
    ([0.0, 0.0, 1.0], [np.nan, 0.0, 0.0], r"got \|v\| = nan m/s"),
    ([0.0, 1.0], [0.0, 3e4, 0.0], r"3 components on their last axis"),
])
def test_bad_input_is_one_sentence(function, u, v, message):
    with pytest.raises(InputError, match=function.__name__ + ": .*" + message) as error:
        function(np.array(u), np.array(v))
    assert "\n" not in str(error.value) and str(error.value).endswith(".")


@pytest.mark.parametrize("jd1, jd2", [(2415020.0, 0.0), (2488070.0, 0.0), (np.nan, 0.0), (2451545.0, [0.0, 1e6])])
def test_bad_dates_are_named(jd1, jd2):
    with pytest.raises(InputError, match=r"earth_barycentric_velocity: Julian date .* is outside 1900-2100"):
        aberration.earth_barycentric_velocity(jd1, jd2)
