"""The star identifier: one call per frame, strategies tried in the order of docs/design.md's closed loop.

``StarIdentifier(catalog, camera, ...)`` holds the navigation catalog (guide stars, pattern pairs,
k-vector, sub-catalogs), the field stars used for verification (every Hipparcos star to the
catalog's magnitude limit) and three strategies, each an object with ``identify(frame, prior)``:

* :class:`~startrack.identify.tracking.Tracking` -- needs ``prior.q_IS`` (and optionally a rate);
* :class:`~startrack.identify.subcatalog.SubCatalog` -- needs a prior boresight (from ``prior.q_IS``
  or ``prior.boresight``);
* :class:`~startrack.identify.lost_in_space.LostInSpace` -- needs nothing; searches the pairs of every
  field star (``dense_fallback``, the default) or of the guide catalog.

Each strategy is one compiled call per frame (lost-in-space: :mod:`startrack.identify.pattern_hash`'s
look-ups, then :mod:`startrack.identify.pyramid`'s search; hypotheses, verification and refit); the
Python layer checks the input, orders the centroids and turns them into directions (one compiled
call), and builds the result.  Profile of the full-sky call on the benchmark frames (16 deg, ~30
centroids, 0-3 false, each frame solved once in turn, median ~33 us): ~3.5 us directions, ~22 us the
compiled search (12 us with warm caches: ~6.5 us verification, ~5 us look-ups; the rest is the tables
a new frame reads from memory), ~6 us the result (matches, quaternion, record), ~2 us checks and
dispatch.  Before issue 17 the call took ~180 us, ~60 us of it in Python orchestration; the pyramid
search alone (no look-ups) ~50 us.

``solve(uv, flux, prior)`` takes centroids [px]; ``solve_vectors(obs_S, flux, prior)`` takes unit
vectors in the sensor frame.  Both return an :class:`~startrack.identify.result.IdentificationResult`
and never raise for the content of a frame (NaN, too few or off-sensor centroids give a status and a
reason); a wrong configuration raises :class:`startrack.base.errors.InputError` at construction.
"""

from __future__ import annotations

import math
import time

import numpy as np

from startrack.base.errors import InputError
from startrack.compiled.numba_setup import njit
from startrack.compiled.sorts import argsort
from startrack.geometry.rotation_kernels import quat_from_matrix
from startrack.identify.context import SearchContext
from startrack.identify.features import (
    ALL_OUTSIDE,
    BAD_COORDINATE,
    BAD_FLUX,
    DIRECTIONS_OK,
    FrameFeatures,
    brightest_first,
    centroid_directions,
    separated,
)
from startrack.identify.kernel_loading import load_kernels
from startrack.identify.lost_in_space import LostInSpace
from startrack.identify.prior import Prior
from startrack.identify.result import IdentificationResult
from startrack.identify.subcatalog import SubCatalog
from startrack.identify.tracking import Tracking
from startrack.identify.verify import DEFAULT_FALSE_MATCH_THRESHOLD, FieldStars

#: Strategy names in the order they are tried.
METHODS = ("tracking", "subcatalog", "lost_in_space")


def _positive(name, value, upper=math.inf):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating))\
            or not math.isfinite(value) or not 0.0 < value <= upper:
        raise InputError(f"star identifier option {name} = {value!r} must be a number in (0, {upper:g}].")
    return float(value)


class StarIdentifier:
    """Star identification over a navigation catalog for one camera.

    catalog: :class:`startrack.catalog.navigation.NavigationCatalog`; camera: :class:`startrack.camera.model.Camera`;
    centroid_sigma_px: centroid noise per axis [px] (covariance and gates); delta_sigmas: the error
    bound delta of 001 §4.3.1 in units of it (3); gate_sigmas: verification match radius in units of it
    (5); pattern_stars: brightest centroids searched first (16, at most 31; then twice as many); max_stars:
    centroids used at all (None: all); false_match_threshold: acceptance threshold (1e-6);
    tracking_window_px: tracking window radius (20 px); methods: strategies tried, a subset of
    :data:`METHODS`; neighbours: search the 4 redundant sub-catalogs; field_stars: a
    :class:`~startrack.identify.verify.FieldStars` (default: every Hipparcos star with V <= field_mag_limit,
    by default the catalog's magnitude limit); dense_fallback: also search the pairs of every field star
    when the guide catalog finds nothing (built at construction, ~0.2 s).

    Construction loads (or compiles, once per machine) every kernel by solving a synthetic frame with
    each strategy, so that no solve pays for it; :attr:`load_ms` is the time that took [ms].
    """

    def __init__(self, catalog, camera, centroid_sigma_px=0.2, delta_sigmas=3.0, gate_sigmas=5.0,
                 pattern_stars=16, max_stars=None, false_match_threshold=DEFAULT_FALSE_MATCH_THRESHOLD,
                 tracking_window_px=20.0, methods=METHODS, neighbours=True, field_stars=None, field_mag_limit=None,
                 dense_fallback=True):
        self.catalog = catalog
        self.camera = camera
        self.centroid_sigma_px = _positive("centroid_sigma_px", centroid_sigma_px, 100.0)
        self.delta_px = _positive("delta_sigmas", delta_sigmas, 100.0) * self.centroid_sigma_px
        self.verify_gate = _positive("gate_sigmas", gate_sigmas, 100.0) * self.centroid_sigma_px / camera.focal_px
        if isinstance(pattern_stars, bool) or not isinstance(pattern_stars, (int, np.integer))\
                or not 4 <= pattern_stars <= 31:
            raise InputError(f"star identifier option pattern_stars = {pattern_stars!r} must be an integer in [4, 31].")
        if max_stars is not None and (isinstance(max_stars, bool) or not isinstance(max_stars, (int, np.integer))
                                      or max_stars < 3):
            raise InputError(f"star identifier option max_stars = {max_stars!r} must be an integer >= 3 or None.")
        self.pattern_stars = int(pattern_stars)
        self.max_stars = None if max_stars is None else int(max_stars)
        self.false_match_threshold = _positive("false_match_threshold", false_match_threshold, 1.0)
        unknown = [m for m in methods if m not in METHODS]
        if unknown or not methods:
            raise InputError(f"star identifier methods {tuple(methods)!r} must be a non-empty subset of {METHODS}.")
        if field_stars is None:
            from startrack.catalog.hipparcos import load_star_catalog

            field_stars = FieldStars.from_star_catalog(
                catalog, camera, load_star_catalog(catalog.params.epoch).in_band(catalog.params.band),
                catalog.params.mag_limit if field_mag_limit is None else _positive("field_mag_limit", field_mag_limit, 20.0))
        self.field = field_stars
        window_px = _positive("tracking_window_px", tracking_window_px, 1e4)
        context = SearchContext(catalog, self.field, self.pattern_stars, self.verify_gate, self.false_match_threshold,
                                self.centroid_sigma_px / camera.focal_px, dense=bool(dense_fallback) and ("lost_in_space" in methods or "subcatalog" in methods))
        available = {
            "tracking": lambda: Tracking(context, window_px),
            "subcatalog": lambda: SubCatalog(context, neighbours),
            "lost_in_space": lambda: LostInSpace(context, context.dense),
        }
        self.strategies = [available[m]() for m in METHODS if m in methods]
        self._max_stars = -1 if self.max_stars is None else self.max_stars
        self._sigma = self.centroid_sigma_px / camera.focal_px
        #: Centroids closer than this (the larger of 1 px and the error bound) are one star.
        self._cos_merge = math.cos(max(1.0, self.delta_px) / camera.focal_px)
        start = time.perf_counter()
        load_kernels(self)
        self.load_ms = 1e3 * (time.perf_counter() - start)

    # ------------------------------------------------------------------ public calls
    def solve(self, uv, flux=None, prior: Prior | None = None) -> IdentificationResult:
        """Identify centroids ``uv`` (n, 2) [px] (``flux`` (n,) optional: brightest first; else given order)."""
        start = time.perf_counter()
        uv = _float_array(uv)
        if uv is None or uv.ndim != 2 or uv.shape[1] != 2:
            return _failed("error", "centroids must be an array of shape (n, 2) of numbers", start)
        flux = self._checked_flux(flux, uv.shape[0])
        if isinstance(flux, str):
            return _failed("error", flux, start)
        status, obs_S, index, beta, gate, filled = centroid_directions(
            np.ascontiguousarray(uv), flux, self.field.camera_params, self._max_stars, 2 * self.pattern_stars,
            self._cos_merge)
        if status != DIRECTIONS_OK:
            return _failed("error", self._direction_errors[status].format(n=uv.shape[0]), start)
        if len(obs_S) < 3:
            return _too_few(len(obs_S), start)
        return self._solve(FrameFeatures(obs_S, index, beta, gate, filled, self.camera.focal_px, self.delta_px,
                                         self.verify_gate), prior, start)

    def solve_vectors(self, obs_S, flux=None, prior: Prior | None = None) -> IdentificationResult:
        """Identify directions ``obs_S`` (n, 3) in the sensor frame (normalised here), brightest first unless ``flux``."""
        start = time.perf_counter()
        obs = _float_array(obs_S)
        if obs is None or obs.ndim != 2 or obs.shape[1] != 3:
            return _failed("error", "directions must be an array of shape (n, 3) of numbers", start)
        norms = np.linalg.norm(obs, axis=1)
        if not (np.all(np.isfinite(obs)) and np.all(norms > 0.0)):
            return _failed("error", "a direction is NaN, infinite or zero", start)
        flux = self._checked_flux(flux, obs.shape[0])
        if isinstance(flux, str):
            return _failed("error", flux, start)
        if not np.all(np.isfinite(flux)):
            return _failed("error", "a flux value is NaN or infinite", start)
        index = brightest_first(flux, obs.shape[0], -1)
        obs, index = separated(obs[index] / norms[index, None], index, self._cos_merge, self._max_stars)
        if len(index) < 3:
            return _too_few(len(index), start)
        return self._solve(self.features(obs, index), prior, start)

    # ------------------------------------------------------------------ internals
    @staticmethod
    def _checked_flux(flux, n):
        """``flux`` as a float array ((0,) when None), or the reason it cannot be one."""
        if flux is None:
            return _NO_FLUX
        flux = _float_array(flux)
        if flux is None or flux.shape != (n,):
            return f"flux must be one number per centroid ({n})"
        return np.ascontiguousarray(flux)

    @property
    def _direction_errors(self):
        cam = self.camera
        return {BAD_COORDINATE: "a centroid coordinate is NaN or infinite", BAD_FLUX: "a flux value is NaN or infinite",
                ALL_OUTSIDE: f"all {{n}} centroids lie outside the {cam.width} x {cam.height} px sensor"}

    def features(self, obs_S, index) -> FrameFeatures:
        """The frame's features for the search: ``obs_S`` (n, 3) directions brightest first, ``index`` their
        positions in the caller's list."""
        return FrameFeatures.build(obs_S, index, self.camera.focal_px, self.delta_px, self.verify_gate,
                                   2 * self.pattern_stars, n_filled=0)

    def _solve(self, frame, prior, start):
        for strategy in self.strategies:
            verified = strategy.identify(frame, prior)
            if verified is not None:
                return self._result(frame, verified, strategy, prior, start)
        tried = ", ".join(s.name for s in self.strategies if s.name == "lost_in_space" or prior is not None)
        return _failed("no_match", f"no star pattern was verified ({tried or 'no method applicable'})", start)

    def _result(self, frame, verified, strategy, prior, start):
        matches, obs_S, ref_I = _matched_stars(frame.index, frame.obs_S, verified.obs_index, verified.star_index,
                                              self.field.hip, self.field.vectors)
        lost = entered = _NO_STARS
        if strategy.name == "tracking":
            lost, entered = strategy.lost_and_entered(prior, verified.R_IS, matches[:, 1])
        return IdentificationResult(
            status="ok", q_IS=quat_from_matrix(verified.R_IS), matches=matches, obs_S=obs_S, ref_I=ref_I,
            sigma=self._sigma, false_match_probability=verified.false_match_probability, method=strategy.name,
            solve_ms=1e3 * (time.perf_counter() - start), lost_hip=lost, entered_hip=entered, camera=self.camera,
            camera_source="given")


@njit
def _matched_stars(index, obs_S, obs_index, star_index, hip, vectors):  # pragma: no cover  (compiled)
    """(matches (M, 2) rows (centroid index, HIP), obs_S (M, 3), ref_I (M, 3)) ordered by centroid index."""
    centroid = index[obs_index]
    order = argsort(centroid.astype(np.float64))
    matches = np.empty((order.size, 2), np.int64)
    seen = np.empty((order.size, 3))
    ref = np.empty((order.size, 3))
    for m in range(order.size):
        matches[m, 0], matches[m, 1] = centroid[order[m]], hip[star_index[order[m]]]
        seen[m] = obs_S[obs_index[order[m]]]
        ref[m] = vectors[star_index[order[m]]]
    return matches, seen, ref


_NO_STARS = np.zeros(0, np.int64)
_NO_FLUX = np.zeros(0)


def _float_array(value):
    """``value`` as a float array, or None when it is not numbers (text, ragged lists, objects)."""
    if type(value) is np.ndarray and value.dtype == np.float64:
        return value
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        return value.astype(float, copy=False)
    try:
        array = np.asarray(value)
    except (ValueError, TypeError):
        return None
    return array.astype(float) if array.dtype.kind in "biuf" else None


def _too_few(n, start):
    return _failed("too_few", f"{n} usable centroids; at least 3 are needed", start)


def _failed(status, reason, start):
    return IdentificationResult(status=status, reason=reason + ".", solve_ms=1e3 * (time.perf_counter() - start))
