"""``startrack render``: a synthetic star-sensor frame for a given attitude.

Stars of the Hipparcos-2 catalog (propagated to ``--epoch``) brighter than
``--mag-limit`` are rendered with the default :class:`~startrack.image.render.SensorModel`
(004's PSF radius and 12-bit ADC) for the boresight (RA, Dec) and roll of
:mod:`startrack.geometry.attitude_angles`, optionally smeared by a body rate; the
frame is written as counts (a 16-bit PNG, FITS or a .npy array) or as an 8-bit picture (JPEG, or PNG with
``--bits 8``) of levels stretched linearly from the counts: level = round(255 (DN - BLACK) / (WHITE - BLACK)),
clipped to 0..255, BLACK by default the background less 3 sigma_n and WHITE by default BLACK + 255 sigma_n
(one level per sigma_n: the noise stays above the 8-bit step, so a star at 004's 5 sigma_n threshold stays
detectable; stars brighter than ~250 sigma_n are clipped).
"""

import json
import math
from pathlib import Path

import numpy as np

from startrack.base.errors import InputError, check_range
from startrack.base.output_paths import check_file
from startrack.base.units import DEG
from startrack.image.fits import FITS_SUFFIXES


def _rate(text):
    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(x) for x in values):
        raise InputError(f"option --rate-deg-s = {text!r} must be three finite numbers wx,wy,wz [deg/s]")
    return np.array(values) * DEG


def register(subparsers):
    parser = subparsers.add_parser(
        "render",
        help="render a synthetic star image for a given attitude (16-bit PNG, FITS, .npy, or an 8-bit JPEG/PNG)",
        description="Render Hipparcos-2 stars for a boresight (RA, Dec) and roll with the default sensor model.",
    )
    parser.add_argument("--ra-deg", type=float, required=True, help="boresight right ascension [deg]")
    parser.add_argument("--dec-deg", type=float, required=True, help="boresight declination [deg]")
    parser.add_argument("--roll-deg", type=float, default=0.0, help="roll about the boresight [deg] (0)")
    parser.add_argument("--fov-deg", type=float, default=20.0, help="field of view across the width [deg] (20)")
    parser.add_argument("--width", type=int, default=1024, help="image width [px] (1024)")
    parser.add_argument("--height", type=int, default=1024, help="image height [px] (1024)")
    parser.add_argument("--mag-limit", type=float, default=6.5, help="faintest visual magnitude rendered (6.5)")
    parser.add_argument("--exposure-ms", type=float, default=100.0, help="exposure time [ms] (100)")
    parser.add_argument("--rate-deg-s", default="0,0,0", help="body rate in the sensor frame wx,wy,wz [deg/s]")
    parser.add_argument("--epoch", type=float, default=2000.0, help="epoch of the star positions [Julian year]")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the noise (0)")
    parser.add_argument("--json", action="store_true", help="print a JSON summary")
    parser.add_argument("-o", "--output", required=True,
                        help="output file: counts as .png (16-bit), .fits or .npy; 8-bit levels as .jpg/.jpeg (quality 90) "
                             "or .png with --bits 8")
    group = parser.add_argument_group(
        "8-bit pictures", "how counts map to 8 bits: level = round(255 (DN - BLACK) / (WHITE - BLACK)), clipped to 0..255 "
                          "(linear; stars above WHITE clipped at 255)")
    group.add_argument("--bits", type=int, choices=(8, 16), default=None,
                       help="bits of a .png: 16 (counts, default) or 8 (levels); a .jpg is always 8")
    group.add_argument("--black-dn", type=float, default=None,
                       help="counts [DN] at level 0 (default: the background less 3 sigma_n, 71 DN at the default exposure)")
    group.add_argument("--white-dn", type=float, default=None,
                       help="counts [DN] at level 255 (default: BLACK + 255 sigma_n, one level per sigma_n of noise)")
    parser.set_defaults(func=run)


def _eight_bit(args):
    """True when the output is an 8-bit picture; stretch options refused on counts (checked)."""
    suffix = Path(args.output).suffix.lower()
    if suffix in (".jpg", ".jpeg") and args.bits == 16:
        raise InputError(f"-o {args.output}: a JPEG holds 8 bits; write a .png for --bits 16")
    if suffix not in (".png", ".jpg", ".jpeg") and args.bits is not None:
        raise InputError(f"--bits {args.bits} sets the bits of a .png; -o {args.output} holds the counts as they are")
    eight = suffix in (".jpg", ".jpeg") or args.bits == 8
    for option, value in (("--black-dn", args.black_dn), ("--white-dn", args.white_dn)):
        if value is not None:
            if not eight:
                raise InputError(f"{option} sets the stretch of an 8-bit picture (.jpg, or .png with --bits 8); "
                                 f"-o {args.output} holds the counts")
            check_range(option, value, -1e9, 1e9)
    return eight


def stretch(sensor, black_dn=None, white_dn=None):
    """(BLACK, WHITE) [DN] of the 8-bit stretch (module text): the given values or the defaults of ``sensor``
    (:class:`startrack.image.render.SensorModel`)."""
    black = sensor.background_dn - 3.0 * sensor.noise_dn if black_dn is None else black_dn
    white = black + 255.0 * sensor.noise_dn if white_dn is None else white_dn
    if not black < white:
        raise InputError(f"--black-dn {black:g} must lie below --white-dn {white:g}")
    return black, white


def run(args):
    from startrack.camera.model import Camera
    from startrack.catalog.hipparcos import load_star_catalog
    from startrack.geometry.attitude_angles import quaternion_from_radec_roll
    from startrack.image.files import stretch_to_8_bit, write_image
    from startrack.image.render import SensorModel, render_star_field

    check_range("--ra-deg", args.ra_deg, -360.0, 720.0)
    check_range("--dec-deg", args.dec_deg, -90.0, 90.0)
    check_range("--roll-deg", args.roll_deg, -360.0, 720.0)
    check_range("--fov-deg", args.fov_deg, 0.1, 120.0)
    check_range("--mag-limit", args.mag_limit, -2.0, 14.0)
    check_range("--exposure-ms", args.exposure_ms, 0.0, 60000.0)
    check_range("--epoch", args.epoch, 1000.0, 3000.0)
    for option, value in (("--width", args.width), ("--height", args.height)):
        if not 8 <= value <= 16384:
            raise InputError(f"option {option} = {value} is not an image size in [8, 16384] px")
    check_file(args.output, "-o", (".png", ".jpg", ".jpeg", ".npy") + FITS_SUFFIXES)
    eight = _eight_bit(args)
    omega = _rate(args.rate_deg_s)

    camera = Camera.from_fov(args.fov_deg * DEG, args.width, args.height)
    sensor = SensorModel(exposure_s=args.exposure_ms / 1000.0)
    catalog = load_star_catalog(args.epoch)
    stars = catalog.brighter_than(args.mag_limit)
    q_IS = quaternion_from_radec_roll(args.ra_deg * DEG, args.dec_deg * DEG, args.roll_deg * DEG)
    rng = np.random.default_rng(np.random.SeedSequence(args.seed))
    frame = render_star_field(camera, sensor, q_IS, stars.vectors, stars.v_mag, rng, omega_S=omega)
    levels = None
    if eight:
        black, white = stretch(sensor, args.black_dn, args.white_dn)
        levels = {"black_dn": black, "white_dn": white}
    path = write_image(args.output, frame.image if levels is None else stretch_to_8_bit(frame.image, black, white))
    inside = (
        (frame.uv_true[:, 0] >= -0.5) & (frame.uv_true[:, 0] <= args.width - 0.5)
        & (frame.uv_true[:, 1] >= -0.5) & (frame.uv_true[:, 1] <= args.height - 0.5)
    )
    summary = {
        "output": str(path),
        "width": args.width,
        "height": args.height,
        "q_IS": [float(x) for x in q_IS],
        "stars_in_image": int(inside.sum()),
        "hip": [int(h) for h in stars.hip[frame.star_index[inside]]],
        "uv_true": [[float(u), float(v)] for u, v in frame.uv_true[inside]],
        "background_dn": sensor.background_dn,
        "sigma_n_dn": float(sensor.noise_dn),
        "saturation_dn": sensor.saturation_dn,
        "stretch": levels,
    }
    if args.json:
        print(json.dumps(summary))
    else:
        bits = "counts" if levels is None else f"8-bit levels {black:g}-{white:g} DN -> 0-255"
        print(f"wrote {path} ({bits}): {args.width} x {args.height} px, {summary['stars_in_image']} stars "
              f"(V <= {args.mag_limit}) at RA {args.ra_deg} deg, Dec {args.dec_deg} deg, roll {args.roll_deg} deg")
    return 0
