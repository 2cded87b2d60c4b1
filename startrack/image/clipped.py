"""Frames whose detection threshold lies above their full scale: pictures stretched for the eye.

An 8-bit picture stretched to be looked at (the background at mid grey, its noise tens of levels: a rendered
field as 155 +- 32 of 255) has arbitrary gain: the background b and noise sigma_n estimated from the frame put
004's threshold b + a sigma_n above the full scale S (310 of 255 at a = 5), so that no pixel can pass it, yet
its stars are there, clipped at S as blobs of several pixels.  Such a frame is detected again (:func:`retry`)
with the threshold at S less half a grey level, i.e. at the pixels at full scale; the grey centre of gravity
(w = I - b: a clipped blob's pixels weigh alike, (S - b) each, and the grey centroider's sigma from sigma_n
and that weight is the clipped blob's own; the thresholded one would weigh each by the half step left above
the threshold, and state sigma_n / (half a step) times too large a sigma); and stars of at least
:data:`MIN_PIXELS` pixels: noise alone reaches S in a fraction Q((S - b) / sigma_n) of the pixels (7e-4 at
3.2 sigma), singly or in pairs, rarely three together (N p^3 ~ 2e-4 per 10^6 pixels for independent pixels).
On that rendered field, as a JPEG: 36 detections, all stars, 0.35 px rms per axis from their true positions
(1.1 px at most), their stated sigma 0.13 px, 0.38 px with ``startrack solve``'s factor 3 for saturated stars;
it solves (tests/startrack/test_solve_answer.py).
"""

from __future__ import annotations

#: Fewest pixels at full scale of a clipped star (module text).
MIN_PIXELS = 3


def above_full_scale(found, full_scale):
    """True when the threshold of detections ``found`` lies at or above the frame's ``full_scale`` [DN] (None:
    unknown, never)."""
    return full_scale is not None and found.threshold >= full_scale


def clipped_threshold(full_scale):
    """The threshold [DN] of a clipped frame: its full scale less half a grey level (integer data)."""
    return full_scale - 0.5


def is_clipped(found, full_scale):
    """True when the detections ``found`` are those of a clipped frame (:func:`retry`)."""
    return full_scale is not None and found.threshold == clipped_threshold(full_scale)


def retry(detect, image, options, found, full_scale):
    """``found`` (the detections of ``image`` with ``options``, the keyword arguments of
    :func:`startrack.image.detection.detect`, here ``detect``), or, when their threshold lies above
    ``full_scale``, the detections of the clipped stars (module text; :func:`is_clipped` tells them)."""
    if not above_full_scale(found, full_scale):
        return found
    clipped = {**options, "threshold": clipped_threshold(full_scale), "centroider": "grey",
               "min_pixels": max(options.get("min_pixels", 1), MIN_PIXELS)}
    return detect(image, **clipped)
