"""RA/Dec-span pre-filter of 003 eq. 2-5 against the exact cone and square-field tests, whole sky."""

import numpy as np
import pytest

from startrack.base.errors import InputError
from startrack.catalog.field_selection import cone_mask, field_radius, radec_prefilter, radec_window
from startrack.geometry.attitude_angles import matrix_from_radec_roll
from startrack.geometry.sphere import radec_to_vector, vector_to_radec


@pytest.fixture(scope="module")
def sky():
    rng = np.random.default_rng(8)
    v = rng.normal(size=(60000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    ra, dec = vector_to_radec(v)
    return v, ra, dec


BORESIGHTS = [(0.0, np.pi / 2), (1.0, -np.pi / 2), (0.0, 0.0), (2 * np.pi - 1e-7, 0.3), (1e-9, -0.2),
              (3.0, np.radians(82.0)), (5.0, np.radians(-83.5)), (0.5, np.radians(88.0)), (4.0, np.radians(40))]


def boresight_list():
    rng = np.random.default_rng(9)
    extra = [(ra, np.arcsin(z)) for ra, z in zip(rng.uniform(0, 2 * np.pi, 40), rng.uniform(-1, 1, 40))]
    return BORESIGHTS + extra


@pytest.mark.parametrize("fov_deg", [4.0, 16.0, 30.0])
def test_prefilter_never_drops_a_star_of_the_cone(sky, fov_deg):
    v, ra, dec = sky
    radius = field_radius(np.radians(fov_deg))
    for ra0, dec0 in boresight_list():
        inside = cone_mask(v, radec_to_vector(ra0, dec0), radius)
        kept = radec_prefilter(ra, dec, ra0, dec0, radius)
        assert not np.any(inside & ~kept), (ra0, dec0)
        assert kept.sum() < 0.5 * len(v)


@pytest.mark.parametrize("roll", [0.0, 0.7])
def test_prefilter_keeps_every_star_of_the_rotated_square_field(sky, roll):
    v, ra, dec = sky
    fov = np.radians(16.0)
    t = np.tan(fov / 2)
    for ra0, dec0 in boresight_list():
        v_S = v @ matrix_from_radec_roll(ra0, dec0, roll)
        in_square = (v_S[:, 2] > 0) & (np.abs(v_S[:, 0]) <= t * v_S[:, 2]) & (np.abs(v_S[:, 1]) <= t * v_S[:, 2])
        kept = radec_prefilter(ra, dec, ra0, dec0, field_radius(fov))
        assert in_square.sum() > 0 and not np.any(in_square & ~kept)


def test_003_inscribed_radius_drops_corner_stars(sky):
    """003 takes rho = A/2; the corners of the square field then fall outside the window."""
    v, ra, dec = sky
    fov = np.radians(16.0)
    t = np.tan(fov / 2)
    v_S = v @ matrix_from_radec_roll(1.0, 0.3, 0.0)
    in_square = (v_S[:, 2] > 0) & (np.abs(v_S[:, 0]) <= t * v_S[:, 2]) & (np.abs(v_S[:, 1]) <= t * v_S[:, 2])
    kept = radec_prefilter(ra, dec, 1.0, 0.3, fov / 2)
    assert np.any(in_square & ~kept)


def test_window_closed_forms():  # default tolerances: rounding level of the same closed forms
    dec_min, dec_max, half = radec_window(1.0, 0.0, 0.1)
    assert (dec_min, dec_max) == pytest.approx((-0.1, 0.1)) and half == pytest.approx(0.1)
    _, _, half = radec_window(1.0, np.radians(60), np.radians(8))        # eq. 3
    assert half == pytest.approx(np.arcsin(np.sin(np.radians(8)) / np.cos(np.radians(60))))
    dec_min, dec_max, half = radec_window(1.0, np.radians(85), np.radians(8))   # eq. 4: pole in the field
    assert half == pytest.approx(np.pi) and dec_max == pytest.approx(np.pi / 2)
    assert field_radius(np.radians(16)) == pytest.approx(np.arctan(np.sqrt(2) * np.tan(np.radians(8))))


def test_window_input_errors():
    with pytest.raises(InputError, match="radius"):
        radec_window(0.0, 0.0, -0.1)
    with pytest.raises(InputError, match="dec0"):
        radec_window(0.0, 2.0, 0.1)
    with pytest.raises(InputError, match="fov_x"):
        field_radius(np.nan)
