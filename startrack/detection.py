"""Star detection and centroiding: threshold, connected components, centre of gravity.

Pipeline (one pass, vectorised):

1. background b and noise sigma_n of the frame, given or estimated robustly
   (iterated 3-sigma-clipped median and MAD of a pixel subsample);
2. threshold V_th = b + a sigma_n (eq. 4 of 004; a = 5);
3. 8-connected components of the pixels above V_th (scipy.ndimage.label,
   on the rows that hold any such pixel only);
4. per component, by weighted sums over its pixels (np.bincount):
   centroid (u, v) by the chosen centroider, flux = sum(I - b), peak grey,
   pixel count, SNR = (peak - b)/sigma_n (eq. 1 of 004), and the flags
   ``saturated`` (peak at the saturation level) and ``edge`` (touches the
   image or window border, so the centroid is biased).

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
from scipy.special import ndtr

from startrack.errors import InputError
from startrack.photometry import detection_threshold

_EIGHT_CONNECTED = np.ones((3, 3), dtype=bool)
#: Pixels used for the background estimate (regular subsample of the frame).
_BACKGROUND_SAMPLE = 16384
#: 1.4826 * MAD is sigma for a normal law.
_MAD_TO_SIGMA = 1.482602218505602


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
    saturated, edge (bool); the background b, noise sigma_n and threshold [DN]
    used; sigma_u, sigma_v [px]: the centroid's σ from the pixel noise
    (:func:`_centroid_sigma`).
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
                          self.sigma_u[mask], self.sigma_v[mask])

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
                    "sigma_u": float(self.sigma_u[i]), "sigma_v": float(self.sigma_v[i]),
                }
                for i in range(len(self))
            ],
        }


def _empty(background, sigma_n, threshold):
    f = np.zeros(0)
    b = np.zeros(0, dtype=bool)
    return Detections(f, f, f, f, np.zeros(0, dtype=np.int64), f, b, b, background, sigma_n, threshold, f, f)


def _validate(image, name="image"):
    array = np.asarray(image)
    if array.ndim != 2:
        raise InputError(f"{name} must be a 2-D greyscale array, got shape {array.shape}")
    if array.size == 0:
        raise InputError(f"{name} has no pixels (shape {array.shape})")
    if not (np.issubdtype(array.dtype, np.number) and not np.issubdtype(array.dtype, np.complexfloating)):
        raise InputError(f"{name} must hold real numbers, got dtype {array.dtype}")
    if np.issubdtype(array.dtype, np.floating) and not np.all(np.isfinite(array)):
        raise InputError(f"{name} contains NaN or infinite pixel values")
    return array


def estimate_background(image, clip=3.0, iterations=5):
    """Robust (b, sigma_n) [DN] of a frame by iterated sigma clipping.

    Starts from the median and 1.4826 MAD of a regular subsample of at most
    16384 pixels, then keeps the pixels within ``clip`` sigma of the level
    and takes their mean and standard deviation (divided by the standard
    deviation of a normal law truncated at +-clip sigma), until the kept set
    stops changing.  Stars and hot pixels are clipped away; the mean and
    standard deviation are not quantised like the median and MAD of integer
    grey levels.  A flat frame gives sigma_n = 0.
    """
    array = _validate(image)
    step = max(1, int(np.ceil(np.sqrt(array.size / _BACKGROUND_SAMPLE))))
    sample = np.asarray(array[::step, ::step], dtype=float).ravel()
    level = float(np.median(sample))
    sigma = _MAD_TO_SIGMA * float(np.median(np.abs(sample - level)))
    if sigma == 0.0:
        sigma = float(np.std(sample))
    if sigma == 0.0:
        return level, 0.0
    density = np.exp(-0.5 * clip * clip) / np.sqrt(2.0 * np.pi)  # standard normal pdf at the clip
    truncation = np.sqrt(1.0 - 2.0 * clip * density / (2.0 * ndtr(clip) - 1.0))
    n_kept = -1
    for _ in range(iterations):
        kept = sample[np.abs(sample - level) <= clip * sigma]
        if kept.size == n_kept or kept.size < 2:
            break
        n_kept = kept.size
        level = float(np.mean(kept))
        sigma = float(np.std(kept)) / truncation
    return level, sigma


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


def _measure(values, rows, cols, labels, n, on_border, background, sigma_n, threshold, centroider,
             saturation_dn, min_pixels, u_coord, v_coord):
    index = labels - 1
    weights = centroider.weights(values, background, threshold)
    npix = np.bincount(index, minlength=n)
    wsum = np.bincount(index, weights=weights, minlength=n)
    u = np.bincount(index, weights=weights * u_coord, minlength=n) / wsum
    v = np.bincount(index, weights=weights * v_coord, minlength=n) / wsum
    sigma_u = _centroid_sigma(index, n, u_coord, u, npix, wsum, sigma_n)
    sigma_v = _centroid_sigma(index, n, v_coord, v, npix, wsum, sigma_n)
    flux = np.bincount(index, weights=values - background, minlength=n)
    peak = np.full(n, -np.inf)
    np.maximum.at(peak, index, values)
    edge = np.bincount(index, weights=on_border, minlength=n) > 0
    saturated = peak >= saturation_dn if saturation_dn is not None else np.zeros(n, dtype=bool)
    snr = (peak - background) / sigma_n if sigma_n > 0 else np.full(n, np.inf)
    keep = np.flatnonzero(npix >= min_pixels)
    keep = keep[np.argsort(-flux[keep], kind="stable")]
    return Detections(u[keep], v[keep], flux[keep], peak[keep], npix[keep], snr[keep], saturated[keep],
                      edge[keep], float(background), float(sigma_n), float(threshold), sigma_u[keep], sigma_v[keep])


def _centroid_sigma(index, n, coord, centre, npix, wsum, sigma_n):
    """σ [px] of a weighted centroid c = Σ wᵢ xᵢ / Σ wᵢ over a component of N pixels: the pixel noise
    σ_n propagated (∂c/∂Iᵢ = (xᵢ − c)/W, so σ_n² Σ (xᵢ − c)² / W²) plus the sampling of the image on the
    pixel grid, 1/(12 N) px² (the rounding of each coordinate to its pixel; 1/12 px² for one pixel)."""
    spread = np.bincount(index, weights=coord * coord, minlength=n) - 2.0 * centre * np.bincount(
        index, weights=coord, minlength=n) + npix * centre * centre
    return np.sqrt(sigma_n**2 * np.maximum(spread, 0.0) / wsum**2 + 1.0 / (12.0 * npix * npix))


def _levels(array, background, sigma_n, a, threshold):
    if background is None or sigma_n is None:
        b_est, s_est = estimate_background(array)
        background = b_est if background is None else background
        sigma_n = s_est if sigma_n is None else sigma_n
    if not (np.isfinite(background) and np.isfinite(sigma_n) and sigma_n >= 0):
        raise InputError(f"background {background!r} and sigma_n {sigma_n!r} must be finite, sigma_n >= 0")
    if threshold is None:
        threshold = detection_threshold(background, sigma_n, a)
    return float(background), float(sigma_n), float(threshold)


def _centroider(centroider):
    if isinstance(centroider, str):
        if centroider not in CENTROIDERS:
            raise InputError(f"unknown centroider {centroider!r}; choose one of {', '.join(CENTROIDERS)}")
        return CENTROIDERS[centroider]
    return centroider


def detect(image, background=None, sigma_n=None, a=5.0, threshold=None, centroider="threshold",
           saturation_dn=None, min_pixels=1):
    """Detect and centroid the star images of a frame (module docstring).

    image: 2-D array [DN].  background, sigma_n [DN]: estimated from the
    frame when None.  threshold: V_th, default b + a sigma_n (eq. 4 of 004).
    centroider: "grey", "threshold", "square" or an object with
    ``weights(values, background, threshold)``.  saturation_dn: grey level
    at which a pixel is saturated (None: no flag).  min_pixels: smallest
    component kept.  Returns :class:`Detections` (empty when nothing
    exceeds the threshold).  NaN pixels raise InputError.
    """
    array = _validate(image)
    background, sigma_n, threshold = _levels(array, background, sigma_n, a, threshold)
    centroider = _centroider(centroider)
    mask = array > threshold
    if not mask.any():
        return _empty(background, sigma_n, threshold)
    rows, cols, labels, n = _label_pixels(mask)
    height, width = array.shape
    values = array[rows, cols].astype(float)
    on_border = ((rows == 0) | (rows == height - 1) | (cols == 0) | (cols == width - 1)).astype(float)
    return _measure(values, rows, cols, labels, n, on_border, background, sigma_n, threshold, centroider,
                    saturation_dn, min_pixels, cols.astype(float), rows.astype(float))


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
    _validate(stack.reshape(-1, stack.shape[2]), "windows")
    row0 = np.asarray(row0, dtype=np.int64)
    col0 = np.asarray(col0, dtype=np.int64)
    if row0.shape != (stack.shape[0],) or col0.shape != (stack.shape[0],):
        raise InputError(f"need one window origin per window: {stack.shape[0]} windows, origins {row0.shape}")
    background, sigma_n, threshold = _levels(stack.reshape(-1, stack.shape[2]), background, sigma_n, a, threshold)
    centroider = _centroider(centroider)
    m, h, w = stack.shape
    mask = np.zeros((m, h + 1, w), dtype=bool)
    mask[:, :h] = stack > threshold
    mask = mask.reshape(m * (h + 1), w)
    if not mask.any():
        return _empty(background, sigma_n, threshold)
    rows, cols, labels, n = _label_pixels(mask)
    window, local_rows = np.divmod(rows, h + 1)
    values = stack[window, local_rows, cols].astype(float)
    on_border = ((local_rows == 0) | (local_rows == h - 1) | (cols == 0) | (cols == w - 1)).astype(float)
    u = (col0[window] + cols).astype(float)
    v = (row0[window] + local_rows).astype(float)
    return _measure(values, rows, cols, labels, n, on_border, background, sigma_n, threshold, centroider,
                    saturation_dn, min_pixels, u, v)
