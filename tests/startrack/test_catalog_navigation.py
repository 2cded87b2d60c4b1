"""Navigation catalog of 000 §2 checked layer by layer against brute force."""

import dataclasses
import math

import numpy as np
import pytest

from startrack.base.errors import InputError
from startrack.catalog.hipparcos import load_star_catalog
from startrack.catalog.navigation import (
    DEG,
    REFERENCE_000,
    NavigationCatalog,
    NavigationCatalogParams,
    build_navigation_catalog,
    cache_path,
    load_navigation_catalog,
)


@pytest.fixture(scope="module")
def catalog():
    return build_navigation_catalog(NavigationCatalogParams())


@pytest.fixture(scope="module")
def candidates(catalog):
    stars = load_star_catalog(catalog.params.epoch)
    keep = (stars.v_mag <= 6.0) & ~stars.multiple & ~stars.variable
    return stars.select(keep)


def angles(a, b):
    return np.arccos(np.clip(a @ b.T, -1.0, 1.0))


def test_base_points_and_radii(catalog):
    assert catalog.n_base == 3100 == REFERENCE_000["base_points"]
    assert math.ceil(np.degrees(catalog.s_max)) == REFERENCE_000["s_max_ceil_deg"]
    # s_max: largest nearest-neighbour distance, brute force over all base-point pairs.
    d = angles(catalog.base_vectors, catalog.base_vectors)
    np.fill_diagonal(d, np.inf)
    assert catalog.s_max == pytest.approx(np.max(np.min(d, axis=1)), abs=1e-9)  # rounding level: the same angles
    assert np.degrees(catalog.rho_sub) == pytest.approx(2.0 + 2.0 + 8.0)  # eq. 6


def test_candidate_counts_per_rule(catalog):
    stars = load_star_catalog(2000.0)
    bright = stars.v_mag <= 6.0
    excluded = catalog.info["excluded"]
    assert excluded["magnitude"] == int(np.sum(~bright))
    assert excluded["multiple"] == int(np.sum(bright & stars.multiple))
    assert excluded["variable"] == int(np.sum(bright & ~stars.multiple & stars.variable))
    assert catalog.info["candidates"] == len(stars) - sum(excluded.values())


def test_guide_stars_are_the_nearest_candidates_brute_force(catalog, candidates):
    d = angles(catalog.base_vectors, candidates.vectors)
    nearest = np.argmin(d, axis=1)
    within = d[np.arange(catalog.n_base), nearest] <= catalog.s_max
    expected_hip = np.unique(candidates.hip[nearest[within]])
    assert np.array_equal(catalog.guide_hip, expected_hip)
    assert np.all(catalog.guide_v_mag <= 6.0)


def test_guide_stars_are_more_uniform_than_candidates(catalog, candidates):
    # Fig. 3 of 000: homogenisation. Stars per field of view (8 deg caps on every base point, equal
    # areas unlike RA/Dec windows) vary much less after the selection.
    def spread(vectors):
        counts = np.sum(angles(catalog.base_vectors, vectors) <= catalog.params.fov / 2, axis=1)
        return counts.std() / counts.mean()

    assert spread(catalog.guide_vectors) < 0.65 * spread(candidates.vectors)  # 0.22 vs 0.39


def test_pattern_pairs_brute_force(catalog):
    p = catalog.params
    d = angles(catalog.guide_vectors, catalog.guide_vectors)
    i, j = np.nonzero(np.triu((d >= p.theta_min) & (d <= p.theta_max), k=1))
    assert catalog.n_pairs == i.size
    assert set(zip(catalog.pair_i.tolist(), catalog.pair_j.tolist())) == set(zip(i.tolist(), j.tolist()))
    assert np.all(np.diff(catalog.pair_theta) >= 0)
    assert np.all(catalog.pair_i < catalog.pair_j)
    assert catalog.pair_theta.dtype == np.float64 and catalog.pair_i.dtype == np.int32
    exact = d[catalog.pair_i, catalog.pair_j]
    # the arccos form is the less accurate one: a few ulp of the dot over sin θ_min = 2e-13 (1e-13 seen); 1e-11 rad
    assert np.max(np.abs(exact - catalog.pair_theta)) < 1e-11


def test_k_vector_search_on_the_pair_table(catalog):
    rng = np.random.default_rng(2)
    centre = rng.uniform(0.0, catalog.params.theta_max, 50)
    width = rng.uniform(0.0, 200.0, 50) * math.pi / (180 * 3600)
    for a, b in zip(centre - width, centre + width):
        expected = np.flatnonzero((catalog.pair_theta >= a) & (catalog.pair_theta <= b))
        assert np.array_equal(catalog.pairs_in_range(a, b), expected)
    lo, hi = catalog.pair_ranges(centre - width, centre + width)
    assert np.array_equal(lo, np.searchsorted(catalog.pair_theta, centre - width, side="left"))
    assert np.array_equal(hi, np.searchsorted(catalog.pair_theta, centre + width, side="right"))


def test_sub_catalog_stars_brute_force(catalog):
    inside = angles(catalog.base_vectors, catalog.guide_vectors) <= catalog.rho_sub
    for b in range(catalog.n_base):
        assert np.array_equal(catalog.sub_catalog_stars(b), np.flatnonzero(inside[b])), b


def test_sub_catalog_pairs_brute_force(catalog):
    rng = np.random.default_rng(4)
    for b in np.concatenate([[0, catalog.n_base - 1], rng.choice(catalog.n_base, 40, replace=False)]):
        members = np.zeros(catalog.n_guide, dtype=bool)
        members[catalog.sub_catalog_stars(b)] = True
        expected = np.flatnonzero(members[catalog.pair_i] & members[catalog.pair_j])
        assert np.array_equal(catalog.sub_catalog_pairs(b), expected), b


def test_sub_catalog_covers_the_field_of_any_boresight(catalog):
    # The sub-catalog addressed by a boresight holds every guide star of its field (000 §2.3).
    rng = np.random.default_rng(9)
    v = rng.normal(size=(300, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    ra = np.arctan2(v[:, 1], v[:, 0])
    dec = np.arcsin(v[:, 2])
    index = catalog.sub_catalog_index(ra, dec)
    in_field = angles(v, catalog.guide_vectors) <= catalog.params.fov / 2
    for k, b in enumerate(index):
        assert set(np.flatnonzero(in_field[k])) <= set(catalog.sub_catalog_stars(b).tolist())


def test_counts_near_000_without_the_hipparcos_specific_rules():
    # Hipparcos flags far more stars as double or variable than SKYMAP 2000 did; with both rules
    # off the counts land within 3 % of 000 (2717 guide stars, 70791 pairs).
    loose = build_navigation_catalog(NavigationCatalogParams(exclude_multiple=False, exclude_variable=False))
    assert loose.n_guide == pytest.approx(REFERENCE_000["guide_stars"], rel=0.03)
    assert loose.n_pairs == pytest.approx(REFERENCE_000["pairs"], rel=0.03)
    assert loose.info["excluded"]["multiple"] == loose.info["excluded"]["variable"] == 0


def test_memory_table_and_statistics(catalog):
    table = catalog.memory_table()
    stats = catalog.statistics()
    total = sum(getattr(catalog, name).nbytes for name in (
        "guide_hip", "guide_ra", "guide_dec", "guide_vectors", "guide_v_mag", "kvector_k", "pair_theta", "pair_i",
        "pair_j", "sub_star_offsets", "sub_star_index", "sub_pair_offsets", "sub_pair_index", "base_ra", "base_dec",
        "base_vectors", "ring_sizes", "ring_offsets"))  # fmt: skip
    assert sum(row["bytes"] for row in table) == total == stats["memory_bytes"]["total"]
    sizes = np.diff(catalog.sub_star_offsets)
    assert stats["subcatalog_stars"] == {"min": int(sizes.min()), "max": int(sizes.max()),
                                         "mean": round(float(sizes.mean()), 2)}  # fmt: skip
    assert stats["pairs"] == catalog.n_pairs and stats["guide_stars"] == catalog.n_guide


def test_arrays_are_read_only(catalog):
    with pytest.raises(ValueError):
        catalog.pair_theta[0] = 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        catalog.s_max = 1.0


def test_cache_round_trip(tmp_path, catalog):
    path = catalog.save(tmp_path / "catalog.npz")
    loaded = NavigationCatalog.load(path)
    assert loaded.from_cache and not catalog.from_cache
    assert loaded.params == catalog.params
    for field in dataclasses.fields(NavigationCatalog):
        value = getattr(catalog, field.name)
        if isinstance(value, np.ndarray):
            other = getattr(loaded, field.name)
            assert other.dtype == value.dtype and np.array_equal(other, value), field.name
    assert loaded.s_max == catalog.s_max and loaded.rho_sub == catalog.rho_sub
    assert np.array_equal(loaded.pairs_in_range(0.1, 0.1001), catalog.pairs_in_range(0.1, 0.1001))
    assert dict(loaded.info) == dict(catalog.info)


def test_load_navigation_catalog_uses_a_cache_keyed_by_parameters():
    params = NavigationCatalogParams(fov=12.0 * DEG, n_d=30)
    path = cache_path(params)
    path.unlink(missing_ok=True)
    first = load_navigation_catalog(params)
    second = load_navigation_catalog(params)
    assert not first.from_cache and second.from_cache and path.is_file()
    assert np.array_equal(first.sub_pair_index, second.sub_pair_index)
    for changed in (dataclasses.replace(params, sigma=params.sigma * 2), dataclasses.replace(params, epoch=2025.0),
                    dataclasses.replace(params, exclude_variable=False)):  # fmt: skip
        assert cache_path(changed) != path
    path.write_bytes(b"not an npz file")  # a damaged cache file is rebuilt, not trusted
    rebuilt = load_navigation_catalog(params)
    assert not rebuilt.from_cache and load_navigation_catalog(params).from_cache


@pytest.mark.parametrize(
    "change, message",
    [({"fov": float("nan")}, "fov"), ({"mag_limit": 30.0}, "mag_limit"), ({"n_d": 2}, "n_d"),
     ({"theta_min": 10.0 * DEG}, "theta_min"), ({"n_d": 5.5}, "n_d"), ({"n_d": "53"}, "n_d"),
     ({"exclude_variable": "no"}, "exclude_variable")],
)  # fmt: skip
def test_bad_parameters_raise_input_error(change, message):
    with pytest.raises(InputError, match=message):
        NavigationCatalogParams(**change)


def test_sub_catalog_pairs_chunking_does_not_change_the_result(catalog):
    from startrack.catalog.navigation import sub_catalog_pairs

    offsets, index = sub_catalog_pairs(catalog.sub_star_offsets, catalog.sub_star_index, catalog.pair_i,
                                       catalog.pair_j, catalog.n_guide, chunk_pairs=20_000)  # fmt: skip
    assert np.array_equal(offsets, catalog.sub_pair_offsets) and np.array_equal(index, catalog.sub_pair_index)


def test_a_catalog_in_the_sensors_band_takes_the_stars_brightest_there():
    """A J-band navigation catalog's candidates are the stars to the limit in J (red giants that V leaves out come
    in): its guide stars all have J <= the limit, the V and J catalogs differ, and the star catalog's V stays V."""
    stars = load_star_catalog()
    in_j = stars.in_band("J")
    assert in_j.band == "J" and np.array_equal(in_j.v_mag, stars.v_mag) and not np.array_equal(in_j.mag, stars.mag)
    assert len(in_j.brighter_than(4.0)) > 4 * len(stars.brighter_than(4.0))  # J - V of -1 to -4 for K and M stars
    j_catalog = build_navigation_catalog(NavigationCatalogParams(mag_limit=4.0, band="J"))
    v_catalog = build_navigation_catalog(NavigationCatalogParams(mag_limit=4.0))
    assert j_catalog.guide_v_mag.max() <= 4.0 and not np.array_equal(j_catalog.guide_hip, v_catalog.guide_hip)
    j_of_guides = in_j.mag[np.searchsorted(in_j.hip, j_catalog.guide_hip)]
    assert np.allclose(j_of_guides, j_catalog.guide_v_mag)
