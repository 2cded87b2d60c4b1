"""Earth model: WGS-84 gravity against the published values, geometry round trips and derivatives,
frame rates, and the ICRS -> ITRS rotation of pyerfa against skyfield (an independent implementation)."""

import numpy as np
import pytest

from navsim.earth import frames, gravity, wgs84
from startrack import rotation as rot
from startrack import units

# NIMA TR8350.2 (3rd ed.), Table 3.4: normal gravity on the ellipsoid at the equator and at the poles.
PUBLISHED_GAMMA_E = 9.7803253359
PUBLISHED_GAMMA_P = 9.8321849378


def test_normal_gravity_matches_the_published_wgs84_values():
    """γ_e and γ_p derived here from (a, f, GM, ω) alone match TR8350.2 Table 3.4 to 1e-6 m/s²."""
    assert gravity.normal_gravity(0.0, 0.0) == pytest.approx(PUBLISHED_GAMMA_E, abs=1e-6)
    assert gravity.normal_gravity(np.pi / 2, 0.0) == pytest.approx(PUBLISHED_GAMMA_P, abs=1e-6)
    assert gravity.normal_gravity(-np.pi / 2, 0.0) == pytest.approx(PUBLISHED_GAMMA_P, abs=1e-6)


def test_free_air_gradient_and_height_term():
    """∂γ/∂h ≈ −0.3086 mGal/m (the standard free-air gradient) and equals the finite difference."""
    lat = 45.0 * units.DEG
    assert gravity.normal_gravity_height_gradient(lat, 0.0) == pytest.approx(-3.086e-6, abs=2e-9)
    h = 3000.0
    numeric = (gravity.normal_gravity(lat, h + 1.0) - gravity.normal_gravity(lat, h - 1.0)) / 2.0
    assert gravity.normal_gravity_height_gradient(lat, h) == pytest.approx(numeric, rel=1e-9)


def test_radii_at_the_equator_and_pole():
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
    np.testing.assert_allclose(back[0], lat, atol=1e-12)
    np.testing.assert_allclose(back[2], h, atol=1e-6)
    away_from_poles = np.abs(lat) < np.pi / 2 - 1e-6
    np.testing.assert_allclose(back[1][away_from_poles], lon[away_from_poles], atol=1e-12)
    np.testing.assert_allclose(wgs84.geodetic_to_ecef(0.0, 0.0, 0.0), [wgs84.A, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(wgs84.geodetic_to_ecef(np.pi / 2, 0.3, 0.0), [0.0, 0.0, wgs84.B], atol=1e-9)


def test_c_en_columns_are_the_position_derivatives():
    """∂r_e/∂L = (R_M + h) north and ∂r_e/∂λ = (R_N + h) cos L east: checks C_en and the radii together."""
    lat, lon, h = 0.7, -1.9, 1234.0
    C = frames.c_en(lat, lon)
    np.testing.assert_allclose(C @ C.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(C) == pytest.approx(1.0)
    r_m, r_n = wgs84.radii(lat)
    eps = 1e-7
    def ecef(*p):
        return np.array(wgs84.geodetic_to_ecef(*p))

    d_lat = (ecef(lat + eps, lon, h) - ecef(lat - eps, lon, h)) / (2 * eps)
    d_lon = (ecef(lat, lon + eps, h) - ecef(lat, lon - eps, h)) / (2 * eps)
    d_h = ecef(lat, lon, h + 1.0) - ecef(lat, lon, h)
    np.testing.assert_allclose(d_lat, (r_m + h) * C[:, 0], rtol=1e-7)
    np.testing.assert_allclose(d_lon, (r_n + h) * np.cos(lat) * C[:, 1], rtol=1e-7)
    np.testing.assert_allclose(d_h, -C[:, 2], atol=1e-7)


def test_earth_and_transport_rates():
    """ω_ie^n is the Earth's axis in n; ω_en^n of a velocity equals the rate of C_en along the track."""
    lat, lon, h = 0.6, 0.2, 500.0
    C = frames.c_en(lat, lon)
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


def test_bad_epoch_is_named():
    from startrack.errors import InputError

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
    np.testing.assert_allclose(g, [[-9.8e-5, 19.6e-5, 3e-4]])
