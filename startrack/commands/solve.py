"""``startrack solve``: identify the stars of frames from an unknown camera and print their attitude and
the camera they calibrate (docs/design.md contract).

INPUT is one or more images (.png/.tif/.tiff/.jpg/.jpeg/.npy: detected first, size from the file) or
centroid CSV files (``u,v[,flux]`` per line [px], header optional; ``--width``/``--height`` give the
image size); ``--batch PATH`` takes a JSON Lines file (``{"id": ..., "centroids": [[u, v, flux], ...]}``
per line), a folder of images or a list of image paths (:mod:`startrack.commands.solve_input`).  One
process solves them all: the start-up (catalogs, compiled kernels) is paid once.

No field of view is needed: the frame is identified by its four-star patterns
(:class:`startrack.identify.plate_solver.PlateSolver`), which also fit the focal length, principal
point and radial distortion.  ``--fov-deg`` is a hint (the nearest pattern levels are searched first),
``--fov-range-deg LO,HI`` narrows the search, ``--camera FILE`` starts from a camera file (its focal
length within 1 % or 3 sigma, its principal point and distortion as priors), ``--boresight-deg RA,DEC``
keeps the hypotheses within ``--boresight-error-deg`` of a prior boresight.  ``--write-camera FILE``
writes the calibrated camera (of the solved frame with the most matched stars) for a later solve or a
navsim scenario (``star_sensor.image.camera_file``).

With ``--json`` one JSON object per frame and line: ``id``, ``status`` ("ok", "no_match", "too_few",
"error"), ``reason`` when not ok, ``q_IS`` [x, y, z, w] of the sensor frame (+z through the principal
point), ``ra_deg``, ``dec_deg``, ``roll_deg`` of it, ``center`` (the pointing of the image centre, as
plate solvers report it), ``camera`` (the calibrated camera with its sigma), ``matches`` [[centroid
index, hip], ...], residuals, sigmas, ``false_match_probability``, ``method``, ``solve_ms`` and, for
images, ``detection``.  Exit status: 0 when every frame is identified, 1 when some is not, 2 for bad
options or an unreadable INPUT.
"""

from __future__ import annotations

import json
import math

import numpy as np

from startrack.commands.detect import add_detection_options, detection_options
from startrack.commands.solve_input import SolveFrame, batch_frames, input_frame
from startrack.errors import InputError, check_range
from startrack.units import DEG


def register(subparsers):
    parser = subparsers.add_parser(
        "solve",
        help="identify stars and calibrate the camera of images (no field of view needed) and print the attitude",
        description="Star identification of images or centroid lists from an unknown camera.",
    )
    parser.add_argument("input", nargs="*", help="images (.png/.tif/.tiff/.jpg/.jpeg/.npy) or centroid CSV files")
    parser.add_argument("--batch", metavar="PATH", help="frames: a .jsonl file, a folder of images or a list of images")
    parser.add_argument("--fov-deg", type=float, help="field of view across the width [deg]: a hint, not required")
    parser.add_argument("--fov-range-deg", metavar="LO,HI", help="search only fields of view in [LO, HI] deg (5,40)")
    parser.add_argument("--camera", metavar="FILE", help="start from this camera file (startrack solve --write-camera)")
    parser.add_argument("--write-camera", metavar="FILE", help="write the calibrated camera (TOML) to FILE")
    parser.add_argument("--width", type=int, help="image width [px] (centroid input; checked for images)")
    parser.add_argument("--height", type=int, help="image height [px] (centroid input; checked for images)")
    parser.add_argument("--boresight-deg", metavar="RA,DEC", help="prior boresight right ascension, declination [deg]")
    parser.add_argument("--boresight-error-deg", type=float, default=10.0,
                        help="largest error of the prior boresight [deg] (10)")
    parser.add_argument("--mag", type=float, default=None, help="faintest catalog star of the verification [V mag] (8)")
    parser.add_argument("--epoch", type=float, default=2000.0, help="epoch of the star positions [Julian year] (2000)")
    parser.add_argument("--centroid-sigma-px", type=float, default=0.3,
                        help="centroid sigma of centroid lists [px] (0.3; images use their detections')")
    parser.add_argument("--time-budget-s", type=float, default=1.0, help="search time per frame before no_match [s] (1)")
    parser.add_argument("--max-false-match", type=float, default=1e-6,
                        help="largest accepted false-match probability (1e-6)")
    add_detection_options(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object per frame (JSON Lines)")
    parser.set_defaults(func=run)


def _pair(option, text):
    try:
        first, second = (float(p) for p in text.split(","))
    except ValueError:
        raise InputError(f"option {option} = {text!r} is not two numbers separated by a comma.") from None
    return first, second


def parse_boresight(text, error_deg):
    """(axis (3,), radius [rad]) of ``--boresight-deg RA,DEC`` and its error [deg]."""
    from startrack.sphere import radec_to_vector

    ra_deg, dec_deg = _pair("--boresight-deg", text)
    check_range("--boresight-deg RA", ra_deg, -360.0, 720.0)
    check_range("--boresight-deg DEC", dec_deg, -90.0, 90.0)
    check_range("--boresight-error-deg", error_deg, 0.0, 180.0)
    return radec_to_vector(ra_deg * DEG, dec_deg * DEG), error_deg * DEG


def _fov_range(args):
    """(low, high) [rad] of the field of view searched, or None for the default range."""
    if args.fov_deg is not None:
        check_range("--fov-deg", args.fov_deg, 0.5, 90.0)
    if args.fov_range_deg is None:
        return None
    low, high = _pair("--fov-range-deg", args.fov_range_deg)
    if not (0.5 <= low <= high <= 90.0):
        raise InputError(f"option --fov-range-deg = {args.fov_range_deg!r} must be LO,HI with 0.5 <= LO <= HI <= 90.")
    return low * DEG, high * DEG


def _frames(args, options):
    """The SolveFrame records of the inputs (a single INPUT's read error is raised, a batch's reported)."""
    if args.batch is not None and args.input:
        raise InputError("give either INPUT files or --batch PATH, not both.")
    if args.batch is None and not args.input:
        raise InputError("no input: give images, centroid CSV files or --batch PATH.")
    for option, value in (("--width", args.width), ("--height", args.height)):
        if value is not None and not 16 <= value <= 100_000:
            raise InputError(f"option {option} = {value} is not a number of pixels in [16, 100000].")
    if args.batch is not None:
        yield from batch_frames(args.batch, options, args.width, args.height)
        return
    single = len(args.input) == 1
    for path in args.input:
        try:
            yield input_frame(path, options, args.width, args.height)
        except InputError as error:
            if single:
                raise
            yield SolveFrame(str(path), reason=str(error))


def _solve(solver, frame, args, camera, boresight):
    from startrack.identify.result import IdentificationResult

    if frame.reason is not None:
        return IdentificationResult(status="error", reason=frame.reason.rstrip(".") + ".", solve_ms=0.0)
    if frame.width is None or frame.height is None:
        return IdentificationResult(status="error", reason="centroid input needs --width and --height.", solve_ms=0.0)
    if len(frame.uv) == 0 and frame.detection is not None:
        return IdentificationResult(status="too_few", reason=_nothing_detected(frame.detection), solve_ms=0.0)
    sigma = frame.sigma if frame.sigma is not None else np.full(len(frame.uv), args.centroid_sigma_px)
    return solver.solve(frame.uv, frame.width, frame.height, frame.flux, sigma,
                        fov_hint=None if args.fov_deg is None else args.fov_deg * DEG, camera=camera,
                        boresight=boresight)


def _nothing_detected(detection):
    """The reason of a frame without detections (the threshold above the full scale says why)."""
    text = (f"0 detections above the threshold {detection['threshold_dn']:.1f} DN (background "
            f"{detection['background_dn']:.1f} DN, noise {detection['sigma_n_dn']:.2f} DN)")
    if detection["full_scale_dn"] is not None and detection["threshold_dn"] >= detection["full_scale_dn"]:
        text += f"; the threshold lies above the full scale {detection['full_scale_dn']:.0f} DN"
    elif detection["sigma_n_dn"] == 0.0:
        text += "; the frame is flat"
    return text + "."


def _line(frame_id, result):
    if not result.ok:
        return f"{frame_id}: {result.status}: {result.reason} ({result.solve_ms:.2f} ms)"
    sigma = np.degrees(np.sqrt(np.diag(result.covariance))) * 3600.0
    text = (f"{frame_id}: ok  RA {math.degrees(result.ra):.5f} deg  Dec {math.degrees(result.dec):+.5f} deg  "
            f"roll {math.degrees(result.roll):+.5f} deg  sigma {sigma[0]:.2f}/{sigma[1]:.2f}/{sigma[2]:.2f} arcsec  "
            f"{len(result.matches)} stars  P_false {result.false_match_probability:.1e}  {result.method}  "
            f"{result.solve_ms:.2f} ms")
    if result.calibration is not None:
        cam, spread = result.calibration.camera, result.calibration.sigma
        text += (f"\n  camera: FOV {math.degrees(cam.angular_width):.4f} +- {spread['fov_deg']:.4f} deg  "
                 f"f {cam.focal_px:.2f} +- {spread['focal_px']:.2f} px  c ({cam.cx:.1f}, {cam.cy:.1f}) +- "
                 f"({spread['cx']:.1f}, {spread['cy']:.1f}) px  k1 {cam.k1:+.4f} +- {spread['k1']:.4f}  "
                 f"rms {result.calibration.rms_px:.2f} px")
    return text


def run(args):
    from startrack.camera_file import read_camera_file, write_camera_file
    from startrack.identify.plate_solver import PlateSolver

    options = detection_options(args)
    fov_range = _fov_range(args)
    check_range("--epoch", args.epoch, 1000.0, 3000.0)
    check_range("--boresight-error-deg", args.boresight_error_deg, 0.0, 180.0)
    check_range("--centroid-sigma-px", args.centroid_sigma_px, 1e-3, 100.0)
    check_range("--time-budget-s", args.time_budget_s, 1e-3, 3600.0)
    check_range("--max-false-match", args.max_false_match, 1e-300, 1.0)
    if args.mag is not None:
        check_range("--mag", args.mag, -2.0, 8.0)
    camera = None if args.camera is None else read_camera_file(args.camera)
    boresight = None if args.boresight_deg is None else parse_boresight(args.boresight_deg, args.boresight_error_deg)
    frames = _frames(args, options)
    first = next(frames, None)  # a single INPUT's read error surfaces before the catalogs are loaded
    solver = PlateSolver(fov_range=fov_range, epoch=args.epoch, threshold=args.max_false_match,
                         time_budget_s=args.time_budget_s, mag_limit=args.mag, progress=True)
    best, all_ok = None, True
    for frame in ([first] if first is not None else []) + list(frames):
        try:
            result = _solve(solver, frame, args, camera, boresight)
        except InputError as error:  # a frame that does not fit the camera file
            from startrack.identify.result import IdentificationResult

            result = IdentificationResult(status="error", reason=str(error), solve_ms=0.0)
        all_ok &= result.ok
        if result.ok and (best is None or len(result.matches) > len(best[1].matches)):
            best = (frame.frame_id, result)
        record = result.to_dict(frame.frame_id)
        if frame.detection is not None:
            record["detection"] = frame.detection
        print(json.dumps(record) if args.json else _line(frame.frame_id, result), flush=True)
    if args.write_camera is not None:
        if best is None:
            raise InputError(f"no frame was identified, so no camera was written to {args.write_camera}.")
        write_camera_file(args.write_camera, best[1].calibration, str(best[0]))
    return 0 if all_ok else 1
