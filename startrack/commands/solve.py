"""``startrack solve``: identify the stars of frames and print their attitude (docs/design.md contract).

INPUT is one or more images (.png/.tif/.tiff/.jpg/.jpeg/.fits/.fit/.fts/.npy: detected first, size from the
file; a FITS image's first image HDU or ``--hdu N``, its DATE-OBS the epoch unless ``--epoch``) or
centroid CSV files (``u,v[,flux]`` per line [px], header optional; ``--width``/``--height`` give the
image size); ``--batch PATH`` takes a JSON Lines file (``{"id": ..., "centroids": [[u, v, flux], ...]}``
per line), a folder of images or a list of image paths (:mod:`startrack.commands.solve_input`), or ``-``:
standard input as a stream, each line's answer printed as soon as it is solved (a camera pipeline's solver).  One
process solves them all: the start-up (catalogs, compiled kernels) is paid once.

Two uses (:mod:`startrack.commands.solve_modes`):

* a **star tracker with its calibrated camera**: ``--camera FILE`` (a camera file) or ``--fov-deg F`` (an
  ideal pinhole of the frame's size: principal point at the centre of the pixel grid, no distortion).
  The frame is identified with that camera and the attitude ``q_IS`` is that camera's frame, with its
  sigma at the Cramér-Rao bound.  ``--refit focal,centre,k1,k2`` (or ``all``) refits the named
  intrinsics per frame from the given camera, the others held.
* an **image from an unknown camera** (no geometry): the frame is identified by its four-star patterns
  (:class:`startrack.identify.plate_solver.PlateSolver`), which also fit the focal length, principal
  point and radial distortion.  ``--fov-hint-deg`` is a hint (the nearest pattern levels are searched
  first), ``--fov-range-deg LO,HI`` narrows the search.  ``--write-camera FILE`` writes the calibrated
  camera (of the solved frame with the most matched stars) for a later ``--camera`` or a navsim
  scenario (``star_sensor.image.camera_file``).

``--boresight-deg RA,DEC`` searches near a prior boresight first (the plate solver within
``--boresight-error-deg``).  With ``--json`` one JSON object per frame and line: ``id``, ``status``
("ok", "no_match", "too_few", "error"), ``reason`` when not ok, ``q_IS`` [x, y, z, w] of the sensor
frame (+z through the principal point), ``ra_deg``, ``dec_deg``, ``roll_deg`` of it, ``sigma_arcsec``,
``center`` (the pointing of the image centre, as plate solvers report it, with ``ra_hms``, ``dec_dms`` and
``sigma_arcsec`` [east, north]), ``field`` (``width_deg``, ``height_deg``, ``pixel_scale_arcsec``,
``orientation_deg``: up is it E of N, ``parity``: :mod:`startrack.camera.sky_field`), ``camera`` (the camera the
attitude refers to: ``source`` given, fitted or refined, and for a fitted or refined camera its sigma),
``stars_matched``, ``matches`` [[centroid index, hip], ...], residuals, ``false_match_probability``, ``method``,
``solve_ms``, ``epoch`` (of the star positions) and, for images, ``detection`` (``clipped`` when its threshold
lay above the full scale: :mod:`startrack.image.clipped`).  The text answer gives the same as astrometry.net's
solve-field prints them.  ``--wcs``, ``--new-fits``, ``--corr`` and ``--annotate`` write each identified frame's
FITS WCS, image with it, matched stars and a PNG of what was matched (:mod:`startrack.commands.solve_outputs`).
Exit status: 0 when every frame is identified, 1 when some is not, 2 for bad options or an unreadable INPUT.
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np

from startrack.base.errors import InputError, check_range
from startrack.base.units import DEG
from startrack.commands.detect import add_detection_options, detection_options
from startrack.commands.solve_input import SolveFrame, batch_frames, input_frame, is_picture
from startrack.commands.solve_modes import FrameSolver, centroid_sigma, parse_refit
from startrack.commands.solve_outputs import add_output_options, check_output_options, write_outputs
from startrack.image.clipped import MIN_PIXELS


def register(subparsers):
    parser = subparsers.add_parser(
        "solve",
        help="identify the stars of images or centroid lists and print the attitude (a given camera, or none)",
        description="Star identification of images or centroid lists: with a calibrated camera (--camera, or "
                    "--fov-deg for an ideal pinhole) as a star tracker, or from an unknown camera, whose focal "
                    "length, principal point and distortion are then fitted.",
    )
    parser.add_argument("input", nargs="*",
                        help="images (.png/.tif/.tiff/.jpg/.jpeg/.fits/.fit/.fts/.npy) or centroid CSV files")
    parser.add_argument("--batch", metavar="PATH",
                        help="frames: a .jsonl file, a folder of images, a list of images, or - for standard input "
                             "read as a stream (per line an image path or a JSON centroid record)")
    parser.add_argument("--camera", metavar="FILE",
                        help="the calibrated camera (a camera file, e.g. from --write-camera): identify with it")
    parser.add_argument("--fov-deg", type=float,
                        help="field of view across the width [deg] of an ideal pinhole camera of the frame's size "
                             "(principal point at the centre of the pixel grid, no distortion): identify with it")
    parser.add_argument("--refit", metavar="LIST",
                        help="refit these intrinsics of the given camera per frame: focal,centre,k1,k2 or all")
    parser.add_argument("--fov-hint-deg", type=float,
                        help="unknown camera: field of view across the width [deg] searched first (a hint; below "
                             "2 deg it extends the search down to it)")
    parser.add_argument("--fov-range-deg", metavar="LO,HI",
                        help="unknown camera: search only fields of view in [LO, HI] deg (default 2,160; "
                             "pinhole and, from 28 deg, fisheye lenses; below 5 deg with Gaia DR3 stars to V 10)")
    parser.add_argument("--write-camera", metavar="FILE", help="write the fitted camera (TOML) to FILE")
    parser.add_argument("--width", type=int,
                        help="image width [px] (centroid input, default the camera file's; checked for images)")
    parser.add_argument("--height", type=int,
                        help="image height [px] (centroid input, default the camera file's; checked for images)")
    parser.add_argument("--boresight-deg", metavar="RA,DEC", help="prior boresight right ascension, declination [deg]")
    parser.add_argument("--boresight-error-deg", type=float, default=10.0,
                        help="largest error of the prior boresight [deg] for the plate solver (10)")
    parser.add_argument("--mag", type=float, default=None,
                        help="faintest catalog star [V mag]: of a given camera's catalog (default from the field's "
                             "size: V 6 at 16 deg) or of the plate solver's verification (10 with the Gaia stars "
                             "of a search below 5 deg, as the default's, else 8)")
    parser.add_argument("--epoch", type=float, default=None,
                        help="epoch of the star positions [Julian year] (a FITS image's observation, else 2000)")
    parser.add_argument("--hdu", type=int, default=None, help="the HDU of FITS images to solve (the first image HDU)")
    parser.add_argument("--centroid-sigma-px", type=float, default=None,
                        help="centroid sigma [px] of centroid lists and of a given camera's gates (the camera "
                             "file's fit RMS, else 0.3; images weight stars by their detections')")
    parser.add_argument("--time-budget-s", type=float, default=1.0, help="search time per frame before no_match [s] (1)")
    parser.add_argument("--max-false-match", type=float, default=1e-6,
                        help="largest accepted false-match probability (1e-6)")
    add_detection_options(parser)
    add_output_options(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object per frame (JSON Lines)")
    parser.set_defaults(func=run)


#: A given camera's refit, or the diagnosis of a frame it cannot identify, searches fields of view within
#: this factor of its own.
_GIVEN_FOV_SPREAD = 1.3


def _pair(option, text):
    try:
        first, second = (float(p) for p in text.split(","))
    except ValueError:
        raise InputError(f"option {option} = {text!r} is not two numbers separated by a comma.") from None
    return first, second


def _parse_boresight(text, error_deg):
    """(axis (3,), radius [rad]) of ``--boresight-deg RA,DEC`` and its error [deg] (checked before)."""
    from startrack.geometry.sphere import radec_to_vector

    ra_deg, dec_deg = _pair("--boresight-deg", text)
    check_range("--boresight-deg RA", ra_deg, -360.0, 720.0)
    check_range("--boresight-deg DEC", dec_deg, -90.0, 90.0)
    return radec_to_vector(ra_deg * DEG, dec_deg * DEG), error_deg * DEG


def _fov_range(args):
    """(low, high) [rad] of the field of view searched, or None for the default range; a hint narrower than
    the default range's low end extends it down to the hint over :data:`_GIVEN_FOV_SPREAD`."""
    if args.fov_range_deg is None:
        from startrack.identify.plate_solver import DEFAULT_FOV_RANGE

        low = DEFAULT_FOV_RANGE[0] / DEG
        if args.fov_hint_deg is not None and args.fov_hint_deg < low:
            return args.fov_hint_deg / _GIVEN_FOV_SPREAD * DEG, _widest_deg() * DEG
        return None
    low, high = _pair("--fov-range-deg", args.fov_range_deg)
    widest = _widest_deg()
    if not (0.5 <= low <= high <= widest):
        raise InputError(f"option --fov-range-deg = {args.fov_range_deg!r} must be LO,HI with 0.5 <= LO <= HI <= {widest:g}.")
    return low * DEG, high * DEG


def _widest_deg():
    """The widest field [deg] the plate solver searches (its pattern catalog's)."""
    from startrack.identify.pattern_catalog import PatternCatalogParams

    return PatternCatalogParams().fov_max / DEG


def _checked_geometry(args):
    """Refuse options that contradict each other: a given camera and the unknown camera's search."""
    for option, value, top in (("--fov-deg", args.fov_deg, 90.0), ("--fov-hint-deg", args.fov_hint_deg, _widest_deg())):
        if value is not None:
            check_range(option, value, 0.5, top)
    given = [o for o, v in (("--camera", args.camera), ("--fov-deg", args.fov_deg)) if v is not None]
    search = [o for o, v in (("--fov-hint-deg", args.fov_hint_deg), ("--fov-range-deg", args.fov_range_deg)) if v is not None]
    if len(given) == 2:
        raise InputError("give the camera as --camera FILE or as --fov-deg F, not both.")
    if given and search:
        raise InputError(f"{given[0]} gives the camera; {search[0]} is the search of an unknown camera's field of view.")
    if args.refit is not None and not given:
        raise InputError("--refit refits a given camera: give --camera FILE or --fov-deg F.")
    if args.write_camera is not None and given and args.refit is None:
        raise InputError("--write-camera writes a fitted camera: give no camera, or --refit with it.")


def frame_solver(args):
    """The :class:`startrack.commands.solve_modes.FrameSolver` of the options (checked)."""
    from startrack.camera.file import read_camera_file

    _checked_geometry(args)
    fov_range = _fov_range(args)
    if args.centroid_sigma_px is not None:
        check_range("--centroid-sigma-px", args.centroid_sigma_px, 1e-3, 100.0)
    if args.epoch is not None:
        check_range("--epoch", args.epoch, 1000.0, 3000.0)
    if args.hdu is not None:
        check_range("--hdu", args.hdu, 0, 10_000)
    check_range("--time-budget-s", args.time_budget_s, 1e-3, 3600.0)
    check_range("--boresight-error-deg", args.boresight_error_deg, 0.0, 180.0)
    check_range("--max-false-match", args.max_false_match, 1e-300, 1.0)
    if args.mag is not None:
        check_range("--mag", args.mag, -2.0, 10.0)
    refit = None if args.refit is None else parse_refit(args.refit)
    camera_file = None if args.camera is None else read_camera_file(args.camera)
    if camera_file is not None or args.fov_deg is not None:  # a refit or a diagnosis searches near the given field
        given = camera_file.camera.angular_width if camera_file is not None else args.fov_deg * DEG
        fov_range = (max(0.5 * DEG, given / _GIVEN_FOV_SPREAD), min(_widest_deg() * DEG, given * _GIVEN_FOV_SPREAD))
    plate = {"fov_range": fov_range, "threshold": args.max_false_match,
             "time_budget_s": args.time_budget_s, "mag_limit": args.mag, "progress": True}
    return FrameSolver(camera_file, None if args.fov_deg is None else args.fov_deg * DEG, refit,
                       centroid_sigma(args.centroid_sigma_px, camera_file), plate,
                       None if args.fov_hint_deg is None else args.fov_hint_deg * DEG, args.mag, args.epoch,
                       args.max_false_match)


def _frames(args, options, camera_file):
    """The SolveFrame records of the inputs (a single INPUT's read error is raised, a batch's reported);
    centroid input has the size of --width/--height, else of the camera file."""
    if args.batch is not None and args.input:
        raise InputError("give either INPUT files or --batch PATH, not both.")
    if args.batch is None and not args.input:
        raise InputError("no input: give images, centroid CSV files or --batch PATH.")
    for option, value in (("--width", args.width), ("--height", args.height)):
        if value is not None and not 16 <= value <= 100_000:
            raise InputError(f"option {option} = {value} is not a number of pixels in [16, 100000].")
    width, height = args.width, args.height
    if camera_file is not None and width is None and height is None:
        width, height = camera_file.camera.width, camera_file.camera.height
    if args.batch is not None:
        yield from batch_frames(args.batch, options, width, height, args.hdu)
        return
    single = len(args.input) == 1
    for path in args.input:
        try:
            yield input_frame(path, options, width, height, args.hdu)
        except InputError as error:
            if single:
                raise
            yield SolveFrame(str(path), reason=str(error))


def _solve(solver, frame, boresight):
    from startrack.identify.result import IdentificationResult

    if frame.reason is not None:
        return IdentificationResult(status="error", reason=frame.reason.rstrip(".") + ".", solve_ms=0.0)
    if frame.width is None or frame.height is None:
        return IdentificationResult(status="error", reason="centroid input needs --width and --height.", solve_ms=0.0)
    if len(frame.uv) == 0 and frame.detection is not None:
        return IdentificationResult(status="too_few", reason=_nothing_detected(frame.detection), solve_ms=0.0)
    try:
        return solver.solve(frame, boresight)
    except InputError as error:  # a frame that does not fit the camera file
        return IdentificationResult(status="error", reason=str(error), solve_ms=0.0)


def _nothing_detected(detection):
    """The reason of a frame without detections (a clipped frame, or a flat one, says why)."""
    text = (f"0 detections above the threshold {detection['threshold_dn']:.1f} DN (background "
            f"{detection['background_dn']:.1f} DN, noise {detection['sigma_n_dn']:.2f} DN)")
    if detection["clipped"]:
        text += f"; {_CLIPPED} (no blob of {MIN_PIXELS} pixels or more)"
    elif detection["sigma_n_dn"] == 0.0:
        text += "; the frame is flat"
    return text + "."


#: What the detection of a clipped frame was (startrack.image.clipped).
_CLIPPED = ("b + a sigma_n lies above the full scale (a picture stretched past it): its stars detected as the "
            "pixels at full scale")


def _line(frame, result):
    """The text answer of a :class:`SolveFrame`: its status; when identified the matched stars and false-match
    probability, the image centre, field, scale, orientation and parity as astrometry.net's solve-field prints
    them, the sensor frame's attitude, a fitted camera and a clipped frame's detection."""
    frame_id = frame.frame_id
    if not result.ok:
        return f"{frame_id}: {result.status}: {result.reason} ({result.solve_ms:.2f} ms)"
    sigma = np.degrees(np.sqrt(np.diag(result.covariance))) * 3600.0
    lines = [f"{frame_id}: ok  {len(result.matches)} stars matched  false-match probability "
             f"{result.false_match_probability:.1e}  {result.method}  {result.solve_ms:.2f} ms"]
    if result.sky_field is not None:
        lines += _field_lines(result.sky_field, is_picture(frame_id))
    lines.append(f"  sensor  RA {math.degrees(result.ra):.5f} deg  Dec {math.degrees(result.dec):+.5f} deg  roll "
                 f"{math.degrees(result.roll):+.5f} deg  sigma {sigma[0]:.2f}/{sigma[1]:.2f}/{sigma[2]:.2f} arcsec  "
                 f"(+z through the principal point)")
    if result.calibration is not None:
        cam, spread = result.calibration.camera, result.calibration.sigma
        lines.append(f"  camera ({result.camera_source}): FOV {math.degrees(cam.angular_width):.4f} +- "
                     f"{spread['fov_deg']:.4f} deg  f {cam.focal_px:.2f} +- {spread['focal_px']:.2f} px  "
                     f"c ({cam.cx:.1f}, {cam.cy:.1f}) +- ({spread['cx']:.1f}, {spread['cy']:.1f}) px  "
                     f"k1 {cam.k1:+.4f} +- {spread['k1']:.4f}  "
                     f"rms {result.calibration.rms_px:.2f} px")
    if frame.detection is not None and frame.detection["clipped"]:
        lines.append(f"  detection: {_CLIPPED} ({frame.detection['detections']} blobs of {MIN_PIXELS} pixels or more)")
    return "\n".join(lines)


def _field_lines(field, picture):
    """The centre and field lines of a :class:`startrack.camera.sky_field.SkyField` (a picture's note: its top as
    shown, top row first, is the FITS axes' down)."""
    ra_hms, dec_dms = field.sexagesimal
    size = (f"{field.width_deg:.4f} x {field.height_deg:.4f} deg" if min(field.width_deg, field.height_deg) >= 1.0 else
            f"{60 * field.width_deg:.3f} x {60 * field.height_deg:.3f} arcmin")
    up = round(field.orientation_deg, 2) + 0.0  # + 0.0: no "-0.00"
    top = (f"  (FITS axes: up is +y, rows increasing; as the picture is shown, top row first, its top is "
           f"{round((field.orientation_deg + 360.0) % 360.0 - 180.0, 2) + 0.0:.2f} deg E of N)" if picture else "")
    return [f"  centre  RA {field.ra_deg:.6f} deg  Dec {field.dec_deg:+.6f} deg  ({ra_hms}, {dec_dms})  sigma "
            f"{field.sigma_east_arcsec:.2f}\" E, {field.sigma_north_arcsec:.2f}\" N",
            f"  field   {size}  scale {field.scale_arcsec:.4f} arcsec/px  up is {up:.2f} deg E of N  "
            f"parity {field.parity}{top}"]


def run(args, frame_solver=frame_solver):
    """The command; ``frame_solver(args)`` gives the solver (``startrack serve`` passes one that keeps them)."""
    from startrack.camera.file import write_camera_file

    options = detection_options(args)
    solver = frame_solver(args)
    check_output_options(args, None if args.batch is not None else len(args.input))
    if args.batch is not None:
        from startrack.base.allocator import reuse_freed_memory

        reuse_freed_memory()  # one frame after another
    if args.batch == "-":
        solver.prepare()
    boresight = None if args.boresight_deg is None else _parse_boresight(args.boresight_deg, args.boresight_error_deg)
    frames = _frames(args, options, solver.camera_file)
    first = next(frames, None)  # a single INPUT's read error surfaces before the catalogs are loaded
    best, all_ok = None, True
    for frame in itertools.chain([] if first is None else [first], frames):
        result = _solve(solver, frame, boresight)
        all_ok &= result.ok
        if result.calibration is not None and (best is None or len(result.matches) > len(best[1].matches)):
            best = (frame.frame_id, result)
        record = result.to_dict(frame.frame_id)
        if frame.reason is None:
            record["epoch"] = solver.epoch_of(frame)
            write_outputs(args, frame, result, record["epoch"])
        if frame.detection is not None:
            record["detection"] = frame.detection
        print(json.dumps(record) if args.json else _line(frame, result), flush=True)
    if args.write_camera is not None:
        if best is None:
            raise InputError(f"no frame was identified, so no camera was written to {args.write_camera}.")
        write_camera_file(args.write_camera, best[1].calibration, str(best[0]))
    return 0 if all_ok else 1
