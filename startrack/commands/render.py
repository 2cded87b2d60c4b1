"""``startrack render``: a synthetic star-sensor frame for a given attitude.

Stars of the Hipparcos-2 catalog (propagated to ``--epoch``) brighter than
``--mag-limit`` are rendered with the default :class:`~startrack.image.render.SensorModel`
(004's PSF radius and 12-bit ADC) for the boresight (RA, Dec) and roll of
:mod:`startrack.geometry.attitude_angles`, optionally smeared by a body rate; the
frame is written as a 16-bit PNG or a .npy array.
"""

import json
import math

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
        help="render a synthetic star image for a given attitude (16-bit PNG or .npy)",
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
    parser.add_argument("-o", "--output", required=True, help="output file: .png (16-bit), .fits or .npy")
    parser.set_defaults(func=run)


def run(args):
    from startrack.camera.model import Camera
    from startrack.catalog.hipparcos import load_star_catalog
    from startrack.geometry.attitude_angles import quaternion_from_radec_roll
    from startrack.image.files import write_image
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
    check_file(args.output, "-o", (".png", ".npy") + FITS_SUFFIXES)
    omega = _rate(args.rate_deg_s)

    camera = Camera.from_fov(args.fov_deg * DEG, args.width, args.height)
    sensor = SensorModel(exposure_s=args.exposure_ms / 1000.0)
    catalog = load_star_catalog(args.epoch)
    stars = catalog.brighter_than(args.mag_limit)
    q_IS = quaternion_from_radec_roll(args.ra_deg * DEG, args.dec_deg * DEG, args.roll_deg * DEG)
    rng = np.random.default_rng(np.random.SeedSequence(args.seed))
    frame = render_star_field(camera, sensor, q_IS, stars.vectors, stars.v_mag, rng, omega_S=omega)
    path = write_image(args.output, frame.image)
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
    }
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"wrote {path}: {args.width} x {args.height} px, {summary['stars_in_image']} stars "
              f"(V <= {args.mag_limit}) at RA {args.ra_deg} deg, Dec {args.dec_deg} deg, roll {args.roll_deg} deg")
    return 0
