"""``startrack solve``: identify the stars of frames and print their attitude (docs/design.md contract).

INPUT is a centroid CSV (``u,v[,flux]`` per line, pixels, header line optional; with flux the
brighter centroids are tried first), an image (.png/.tif/.tiff/.npy: detected and centroided first
by :func:`startrack.detection.detect`), or ``--batch FILE.jsonl`` with one frame per line
``{"id": ..., "centroids": [[u, v, flux], ...]}`` (flux optional).  ``--boresight-deg RA,DEC`` is a
prior boresight: the predicted sub-catalog and its redundant neighbours are searched before the full
sky.  With ``--json`` one JSON object per frame and line (JSON Lines): ``id``, ``status`` ("ok",
"no_match", "too_few", "error"), ``reason`` when not ok, ``q_IS`` [x, y, z, w], ``ra_deg``, ``dec_deg``,
``roll_deg``, ``matches`` [[centroid_index, hip], ...], residuals, sigmas, ``false_match_probability``,
``method`` and ``solve_ms``.

A frame that cannot be solved (NaN, fewer than 3 centroids, all off the sensor, a broken batch line)
gets a status and a reason; the other frames are still solved.  Exit status: 0 when every frame is
identified, 1 when some is not, 2 for bad options or an unreadable INPUT.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from startrack.errors import InputError
from startrack.units import DEG

_IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".npy")


def register(subparsers):
    parser = subparsers.add_parser(
        "solve",
        help="identify stars (lost-in-space, predicted sub-catalog) and print the attitude",
        description="Star identification of centroid lists or images against the navigation catalog.",
    )
    parser.add_argument("input", nargs="?", help="centroid CSV (u,v[,flux]) or image (.png/.tif/.tiff/.npy)")
    parser.add_argument("--batch", metavar="FILE.jsonl", help='frames, one JSON per line: {"id", "centroids"}')
    parser.add_argument("--fov-deg", type=float, required=True, help="field of view across the image width [deg]")
    parser.add_argument("--width", type=int, required=True, help="image width [px]")
    parser.add_argument("--height", type=int, required=True, help="image height [px]")
    parser.add_argument("--boresight-deg", metavar="RA,DEC", help="prior boresight right ascension, declination [deg]")
    parser.add_argument("--circular", action="store_true", help="circular field (the circle inscribed in the width)")
    parser.add_argument("--mag", type=float, default=6.0, help="magnitude limit of the catalog [mag] (6.0)")
    parser.add_argument("--nd", type=int, default=53, help="declination divisions n_d of the sub-catalogs (53)")
    parser.add_argument("--centroid-sigma-px", type=float, default=0.2, help="centroid noise per axis [px] (0.2)")
    parser.add_argument("--json", action="store_true", help="print one JSON object per frame (JSON Lines)")
    parser.set_defaults(func=run)


def _check(option, value, low, high):
    if not math.isfinite(value) or not low <= value <= high:
        raise InputError(f"option {option} = {value} is not a finite number in [{low}, {high}].")
    return value


def parse_boresight(text):
    """(ra, dec) [rad] from 'RA,DEC' in degrees."""
    parts = text.split(",")
    try:
        ra_deg, dec_deg = (float(p) for p in parts)
    except ValueError:
        raise InputError(f"option --boresight-deg = {text!r} is not two numbers RA,DEC in degrees.") from None
    _check("--boresight-deg RA", ra_deg, -360.0, 720.0)
    _check("--boresight-deg DEC", dec_deg, -90.0, 90.0)
    return ra_deg * DEG, dec_deg * DEG


def read_centroid_csv(path):
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


def _batch_frames(path):
    """Yield (id, uv, flux, error reason or None) for each non-empty line of a JSON Lines file."""
    path = Path(path)
    try:
        handle = path.open()
    except OSError as error:
        raise InputError(f"batch file {path} cannot be read ({error}).") from None
    with handle:
        for number, line in enumerate(handle, 1):
            if not line.strip():
                continue
            frame_id = number
            try:
                record = json.loads(line)
                if not isinstance(record, dict):
                    raise ValueError("the line is not a JSON object")
                frame_id = record.get("id", number)
                unknown = set(record) - {"id", "centroids"}
                if unknown:
                    raise ValueError(f"unknown key(s) {', '.join(sorted(unknown))}")
                if "centroids" not in record:
                    raise ValueError('the key "centroids" is missing')
                rows = record["centroids"]
                if not isinstance(rows, list) or any(
                        not isinstance(r, list) or len(r) not in (2, 3)
                        or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in r) for r in rows):
                    raise ValueError('"centroids" must be a list of [u, v] or [u, v, flux] numbers')
                widths = {len(r) for r in rows}
                if len(widths) > 1:
                    raise ValueError('"centroids" rows must all have the same length')
                array = np.array(rows, dtype=float).reshape(-1, widths.pop() if widths else 2)
                yield frame_id, array[:, :2], (array[:, 2] if array.shape[1] == 3 else None), None
            except ValueError as error:  # json.JSONDecodeError is a ValueError
                yield frame_id, None, None, f"batch file {path.name} line {number}: {error}"


def _frames(args):
    if args.batch is not None:
        if args.input is not None:
            raise InputError("give either INPUT or --batch FILE.jsonl, not both.")
        yield from _batch_frames(args.batch)
        return
    if args.input is None:
        raise InputError("no input: give a centroid CSV, an image, or --batch FILE.jsonl.")
    path = Path(args.input)
    if not path.is_file():
        raise InputError(f"input file {path} does not exist.")
    if path.suffix.lower() in _IMAGE_SUFFIXES:
        from startrack.detection import detect
        from startrack.image_io import read_image

        image = read_image(path)
        if image.shape != (args.height, args.width):
            raise InputError(f"image {path} is {image.shape[1]} x {image.shape[0]} px, not --width {args.width} "
                             f"x --height {args.height}.")
        found = detect(image)
        yield str(path), found.uv, found.flux, None
        return
    uv, flux = read_centroid_csv(path)
    yield str(path), uv, flux, None


def _line(frame_id, result):
    if not result.ok:
        return f"{frame_id}: {result.status}: {result.reason} ({result.solve_ms:.2f} ms)"
    sigma = np.degrees(np.sqrt(np.diag(result.covariance))) * 3600.0
    return (f"{frame_id}: ok  RA {math.degrees(result.ra):.5f} deg  Dec {math.degrees(result.dec):+.5f} deg  "
            f"roll {math.degrees(result.roll):+.5f} deg  sigma {sigma[0]:.2f}/{sigma[1]:.2f}/{sigma[2]:.2f} arcsec  "
            f"{len(result.matches)} stars  P_false {result.false_match_probability:.1e}  {result.method}  "
            f"{result.solve_ms:.2f} ms")


def run(args):
    from startrack.camera import Camera
    from startrack.identify import Prior, StarIdentifier
    from startrack.identify.result import IdentificationResult
    from startrack.navigation_catalog import NavigationCatalogParams, load_navigation_catalog

    _check("--fov-deg", args.fov_deg, 0.1, 90.0)
    _check("--mag", args.mag, -2.0, 14.0)
    _check("--centroid-sigma-px", args.centroid_sigma_px, 1e-3, 100.0)
    for option, value in (("--width", args.width), ("--height", args.height)):
        if not 1 <= value <= 100_000:
            raise InputError(f"option {option} = {value} is not a number of pixels in [1, 100000].")
    prior = None if args.boresight_deg is None else Prior(boresight=parse_boresight(args.boresight_deg))
    frames = _frames(args)
    first = next(frames, None)  # read errors of a single INPUT surface before the catalog is built
    camera = Camera.from_fov(args.fov_deg * DEG, args.width, args.height, circular_fov=args.circular)
    catalog = load_navigation_catalog(NavigationCatalogParams(mag_limit=args.mag, fov=args.fov_deg * DEG, n_d=args.nd))
    identifier = StarIdentifier(catalog, camera, centroid_sigma_px=args.centroid_sigma_px)
    all_ok = True
    for frame_id, uv, flux, reason in ([first] if first is not None else []) + list(frames):
        if reason is not None:
            result = IdentificationResult(status="error", reason=reason + ".", solve_ms=0.0)
        else:
            result = identifier.solve(uv, flux, prior)
        all_ok &= result.ok
        print(json.dumps(result.to_dict(frame_id)) if args.json else _line(frame_id, result), flush=True)
    return 0 if all_ok else 1
