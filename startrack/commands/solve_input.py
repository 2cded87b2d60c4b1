"""The frames of ``startrack solve``: images, centroid CSV files, JSON Lines batches, folders and lists.

Every source yields :class:`SolveFrame` records; a frame that cannot be read in a batch becomes a record
with a reason (its status is "error"), so the other frames are still solved.  A single INPUT that
cannot be read is bad input (one line, exit 2).

* image (.png/.tif/.tiff/.jpg/.jpeg/.fits/.fit/.fts/.npy): detected and centroided
  (:mod:`startrack.commands.detect`); its size is the file's; a FITS image's first image HDU (or ``--hdu``),
  with its observation's epoch;
* centroid CSV: ``u,v[,flux]`` per line [px], header line optional; ``--width``/``--height`` give
  the image size;
* JSON Lines (``--batch FILE.jsonl``): ``{"id": ..., "centroids": [[u, v, flux], ...]}`` per line;
* folder (``--batch DIR``): its image files, sorted by name;
* list (``--batch FILE.txt``): one image path per line (relative to the list's folder; # comments);
* stream (``--batch -``): standard input read as it comes, per line an image path or a JSON centroid
  record, each answer printed (and flushed) before the next line is read: a camera pipeline's solver
  that pays the start-up once.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from startrack.base.errors import InputError
from startrack.image.files import IMAGE_SUFFIXES
from startrack.image.fits import is_fits


@dataclass(frozen=True)
class SolveFrame:
    """One frame to solve: ``uv`` (n, 2) [px], ``flux`` (n,) or None, ``sigma`` (n,) centroid sigma [px]
    or None, image ``width`` x ``height`` [px]; ``reason`` when it could not be read; ``detection`` a
    summary of the detection (images); an image's ``image`` (H, W) [DN], ``epoch`` of its observation
    [Julian year] or None, and ``hdu``, the HDU read of a FITS file."""

    frame_id: object
    uv: np.ndarray | None = None
    flux: np.ndarray | None = None
    sigma: np.ndarray | None = None
    width: int | None = None
    height: int | None = None
    reason: str | None = None
    detection: dict | None = None
    image: np.ndarray | None = None
    epoch: float | None = None
    hdu: int | None = None


def is_picture(frame_id):
    """True for a frame read from a PNG, TIFF, JPEG or .npy file: an array shown top row first (row 0 at the top),
    unlike a FITS image, whose viewers put row 1 at the bottom."""
    suffix = Path(str(frame_id)).suffix.lower()
    return suffix in IMAGE_SUFFIXES and not is_fits(str(frame_id))


def _read_centroid_csv(path):
    """(uv (n, 2), flux (n,) or None) from a CSV of u,v[,flux] rows; a first non-numeric line is a header."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"centroid file {path} cannot be read ({error}).") from None
    rows = [(number, line) for number, line in enumerate(lines, 1) if line.strip() and not line.lstrip().startswith("#")]
    columns = None
    if rows:
        fields = [f.strip().lower() for f in rows[0][1].split(",")]
        try:
            [float(f) for f in fields]
        except ValueError:
            columns = fields
            rows = rows[1:]
            if fields[:2] != ["u", "v"] or fields[2:] not in ([], ["flux"]):
                raise InputError(f"centroid file {path} has header {','.join(fields)!r}; expected u,v or u,v,flux.")
    values = []
    for number, line in rows:
        try:
            values.append([float(f) for f in line.split(",")])
        except ValueError:
            raise InputError(f"centroid file {path} line {number} is not numbers: {line.strip()!r}.") from None
    widths = {len(v) for v in values}
    if len(widths) > 1 or widths - {2, 3} or (columns is not None and widths and widths != {len(columns)}):
        raise InputError(f"centroid file {path} must have 2 (u,v) or 3 (u,v,flux) columns on every line.")
    array = np.array(values, dtype=float).reshape(-1, widths.pop() if widths else 2)
    return array[:, :2], (array[:, 2] if array.shape[1] == 3 else None)


def _centroid_rows(rows):
    """(uv, flux or None) of a JSON "centroids" value, or ValueError."""
    if not isinstance(rows, list) or any(
            not isinstance(r, list) or len(r) not in (2, 3)
            or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in r) for r in rows):
        raise ValueError('"centroids" must be a list of [u, v] or [u, v, flux] numbers')
    widths = {len(r) for r in rows}
    if len(widths) > 1:
        raise ValueError('"centroids" rows must all have the same length')
    array = np.array(rows, dtype=float).reshape(-1, widths.pop() if widths else 2)
    return array[:, :2], (array[:, 2] if array.shape[1] == 3 else None)


def _batch_jsonl(path, width, height):
    """SolveFrame records of a JSON Lines file (one per non-empty line)."""
    try:
        handle = path.open("rb")
    except OSError as error:
        raise InputError(f"batch file {path} cannot be read ({error}).") from None
    frames = 0
    with handle:
        for number, raw in enumerate(handle, 1):
            if not raw.strip():
                continue
            frames += 1
            yield _json_frame(raw, number, width, height, f"batch file {path.name}")
    if not frames:
        raise InputError(f"batch file {path} holds no frame (every line is empty).")


def _json_frame(raw, number, width, height, source):
    """The SolveFrame of one JSON line (bytes or text) ``{"id": ..., "centroids": [...]}``, or its error record
    (``source`` and ``number`` name the line)."""
    frame_id = number
    try:
        record = json.loads(raw.decode("utf-8") if isinstance(raw, bytes) else raw)  # bad bytes: this frame's error
        if not isinstance(record, dict):
            raise ValueError("the line is not a JSON object")
        frame_id = record.get("id", number)
        unknown = set(record) - {"id", "centroids"}
        if unknown:
            raise ValueError(f"unknown key(s) {', '.join(sorted(unknown))}")
        if "centroids" not in record:
            raise ValueError('the key "centroids" is missing')
        uv, flux = _centroid_rows(record["centroids"])
        return SolveFrame(frame_id, uv, flux, None, width, height)
    except ValueError as error:  # json.JSONDecodeError and UnicodeDecodeError are ValueErrors
        return SolveFrame(frame_id, reason=f"{source} line {number}: {error}")


def _stream_frames(lines, options, width, height, hdu=None):
    """SolveFrame records of a stream read as it comes (``--batch -``: standard input, a camera pipeline's
    frames): per non-empty line a JSON centroid record (a line starting with "{") or an image path."""
    for number, line in enumerate(lines, 1):
        text = line.strip()
        if not text:
            continue
        if text.startswith("{"):
            yield _json_frame(text, number, width, height, "standard input")
            continue
        try:
            yield image_frame(Path(text), options, hdu=hdu)
        except InputError as error:
            yield SolveFrame(text, reason=str(error))


def image_frame(path, options, width=None, height=None, hdu=None):
    """The SolveFrame of an image file (a FITS file's HDU ``hdu``): read, size checked against the given one,
    detected."""
    from startrack.commands.detect import detect_frame
    from startrack.image.clipped import is_clipped
    from startrack.image.files import read_frame

    frame = read_frame(path, hdu)
    rows, cols = frame.image.shape
    if (width is not None and width != cols) or (height is not None and height != rows):
        wanted = f"{cols if width is None else width} x {rows if height is None else height}"
        raise InputError(f"image {path} is {cols} x {rows} px, not the {wanted} px of --width/--height or the camera file.")
    found = detect_frame(frame, options)
    summary = {"detections": len(found), "background_dn": found.background, "sigma_n_dn": found.sigma_n,
               "threshold_dn": found.threshold, "full_scale_dn": frame.full_scale,
               "clipped": is_clipped(found, frame.full_scale)}
    sigma = np.hypot(found.sigma_u, found.sigma_v) / np.sqrt(2.0)
    sigma = np.where(found.saturated, 3.0 * sigma, sigma)  # a clipped peak biases the centroid
    return SolveFrame(str(path), found.uv, found.flux, sigma, cols, rows, detection=summary, image=frame.image,
                      epoch=frame.epoch, hdu=frame.hdu)


def _listed_images(path):
    """Image paths of a folder (sorted) or of a list file (one per line, relative to the list)."""
    if path.is_dir():
        images = sorted(p for p in path.iterdir() if (p.suffix.lower() in IMAGE_SUFFIXES or is_fits(p)) and p.is_file())
        if not images:
            raise InputError(f"batch folder {path} holds no image ({', '.join(IMAGE_SUFFIXES)}).")
        return images
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"batch list {path} cannot be read ({error}).") from None
    return [path.parent / line.strip() for line in lines if line.strip() and not line.lstrip().startswith("#")]


def batch_frames(path, options, width, height, hdu=None):
    """SolveFrame records of ``--batch PATH``: JSON Lines, a folder of images, a list of images, or ``-``:
    standard input as a stream (:func:`_stream_frames`)."""
    if path == "-":
        yield from _stream_frames(sys.stdin, options, width, height, hdu)
        return
    path = Path(path)
    if not path.exists():
        raise InputError(f"batch input {path} does not exist.")
    if path.is_file() and path.suffix.lower() == ".jsonl":
        if hdu is not None:
            raise InputError(f"--hdu {hdu} selects an HDU of a FITS file; {path} is a JSON Lines batch of centroids.")
        yield from _batch_jsonl(path, width, height)
        return
    for image in _listed_images(path):
        try:
            yield image_frame(image, options, hdu=hdu)
        except InputError as error:
            yield SolveFrame(str(image), reason=str(error))


def input_frame(path, options, width, height, hdu=None):
    """The SolveFrame of one INPUT: an image or a centroid CSV."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"input {path} is a directory; give an image or centroid file, or --batch for a folder.")
    if not path.is_file():
        raise InputError(f"input file {path} does not exist.")
    if path.suffix.lower() in IMAGE_SUFFIXES or is_fits(path):
        return image_frame(path, options, width, height, hdu)
    if hdu is not None:
        raise InputError(f"--hdu {hdu} selects an HDU of a FITS file; {path} is a centroid list.")
    uv, flux = _read_centroid_csv(path)
    return SolveFrame(str(path), uv, flux, None, width, height)
