"""``startrack detect IMAGE``: star centroids of a frame (PNG/TIFF/JPEG/NPY/FITS), by one of two detectors.

Without ``--smear-px``, 004's threshold detector: background and noise on a mesh of cells (or given), threshold
V_th = b + a sigma_n (eq. 4 of 004), 8-connected components and a centre-of-gravity centroider, single-pixel
events (hot pixels) and extended or elongated detections (clouds, streaks) dropped, saturation at the full scale
of the file's bit depth (:mod:`startrack.image.files`).  The same detection, with the same options
(:func:`add_detection_options`), is the image front end of ``startrack solve``.

With ``--smear-px DU,DV`` (the stars' trail over the exposure, known; ``0,0`` for still stars) and
``--psf-sigma-px``, the matched filter of the PSF drawn along that trail (:class:`MatchedFilter`,
:func:`startrack.detect_trailed`): the same background, noise, mesh and saturation (the mesh's cells measured on
every pixel: the filter sums ~20 pixels, so it needs the level ~√20 times better than a pixel's threshold does), a
threshold on the filter's SNR set by the false detections allowed per frame (``--false-alarms``) in place of
``--a``, and no centroider or shape tests (the template is the star's shape): those options are refused with it.

With ``--psf-sigma-px`` each detection's position is then fitted at the Cramér-Rao bound with its 2 x 2
covariance (:func:`startrack.image.psf_fit.fit_detections`, as ``detect_trailed`` fits: the Gaussian PSF of that
radius, the trail ``--smear-px`` and the star's shot noise through ``--gain-e-per-dn`` when given), flagged when
the model does not explain its pixels (outlier, edge, saturated, failed) or another detection's light reaches its
window (blended).  Prints one line per star, brightest first, or JSON (non-finite numbers as null).
"""

import time
from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError, check_range
from startrack.commands.detect_output import fit_dict, print_stars, strict_json

#: Largest grey level accepted on the command line [DN] (a 32-bit float frame's useful range).
_MAX_DN = 1e9


def add_detection_options(parser):
    """The detection options shared by ``detect`` and ``solve``."""
    group = parser.add_argument_group("detection")
    group.add_argument("--a", type=float, default=None,
                       help="threshold detector: factor a of V_th = b + a sigma_n (5)")
    group.add_argument("--background-dn", type=float, default=None, help="background level b [DN] (estimated)")
    group.add_argument("--sigma-n-dn", type=float, default=None,
                       help="background noise sigma_n [DN]: a star-free pixel's, as read (estimated)")
    group.add_argument("--mesh-px", type=int, default=64,
                       help="cell size of the background mesh [px] (64); 0: one level for the whole frame")
    group.add_argument("--centroider", choices=("threshold", "grey", "square"), default=None,
                       help="threshold detector: thresholded (004), grey-level or square-weighted centre of gravity "
                            "(threshold)")
    group.add_argument("--min-pixels", type=int, default=None, help="threshold detector: smallest star image kept [px] (1)")
    group.add_argument("--keep-single-pixels", action="store_true",
                       help="threshold detector: keep single-pixel events (hot pixels, cosmic rays), which are "
                            "dropped by default")
    group.add_argument("--keep-extended", action="store_true",
                       help="threshold detector: keep extended and elongated detections (clouds, streaks), which are "
                            "dropped by default")
    group.add_argument("--saturation-dn", type=float, default=None,
                       help="grey level of a saturated pixel [DN] (default: the full scale of the file's bit depth)")


#: The threshold detector's defaults of its own options (None on the command line: not given).
_THRESHOLD_DEFAULTS = {"a": 5.0, "centroider": "threshold", "min_pixels": 1}


def detection_options(args) -> dict:
    """Keyword arguments of :func:`startrack.image.detection.detect` from the parsed options (checked)."""
    a, centroider, min_pixels = (_THRESHOLD_DEFAULTS[name] if getattr(args, name) is None else getattr(args, name)
                                 for name in _THRESHOLD_DEFAULTS)
    check_range("--a", a, 0.1, 1000.0)
    for option, value, low in (("--saturation-dn", args.saturation_dn, 1.0), ("--background-dn", args.background_dn, 0.0),
                               ("--sigma-n-dn", args.sigma_n_dn, 1e-6)):
        if value is not None:
            check_range(option, value, low, _MAX_DN)
    if min_pixels < 1:
        raise InputError(f"option --min-pixels = {min_pixels} must be >= 1")
    if args.mesh_px != 0 and not 8 <= args.mesh_px <= 4096:
        raise InputError(f"option --mesh-px = {args.mesh_px} must be 0 or a cell size in [8, 4096] px")
    return {"background": args.background_dn, "sigma_n": args.sigma_n_dn, "a": a, "centroider": centroider,
            "min_pixels": min_pixels, "mesh_px": args.mesh_px or None,
            "reject_single_pixels": not args.keep_single_pixels, "reject_extended": not args.keep_extended,
            "saturation_dn": args.saturation_dn}


def detect_frame(frame, options):
    """:func:`startrack.image.detection.detect` of a :class:`startrack.image.files.Frame` with ``options``
    (:func:`detection_options`; saturation at the frame's full scale unless given; a frame whose threshold lies
    above its full scale, a stretched picture, detected at its clipped stars: :mod:`startrack.image.clipped`),
    without the stars near the frame's pixels without data (:func:`without_masked`)."""
    from startrack.image.clipped import retry
    from startrack.image.detection import detect

    options = {**options, "saturation_dn": saturation(frame, options)}
    return without_masked(frame, retry(detect, frame.image, options, detect(frame.image, **options), frame.full_scale))


def saturation(frame, options):
    """The grey level of a saturated pixel [DN]: ``options["saturation_dn"]``, else the frame's full scale."""
    return frame.full_scale if options["saturation_dn"] is None else options["saturation_dn"]


def without_masked(frame, found):
    """The detections ``found`` of ``frame`` none of whose stars lies within
    :data:`startrack.image.fits.MASK_MARGIN_PX` of a pixel without data (the frame's mask)."""
    if frame.mask is None or not len(found):
        return found
    from scipy.ndimage import binary_dilation

    from startrack.image.fits import MASK_MARGIN_PX

    near = binary_dilation(frame.mask, iterations=MASK_MARGIN_PX)
    rows = np.clip(np.rint(found.v).astype(int), 0, near.shape[0] - 1)
    cols = np.clip(np.rint(found.u).astype(int), 0, near.shape[1] - 1)
    return found.select(~near[rows, cols])


@dataclass(frozen=True)
class Detected:
    """A detector's answer on a frame: the detections ``found``, the detector and its settings for the JSON
    (``about``) and the text header's words for its threshold (``threshold_text``)."""

    found: object
    about: dict
    threshold_text: str


@dataclass(frozen=True)
class ThresholdDetector:
    """004's threshold detector (:func:`detect_frame`) with the checked ``options`` of :func:`detection_options`."""

    options: dict

    def find(self, frame):
        from startrack.image.clipped import is_clipped

        found = detect_frame(frame, self.options)
        about = {"detector": "threshold", "centroider": self.options["centroider"], "a": self.options["a"],
                 "saturation_dn": saturation(frame, self.options)}
        text = f"V_th = {found.threshold:.2f} DN"
        if is_clipped(found, frame.full_scale):
            text += " (b + a sigma_n lies above the full scale: the stars detected as their pixels at full scale)"
        return Detected(found, about, text)


@dataclass(frozen=True)
class MatchedFilter:
    """The matched filter of the PSF (radius ``psf_sigma_px`` [px]) drawn along the trail ``trail_px`` (Δu, Δv)
    [px] (:func:`startrack.detect_trailed`, without its fit: the command fits), its SNR threshold set for
    ``false_alarms`` expected false detections per frame; background, noise, mesh and saturation from the
    ``options`` of :func:`detection_options`, as the threshold detector reads them."""

    psf_sigma_px: float
    trail_px: tuple
    false_alarms: float
    options: dict

    def find(self, frame):
        from startrack.image.trail_detection import detect_trailed, snr_threshold

        u = snr_threshold(self.false_alarms, frame.image.shape, self.psf_sigma_px, self.trail_px)
        level = saturation(frame, self.options)
        found = detect_trailed(frame.image, self.psf_sigma_px, self.trail_px, background=self.options["background"],
                               sigma_n=self.options["sigma_n"], mesh_px=self.options["mesh_px"], threshold_snr=u,
                               saturation_dn=level, fit=False)
        about = {"detector": "matched_filter", "psf_sigma_px": self.psf_sigma_px, "trail_px": list(self.trail_px),
                 "false_alarms_per_frame": self.false_alarms, "threshold_snr": u, "saturation_dn": level}
        text = f"S > {u:.2f} (matched filter: {self.false_alarms:g} false detections per frame expected)"
        return Detected(without_masked(frame, found), about, text)


#: The threshold detector's own options, refused with the matched filter: (option, attribute).
_THRESHOLD_ONLY = (("--a", "a"), ("--centroider", "centroider"), ("--min-pixels", "min_pixels"),
                   ("--keep-single-pixels", "keep_single_pixels"), ("--keep-extended", "keep_extended"))


def _matched_filter(args, fitting):
    """The :class:`MatchedFilter` of the parsed options (``fitting`` of :func:`_fit_options`), checked: the
    threshold detector's own options refused, the trail no longer than the template is built for."""
    from startrack.image.trail_detection import FALSE_ALARMS_PER_FRAME, MAX_TRAIL_PX

    refused = [option for option, name in _THRESHOLD_ONLY if getattr(args, name) not in (None, False)]
    if refused:
        raise InputError(f"option {', '.join(refused)} is the threshold detector's: with --smear-px the matched "
                         "filter runs, its threshold set by --false-alarms per frame and the star's shape its "
                         "template (no centroider, size or shape test)")
    sigma, _, trail = fitting
    if np.hypot(*trail) > MAX_TRAIL_PX:
        raise InputError(f"option --smear-px = {args.smear_px}: a trail of {np.hypot(*trail):.1f} px is longer than "
                         f"the {MAX_TRAIL_PX:g} px the matched filter's template is built for")
    false_alarms = FALSE_ALARMS_PER_FRAME
    if args.false_alarms is not None:
        false_alarms = check_range("--false-alarms", args.false_alarms, 1e-6, 1e3)
    return MatchedFilter(sigma, trail, false_alarms, detection_options(args))


def _add_fit_options(parser):
    """The options of the trailed stars' matched filter and of the PSF fit (:mod:`startrack.image.psf_fit`)."""
    group = parser.add_argument_group("trailed stars' matched filter and position fit at the Cramér-Rao bound")
    group.add_argument("--psf-sigma-px", type=float, default=None,
                       help="Gaussian PSF radius [px]: fit every star's position and covariance (off by default); with "
                            "--smear-px also the matched filter's")
    group.add_argument("--gain-e-per-dn", type=float, default=None,
                       help="detector gain [e-/DN] for the stars' shot noise in the fit (default: left out of the noise)")
    group.add_argument("--smear-px", default=None, metavar="DU,DV",
                       help="the stars' trail during the exposure [px] (0,0: still stars), with --psf-sigma-px: "
                            "detect with the matched filter of the PSF drawn along it (startrack.detect_trailed) "
                            "and fit the trailed stars; without it the threshold detector runs (a negative DU: "
                            "--smear-px=-3,4)")
    group.add_argument("--false-alarms", type=float, default=None,
                       help="matched filter (--smear-px): expected false detections per frame that set its SNR "
                            "threshold (0.01: startrack.image.trail_detection.FALSE_ALARMS_PER_FRAME)")


def _fit_options(args):
    """(PSF radius, gain, smear) of the parsed fit options, checked; None without --psf-sigma-px."""
    if args.psf_sigma_px is None:
        given = [name for name, value in (("--gain-e-per-dn", args.gain_e_per_dn), ("--smear-px", args.smear_px))
                 if value is not None]
        if given:
            raise InputError(f"{' and '.join(given)} given without --psf-sigma-px, the PSF radius of the fit and of "
                             "--smear-px's matched filter")
        return None
    check_range("--psf-sigma-px", args.psf_sigma_px, 0.05, 100.0)
    if args.gain_e_per_dn is not None:
        check_range("--gain-e-per-dn", args.gain_e_per_dn, 1e-6, 1e6)
    smear = (0.0, 0.0)
    if args.smear_px is not None:
        try:
            smear = tuple(float(x) for x in args.smear_px.split(","))
        except ValueError:
            smear = ()
        if len(smear) != 2:
            raise InputError(f"option --smear-px = {args.smear_px!r}: expected two numbers DU,DV [px]")
        for value in smear:
            check_range("--smear-px", value, -1000.0, 1000.0)
    return args.psf_sigma_px, args.gain_e_per_dn, smear


def _detector(args, fitting):
    """The detector the options choose: the matched filter with ``--smear-px``, else the threshold detector."""
    if args.smear_px is None:
        if args.false_alarms is not None:
            raise InputError("option --false-alarms sets the matched filter's threshold: it goes with --smear-px")
        return ThresholdDetector(detection_options(args))
    return _matched_filter(args, fitting)


def _fit_frame(frame, detected, options):
    """:func:`startrack.image.psf_fit.fit_detections` of the detections of ``frame`` (``options`` of
    :func:`_fit_options`), saturated at the detector's level."""
    from startrack.image.psf_fit import fit_detections

    sigma, gain, smear = options
    found = detected.found
    return fit_detections(frame.image, found.uv, sigma, found.sigma_n, found.background, smear_px=smear,
                          gain_e_per_dn=gain, saturation_dn=detected.about["saturation_dn"])


def register(subparsers):
    parser = subparsers.add_parser(
        "detect",
        help="detect stars in an image and print their centroids",
        description="Detect and centroid star images. Without --smear-px: the threshold detector (V_th = b + a "
                    "sigma_n, connected components, centre of gravity). With --smear-px DU,DV and --psf-sigma-px: "
                    "the matched filter of the PSF drawn along the stars' known trail (startrack.detect_trailed), "
                    "its threshold set by --false-alarms per frame, every detection then fitted at the "
                    "Cramér-Rao bound. --psf-sigma-px alone: the threshold detector's stars fitted so.",
    )
    parser.add_argument("image", help="frame: .png, .tif/.tiff, .jpg/.jpeg, .fits/.fit/.fts or .npy")
    parser.add_argument("--hdu", type=int, default=None, help="the HDU of a FITS image (the first image HDU)")
    add_detection_options(parser)
    _add_fit_options(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=run)


def run(args):
    from startrack.image.files import read_frame

    fitting = _fit_options(args)
    detector = _detector(args, fitting)
    frame = read_frame(args.image, args.hdu)
    image = frame.image
    start = time.perf_counter()
    detected = detector.find(frame)
    found = detected.found
    fits = _fit_frame(frame, detected, fitting) if fitting is not None and len(found) else None
    elapsed_ms = 1000.0 * (time.perf_counter() - start)
    if args.json:
        result = {"image": args.image, "height": image.shape[0], "width": image.shape[1], **detected.about,
                  "full_scale_dn": frame.full_scale, "detect_ms": elapsed_ms, **found.to_dict()}
        if fits is not None:
            for i, star in enumerate(result["stars"]):
                star["psf_fit"] = fit_dict(fits, i)
        print(strict_json(result))
        return 0
    print(f"{args.image}: {image.shape[1]} x {image.shape[0]} px, {detected.about['detector']} detector, "
          f"b = {found.background:.2f} DN, sigma_n = {found.sigma_n:.2f} DN, {detected.threshold_text}, "
          f"{len(found)} stars, {elapsed_ms:.1f} ms")
    print_stars(found, fits)
    return 0
