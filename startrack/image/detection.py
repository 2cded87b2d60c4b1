"""Star detection and centroiding: threshold, connected components, centre of gravity.

Pipeline (one pass, vectorised):

1. background b and noise sigma_n, given, estimated for the whole frame, or on a mesh of cells that
   follows vignetting and nebulosity (:mod:`startrack.image.background`);
2. threshold V_th = b + a sigma_n (eq. 4 of 004; a = 5), per pixel with a mesh;
3. 8-connected components of the pixels above V_th (scipy.ndimage.label,
   on the rows that hold any such pixel only);
4. per component, by weighted sums over its pixels (np.bincount):
   centroid (u, v) by the chosen centroider, flux = sum(I - b), peak grey,
   pixel count, SNR = (peak - b)/sigma_n (eq. 1 of 004), and the flags
   ``saturated`` (peak at the saturation level), ``edge`` (touches the
   image or window border, so the centroid is biased), ``single_pixel`` and
   ``extended``;
5. optionally, components flagged ``single_pixel`` or ``extended`` are dropped.

Single-pixel events (hot pixels and adjacent pairs of them, cosmic-ray hits, JPEG block noise): the
optics spread a star over several pixels and in every direction, so the 8 pixels around a star's peak
hold a large fraction of the peak's own excess even without the brightest of them -- the sum R of the
other 7 (the ring, background removed) is at least 1.7 times it for a Gaussian PSF of sigma = 0.67 px,
0.8 times at 0.5 px and 0.4 times at 0.4 px, whatever the pixel phase (pixel-integrated PSF), while a
hot pixel has none and a pair of hot pixels (a few hundred of them among 10 000 hot pixels of a
1024 x 768 sensor) only its twin, which is the pixel left out.  The frame's own stars set the cut
(:func:`_ring_cut`: half the median ratio of its bright detections, at least :data:`_MIN_RING_RATIO`);
a detection whose ring ratio R / (I_peak - b) lies below the cut by more than 3 times its noise
(sqrt(7) sigma_n / (I_peak - b)) is flagged: at high SNR a hot pixel is told from a star with
certainty, near the threshold the test keeps the detection.  Clusters of three or more hot pixels pass
that test but not another: a star whose peak reaches the saturation level S covers 2 pi sigma^2
ln((S - b)/(V_th - b)) pixels above the threshold (a Gaussian image: ~14 px for sigma = 0.67 px on a
12-bit frame); a saturated detection of fewer than half of them, with sigma the frame's star size
(below, an underestimate: the margin grows), is flagged ``single_pixel`` too.  (A hot pixel that
touches a star still takes the star with it: the component's peak is the hot pixel.)

Extended detections (clouds lit from below, satellite and aircraft streaks, nebulae): a star is the
image of a point, as large as the frame's other stars and round.  The second moments of the
component's light, M = sum w (x - c)(x - c)^T / sum w with w = I - b, give its size s = sqrt(tr M / 2)
[px] (sigma for a Gaussian image without its wings below the threshold) and its elongation
sqrt(lambda_max / lambda_min) (1 for a round image; a streak of length L and width sigma_w:
L / (sqrt(12) sigma_w)).  A detection is flagged ``extended`` when it is longer than
:data:`MAX_ELONGATION` with at least :data:`MIN_SHAPE_PIXELS` pixels (fewer pixels do not measure a
shape), or larger than :data:`_EXTENDED_SIZE` times the median size of the frame's bright (SNR >= 20)
unsaturated stars when it has 5 of them.  A saturated star's flat top widens it by about 1.5 for a
peak 100 times the saturation level, well inside the cut.

Centroiders (strategy objects, all over the component's pixels, u = column,
v = row, image convention of docs/design.md):

* :class:`GreyCentroid`: grey-level centre of gravity, w = I - b;
* :class:`ThresholdedCentroid`: thresholded centre of gravity of 004
  ("带阈值的灰度重心法"), w = I - V_th;
* :class:`SquareWeightedCentroid`: square-weighted, w = (I - b)^2.
"""

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from startrack.base.errors import InputError
from startrack.image.background import CELL_SAMPLE, Background, estimate_background, mesh_background

_EIGHT_CONNECTED = np.ones((3, 3), dtype=bool)
#: Smallest ring ratio of a star image (module text).
_MIN_RING_RATIO = 0.3
#: Largest axis ratio of a star image; fewest pixels that measure it (module text).
MAX_ELONGATION, MIN_SHAPE_PIXELS = 3.0, 10
#: Largest size of a star image over the median of the frame's bright stars (module text).
_EXTENDED_SIZE = 3.0


class GreyCentroid:
    """Grey-level centre of gravity: weights I - b."""

    name = "grey"

    @staticmethod
    def weights(values, background, threshold):
        return values - background


class ThresholdedCentroid:
    """Thresholded centre of gravity (004): weights I - V_th over pixels above V_th."""

    name = "threshold"

    @staticmethod
    def weights(values, background, threshold):
        return values - threshold


class SquareWeightedCentroid:
    """Square-weighted centre of gravity: weights (I - b)^2."""

    name = "square"

    @staticmethod
    def weights(values, background, threshold):
        return (values - background) ** 2


CENTROIDERS = {c.name: c for c in (GreyCentroid(), ThresholdedCentroid(), SquareWeightedCentroid())}


@dataclass(frozen=True)
class Detections:
    """Detected star images, brightest (largest flux) first.

    u, v [px]; flux = sum(I - b) [DN]; peak [DN]; npix; snr (eq. 1 of 004);
    saturated, edge, single_pixel, extended (bool, module text); the background b,
    noise sigma_n and threshold [DN] used (medians over the frame for a mesh); sigma_u,
    sigma_v [px]: the centroid's σ from the pixel noise (:func:`_centroid_sigma`);
    size [px], elongation: the shape of the image's light (module text).
    """

    u: np.ndarray
    v: np.ndarray
    flux: np.ndarray
    peak: np.ndarray
    npix: np.ndarray
    snr: np.ndarray
    saturated: np.ndarray
    edge: np.ndarray
    background: float
    sigma_n: float
    threshold: float
    sigma_u: np.ndarray
    sigma_v: np.ndarray
    single_pixel: np.ndarray
    size: np.ndarray
    elongation: np.ndarray
    extended: np.ndarray

    def __len__(self):
        return len(self.u)

    @property
    def uv(self):
        """Centroids (N, 2) [px]."""
        return np.stack([self.u, self.v], axis=-1)

    def select(self, mask):
        """The detections where ``mask`` (bool or indices) holds, same order."""
        fields = ("u", "v", "flux", "peak", "npix", "snr", "saturated", "edge")
        return Detections(*(getattr(self, f)[mask] for f in fields), self.background, self.sigma_n, self.threshold,
                          *(getattr(self, f)[mask] for f in ("sigma_u", "sigma_v", "single_pixel", "size", "elongation",
                                                             "extended")))

    def to_dict(self):
        """Plain dict (lists) for JSON output."""
        return {
            "background_dn": self.background,
            "sigma_n_dn": self.sigma_n,
            "threshold_dn": self.threshold,
            "stars": [
                {
                    "u": float(self.u[i]), "v": float(self.v[i]), "flux_dn": float(self.flux[i]),
                    "peak_dn": float(self.peak[i]), "npix": int(self.npix[i]), "snr": float(self.snr[i]),
                    "saturated": bool(self.saturated[i]), "edge": bool(self.edge[i]),
                    "single_pixel": bool(self.single_pixel[i]), "extended": bool(self.extended[i]),
                    "size_px": float(self.size[i]), "elongation": float(self.elongation[i]),
                    "sigma_u": float(self.sigma_u[i]), "sigma_v": float(self.sigma_v[i]),
                }
                for i in range(len(self))
            ],
        }


def _empty(background, sigma_n, threshold):
    f = np.zeros(0)
    b = np.zeros(0, dtype=bool)
    return Detections(f, f, f, f, np.zeros(0, dtype=np.int64), f, b, b, background, sigma_n, threshold, f, f, b, f, f, b)


def validated_frame(image, name="image"):
    """``image`` as an array once it is a non-empty 2-D frame of real, finite pixels (InputError naming the problem)."""
    array = np.asarray(image)
    if array.ndim != 2:
        raise InputError(f"{name} must be a 2-D greyscale array, got shape {array.shape}")
    if array.size == 0:
        raise InputError(f"{name} has no pixels (shape {array.shape}): a non-empty frame is needed")
    if not (np.issubdtype(array.dtype, np.number) and not np.issubdtype(array.dtype, np.complexfloating)):
        raise InputError(f"{name} must hold real numbers, got dtype {array.dtype}")
    if np.issubdtype(array.dtype, np.floating) and not np.all(np.isfinite(array)):
        raise InputError(f"{name} contains NaN or infinite pixel values")
    return array


def _label_pixels(mask):
    """(rows, cols, labels (1..n), n) of the pixels of the 8-connected components of ``mask``.

    Only rows holding a set pixel are labelled, each run of them followed by
    one blank row that keeps separate runs apart (exact, much faster than
    labelling the whole frame when stars are sparse).
    """
    hit = mask.any(axis=1)
    keep = hit.copy()
    keep[1:] |= hit[:-1]
    rows_kept = np.flatnonzero(keep)
    labels, n = ndimage.label(mask[rows_kept], structure=_EIGHT_CONNECTED)
    flat = np.flatnonzero(labels)
    sub_rows, cols = np.divmod(flat, mask.shape[1])
    return rows_kept[sub_rows], cols, labels.reshape(-1)[flat], n


def _peak_pixels(values, index, n):
    """Position in ``values`` of the brightest pixel of each of the n components (last of equal ones)."""
    order = np.lexsort((values, index))
    last = np.flatnonzero(np.r_[index[order][1:] != index[order][:-1], True])
    peaks = np.empty(n, np.int64)
    peaks[index[order][last]] = order[last]
    return peaks


def _at(level, positions):
    """A per-pixel level at ``positions`` (a uniform level is one number)."""
    return level if np.ndim(level) == 0 else level[positions]


def _measure(values, labels, n, on_border, levels, centroider, saturation_dn, min_pixels, u_coord, v_coord,
             ring=None):
    """Detections of the n labelled components; ``levels`` = (b, sigma_n, V_th), each one number or one
    value per pixel of ``values``; ``ring(peak positions)`` gives the ring sums of the peaks (full frames)."""
    background, sigma_n, threshold = levels
    index = labels - 1
    weights = centroider.weights(values, background, threshold)
    npix = np.bincount(index, minlength=n)
    wsum = np.bincount(index, weights=weights, minlength=n)
    u = np.bincount(index, weights=weights * u_coord, minlength=n) / wsum
    v = np.bincount(index, weights=weights * v_coord, minlength=n) / wsum
    sigma_u = _centroid_sigma(index, n, u_coord, u, npix, wsum, sigma_n)
    sigma_v = _centroid_sigma(index, n, v_coord, v, npix, wsum, sigma_n)
    light = values - background
    flux = np.bincount(index, weights=light, minlength=n)
    peaks = _peak_pixels(values, index, n)
    peak = values[peaks]
    b_peak, s_peak = _at(background, peaks), _at(sigma_n, peaks)
    edge = np.bincount(index, weights=on_border, minlength=n) > 0
    saturated = peak >= saturation_dn if saturation_dn is not None else np.zeros(n, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        snr = np.where(s_peak > 0, (peak - b_peak) / s_peak, np.inf)
    size, elongation = _shape(index, n, light, u_coord, v_coord)
    star_size = _star_size(size, snr, saturated, npix)
    single = np.zeros(n, dtype=bool)
    if ring is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            excess = peak - b_peak
            ratio = (ring(peaks) - 7.0 * b_peak) / excess
            single = ratio < _ring_cut(ratio, snr, npix, saturated) - 3.0 * np.sqrt(7.0) * s_peak / excess
        if saturation_dn is not None:
            single |= saturated & (npix < _saturated_pixels(star_size, saturation_dn - b_peak, _at(threshold, peaks) - b_peak))
    with np.errstate(invalid="ignore"):
        extended = ((elongation > MAX_ELONGATION) & (npix >= MIN_SHAPE_PIXELS)) | (size > _EXTENDED_SIZE * star_size)
    keep = np.flatnonzero(npix >= min_pixels)
    keep = keep[np.argsort(-flux[keep], kind="stable")]
    summary = (float(np.median(level)) for level in levels)
    return Detections(u[keep], v[keep], flux[keep], peak[keep], npix[keep], snr[keep], saturated[keep],
                      edge[keep], *summary, sigma_u[keep], sigma_v[keep], single[keep], size[keep], elongation[keep],
                      extended[keep])


def _shape(index, n, excess, u_coord, v_coord):
    """(size s [px], elongation) of the n components from the second moments of their light, weights
    w = max(I - b, 0) (module text)."""
    w = np.maximum(excess, 0.0)
    sums = [np.bincount(index, weights=w * term, minlength=n) for term in
            (1.0, u_coord, v_coord, u_coord * u_coord, v_coord * v_coord, u_coord * v_coord)]
    with np.errstate(divide="ignore", invalid="ignore"):
        total = np.where(sums[0] > 0, sums[0], np.nan)
        cu, cv = sums[1] / total, sums[2] / total
        muu, mvv, muv = sums[3] / total - cu * cu, sums[4] / total - cv * cv, sums[5] / total - cu * cv
        half_trace, half_gap = 0.5 * (muu + mvv), np.hypot(0.5 * (muu - mvv), muv)
        size = np.sqrt(np.maximum(half_trace, 0.0))
        elongation = np.sqrt((half_trace + half_gap) / np.maximum(half_trace - half_gap, 1e-12))
    return size, elongation


def _saturated_pixels(star_size, saturation_excess, threshold_excess):
    """Fewest pixels of a saturated star image (module text): half the 2 pi s^2 ln((S - b)/(V_th - b)) pixels
    above the threshold of a Gaussian image of the frame's star size s [px] whose peak reaches S; 0 when the
    frame has no star size."""
    if not np.isfinite(star_size):
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.pi * star_size**2 * np.log(np.maximum(saturation_excess / threshold_excess, 1.0))  # half of 2 pi s^2 ln


def _star_size(size, snr, saturated, npix):
    """Median size [px] of the frame's bright (SNR >= 20) unsaturated detections of 2 pixels or more when
    there are 5 of them, else infinite (no size cut)."""
    bright = _bright(snr, npix, saturated) & np.isfinite(size)
    return float(np.median(size[bright])) if np.count_nonzero(bright) >= 5 else np.inf


def _bright(snr, npix, saturated):
    """The detections that show the frame's star image: SNR >= 20, 2 pixels or more, unsaturated."""
    return (snr >= 20.0) & (npix >= 2) & ~saturated


def _ring_cut(ratio, snr, npix, saturated):
    """Smallest ring ratio of a star in this frame: half the median ratio of its bright (SNR >= 20),
    unsaturated detections of 2 pixels or more when there are 5 of them -- the smallest ratio over pixel
    phases is 0.7-0.95 times the median (sigma 0.4-0.67 px) -- within [_MIN_RING_RATIO, 1.5]."""
    bright = _bright(snr, npix, saturated)
    if np.count_nonzero(bright) < 5:
        return _MIN_RING_RATIO
    return float(np.clip(0.5 * np.median(ratio[bright]), _MIN_RING_RATIO, 1.5))


def _centroid_sigma(index, n, coord, centre, npix, wsum, sigma_n):
    """σ [px] of a weighted centroid c = Σ wᵢ xᵢ / Σ wᵢ over a component of N pixels: the pixel noise
    σ_n propagated (∂c/∂Iᵢ = (xᵢ − c)/W, so Σ σ_n,ᵢ² (xᵢ − c)² / W²) plus the sampling of the image on
    the pixel grid, 1/(12 N) px² (the rounding of each coordinate to its pixel; 1/12 px² for one pixel).
    ``sigma_n`` one number or one per pixel (mesh background)."""
    weight = 1.0 if np.ndim(sigma_n) == 0 else sigma_n**2
    spread = np.bincount(index, weights=weight * coord * coord, minlength=n) - 2.0 * centre * np.bincount(
        index, weights=weight * coord, minlength=n) + np.bincount(index, weights=np.broadcast_to(weight, coord.shape),
                                                                  minlength=n) * centre * centre
    scale = sigma_n**2 if np.ndim(sigma_n) == 0 else 1.0
    return np.sqrt(scale * np.maximum(spread, 0.0) / wsum**2 + 1.0 / (12.0 * npix * npix))


def frame_background(array, background, sigma_n, mesh_px, every_pixel=False):
    """The :class:`~startrack.image.background.Background` of a frame: the given level and noise (the missing one
    estimated over the frame), a mesh of ``mesh_px`` cells (each from a subsample of its pixels, or from
    ``every_pixel`` of it), or one estimate for the whole frame."""
    if background is None and sigma_n is None and mesh_px is not None:
        if isinstance(mesh_px, bool) or not isinstance(mesh_px, (int, np.integer)) or not 8 <= mesh_px <= 4096:
            raise InputError(f"mesh_px = {mesh_px!r} must be an integer number of pixels in [8, 4096]")
        return mesh_background(array, int(mesh_px), cell_sample=int(mesh_px) ** 2 if every_pixel else CELL_SAMPLE)
    if background is None or sigma_n is None:
        b_est, s_est = estimate_background(array)
        background = b_est if background is None else background
        sigma_n = s_est if sigma_n is None else sigma_n
    if not (np.isfinite(background) and np.isfinite(sigma_n) and sigma_n >= 0):
        raise InputError(f"background {background!r} and sigma_n {sigma_n!r} must be finite, sigma_n >= 0")
    return Background.uniform(float(background), float(sigma_n), array.shape)


def _levels(found, a, threshold, rows, cols):
    """(b, sigma_n, V_th) at the pixels (rows, cols): numbers for a uniform background."""
    if found.level.size == 1:
        b, s = found.median_level, found.median_sigma
        return b, s, float(b + a * s) if threshold is None else float(threshold)
    b, s = found.at(rows, cols)
    return b, s, (b + a * s) if threshold is None else np.full(b.shape, float(threshold))


def _centroider(centroider):
    if isinstance(centroider, str):
        if centroider not in CENTROIDERS:
            raise InputError(f"unknown centroider {centroider!r}; choose one of {', '.join(CENTROIDERS)}")
        return CENTROIDERS[centroider]
    return centroider


def _ring_sums(array):
    """ring(peaks_rc) -> sum of the (up to) 8 pixels around each peak (row, col) but the brightest of them,
    scaled to 7 pixels at the border."""
    height, width = array.shape

    def ring(rows, cols):
        total, count, brightest = np.zeros(rows.size), np.zeros(rows.size), np.full(rows.size, -np.inf)
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if dr == 0 and dc == 0:
                    continue
                r, c = rows + dr, cols + dc
                inside = (r >= 0) & (r < height) & (c >= 0) & (c < width)
                value = array[r[inside], c[inside]].astype(float)
                total[inside] += value
                brightest[inside] = np.maximum(brightest[inside], value)
                count += inside
        return (total - brightest) * 7.0 / np.maximum(count - 1.0, 1.0)

    return ring


def detect(image, background=None, sigma_n=None, a=5.0, threshold=None, centroider="threshold",
           saturation_dn=None, min_pixels=1, mesh_px=None, reject_single_pixels=False, reject_extended=False):
    """Detect and centroid the star images of a frame (module docstring).

    image: 2-D array [DN].  background, sigma_n [DN]: estimated from the frame when None -- on a mesh of
    ``mesh_px`` cells if given, else one level for the frame.  threshold: V_th, default b + a sigma_n
    (eq. 4 of 004).  centroider: "grey", "threshold", "square" or an object with
    ``weights(values, background, threshold)``.  saturation_dn: grey level at which a pixel is saturated
    (None: no flag).  min_pixels: smallest component kept.  reject_single_pixels, reject_extended: drop
    the detections flagged ``single_pixel``, ``extended``.  Returns :class:`Detections` (empty when
    nothing exceeds the threshold).  NaN pixels raise InputError.
    """
    array = validated_frame(image)
    found = frame_background(array, background, sigma_n, mesh_px)
    centroider = _centroider(centroider)
    mask = array > (found.threshold(a) if threshold is None else float(threshold))
    if not mask.any():
        b, s = found.median_level, found.median_sigma
        return _empty(b, s, b + a * s if threshold is None else float(threshold))
    rows, cols, labels, n = _label_pixels(mask)
    height, width = array.shape
    values = array[rows, cols].astype(float)
    on_border = ((rows == 0) | (rows == height - 1) | (cols == 0) | (cols == width - 1)).astype(float)
    ring_of = _ring_sums(array)
    detections = _measure(values, labels, n, on_border, _levels(found, a, threshold, rows, cols), centroider,
                          saturation_dn, min_pixels, cols.astype(float), rows.astype(float),
                          ring=lambda peaks: ring_of(rows[peaks], cols[peaks]))
    drop = (detections.single_pixel if reject_single_pixels else False) | (
        detections.extended if reject_extended else False)
    return detections.select(~drop) if np.any(drop) else detections


def detect_windows(window_images, row0, col0, background, sigma_n, a=5.0, threshold=None,
                   centroider="threshold", saturation_dn=None, min_pixels=1):
    """Detect and centroid in M windows (M, s, s) with top-left pixels (row0, col0) (M,).

    Same measurement as :func:`detect` (one labelling pass over the windows
    laid one under the other with a blank row between them); (u, v) are in
    full-image pixels and ``edge`` means touching the window border.
    background and sigma_n are estimated from all window pixels when None.
    """
    stack = np.asarray(window_images)
    if stack.ndim != 3 or stack.shape[0] == 0 or stack.size == 0:
        raise InputError(f"windows must be a non-empty array of shape (M, s, s), got {stack.shape}")
    validated_frame(stack.reshape(-1, stack.shape[2]), "windows")
    row0 = np.asarray(row0, dtype=np.int64)
    col0 = np.asarray(col0, dtype=np.int64)
    if row0.shape != (stack.shape[0],) or col0.shape != (stack.shape[0],):
        raise InputError(f"need one window origin per window: {stack.shape[0]} windows, origins {row0.shape}")
    found = frame_background(stack.reshape(-1, stack.shape[2]), background, sigma_n, None)
    levels = _levels(found, a, threshold, None, None)
    centroider = _centroider(centroider)
    m, h, w = stack.shape
    mask = np.zeros((m, h + 1, w), dtype=bool)
    mask[:, :h] = stack > levels[2]
    mask = mask.reshape(m * (h + 1), w)
    if not mask.any():
        return _empty(*levels)
    rows, cols, labels, n = _label_pixels(mask)
    window, local_rows = np.divmod(rows, h + 1)
    values = stack[window, local_rows, cols].astype(float)
    on_border = ((local_rows == 0) | (local_rows == h - 1) | (cols == 0) | (cols == w - 1)).astype(float)
    u = (col0[window] + cols).astype(float)
    v = (row0[window] + local_rows).astype(float)
    return _measure(values, labels, n, on_border, levels, centroider, saturation_dn, min_pixels, u, v)
