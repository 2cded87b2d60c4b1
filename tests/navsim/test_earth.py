"""Earth model: WGS-84 gravity against the published values, geometry round trips and derivatives,
frame rates, and the ICRS -> ITRS rotation of pyerfa against skyfield (an independent implementation)."""

import numpy as np
import pytest

from navsim.earth import frames, gravity, orientation, wgs84
from startrack.base import units
from startrack.catalog import apparent_place as aberration
from startrack.geometry import rotation as rot
from startrack.geometry import sphere
from tests.sky_support import deflected_by_the_sun, random_directions, skyfield_stars, skyfield_vectors

# NIMA TR8350.2 (3rd ed.), Table 3.4: normal gravity on the ellipsoid at the equator and at the poles.
PUBLISHED_GAMMA_E = 9.7803253359
PUBLISHED_GAMMA_P = 9.8321849378


def test_normal_gravity_matches_the_published_wgs84_values():
    """γ_e and γ_p derived here from (a, f, GM, ω) alone match TR8350.2 Table 3.4 to 1e-6 m/s² (0.1 µg, far
    below the best accelerometer bias; a GM or ω wrong in its 7th digit moves γ by more; 6e-11 seen)."""
    assert gravity.normal_gravity(0.0, 0.0) == pytest.approx(PUBLISHED_GAMMA_E, abs=1e-6)
    assert gravity.normal_gravity(np.pi / 2, 0.0) == pytest.approx(PUBLISHED_GAMMA_P, abs=1e-6)
    assert gravity.normal_gravity(-np.pi / 2, 0.0) == pytest.approx(PUBLISHED_GAMMA_P, abs=1e-6)


def test_free_air_gradient_and_height_term():
    """∂γ/∂h ≈ −0.3086 mGal/m (the standard free-air gradient) and equals the finite difference."""
    lat = 45.0 * units.DEG
    # two units of the standard value's last digit (1e-9 s⁻²)
    assert gravity.normal_gravity_height_gradient(lat, 0.0) == pytest.approx(-3.086e-6, abs=2e-9)
    h = 3000.0
    numeric = (gravity.normal_gravity(lat, h + 1.0) - gravity.normal_gravity(lat, h - 1.0)) / 2.0
    # the difference's rounding, eps γ / (2 m) = 1e-15 s⁻² of 3e-6 (4e-10 relative; 6e-11 seen); its truncation
    # is (Δh / a)² ~ 1e-14 (γ is quadratic in h: none at all)
    assert gravity.normal_gravity_height_gradient(lat, h) == pytest.approx(numeric, rel=1e-9)


def test_radii_at_the_equator_and_pole():
    """Rounding level: closed forms of the same radii."""
    r_m, r_n = wgs84.radii(0.0)
    assert r_m == pytest.approx(wgs84.A * (1.0 - wgs84.E2), rel=1e-15)
    assert r_n == pytest.approx(wgs84.A, rel=1e-15)
    r_m, r_n = wgs84.radii(np.pi / 2)
    assert r_m == pytest.approx(r_n, rel=1e-15)
    assert r_n == pytest.approx(wgs84.A**2 / wgs84.B, rel=1e-15)


def test_geodetic_ecef_round_trip():
    rng = np.random.default_rng(1)
    lat = np.concatenate([rng.uniform(-np.pi / 2, np.pi / 2, 200), [np.pi / 2, -np.pi / 2, 0.0]])
    lon = rng.uniform(-np.pi, np.pi, lat.size)
    h = rng.uniform(-1000.0, 100e3, lat.size)
    back = wgs84.ecef_to_geodetic(*wgs84.geodetic_to_ecef(lat, lon, h))
    # Bowring's five passes converge to rounding (2e-16 rad, 2e-9 m seen); 1e-12 rad (6 µm on the ground) and
    # 1 µm in h are far below any navigation error and well above the rounding of 6e6 m coordinates (1e-9 m)
    np.testing.assert_allclose(back[0], lat, atol=1e-12)
    np.testing.assert_allclose(back[2], h, atol=1e-6)
    away_from_poles = np.abs(lat) < np.pi / 2 - 1e-6
    np.testing.assert_allclose(back[1][away_from_poles], lon[away_from_poles], atol=1e-12)
    # rounding level (ulp of 6e6 m is 1e-9 m): closed forms
    np.testing.assert_allclose(wgs84.geodetic_to_ecef(0.0, 0.0, 0.0), [wgs84.A, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(wgs84.geodetic_to_ecef(np.pi / 2, 0.3, 0.0), [0.0, 0.0, wgs84.B], atol=1e-9)


def test_c_en_columns_are_the_position_derivatives():
    """∂r_e/∂L = (R_M + h) north and ∂r_e/∂λ = (R_N + h) cos L east: checks C_en and the radii together."""
    lat, lon, h = 0.7, -1.9, 1234.0
    C = frames.c_en(lat, lon)
    np.testing.assert_allclose(C @ C.T, np.eye(3), atol=1e-15)  # rounding level: a closed-form rotation
    assert np.linalg.det(C) == pytest.approx(1.0)
    r_m, r_n = wgs84.radii(lat)
    eps = 1e-7
    def ecef(*p):
        return np.array(wgs84.geodetic_to_ecef(*p))

    d_lat = (ecef(lat + eps, lon, h) - ecef(lat - eps, lon, h)) / (2 * eps)
    d_lon = (ecef(lat, lon + eps, h) - ecef(lat, lon - eps, h)) / (2 * eps)
    d_h = ecef(lat, lon, h + 1.0) - ecef(lat, lon, h)
    # central differences: rounding of the 6e6 m coordinates (a few ulp, 3e-9 m, over 2e-7 rad: 4e-9 relative),
    # truncation eps² ~ 1e-14; r_e is linear in h, so d_h has the rounding alone (1e-9 m over 1 m)
    np.testing.assert_allclose(d_lat, (r_m + h) * C[:, 0], rtol=1e-7)
    np.testing.assert_allclose(d_lon, (r_n + h) * np.cos(lat) * C[:, 1], rtol=1e-7)
    np.testing.assert_allclose(d_h, -C[:, 2], atol=1e-7)


def test_earth_and_transport_rates():
    """ω_ie^n is the Earth's axis in n; ω_en^n of a velocity equals the rate of C_en along the track."""
    lat, lon, h = 0.6, 0.2, 500.0
    C = frames.c_en(lat, lon)
    # rounding level (ω_ie's ulp is 1.4e-20 rad/s): closed forms
    np.testing.assert_allclose(C @ np.array(frames.earth_rate_n(lat)), [0.0, 0.0, wgs84.OMEGA_IE], atol=1e-18)
    v = np.array([120.0, -80.0, 0.0])
    r_m, r_n = wgs84.radii(lat)
    dt = 1e-3
    lat1 = lat + v[0] / (r_m + h) * dt
    lon1 = lon + v[1] / ((r_n + h) * np.cos(lat)) * dt
    # Ċ_en = C_en [ω_en^n ×]
    rate = C.T @ (frames.c_en(lat1, lon1) - C) / dt
    numeric = np.array([rate[2, 1], rate[0, 2], rate[1, 0]])
    np.testing.assert_allclose(numeric, frames.transport_rate_n(lat, h, v[0], v[1]), rtol=1e-5, atol=1e-12)


@pytest.mark.parametrize("epoch", ["2000-01-01T12:00:00", "2019-07-15T03:30:00", "2026-03-01T12:00:00"])
def test_icrs_to_itrs_against_skyfield(epoch):
    """pyerfa's IAU 2006/2000A C_ei against skyfield's ITRS frame (equinox based, its own nutation
    series) with the same UT1 and no polar motion: within 0.01 arcsec."""
    from skyfield.api import load
    from skyfield.framelib import itrs

    ts = load.timescale(builtin=True)  # ships with skyfield: nothing is downloaded
    date, clock = epoch.split("T")
    y, mo, d = (int(x) for x in date.split("-"))
    hh, mi, ss = (float(x) for x in clock.split(":"))
    for offset in (0.0, 3600.0, 86400.0 * 10):
        t = ts.utc(y, mo, d, hh, mi, ss + offset)
        ours = frames.c_ei(epoch, offset, dut1=float(t.dut1))
        difference = rot.to_rotation_vector(rot.from_matrix(ours @ itrs.rotation_at(t).T))
        assert np.linalg.norm(difference) < 0.01 * units.ARCSEC


def test_c_ei_rotates_at_the_earth_rate():
    """Over one minute C_ei turns about the ITRS z axis at ω_ie (precession-nutation adds < 1e-10 rad/s)."""
    C0, C1 = frames.c_ei("2026-03-01T00:00:00", np.array([0.0, 60.0]))
    phi = rot.to_rotation_vector(rot.from_matrix(C1 @ C0.T))
    np.testing.assert_allclose(phi / 60.0, [0.0, 0.0, -wgs84.OMEGA_IE], atol=1e-10)


def test_slow_terms_on_their_grid_equal_erfa_at_every_second():
    """Six hours of frames every second: C_ei with the precession-nutation interpolated from its 60 s grid equals
    erfa.c2t06a (within 1e-14 rad; measured 5e-15), and the geocentre's velocity erfa.epv00 (within 1e-6 m/s,
    3e-15 of aberration; measured 5e-7)."""
    import erfa

    epoch, t, dut1 = "2024-03-20T20:00:00", np.arange(1, 21_601) + 0.37, 0.3
    utc = frames._utc(epoch, t)
    tt = erfa.taitt(*erfa.utctai(*utc))
    assert np.abs(frames.c_ei(epoch, t, dut1) - erfa.c2t06a(*tt, *erfa.utcut1(*utc, dut1), 0.0, 0.0)).max() < 1e-14
    v_earth = orientation.EarthOrientation.compute(epoch, t, dut1).v_earth
    assert np.abs(v_earth - aberration.earth_barycentric_velocity(*tt)).max() < 1e-6
    assert frames.c_ei(epoch, t[:3]).shape == (3, 3, 3) and frames.c_ei(epoch, 7.0).shape == (3, 3)


def test_bad_epoch_is_named():
    from startrack.base.errors import InputError

    with pytest.raises(InputError, match="epoch_utc: expected"):
        frames.c_ei("yesterday")
    with pytest.raises(InputError, match="epoch_utc: must be UTC"):
        frames.c_ei("2026-03-01T12:00:00+02:00")
    np.testing.assert_array_equal(frames.c_ei("2026-03-01T12:00:00Z"), frames.c_ei("2026-03-01T12:00:00"))


def test_random_gravity_disturbance_statistics_and_seed():
    """The along-track Gauss-Markov field has its σ and correlation e⁻¹ at one correlation length."""
    field = gravity.GravityDisturbance.random(5 * units.ARCSEC, 3 * units.ARCSEC, 30e-5, 20e3)
    distance = np.linspace(0.0, 2e7, 200_001)  # 1000 correlation lengths, 100 m apart
    a = field.components(distance, np.random.default_rng(3))
    b = field.components(distance, np.random.default_rng(3))
    np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(a.std(axis=0), [5 * units.ARCSEC, 3 * units.ARCSEC, 30e-5], rtol=0.1)
    lag = 200  # 20 km
    rho = np.mean(a[:-lag] * a[lag:], axis=0) / a.var(axis=0)
    np.testing.assert_allclose(rho, np.exp(-1.0), atol=0.08)
    g = gravity.disturbance_n(np.array([[1e-5, -2e-5, 3e-4]]), np.array([9.8]))
    np.testing.assert_allclose(g, [[-9.8e-5, 19.6e-5, 3e-4]])  # rounding level: products of the inputs


SITES = [(0.0, 30.0, 0.0), (45.0, -70.0, 3000.0), (-33.9, 151.2, 11000.0)]


def site_velocity(epoch_utc, t, site, v_n, dut1=0.0):
    """Barycentric velocities (len(t), 3) [m/s] of a vehicle at ``site`` (L, λ [deg], h [m]) moving
    at v_n (NED) at times ``t`` [s] after the epoch (:func:`orientation.observer_velocity`)."""
    earth = orientation.EarthOrientation.compute(epoch_utc, t, dut1)
    lat, lon = site[0] * units.DEG, site[1] * units.DEG
    return np.array([orientation.observer_velocity(c, v, lat, lon, float(site[2]), np.asarray(v_n, float))
                     for c, v in zip(earth.c_ie, earth.v_earth)])


@pytest.mark.parametrize("site", SITES)
def test_observer_velocity_against_skyfield(skyfield_sky, site):
    """The barycentric velocity of a point fixed on the WGS-84 ellipsoid (Earth's orbit + rotation),
    over a day, against skyfield's (DE421, its own GCRS-ITRS rotation, same UT1): within 0.01 m/s
    (7 µas of aberration); the rotation term alone is ω_ie R cos L, 465 m/s on the equator."""
    from skyfield.api import wgs84 as sf_wgs84

    ts, ephemeris = skyfield_sky
    offsets = np.arange(0.0, 86400.0, 3600.0)
    t = ts.utc(2026, 3, 1, 12, 0, offsets)
    theirs = (ephemeris["earth"] + sf_wgs84.latlon(*site)).at(t).velocity.m_per_s.T
    r_e = np.array(wgs84.geodetic_to_ecef(site[0] * units.DEG, site[1] * units.DEG, site[2]))
    ours = site_velocity("2026-03-01T12:00:00", offsets, site, np.zeros(3), dut1=float(t.dut1[0]))
    assert np.linalg.norm(ours - theirs, axis=-1).max() < 0.01
    rotation = ours - aberration.earth_barycentric_velocity(*frames.tt_epoch("2026-03-01T12:00:00", offsets))
    radius = np.hypot(*r_e[:2])
    # rounding level: |C_ie (ω × r_e)| = ω_ie hypot(x, y) exactly, less the same Earth velocity
    np.testing.assert_allclose(np.linalg.norm(rotation, axis=-1), wgs84.OMEGA_IE * radius, rtol=1e-12)


def test_observer_velocity_adds_the_vehicle_velocity():
    """A vehicle's own velocity enters rotated into ICRS: v_i(v_n) − v_i(0) = C_ie C_en v_n."""
    site, v_n = (20.0, 40.0, 11000.0), np.array([200.0, -50.0, 3.0])
    t = np.array([0.0, 600.0])
    moving = site_velocity("2026-03-01T12:00:00", t, site, v_n)
    still = site_velocity("2026-03-01T12:00:00", t, site, np.zeros(3))
    c_ie = np.swapaxes(frames.c_ei("2026-03-01T12:00:00", t), -1, -2)
    v_e = frames.c_en(site[0] * units.DEG, site[1] * units.DEG) @ v_n
    np.testing.assert_allclose(moving - still, c_ie @ v_e, atol=1e-9)  # rounding level: linear in v_n (3e4 m/s terms)


@pytest.mark.parametrize("site", SITES)
def test_topocentric_apparent_places_against_skyfield(skyfield_sky, site):
    """The whole chain for a site on the Earth: ``aberrate(u, observer_velocity(...))`` (after the
    Sun's deflection, erfa.ldsun, which skyfield applies and ours leaves out) against skyfield's
    ``(earth + wgs84.latlon(...)).at(t).observe(star).apparent(deflectors=(10,))``, ICRS axes, 200
    random stars at 4 times of a day: within 0.01" (measured 0.41 mas over the 3 sites, 2400 places:
    skyfield also deflects by the Earth's own mass, <= 0.6 mas, stars more than 0.8 rad from the
    nadir; 13 µas for the others); the Earth's rotation (up to 0.32") is needed for it."""
    from skyfield.api import wgs84 as sf_wgs84

    ts, ephemeris = skyfield_sky
    u = random_directions(200, seed=7)
    stars = skyfield_stars(u)
    for offset in (0.0, 21600.0, 43200.0, 64800.0):
        t = ts.utc(2019, 7, 15, 3, 30, offset)
        theirs = skyfield_vectors((ephemeris["earth"] + sf_wgs84.latlon(*site)).at(t).observe(stars)
                                  .apparent(deflectors=(10,)))
        jd = frames.tt_epoch("2019-07-15T03:30:00", offset)
        deflected = deflected_by_the_sun(u, *jd)
        v_i = site_velocity("2019-07-15T03:30:00", [offset], site, np.zeros(3), dut1=float(t.dut1))[0]
        ours = aberration.aberrate(deflected, v_i)
        assert sphere.angular_distance(ours, theirs).max() < 0.01 * units.ARCSEC
        geocentric = aberration.aberrate(deflected, aberration.earth_barycentric_velocity(*jd))
        assert sphere.angular_distance(geocentric, theirs).max() > 0.1 * units.ARCSEC
