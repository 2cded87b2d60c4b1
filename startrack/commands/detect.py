"""``startrack detect IMAGE``: star centroids of a frame (PNG/TIFF/JPEG/NPY).

Background and noise on a mesh of cells (or given), threshold V_th = b + a sigma_n (eq. 4 of 004),
8-connected components and a centre-of-gravity centroider, single-pixel events (hot pixels) and
extended or elongated detections (clouds, streaks) dropped,
saturation at the full scale of the file's bit depth (:mod:`startrack.image.files`); prints one line
per star, brightest first, or JSON.  The same detection, with the same options
(:func:`add_detection_options`), is the image front end of ``startrack solve``.

With ``--psf-sigma-px`` each star's position is then fitted at the Cramér-Rao bound with its 2 x 2
covariance (:mod:`startrack.image.psf_fit`: the Gaussian PSF of that radius, the smear ``--smear-px`` and the
star's shot noise through ``--gain-e-per-dn`` when given), flagged when the model does not explain its
pixels (outlier, edge, saturated, failed) or another detection's light reaches its window (blended).
"""

import json
import time

import numpy as np

from startrack.base.errors import InputError, check_range

#: Largest grey level accepted on the command line [DN] (a 32-bit float frame's useful range).
_MAX_DN = 1e9


def add_detection_options(parser):
    """The detection options shared by ``detect`` and ``solve``."""
    group = parser.add_argument_group("detection")
    group.add_argument("--a", type=float, default=5.0, help="threshold factor a of V_th = b + a sigma_n (5)")
    group.add_argument("--background-dn", type=float, default=None, help="background level b [DN] (estimated)")
    group.add_argument("--sigma-n-dn", type=float, default=None, help="background noise sigma_n [DN] (estimated)")
    group.add_argument("--mesh-px", type=int, default=64,
                       help="cell size of the background mesh [px] (64); 0: one level for the whole frame")
    group.add_argument("--centroider", choices=("threshold", "grey", "square"), default="threshold",
                       help="thresholded (004), grey-level or square-weighted centre of gravity (threshold)")
    group.add_argument("--min-pixels", type=int, default=1, help="smallest star image kept [px] (1)")
    group.add_argument("--keep-single-pixels", action="store_true",
                       help="keep single-pixel events (hot pixels, cosmic rays), which are dropped by default")
    group.add_argument("--keep-extended", action="store_true",
                       help="keep extended and elongated detections (clouds, streaks), which are dropped by default")
    group.add_argument("--saturation-dn", type=float, default=None,
                       help="grey level of a saturated pixel [DN] (default: the full scale of the file's bit depth)")


def detection_options(args) -> dict:
    """Keyword arguments of :func:`startrack.image.detection.detect` from the parsed options (checked)."""
    check_range("--a", args.a, 0.1, 1000.0)
    for option, value, low in (("--saturation-dn", args.saturation_dn, 1.0), ("--background-dn", args.background_dn, 0.0),
                               ("--sigma-n-dn", args.sigma_n_dn, 1e-6)):
        if value is not None:
            check_range(option, value, low, _MAX_DN)
    if args.min_pixels < 1:
        raise InputError(f"option --min-pixels = {args.min_pixels} must be >= 1")
    if args.mesh_px != 0 and not 8 <= args.mesh_px <= 4096:
        raise InputError(f"option --mesh-px = {args.mesh_px} must be 0 or a cell size in [8, 4096] px")
    return {"background": args.background_dn, "sigma_n": args.sigma_n_dn, "a": args.a, "centroider": args.centroider,
            "min_pixels": args.min_pixels, "mesh_px": args.mesh_px or None,
            "reject_single_pixels": not args.keep_single_pixels, "reject_extended": not args.keep_extended,
            "saturation_dn": args.saturation_dn}


def detect_frame(frame, options):
    """:func:`startrack.image.detection.detect` of a :class:`startrack.image.files.Frame` with ``options``
    (:func:`detection_options`; saturation at the frame's full scale unless given; a frame whose threshold lies
    above its full scale, a stretched picture, detected at its clipped stars: :mod:`startrack.image.clipped`); a frame's pixels
    without data (its mask) take no star within :data:`startrack.image.fits.MASK_MARGIN_PX` of them."""
    from startrack.image.clipped import retry
    from startrack.image.detection import detect

    if options["saturation_dn"] is None:
        options = {**options, "saturation_dn": frame.full_scale}
    found = retry(detect, frame.image, options, detect(frame.image, **options), frame.full_scale)
    if frame.mask is None or not len(found):
        return found
    from scipy.ndimage import binary_dilation

    from startrack.image.fits import MASK_MARGIN_PX

    near = binary_dilation(frame.mask, iterations=MASK_MARGIN_PX)
    rows = np.clip(np.rint(found.v).astype(int), 0, near.shape[0] - 1)
    cols = np.clip(np.rint(found.u).astype(int), 0, near.shape[1] - 1)
    return found.select(~near[rows, cols])


def _add_fit_options(parser):
    """The options of the PSF fit (:mod:`startrack.image.psf_fit`)."""
    group = parser.add_argument_group("position fit at the Cramér-Rao bound")
    group.add_argument("--psf-sigma-px", type=float, default=None,
                       help="Gaussian PSF radius [px]: fit every star's position and covariance (off by default)")
    group.add_argument("--gain-e-per-dn", type=float, default=None,
                       help="detector gain [e-/DN] for the stars' shot noise (default: left out of the noise)")
    group.add_argument("--smear-px", default=None, metavar="DU,DV",
                       help="the stars' trail during the exposure [px] (default: none)")


def _fit_options(args):
    """(PSF radius, gain, smear) of the parsed fit options, checked; None without --psf-sigma-px."""
    if args.psf_sigma_px is None:
        if args.gain_e_per_dn is not None or args.smear_px is not None:
            raise InputError("options --gain-e-per-dn and --smear-px go with --psf-sigma-px (the PSF fit)")
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


def _fit_frame(frame, found, options):
    """:func:`startrack.image.psf_fit.fit_stars` of the detections ``found`` of ``frame`` (``options`` of :func:`_fit_options`),
    each detection's neighbours the others: a star whose window another detection's light reaches is ``blended``."""
    import numpy as np

    from startrack.image.psf_fit import PixelNoise, fit_stars

    sigma, gain, smear = options
    noise = PixelNoise(found.sigma_n, gain_e_per_dn=gain)
    others = [np.delete(found.uv, i, axis=0) for i in range(len(found))]
    return fit_stars(frame.image, found.uv, sigma, noise, found.background, smear_px=smear,
                     saturation_dn=frame.full_scale, neighbours=others)


def _fit_dict(fits, i):
    return {"u": float(fits.uv[i, 0]), "v": float(fits.uv[i, 1]), "cov_uv_px2": fits.cov[i].tolist(),
            "flux_dn": float(fits.flux[i]), "background_dn": float(fits.background[i]), "chi2": float(fits.chi2[i]),
            "dof": int(fits.dof[i]), **{flag: bool(getattr(fits, flag)[i]) for flag in _FIT_FLAGS}}


#: The flags of a position fit (startrack.image.psf_fit).
_FIT_FLAGS = ("outlier", "edge", "saturated", "failed", "blended")


def register(subparsers):
    parser = subparsers.add_parser(
        "detect",
        help="detect stars in an image and print their centroids",
        description="Detect and centroid star images (threshold, connected components, centre of gravity).",
    )
    parser.add_argument("image", help="frame: .png, .tif/.tiff, .jpg/.jpeg, .fits/.fit/.fts or .npy")
    parser.add_argument("--hdu", type=int, default=None, help="the HDU of a FITS image (the first image HDU)")
    add_detection_options(parser)
    _add_fit_options(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=run)


def run(args):
    from startrack.image.files import read_frame

    options, fitting = detection_options(args), _fit_options(args)
    frame = read_frame(args.image, args.hdu)
    image = frame.image
    start = time.perf_counter()
    found = detect_frame(frame, options)
    fits = _fit_frame(frame, found, fitting) if fitting is not None and len(found) else None
    elapsed_ms = 1000.0 * (time.perf_counter() - start)
    if args.json:
        result = {"image": args.image, "height": image.shape[0], "width": image.shape[1],
                  "centroider": args.centroider, "full_scale_dn": frame.full_scale, "detect_ms": elapsed_ms,
                  **found.to_dict()}
        if fits is not None:
            for i, star in enumerate(result["stars"]):
                star["psf_fit"] = _fit_dict(fits, i)
        print(json.dumps(result))
        return 0
    print(f"{args.image}: {image.shape[1]} x {image.shape[0]} px, b = {found.background:.2f} DN, "
          f"sigma_n = {found.sigma_n:.2f} DN, V_th = {found.threshold:.2f} DN, {len(found)} stars, "
          f"{elapsed_ms:.1f} ms")
    fitted = "" if fits is None else f" {'fit_u_px':>10} {'fit_v_px':>10} {'sig_u':>6} {'sig_v':>6}"
    print(f"{'#':>4} {'u_px':>10} {'v_px':>10} {'flux_dn':>10} {'peak_dn':>8} {'npix':>5} {'snr':>7}{fitted}  flags")
    for i in range(len(found)):
        flags = [name for name, on in (("saturated", found.saturated[i]), ("edge", found.edge[i])) if on]
        columns = ""
        if fits is not None:
            sigma_u, sigma_v = fits.cov[i, 0, 0] ** 0.5, fits.cov[i, 1, 1] ** 0.5
            columns = f" {fits.uv[i, 0]:>10.3f} {fits.uv[i, 1]:>10.3f} {sigma_u:>6.3f} {sigma_v:>6.3f}"
            flags += [f"fit-{name}" for name in _FIT_FLAGS if getattr(fits, name)[i]]
        print(f"{i:>4} {found.u[i]:>10.3f} {found.v[i]:>10.3f} {found.flux[i]:>10.1f} {found.peak[i]:>8.0f} "
              f"{found.npix[i]:>5d} {found.snr[i]:>7.1f}{columns}  {','.join(flags)}")
    return 0
