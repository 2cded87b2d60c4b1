"""Declination-zone index (startrack.identify.zones) against a brute-force pass over every star."""

import math

import numpy as np
import pytest

from startrack.identify.zones import ZONE_HEIGHT, stars_near, zone_index


@pytest.fixture(scope="module")
def stars():
    rng = np.random.default_rng(11)
    v = rng.normal(size=(50_000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v[:4] = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [1.0, -1e-15, 0.0]]  # poles, RA 0 and just below 2 pi
    v[3] /= np.linalg.norm(v[3])
    return v


def test_each_zone_holds_its_stars_sorted_by_ra(stars):
    offsets, ra, star, height = zone_index(stars)
    dec = np.arcsin(np.clip(stars[star, 2], -1.0, 1.0))
    assert height == ZONE_HEIGHT and offsets[0] == 0 and offsets[-1] == len(stars) and np.array_equal(np.sort(star),
                                                                                                        np.arange(len(stars)))
    for z in range(offsets.size - 1):
        part = slice(offsets[z], offsets[z + 1])
        assert np.all(np.diff(ra[part]) >= 0.0)
        assert np.all((dec[part] >= z * height - 0.5 * np.pi - 1e-12) & (dec[part] <= (z + 1) * height - 0.5 * np.pi + 1e-12))


@pytest.mark.parametrize("radius_deg", [0.3, 2.0, 15.0, 60.0, 120.0])
def test_stars_near_are_exactly_those_within_the_radius(stars, radius_deg):
    """Centres at random, at the poles and on RA = 0: the set a brute-force dot product gives."""
    zones, rng = zone_index(stars), np.random.default_rng(int(radius_deg * 10))
    centres = np.vstack([rng.normal(size=(40, 3)), [[0, 0, 1], [0, 0, -1], [1, 0, 0], [1, 0, 0.3]]])
    centres /= np.linalg.norm(centres, axis=1, keepdims=True)
    out = np.empty(len(stars), np.int64)
    radius = math.radians(radius_deg)
    for centre in centres:
        count = stars_near(zones, stars, centre, radius, out)
        expected = np.flatnonzero(stars @ centre >= math.cos(radius))
        assert np.array_equal(np.sort(out[:count]), expected)
        brightest = stars_near(zones, stars, centre, radius, out, 1000)
        assert np.array_equal(np.sort(out[:brightest]), expected[expected < 1000])
