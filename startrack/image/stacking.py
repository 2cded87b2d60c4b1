"""Inter-frame shifted-window grey stacking of a dim star (004, section 2.2).

While tracking, the grey window of side 2l+1 centred on the pixel
P_k = (r_k, c_k) nearest the predicted image of the candidate dim star (the
brightest catalog star in the field that is not detected) is kept for each
of the last n frames (the "pipeline cache", n = 4).  When the detected stars
drop below three, the windows are shifted by the integer offsets of eq. 13,

    N_r,k = r_k - r_0,   N_c,k = c_k - c_0     (k = 0 is the current frame m),

into the current frame and added.  Since each window is centred on its own
P_k, the shift is a relabelling: pixel (i, j) of every window lands on
pixel (r_0 - l + i, c_0 - l + j) of the current frame.  The sum is detected
against V_th' = n b + a sqrt(n) sigma_n (eq. 5) and centroided (eq. 14); by
eq. 15-17 the grey centre of gravity of the stacked window equals

    x_sp = sum_k S_k (x_k - N_k) / sum_k S_k,

with x_k the centroid of window k in its own frame and S_k its grey sum,
which is eq. 18, x_sp = (1/n) sum_k (x_k - N_k), when the S_k are equal
(eq. 16).  Eq. 14-17 use raw grey sums C(r); :class:`StackedStar` carries
both sides of the identity as a check.

Integer shifts keep each frame's sub-pixel phase x_k - r_k, so the stacked
centroid is the current pixel plus the *mean* phase of the n frames, not the
current one: for uniformly distributed phases its error is sqrt(1/12 (1 -
1/n)^2 + (n-1)/(12 n^2)) = 0.25 px per axis for n = 4.  When the predicted
centroids p_k are accurate to a fraction of a pixel the phase difference is
known, delta = (p_0 - r_0) - (1/n) sum_k (p_k - r_k); ``u_corrected`` and
``v_corrected`` add it (an extension, not part of 004).
"""

from collections import deque
from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError
from startrack.image.detection import detect
from startrack.photometry.star_signal import stacked_snr, stacked_threshold


def window_centre(uv):
    """Integer pixel (row, col) nearest the predicted centroid (u, v): P_n = round(P_en)."""
    uv = np.asarray(uv, dtype=float)
    return np.array([int(np.rint(uv[1])), int(np.rint(uv[0]))])


def cut_window(image, centre_rc, half_width):
    """The (2l+1)^2 window of ``image`` centred on pixel (r, c), or None if it leaves the image."""
    r, c = int(centre_rc[0]), int(centre_rc[1])
    l = int(half_width)
    height, width = image.shape
    if r - l < 0 or c - l < 0 or r + l >= height or c + l >= width:
        return None
    return np.asarray(image[r - l : r + l + 1, c - l : c + l + 1], dtype=float)


def window_shifts(centres_rc):
    """Integer shifts (N_r, N_c) (n, 2) of eq. 13 of each window relative to window 0 (current)."""
    centres = np.asarray(centres_rc, dtype=np.int64)
    return centres - centres[0]


def grey_centroid(window, centre_rc, background=0.0):
    """Grey centre of gravity (u, v) [px, image frame] and grey sum of a window centred on (r, c).

    Weights I - background over the whole window (the C(r) row sums of eq. 14).
    """
    window = np.asarray(window, dtype=float) - background
    l = window.shape[0] // 2
    offsets = np.arange(-l, l + 1, dtype=float)
    total = window.sum()
    v = centre_rc[0] + (window.sum(axis=1) @ offsets) / total
    u = centre_rc[1] + (window.sum(axis=0) @ offsets) / total
    return u, v, total


def stacked_centroid_direct(windows, centres_rc, background):
    """Eq. 14: grey centroid (u, v) in the current frame of the sum of the windows (n, s, s)."""
    windows = np.asarray(windows, dtype=float)
    u, v, _ = grey_centroid(windows.sum(axis=0), centres_rc[0], len(windows) * background)
    return u, v


def stacked_centroid_from_frames(frame_uv, centres_rc, weights=None):
    """Eq. 17-18: stacked centroid from the per-window centroids (n, 2) [u, v] and eq. 13 shifts.

    x_sp = sum_k S_k (x_k - N_k) / sum_k S_k; with ``weights`` None all S_k
    are equal and this is eq. 18, (1/n) sum_k (x_k - N_k).
    """
    frame_uv = np.asarray(frame_uv, dtype=float)
    shifts = window_shifts(centres_rc)  # (N_r, N_c)
    shifted = frame_uv - shifts[:, ::-1]  # u shifts by N_c, v by N_r
    w = np.ones(len(frame_uv)) if weights is None else np.asarray(weights, dtype=float)
    return tuple(w @ shifted / w.sum())


@dataclass(frozen=True)
class StackedStar:
    """Result of stacking the cached windows of the candidate dim star.

    detected: the stacked window exceeds V_th' (eq. 5); (u, v): thresholded
    centroid of the stacked star in the current frame [px] (NaN when not
    detected); peak [DN] and snr (eq. 1 with eq. 2) of the stacked window;
    threshold V_th'; grey_uv_direct (eq. 14 on the stacked window, raw
    grey) and grey_uv_eq17 (eq. 17 from the frames' raw grey centroids)
    must agree; u_corrected, v_corrected: (u, v) plus the predicted
    sub-pixel phase difference (module docstring; NaN without predictions);
    centres (n, 2) pixel (r, c) of the windows, current frame first;
    window: the sum.
    """

    detected: bool
    u: float
    v: float
    u_corrected: float
    v_corrected: float
    peak: float
    snr: float
    threshold: float
    grey_uv_direct: tuple
    grey_uv_eq17: tuple
    centres: np.ndarray
    window: np.ndarray
    star_id: object


def stack(windows, centres_rc, background, sigma_n, a=5.0, centroider="threshold", star_id=None,
          predicted_uv=None):
    """Stack windows (n, s, s) (current frame first) and detect the star against V_th' (eq. 5, 13-18).

    ``predicted_uv`` (n, 2), the predicted centroids the windows were cut
    around, enables the sub-pixel phase correction (module docstring).
    """
    windows = np.asarray(windows, dtype=float)
    centres = np.asarray(centres_rc, dtype=np.int64)
    if windows.ndim != 3 or windows.shape[1] != windows.shape[2] or windows.shape[1] % 2 != 1:
        raise InputError(f"stacking needs n square windows of odd side, got shape {windows.shape}")
    if centres.shape != (len(windows), 2):
        raise InputError(f"stacking needs one window centre (row, col) per window, got shape {centres.shape}")
    n = len(windows)
    summed = windows.sum(axis=0)
    l = summed.shape[0] // 2
    threshold = stacked_threshold(background, sigma_n, n, a)
    found = detect(summed, background=n * background, sigma_n=np.sqrt(n) * sigma_n, threshold=threshold,
                   centroider=centroider)
    peak = float(summed.max())
    raw = [grey_centroid(w, c) for w, c in zip(windows, centres)]
    direct = stacked_centroid_direct(windows, centres, 0.0)
    eq17 = stacked_centroid_from_frames([r[:2] for r in raw], centres, [r[2] for r in raw])
    u = v = u_corr = v_corr = float("nan")
    detected = len(found) > 0
    if detected:
        nearest = np.argmin(np.hypot(found.u - l, found.v - l))
        u = centres[0, 1] - l + float(found.u[nearest])
        v = centres[0, 0] - l + float(found.v[nearest])
        if predicted_uv is not None:
            phase = np.asarray(predicted_uv, dtype=float) - centres[:, ::-1]  # (u - c_k, v - r_k)
            delta = phase[0] - phase.mean(axis=0)
            u_corr, v_corr = u + delta[0], v + delta[1]
    return StackedStar(detected, u, v, u_corr, v_corr, peak, float(stacked_snr(peak, background, sigma_n, n)),
                       float(threshold), direct, eq17, centres, summed, star_id)


class DimStarCache:
    """Pipeline cache of 004: windows of the candidate dim star over the last ``depth`` frames.

    ``push`` each frame with the predicted centroid (u, v) of the candidate;
    a new candidate (different ``star_id``) or a window leaving the image
    empties the cache.  ``stack`` adds the cached windows once it is full.
    """

    def __init__(self, half_width=2, depth=4):
        if int(half_width) < 1 or int(depth) < 1:
            raise InputError(f"window half-width l and cache depth n must be >= 1, got {half_width!r}, {depth!r}")
        self.half_width = int(half_width)
        self.depth = int(depth)
        self._windows = deque(maxlen=self.depth)
        self._centres = deque(maxlen=self.depth)
        self._predicted = deque(maxlen=self.depth)
        self.star_id = None

    def __len__(self):
        return len(self._windows)

    @property
    def full(self):
        """True once ``depth`` consecutive windows of the same candidate are cached."""
        return len(self._windows) == self.depth

    def reset(self):
        self._windows.clear()
        self._centres.clear()
        self._predicted.clear()
        self.star_id = None

    def push(self, image, predicted_uv, star_id=None):
        """Cache the window around ``predicted_uv`` of this frame; False (cache emptied) if it leaves the image."""
        centre = window_centre(predicted_uv)
        window = cut_window(np.asarray(image), centre, self.half_width)
        if window is None:
            self.reset()
            return False
        return self.push_window(window, predicted_uv, star_id)

    def push_window(self, window, predicted_uv, star_id=None):
        """Cache a window already cut (window-mode rendering) around the pixel nearest ``predicted_uv``."""
        side = 2 * self.half_width + 1
        window = np.asarray(window, dtype=float)
        if window.shape != (side, side):
            raise InputError(f"the dim-star cache needs {side} x {side} windows, got shape {window.shape}")
        if star_id != self.star_id:
            self.reset()
            self.star_id = star_id
        self._windows.append(window)
        self._centres.append(window_centre(predicted_uv))
        self._predicted.append(np.asarray(predicted_uv, dtype=float))
        return True

    def stack(self, background, sigma_n, a=5.0, centroider="threshold"):
        """Stack the cached windows into the latest frame (:func:`stack`); the cache must be full."""
        if not self.full:
            raise InputError(f"the dim-star cache holds {len(self)} of the {self.depth} frames needed to stack")
        windows = np.array(self._windows)[::-1]
        centres = np.array(self._centres)[::-1]
        predicted = np.array(self._predicted)[::-1]
        return stack(windows, centres, background, sigma_n, a, centroider, self.star_id, predicted)
