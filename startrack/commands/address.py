"""``startrack address``: sub-catalog address (l_d, l_ra) of a boresight (eq. 7-8 of 000) and its 4 neighbours.

The redundant neighbours (§4) are the sub-catalogs of the boresights moved by
rho_sub (eq. 6) east, west, north and south; rho_sub depends on n_d (through
s_max), ``--fov-deg`` and ``--max-delta-deg``. No star catalog is needed.
"""

from __future__ import annotations

import json

import numpy as np

from startrack.base.errors import check_range
from startrack.base.units import DEG
from startrack.commands.catalog import check_option


def register(subparsers):
    parser = subparsers.add_parser(
        "address",
        help="sub-catalog address (l_d, l_ra) of a boresight, eq. 7-8 of 000, with its 4 redundant neighbours",
        description="Sub-catalog address index of document 000 (eq. 7-8) and the four redundant "
        "neighbouring sub-catalogs of §4.",
    )
    parser.add_argument("--ra-deg", type=float, required=True, help="boresight right ascension [deg]")
    parser.add_argument("--dec-deg", type=float, required=True, help="boresight declination [deg], -90 .. 90")
    parser.add_argument("--nd", type=int, default=53, help="declination divisions n_d of eq. 1 (53)")
    parser.add_argument("--fov-deg", type=float, default=16.0, help="circular field of view diameter [deg] (16)")
    parser.add_argument("--max-delta-deg", type=float, default=2.0, help="largest boresight error max(delta) [deg]")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=run)


def _address_report(ra_deg: float, dec_deg: float, n_d: int, fov_deg: float, max_delta_deg: float) -> dict:
    """The address of boresight (ra_deg, dec_deg) and its redundant neighbours, as a JSON-ready dict."""
    from startrack.catalog import address as addr
    from startrack.catalog.navigation import base_points, max_base_spacing, sub_catalog_radius

    ra, dec = ra_deg * DEG, dec_deg * DEG
    base_ra, base_dec, base_vectors = base_points(n_d)
    rho_sub = sub_catalog_radius(max_base_spacing(base_vectors), max_delta_deg * DEG, fov_deg * DEG)
    l_d, l_ra = addr.address(ra, dec, n_d)
    index = int(addr.base_index(l_d, l_ra, n_d))
    moved_ra, moved_dec = addr.offset_directions(ra, dec, rho_sub)
    n_l_d, n_l_ra = addr.address(moved_ra, moved_dec, n_d)
    neighbours = []
    for k, direction in enumerate(addr.NEIGHBOUR_DIRECTIONS):
        neighbours.append(
            {
                "direction": direction,
                "ra_deg": float(np.degrees(moved_ra[k])),
                "dec_deg": float(np.degrees(moved_dec[k])),
                "l_d": int(n_l_d[k]),
                "l_ra": int(n_l_ra[k]),
                "index": int(addr.base_index(n_l_d[k], n_l_ra[k], n_d)),
            }
        )
    return {
        "ra_deg": float(np.degrees(np.mod(ra, 2.0 * np.pi))),
        "dec_deg": dec_deg,
        "n_d": n_d,
        "l_d": int(l_d),
        "l_ra": int(l_ra),
        "index": index,
        "base_ra_deg": float(np.degrees(base_ra[index])),
        "base_dec_deg": float(np.degrees(base_dec[index])),
        "base_points": int(base_ra.size),
        "rho_sub_deg": float(np.degrees(rho_sub)),
        "neighbours": neighbours,
    }


def run(args) -> int:
    check_range("--ra-deg", args.ra_deg, -360.0, 720.0)
    check_range("--dec-deg", args.dec_deg, -90.0, 90.0)
    check_option("--nd", args.nd)
    check_option("--fov-deg", args.fov_deg)
    check_option("--max-delta-deg", args.max_delta_deg)
    report = _address_report(args.ra_deg, args.dec_deg, args.nd, args.fov_deg, args.max_delta_deg)
    if args.json:
        print(json.dumps(report))
        return 0
    print(
        f"boresight ({report['ra_deg']:.4f}, {report['dec_deg']:.4f}) deg, n_d = {report['n_d']} "
        f"({report['base_points']} base points), rho_sub = {report['rho_sub_deg']:.3f} deg"
    )
    print(f"{'sub-catalog':<12}{'RA [deg]':>11}{'Dec [deg]':>11}{'l_d':>6}{'l_ra':>6}{'index':>7}")
    print(
        f"{'predicted':<12}{report['base_ra_deg']:>11.3f}{report['base_dec_deg']:>11.3f}"
        f"{report['l_d']:>6}{report['l_ra']:>6}{report['index']:>7}   (base point)"
    )
    for n in report["neighbours"]:
        print(
            f"{n['direction']:<12}{n['ra_deg']:>11.3f}{n['dec_deg']:>11.3f}{n['l_d']:>6}{n['l_ra']:>6}"
            f"{n['index']:>7}   (moved boresight)"
        )
    return 0
