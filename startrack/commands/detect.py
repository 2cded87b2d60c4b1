"""``startrack detect IMAGE``: star centroids of a frame (PNG/TIFF/NPY).

Threshold V_th = b + a sigma_n (eq. 4 of 004, b and sigma_n estimated from
the frame unless given), 8-connected components and a centre-of-gravity
centroider; prints one line per star, brightest first, or JSON.  This is the
image front end of ``startrack solve IMAGE``.
"""

import json
import math
import time

from startrack.errors import InputError


def register(subparsers):
    parser = subparsers.add_parser(
        "detect",
        help="detect stars in an image and print their centroids",
        description="Detect and centroid star images (threshold, connected components, centre of gravity).",
    )
    parser.add_argument("image", help="frame: .png, .tif/.tiff or .npy")
    parser.add_argument("--a", type=float, default=5.0, help="threshold factor a of V_th = b + a sigma_n (5)")
    parser.add_argument("--background-dn", type=float, default=None, help="background level b [DN] (estimated)")
    parser.add_argument("--sigma-n-dn", type=float, default=None, help="background noise sigma_n [DN] (estimated)")
    parser.add_argument("--centroider", choices=("threshold", "grey", "square"), default="threshold",
                        help="thresholded (004), grey-level or square-weighted centre of gravity (threshold)")
    parser.add_argument("--min-pixels", type=int, default=1, help="smallest star image kept [px] (1)")
    parser.add_argument("--saturation-dn", type=float, default=4095.0,
                        help="grey level of a saturated pixel [DN] (4095: 12-bit full scale)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=run)


def run(args):
    from startrack.detection import detect
    from startrack.image_io import read_image

    for option, value in (("--a", args.a), ("--saturation-dn", args.saturation_dn)):
        if not math.isfinite(value) or value <= 0:
            raise InputError(f"option {option} = {value} must be a positive finite number")
    if args.min_pixels < 1:
        raise InputError(f"option --min-pixels = {args.min_pixels} must be >= 1")
    image = read_image(args.image)
    start = time.perf_counter()
    found = detect(image, background=args.background_dn, sigma_n=args.sigma_n_dn, a=args.a,
                   centroider=args.centroider, saturation_dn=args.saturation_dn, min_pixels=args.min_pixels)
    elapsed_ms = 1000.0 * (time.perf_counter() - start)
    if args.json:
        result = {"image": args.image, "height": image.shape[0], "width": image.shape[1],
                  "centroider": args.centroider, "detect_ms": elapsed_ms, **found.to_dict()}
        print(json.dumps(result))
        return 0
    print(f"{args.image}: {image.shape[1]} x {image.shape[0]} px, b = {found.background:.2f} DN, "
          f"sigma_n = {found.sigma_n:.2f} DN, V_th = {found.threshold:.2f} DN, {len(found)} stars, "
          f"{elapsed_ms:.1f} ms")
    print(f"{'#':>4} {'u_px':>10} {'v_px':>10} {'flux_dn':>10} {'peak_dn':>8} {'npix':>5} {'snr':>7}  flags")
    for i in range(len(found)):
        flags = ",".join(name for name, on in (("saturated", found.saturated[i]), ("edge", found.edge[i])) if on)
        print(f"{i:>4} {found.u[i]:>10.3f} {found.v[i]:>10.3f} {found.flux[i]:>10.1f} {found.peak[i]:>8.0f} "
              f"{found.npix[i]:>5d} {found.snr[i]:>7.1f}  {flags}")
    return 0
