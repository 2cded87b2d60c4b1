"""Base points (eq. 1-2) and sub-catalog address index (eq. 7-8, §4) of document 000."""

import math

import numpy as np
import pytest

from startrack.base.errors import InputError
from startrack.catalog import address as addr
from startrack.geometry.sphere import angular_distance, radec_to_vector, vector_to_radec

DEG = math.pi / 180.0
RHO_SUB = 12.0 * DEG  # eq. 6 for n_d = 53, 16 deg, max(delta) = 2 deg


def test_exactly_3100_base_points_for_53_divisions():
    assert addr.base_point_count(53) == 3100
    # Eq. 1-2 recomputed ring by ring with plain floats.
    sizes = [math.floor(0.5 + math.sqrt(3) * 53 * math.cos(math.pi * j / 53 - math.pi / 2)) for j in range(1, 53)]
    assert addr.ring_sizes(53).tolist() == sizes
    ra, dec = addr.base_points_radec(53)  # default tolerances below: rounding level of the closed forms
    assert ra.size == 3100
    assert np.allclose(np.unique(np.round(dec, 12)), np.round(addr.ring_declinations(53), 12))
    assert ra[0] == 0.0 and dec[0] == pytest.approx(math.pi / 53 - math.pi / 2)


@pytest.mark.parametrize(
    "ra_deg, dec_deg, l_d, l_ra",
    [(62.27, 38.67, 38, 13), (65.89, 26.84, 34, 16), (60.32, 47.51, 40, 12), (58.55, 57.91, 44, 9)],
)
def test_table_2_addresses(ra_deg, dec_deg, l_d, l_ra):
    # Table 2 of 000 prints l_d under "R.A." and l_ra under "Dec.".
    got = addr.address(ra_deg * DEG, dec_deg * DEG, 53)
    assert (int(got[0]), int(got[1])) == (l_d, l_ra)


def test_every_base_point_addresses_itself_and_index_round_trip():
    for n_d in (5, 17, 53, 120):
        ra, dec = addr.base_points_radec(n_d)
        index = addr.sub_catalog_index(ra, dec, n_d)
        assert np.array_equal(index, np.arange(ra.size))
        l_d, l_ra = addr.address_of_index(index, n_d)
        assert np.array_equal(addr.base_index(l_d, l_ra, n_d), index)


def test_address_is_nearest_ring_then_nearest_point_brute_force():
    n_d = 53
    rng = np.random.default_rng(11)
    v = rng.normal(size=(20000, 3))
    ra, dec = vector_to_radec(v)
    l_d, l_ra = addr.address(ra, dec, n_d)
    phi = addr.ring_declinations(n_d)
    ring = np.argmin(np.abs(dec[:, None] - phi[None, :]), axis=1)
    assert np.array_equal(l_d, ring + 1)
    n_ra = addr.ring_sizes(n_d)[ring]
    step = 2 * np.pi / n_ra
    k = np.arange(addr.ring_sizes(n_d).max())[None, :]
    gap = np.abs((ra[:, None] - k * step[:, None] + np.pi) % (2 * np.pi) - np.pi)
    gap = np.where(k < n_ra[:, None], gap, np.inf)
    assert np.array_equal(l_ra, np.argmin(gap, axis=1) + 1)


def test_addressed_base_point_is_within_s_max():
    base = radec_to_vector(*addr.base_points_radec(53))
    rng = np.random.default_rng(5)
    v = rng.normal(size=(50000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    index = addr.sub_catalog_index(*vector_to_radec(v), 53)
    # s_max = 3.914 deg; the worst case is near the poles (3.36 deg), 2.67 deg for |dec| <= 80 deg.
    assert np.degrees(np.max(angular_distance(v, base[index]))) < 3.4


def test_wrap_across_ra_0_and_poles():
    assert addr.address(359.95 * DEG, 0.0, 53)[1] == 1
    assert addr.address(0.05 * DEG, 0.0, 53)[1] == 1
    assert addr.address(2 * math.pi, 0.3, 53) == addr.address(0.0, 0.3, 53)
    assert addr.address(-1.0 * DEG, 0.0, 53) == addr.address(359.0 * DEG, 0.0, 53)
    assert addr.address(123 * DEG, 90 * DEG, 53)[0] == 52
    assert addr.address(123 * DEG, -90 * DEG, 53)[0] == 1
    assert addr.address(0.0, -88.4 * DEG, 53)[0] == 1  # below (2 - n_d) pi / (2 n_d): first ring


def test_redundant_neighbours_across_ra_0():
    l_d, l_ra = addr.redundant_neighbours(359.0 * DEG, 0.0, 53, RHO_SUB)
    expected = [addr.address(a * DEG, d * DEG, 53) for a, d in ((11.0, 0.0), (347.0, 0.0), (359.0, 12.0), (359.0, -12.0))]
    assert [(int(a), int(b)) for a, b in zip(l_d, l_ra)] == [(int(a), int(b)) for a, b in expected]
    assert int(l_ra[0]) < 10  # east neighbour wrapped past RA = 0 to the start of its ring


def test_redundant_neighbours_over_the_pole():
    ra, dec = 30.0 * DEG, 85.0 * DEG
    moved_ra, moved_dec = addr.offset_directions(ra, dec, RHO_SUB)  # default tolerances: rounding level, closed forms
    assert np.allclose(angular_distance(radec_to_vector(ra, dec), radec_to_vector(moved_ra, moved_dec)), RHO_SUB)
    # North crosses the pole: comes down at RA + 180 deg, Dec = 180 - 85 - 12 deg.
    assert np.degrees(moved_ra[2]) == pytest.approx(210.0)
    assert np.degrees(moved_dec[2]) == pytest.approx(83.0)
    assert np.degrees(moved_dec[3]) == pytest.approx(73.0)
    l_d, l_ra = addr.redundant_neighbours(ra, dec, 53, RHO_SUB)
    assert (int(l_d[2]), int(l_ra[2])) == tuple(int(x) for x in addr.address(210 * DEG, 83 * DEG, 53))
    # Exactly at a pole the four moves stay defined and ρ_sub away.
    moved_ra, moved_dec = addr.offset_directions(0.0, -90 * DEG, RHO_SUB)
    assert np.all(np.isfinite(moved_ra)) and np.allclose(np.degrees(moved_dec), -78.0)


def test_bad_inputs_raise_input_error():
    with pytest.raises(InputError, match="declination"):
        addr.address(0.0, 1.7, 53)
    with pytest.raises(InputError, match="finite"):
        addr.address(float("nan"), 0.0, 53)
    with pytest.raises(InputError, match="n_d"):
        addr.ring_sizes(2)
    with pytest.raises(InputError, match="l_ra"):
        addr.base_index(38, 72, 53)
    with pytest.raises(InputError, match="rho_sub"):
        addr.redundant_neighbours(0.0, 0.0, 53, -1.0)


def test_scalar_path_equals_array_path():
    rng = np.random.default_rng(21)
    v = rng.normal(size=(3000, 3))
    ra, dec = vector_to_radec(v)
    ra = np.concatenate([ra, [0.0, 2 * np.pi, np.nextafter(2 * np.pi, 0), 1e-300], addr.base_points_radec(53)[0]])
    dec = np.concatenate([dec, [np.pi / 2, -np.pi / 2, 0.0, 0.0], addr.base_points_radec(53)[1]])
    for n_d in (7, 53):
        l_d, l_ra = addr.address(ra, dec, n_d)
        index = addr.base_index(l_d, l_ra, n_d)
        for k in range(ra.size):
            assert addr.address(float(ra[k]), float(dec[k]), n_d) == (l_d[k], l_ra[k])
            assert addr.sub_catalog_index(float(ra[k]), float(dec[k]), n_d) == index[k]
