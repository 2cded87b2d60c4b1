"""Identification of frames from an unknown camera: field of view, principal point and distortion found
from the stars (a plate solver).

:class:`PlateSolver` holds the pattern catalog (:mod:`startrack.identify.pattern_catalog`) and the
verification stars (the same stars, V <= its magnitude limit, at the frames' epoch, in a
declination-zone index): the Hipparcos-2 stars to V 8, or when the fields searched reach below 5 deg
the Gaia DR3 stars to V 10 (:mod:`startrack.catalog.gaia`; a 2 deg field holds a median 28 of them, 6
Hipparcos-2 stars to V 9), as the default range, 2-160 deg (:data:`DEFAULT_FOV_RANGE`), does.  The answer
names each star by its id (:attr:`startrack.catalog.hipparcos.StarCatalog.ids`: the HIP number, else the Gaia
DR3 source_id).
``solve`` orders the detections brightest first, thins them into pattern candidates, measures the local
density of the detections (a grid of the frame, the false-match model of
:mod:`startrack.identify.self_calibration`), and runs the compiled search
(:func:`startrack.identify.scale_free.search`) in chunks of combinations (one at first, growing while
the budget holds them) until a hypothesis is
accepted, the combinations are exhausted or the time budget is spent.  The answer carries the
calibrated camera (:class:`startrack.camera.fit.CameraCalibration`) with its sigma.

Verification depth: the ``n_predicted`` brightest catalog stars imaged in the frame, twice the
number of detections within [30, 1000]; the faintest of them is the frame's catalog depth
(reported as ``mag_limit``), so a rich frame is checked against a deep catalog and a sparse one
against its brightest stars; the stars near the boresight are gathered down to the depth that puts about
4 n_predicted of them in the field (all of Hipparcos-2's to V 8 but for the widest fields; the
brightest ~50 000 of Gaia's 480 000 for a 60 deg one).  In a frame of more than 75 detections a
hypothesis is first screened against its :data:`SCREEN_STARS` brightest predicted stars
(:mod:`startrack.identify.scale_free`, step 6), so that a crowded frame's budget holds about three times
the hypotheses.
"""

from __future__ import annotations

import math
import time

import numpy as np

from startrack.base.errors import InputError
from startrack.base.units import DEG
from startrack.camera.fit import CameraCalibration
from startrack.camera.model import PROJECTIONS, Camera, radius_of_angle
from startrack.identify.pattern_catalog import (
    RECTILINEAR_TO,
    PatternCatalogParams,
    fisheye_tolerance,
    load_pattern_catalog,
    load_source,
)
from startrack.identify.result import IdentificationResult
from startrack.identify.scale_free import COMBINATIONS_BELOW, pattern_candidates, search
from startrack.identify.zones import SKY, cap, zone_index

#: Default acceptance threshold of the false-match probability.
_DEFAULT_THRESHOLD = 1e-6
#: Most combinations searched per compiled call between two looks at the clock.
CHUNK = 48
#: Most hypotheses verified per compiled call.
MAX_TRIED = 1000
#: Cells of the detection-density grid along each image axis.
_DENSITY_CELLS = 8
#: Detections and predicted stars of the first verification pass.
_FIRST_STARS = 40
#: Most predicted stars of a hypothesis's first verification, before the full depth (the screen of
#: :func:`startrack.identify.scale_free.search`): 150 verify about three times the hypotheses per second of
#: a crowded frame's 1000 (1150-2440 detections: 270-450 -> 600-1370 in the 1 s budget).
SCREEN_STARS = 150
#: The screen passes a hypothesis on to the full verification when the chance of its matches (the Poisson
#: tail alone, without the look-elsewhere factor of the full verification) is below this: a noisy frame's
#: right hypothesis matches few of 150 stars (4 px centroid noise: screened out at 0.01, kept at 0.1).
_SCREEN_THRESHOLD = 0.1
#: Centroid error [px] added in quadrature to every detection's sigma: the pixel noise a detection
#: reports leaves out the PSF's asymmetries, the pixel response and compression, so without a floor the
#: brightest stars would take nearly all the weight of the fit.
SIGMA_FLOOR_PX = 0.1
#: The intrinsics a known camera can have refitted: focal length, principal point, k1, k2; and those
#: refitted unless told otherwise (k2 is rarely determined by one frame).
REFIT = ("focal", "centre", "k1", "k2")
_DEFAULT_REFIT = ("focal", "centre", "k1")
#: Prior sigma of a held focal length, as a fraction of it: the fit's first step puts it at the camera's.
_HELD_FOCAL = 1e-9
#: Level [rad] from which up frames are also searched as fisheye images (the pinhole ones up to
#: :data:`startrack.identify.pattern_catalog.RECTILINEAR_TO`).
_FISHEYE_FROM = 40.0 * DEG * (1 - 1e-9)
#: Prior sigma of k2 of a fisheye hypothesis when the solver holds k2 (the equisolid, stereographic and
#: orthographic lenses have k2 = 1/1920, 1/120 and 1/120 in the equidistant model).
_FISHEYE_K2_SIGMA = 0.02
#: Widest pinhole field [rad] whose focal length the search allows.
_PINHOLE_WIDEST = 170.0 * DEG
#: Faintest star [V mag] of the Gaia DR3 stars a search below the Hipparcos levels (5 deg) takes.
_GAIA_MAG_LIMIT = 10.0
#: Fields of view [rad] searched unless told otherwise: 2 deg (a 2 deg 4:3 field holds a median 28 Gaia
#: stars to V 10, never fewer than 4; benchmarks/narrow_field_stars.py) to the widest level, 160 deg.
DEFAULT_FOV_RANGE = (2.0 * DEG, PatternCatalogParams().fov_max)


def _positions(ids, wanted):
    """Indices into ``ids`` of the ids ``wanted`` (both brightest first: mostly the same order), or None
    when ``ids`` does not hold each of them once."""
    if np.array_equal(ids, wanted):
        return np.arange(ids.size)
    order = np.argsort(ids, kind="stable")
    position = order[np.clip(np.searchsorted(ids[order], wanted), 0, max(ids.size - 1, 0))]
    return position if ids.size == wanted.size and np.array_equal(ids[position], wanted) else None


def _density_grid(uv, width, height):
    """(detections per px^2 on a _DENSITY_CELLS^2 grid, box-smoothed over 3 x 3 cells and never below the
    frame's mean, cell width, cell height)."""
    counts, _, _ = np.histogram2d(uv[:, 1], uv[:, 0], bins=_DENSITY_CELLS, range=[[-0.5, height - 0.5], [-0.5, width - 0.5]])
    padded = np.pad(counts, 1)
    cells = np.pad(np.ones_like(counts), 1)
    window = sum(padded[i:i + _DENSITY_CELLS, j:j + _DENSITY_CELLS] for i in range(3) for j in range(3))
    area = sum(cells[i:i + _DENSITY_CELLS, j:j + _DENSITY_CELLS] for i in range(3) for j in range(3))
    cell_w, cell_h = width / _DENSITY_CELLS, height / _DENSITY_CELLS
    density = np.maximum(window / (area * cell_w * cell_h), len(uv) / (width * height))
    return np.ascontiguousarray(density), float(cell_w), float(cell_h)


class PlateSolver:
    """Star identification and camera calibration of frames whose field of view is unknown.

    fov_range: (min, max) field of view across the image width [rad] (default :data:`DEFAULT_FOV_RANGE`);
    epoch: of the star positions [Julian year]; threshold: largest accepted false-match probability;
    time_budget_s: search time per frame before ``no_match``; final_gate_px: match radius of the last
    verification passes [px]; principal_point_sigma: prior sigma of the principal point about the
    image centre, as a fraction of the larger image side; k1_sigma, k2_sigma: prior sigma of the
    distortion about 0 (k2_sigma = 0 holds k2 at 0); mag_limit: faintest star of the verification
    [V mag] (default: the pattern catalog's, 8, or :data:`_GAIA_MAG_LIMIT` with the Gaia stars); progress:
    show the pattern catalog's build.
    """

    def __init__(self, fov_range=None, epoch=2000.0, threshold=_DEFAULT_THRESHOLD, time_budget_s=1.0, final_gate_px=2.0,
                 principal_point_sigma=0.005, k1_sigma=0.5, k2_sigma=0.0, mag_limit=None, progress=False):
        defaults = PatternCatalogParams()
        low, high = DEFAULT_FOV_RANGE if fov_range is None else (float(fov_range[0]), float(fov_range[1]))
        if not (0.5 * DEG <= low <= high <= defaults.fov_max):
            raise InputError(f"field of view range [{low / DEG:g}, {high / DEG:g}] deg must lie within "
                             f"[0.5, {defaults.fov_max / DEG:g}] deg.")
        for name, value, top in (("threshold", threshold, 1.0), ("time_budget_s", time_budget_s, 3600.0),
                                 ("final_gate_px", final_gate_px, 100.0), ("principal_point_sigma", principal_point_sigma, 1.0)):
            if not (math.isfinite(value) and 0.0 < value <= top):
                raise InputError(f"plate solver option {name} = {value!r} must lie in (0, {top:g}].")
        if not (0.0 <= k1_sigma < math.inf and 0.0 <= k2_sigma < math.inf):
            raise InputError("plate solver options k1_sigma and k2_sigma must be finite and >= 0.")
        params = defaults if low >= defaults.fov_min else\
            PatternCatalogParams(fov_min=low, mag_limit=_GAIA_MAG_LIMIT, source="gaia")  # fainter stars than Hipparcos-2's
        self.fov_range = (low, high)
        self.threshold, self.time_budget_s, self.final_gate_px = float(threshold), float(time_budget_s), float(final_gate_px)
        self.prior_sigma = np.array([math.inf, principal_point_sigma, principal_point_sigma, k1_sigma, k2_sigma])
        self.fisheye_k2_sigma = max(k2_sigma, _FISHEYE_K2_SIGMA)
        self.catalog = load_pattern_catalog(params, progress=progress)
        stars = load_source(params.source, epoch).brighter_than(params.mag_limit)
        position = _positions(stars.ids, self.catalog.ids)
        if position is None:
            raise InputError("pattern catalog and star catalog disagree (stale cache): remove the patterns-* cache folder.")
        self.source = params.source
        self.ids = np.asarray(self.catalog.ids, np.int64)  # brightest first
        self.vectors = np.ascontiguousarray(stars.vectors[position], dtype=float)
        self.v_mag = np.ascontiguousarray(stars.v_mag[position], dtype=float)
        cap = params.mag_limit if mag_limit is None else float(mag_limit)
        if not math.isfinite(cap) or not -2.0 <= cap <= params.mag_limit:
            raise InputError(f"verification magnitude limit {mag_limit!r} must lie in [-2, {params.mag_limit:g}] mag.")
        self.field = (self.vectors, self.v_mag, zone_index(self.vectors), int(np.searchsorted(self.v_mag, cap, "right")))
        ratio = params.level_ratio
        self.levels = [level for level in self.catalog.levels if level.fov / ratio < high and level.fov >= low]
        self._arrays = tuple(level.arrays for level in self.levels)
        # the look-ups: (level, projection code) of every level and the projections its frames may have
        self._entries = np.array([(n, code) for n, level in enumerate(self.levels) for code, limit in
                                  ((0, level.fov <= RECTILINEAR_TO), (1, level.fov >= _FISHEYE_FROM)) if limit], np.int64)
        self._mid_fov = np.array([self.levels[n].fov / math.sqrt(ratio) for n, _ in self._entries])
        self._tolerance = np.array([self.levels[n].tolerance if code == 0 else fisheye_tolerance(self.levels[n].fov)
                                    for n, code in self._entries])
        self._per_lookup = sum(self.levels[n].per_lookup for n, _ in self._entries)
        start = time.perf_counter()
        self._warm_up()
        self.load_ms = 1e3 * (time.perf_counter() - start)

    # ------------------------------------------------------------------ public
    def solve(self, uv, width, height, flux=None, sigma_px=None, fov_hint=None, camera=None, refit=_DEFAULT_REFIT,
              boresight=None) -> IdentificationResult:
        """Identify the detections ``uv`` (n, 2) [px] of a ``width`` x ``height`` frame; ``flux`` orders them
        (brightest first; else given order); ``sigma_px`` (n,) their centroid sigma [px] (default 0.3, with
        :data:`SIGMA_FLOOR_PX` added in quadrature);
        ``fov_hint`` [rad] searches the levels nearest it first; ``camera`` a
        :class:`startrack.camera.file.CameraFile` known before, refined: the intrinsics named in ``refit``
        (a subset of :data:`REFIT`) are fitted -- the focal length within 1 % or 3 sigma, the principal
        point and distortion with priors about the camera's, 3 times its sigma where the file gives one
        (else the solver's own prior; k2 that of k1 when the solver holds it) -- the others held at the
        camera's (InputError if its size differs); ``boresight`` = (axis (3,) unit vector, radius [rad]):
        the hypotheses whose pattern starts inside that cap are searched first, then the whole sky.  Never
        raises for the frame's content."""
        start = time.perf_counter()
        checked = self._checked(uv, width, height, flux, sigma_px)
        if isinstance(checked, str):
            return _failed("error", checked, start)
        uv, sigma, index = checked
        candidates = pattern_candidates(uv, max(width, height) / 20.0)
        if candidates.size < 4:
            return _failed("too_few", f"{candidates.size} separated detections; at least 4 are needed", start)
        params, priors, f_range = self._start(width, height, camera, refit)
        grid = _density_grid(uv, width, height)
        n_predicted = int(np.clip(2 * len(uv), 30, 1000))

        def verification(n, threshold):  # verify_calibrate's settings per projection code
            return tuple((self.final_gate_px, _FIRST_STARS, n, prior[1] > 0.0, prior, grid, threshold) for prior in priors)

        settings = verification(n_predicted, self.threshold)
        screen = verification(min(n_predicted, SCREEN_STARS), _SCREEN_THRESHOLD)
        regions = [SKY] if boresight is None else [cap(*boresight), SKY]  # the prior's region first
        n_combinations = int(COMBINATIONS_BELOW[candidates.size])
        known = None if camera is None else camera.camera
        frame = (uv, sigma, candidates, self._entry_arrays(width, fov_hint if known is None else known.fov_x, known),
                 f_range, params, (settings, screen), float(len(regions) * max(n_combinations, 1) * max(self._per_lookup, 1.0)))
        tried = 0
        for region in regions:
            result, count, done = self._search(frame, region, start)
            tried += count
            if result[0]:
                return self._result(result, uv, sigma, index, width, height, start,
                                    "fitted" if camera is None else "refined")
            if done < n_combinations:
                return _failed("no_match", f"time budget of {self.time_budget_s:g} s spent after {done} of "
                               f"{n_combinations} patterns ({tried} hypotheses verified)", start)
        return _failed("no_match", f"no pattern of the {candidates.size} brightest separated detections verified "
                       f"({tried} hypotheses)", start)

    def _search(self, frame, region, start):
        """(verify_calibrate's tuple, hypotheses verified, combinations searched) of the compiled search,
        stopped by the time budget.  Each call's work is sized from the pace measured so far, to a quarter
        of the budget left: its combinations (one at first, at most :data:`CHUNK`) and the hypotheses it may
        verify (one at first; a crowded frame verifies many per combination, ~10 ms each), so that the
        budget is overrun by at most about one hypothesis's verification or one combination's look-ups."""
        uv, sigma, candidates, entries, f_range, params, (settings, screen), n_hypotheses = frame
        n_combinations = int(COMBINATIONS_BELOW[candidates.size])
        done, skip, tried, chunk, cap = 0, 0, 0, 1, 1
        while done < n_combinations:
            begin, first = time.perf_counter(), done
            result, count, done, skip = search(uv, sigma, candidates, done, done + chunk, skip, cap, self._arrays, entries,
                                               self.vectors, f_range, params, region, self.field, settings, screen,
                                               n_hypotheses)
            tried += count
            now = time.perf_counter()
            if result[0] or now - start > self.time_budget_s:
                return result, tried, done
            left = 0.25 * (self.time_budget_s - (now - start))
            chunk = int(np.clip(left * max(done - first, 1) / max(now - begin, 1e-9), 1, CHUNK))
            if count:
                cap = int(np.clip(left * count / max(now - begin, 1e-9), 1, MAX_TRIED))
        return result, tried, done

    # ------------------------------------------------------------------ internals
    def _start(self, width, height, known, refit):
        """(camera parameters the hypotheses start from (:func:`startrack.camera.projection_kernels.camera_array`), the priors
        per projection code (mean (5,), sigma (5,): inf free without a prior, 0 held) of (f, cx, cy, k1, k2),
        focal-length ranges (2, 2) [px] per projection code) for a frame, with or without a known camera (a
        :class:`startrack.camera.file.CameraFile`) and the intrinsics of it ``refit``."""
        params = np.array([1.0, (width - 1) / 2.0, (height - 1) / 2.0, float(width), float(height), 0.0, 0.0, 0.0, 0.0])
        sigma = self.prior_sigma.copy()
        sigma[1:3] *= max(width, height)
        if known is None:
            low, high = self.fov_range
            f_range = np.array([[width / 2.0 / radius_of_angle(min(fov, _PINHOLE_WIDEST) / 2.0, projection)
                                 for fov in (high, low)] for projection in PROJECTIONS])
            fisheye = sigma.copy()
            fisheye[4] = self.fisheye_k2_sigma
            return params, tuple((params[[0, 1, 2, 5, 6]].copy(), spread) for spread in (sigma, fisheye)), f_range
        unknown = set(refit) - set(REFIT)
        if unknown:
            raise InputError(f"cannot refit {', '.join(sorted(unknown))}: the intrinsics are {', '.join(REFIT)}.")
        cam = known.camera
        if (cam.width, cam.height) != (width, height):
            raise InputError(f"the camera is {cam.width} x {cam.height} px, the frame {width} x {height} px.")
        params[[0, 1, 2, 5, 6]] = cam.focal_px, cam.cx, cam.cy, cam.k1, cam.k2
        params[8] = PROJECTIONS.index(cam.projection)
        sigma[4] = sigma[4] or sigma[3]  # k2 named for a refit is fitted, with k1's prior unless the solver has one
        for k, name in enumerate(("cx", "cy", "k1", "k2")):
            given = known.sigma.get(name, 0.0)
            refitted = ("centre" if k < 2 else name) in refit
            sigma[k + 1] = (3.0 * given if given > 0.0 else sigma[k + 1]) if refitted else 0.0
        spread = max(0.01, 3.0 * known.sigma.get("focal_px", 0.0) / cam.focal_px)
        f_range = np.tile([cam.focal_px * (1.0 - spread), cam.focal_px * (1.0 + spread)], (2, 1))
        if "focal" not in refit:  # the pattern's focal length starts the fit, which a tight prior pulls to the camera's
            sigma[0] = _HELD_FOCAL * cam.focal_px
        prior = (params[[0, 1, 2, 5, 6]].copy(), sigma)
        return params, (prior, prior), f_range

    def _entry_arrays(self, width, fov_hint, known):
        """The search's ``entries`` (:func:`startrack.identify.scale_free.search`): every look-up (of a known
        camera's projection only), those whose level is nearest ``fov_hint`` [rad] first."""
        keep = np.ones(len(self._entries), bool) if known is None else\
            self._entries[:, 1] == PROJECTIONS.index(known.projection)
        order = np.flatnonzero(keep)
        if fov_hint is not None:
            order = order[np.argsort(np.abs(np.log(self._mid_fov[order] / float(fov_hint))), kind="stable")]
        code = self._entries[order, 1].astype(float)
        half = self._mid_fov[order] / 2.0
        focal = width / 2.0 / np.where(code == 0, np.tan(half), half)
        return (np.ascontiguousarray(self._entries[order, 0]), code, focal, self._tolerance[order].copy())

    @staticmethod
    def _checked(uv, width, height, flux, sigma_px):
        """(uv brightest first, sigma, their input positions) or the reason the input cannot be solved."""
        for name, value in (("width", width), ("height", height)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 16 <= value <= 100_000:
                return f"image {name} must be an integer number of pixels in [16, 100000], got {value!r}"
        try:
            uv = np.asarray(uv, dtype=float).reshape(-1, 2)
            flux = None if flux is None else np.asarray(flux, dtype=float).reshape(-1)
            sigma = np.full(len(uv), 0.3) if sigma_px is None else np.asarray(sigma_px, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            return "centroids, flux and sigma must be numbers (uv of shape (n, 2))"
        if not np.all(np.isfinite(uv)) or (flux is not None and not np.all(np.isfinite(flux)))\
                or not np.all(np.isfinite(sigma)):
            return "a centroid, flux or sigma is NaN or infinite"
        if (flux is not None and flux.shape != (len(uv),)) or sigma.shape != (len(uv),):
            return f"flux and sigma need one value per centroid ({len(uv)})"
        index = np.arange(len(uv)) if flux is None else np.argsort(-flux, kind="stable")
        inside = (uv[index, 0] >= -0.5) & (uv[index, 0] <= width - 0.5) & (uv[index, 1] >= -0.5) & (uv[index, 1] <= height - 0.5)
        if len(uv) and not inside.any():
            return f"all {len(uv)} centroids lie outside the {width} x {height} px image"
        index = index[inside]
        return np.ascontiguousarray(uv[index]), np.ascontiguousarray(np.hypot(sigma[index], SIGMA_FLOOR_PX)), index

    def _result(self, result, uv, sigma, index, width, height, start, source):
        _, R_IS, params, covariance, obs_index, star_index, probability, n_predicted, _, reduced = result
        camera = Camera(width, height, params[0], cx=params[1], cy=params[2], k1=params[5], k2=params[6],
                        projection=PROJECTIONS[int(params[8])])
        order = np.argsort(index[obs_index], kind="stable")
        obs_index, star_index = obs_index[order], star_index[order]
        residual = uv[obs_index] - camera.project_body(self.vectors[star_index] @ R_IS)[0]
        rms = float(np.sqrt(np.mean(residual**2)))
        calibration = CameraCalibration(camera, covariance, float(reduced), rms, int(obs_index.size), int(n_predicted),
                                        float(self.v_mag[star_index].max()))
        from startrack.geometry.rotation import from_matrix

        return IdentificationResult(
            status="ok", q_IS=from_matrix(R_IS), matches=np.column_stack([index[obs_index], self.ids[star_index]]),
            obs_S=camera.unproject(uv[obs_index]), ref_I=self.vectors[star_index], sigma=rms / camera.focal_px,
            false_match_probability=float(probability), method="pattern", calibration=calibration, camera=camera,
            camera_source=source, solve_ms=1e3 * (time.perf_counter() - start))

    def _warm_up(self):
        """Load (or compile) the kernels: an identifiable frame of catalog stars and an unidentifiable one."""
        from startrack.geometry.rotation import from_rotation_vector

        fov = math.sqrt(self.fov_range[0] * self.fov_range[1])
        camera = Camera.from_fov(fov, 1024, 768)
        q_IS = from_rotation_vector(np.array([0.4, 1.1, 0.3]))
        seen = camera.stars_in_field(q_IS, self.vectors)
        seen = seen[np.argsort(self.v_mag[seen], kind="stable")][:30]
        uv, _ = camera.project(q_IS, self.vectors[seen])
        self.solve(uv, 1024, 768, fov_hint=fov)
        phase = np.linspace(0.0, 2.0 * math.pi, 9)[:-1]
        self.solve(np.column_stack([511.5 + 200 * np.cos(phase), 383.5 + 200 * np.sin(phase)]), 1024, 768)


def _failed(status, reason, start):
    return IdentificationResult(status=status, reason=reason + ".", solve_ms=1e3 * (time.perf_counter() - start))
