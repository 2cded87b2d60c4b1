"""The azimuthal equidistant map (startrack.geometry.sphere.azimuthal_equidistant) against its defining properties
(Snyder 1987, ch. 25) and its closed form at a pole."""

import numpy as np

from startrack.geometry.sphere import angular_distance, azimuthal_equidistant, radec_to_vector


def test_every_point_lies_at_its_distance_from_the_centre_in_its_bearing():
    """Radial distance = angular distance (to 1e-12 rad); a point due north of the centre on its meridian is on +y, one
    a small step east is on +x; the centre maps to the origin."""
    rng = np.random.default_rng(7)
    ra, dec = rng.uniform(0.0, 2.0 * np.pi, 500), np.arcsin(rng.uniform(-1.0, 1.0, 500))
    c_ra, c_dec = 1.0, 0.6
    x, y = azimuthal_equidistant(ra, dec, c_ra, c_dec)
    distance = angular_distance(radec_to_vector(c_ra, c_dec), radec_to_vector(ra, dec))
    np.testing.assert_allclose(np.hypot(x, y), distance, atol=1e-12)
    x, y = azimuthal_equidistant(np.array([c_ra, c_ra, c_ra + 1e-3]), np.array([c_dec, c_dec + 0.2, c_dec]), c_ra, c_dec)
    np.testing.assert_allclose([x[0], y[0], x[1], y[1]], [0.0, 0.0, 0.0, 0.2], atol=1e-12)
    assert x[2] > 0.0 and abs(y[2]) < 1e-3 * x[2]


def test_centred_on_a_pole_it_is_the_polar_closed_form_and_crosses_the_antimeridian_smoothly():
    """Centred on the North Pole: x = (π/2 − φ) sin λ, y = −(π/2 − φ) cos λ (the polar aspect); from 80° N on the 0° meridian the pole is at (0, 10°); a track across 180° of longitude stays continuous."""
    lat, lon = np.radians([89.0, 60.0, 75.0]), np.radians([30.0, -120.0, 179.0])
    x, y = azimuthal_equidistant(lon, lat, 0.0, 0.5 * np.pi)
    colatitude = 0.5 * np.pi - lat
    np.testing.assert_allclose(x, colatitude * np.sin(lon), atol=1e-12)
    np.testing.assert_allclose(y, -colatitude * np.cos(lon), atol=1e-12)
    x, y = azimuthal_equidistant(0.0, 0.5 * np.pi, 0.0, np.radians(80.0))
    np.testing.assert_allclose([x, y], [0.0, np.radians(10.0)], atol=1e-12)
    lon = np.radians(np.linspace(179.0, 181.0, 21))
    x, y = azimuthal_equidistant(lon, np.full(21, np.radians(70.0)), np.radians(180.0), np.radians(70.0))
    assert np.all(np.diff(x) > 0.0) and np.max(np.abs(np.diff(x))) < 1.5 * np.radians(0.1) * np.cos(np.radians(70.0))
