"""``startrack catalog``: build (or load from cache) the navigation catalog and print its statistics.

``--json`` prints one JSON object (docs/design.md contract); without it a readable
table, including a memory table like Table 1 of document 000. ``--plot DIR``
writes ``DIR/catalog_homogenisation.png`` (Fig. 3 of 000: candidates and guide
stars per 6 x 6 deg RA/Dec window) and ``DIR/catalog_subcatalogs.png``
(Fig. 4: base points, one sub-catalog and its four redundant neighbours).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from startrack.base.errors import InputError, check_range
from startrack.base.output_paths import check_directory
from startrack.base.units import ARCSEC, DEG

#: Option -> (low, high) accepted range, in the option's unit.
_RANGES = {
    "--mag": (-2.0, 14.0),
    "--fov-deg": (0.1, 90.0),
    "--nd": (3, 400),
    "--sigma-arcsec": (0.0, 3600.0),
    "--max-delta-deg": (0.0, 30.0),
    "--theta-min-deg": (0.0, 45.0),
    "--epoch": (1000.0, 3000.0),
    "--plot-ra-deg": (-360.0, 720.0),
    "--plot-dec-deg": (-90.0, 90.0),
}


def check_option(option: str, value):
    """``value`` of ``option`` if it is finite and inside the option's range in ``_RANGES``."""
    return check_range(option, value, *_RANGES[option])


def register(subparsers):
    parser = subparsers.add_parser(
        "catalog",
        help="build or load the navigation catalog (000 §2) and print its statistics",
        description="Navigation catalog of document 000 §2 from Hipparcos-2: candidates, uniform guide "
        "stars, k-vector pattern pairs, sub-catalogs and their address index.",
    )
    parser.add_argument("--mag", type=float, default=6.0, help="visual magnitude threshold m_t [mag] (6.0)")
    parser.add_argument("--fov-deg", type=float, default=16.0, help="circular field of view diameter [deg] (16)")
    parser.add_argument("--nd", type=int, default=53, help="declination divisions n_d of eq. 1 (53)")
    parser.add_argument("--sigma-arcsec", type=float, default=100.0, help="largest measurement error [arcsec] (100)")
    parser.add_argument("--max-delta-deg", type=float, default=2.0, help="largest boresight error max(delta) [deg] (2)")
    parser.add_argument("--theta-min-deg", type=float, default=0.1, help="smallest pair distance kept [deg] (0.1)")
    parser.add_argument("--epoch", type=float, default=2000.0, help="epoch of the star positions [Julian year]")
    parser.add_argument("--keep-multiple", action="store_true", help="do not exclude multiple stars")
    parser.add_argument("--keep-variable", action="store_true", help="do not exclude variable stars")
    parser.add_argument("--rebuild", action="store_true", help="build again even if a cached catalog exists")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plot", metavar="DIR", help="write the Fig. 3 / Fig. 4-like figures into DIR")
    parser.add_argument("--plot-ra-deg", type=float, default=62.27, help="boresight RA of the Fig. 4 map [deg]")
    parser.add_argument("--plot-dec-deg", type=float, default=38.67, help="boresight Dec of the Fig. 4 map [deg]")
    parser.set_defaults(func=run)


def _params_from_args(args):
    """NavigationCatalogParams from the parsed options (validated, degrees -> radians)."""
    from startrack.catalog.navigation import NavigationCatalogParams

    for option, value in (
        ("--mag", args.mag), ("--fov-deg", args.fov_deg), ("--nd", args.nd),
        ("--sigma-arcsec", args.sigma_arcsec), ("--max-delta-deg", args.max_delta_deg),
        ("--theta-min-deg", args.theta_min_deg), ("--epoch", args.epoch),
    ):  # fmt: skip
        check_option(option, value)
    if args.theta_min_deg > 0.5 * args.fov_deg:
        raise InputError(f"option --theta-min-deg = {args.theta_min_deg} exceeds half of --fov-deg = {args.fov_deg}.")
    return NavigationCatalogParams(
        mag_limit=args.mag,
        fov=args.fov_deg * DEG,
        n_d=args.nd,
        sigma=args.sigma_arcsec * ARCSEC,
        max_delta=args.max_delta_deg * DEG,
        theta_min=args.theta_min_deg * DEG,
        epoch=args.epoch,
        exclude_multiple=not args.keep_multiple,
        exclude_variable=not args.keep_variable,
    )


def run(args) -> int:
    from startrack.catalog.navigation import load_navigation_catalog

    params = _params_from_args(args)
    check_option("--plot-ra-deg", args.plot_ra_deg)
    check_option("--plot-dec-deg", args.plot_dec_deg)
    plot_dir = None if args.plot is None else check_directory(args.plot, "--plot")
    catalog = load_navigation_catalog(params, rebuild=args.rebuild, progress=True)
    stats = catalog.statistics()
    if plot_dir is not None:
        stats["figures"] = [
            str(p) for p in _write_catalog_figures(catalog, plot_dir, args.plot_ra_deg * DEG, args.plot_dec_deg * DEG)
        ]
    if args.json:
        print(json.dumps(stats))
    else:
        print(_format_statistics(stats, catalog.memory_table()))
    return 0


def _format_statistics(stats: dict, memory_table: list[dict]) -> str:
    """Readable text of :meth:`NavigationCatalog.statistics` with 000's numbers beside ours."""
    ref = stats["reference_000"]
    sub_s, sub_p = stats["subcatalog_stars"], stats["subcatalog_pairs"]
    ref_s, ref_p = ref["subcatalog_stars"], ref["subcatalog_pairs"]
    lines = [
        f"Navigation catalog (Hipparcos-2, epoch J{stats['epoch']:g}): m_t = {stats['mag_limit']:g} mag, "
        f"FOV {stats['fov_deg']:g} deg, n_d = {stats['n_d']}, sigma = {stats['sigma_arcsec']:g} arcsec, "
        f"max(delta) = {stats['max_delta_deg']:g} deg",
        "",
        f"{'quantity':<34}{'this catalog':>16}{'000 (SKYMAP 2000)':>20}",
        f"{'Hipparcos-2 stars':<34}{stats['hipparcos_stars']:>16}{'':>20}",
        *(f"{'  excluded: ' + rule:<34}{count:>16}" for rule, count in stats["excluded"].items()),
        f"{'candidates':<34}{stats['candidates']:>16}{ref['candidates']:>20}",
        f"{'base points':<34}{stats['base_points']:>16}{ref['base_points']:>20}",
        f"{'s_max [deg]':<34}{stats['s_max_deg']:>16.3f}{'ceil = ' + str(ref['s_max_ceil_deg']):>20}",
        f"{'guide stars':<34}{stats['guide_stars']:>16}{ref['guide_stars']:>20}",
        f"{'theta range [deg]':<34}{stats['theta_min_deg']:>7.3f} .. {stats['theta_max_deg']:<6.3f}",
        f"{'pattern pairs':<34}{stats['pairs']:>16}{ref['pairs']:>20}",
        f"{'rho_sub [deg]':<34}{stats['rho_sub_deg']:>16.3f}",
        f"{'stars per sub-catalog min/max/mean':<34}{_triple(sub_s):>16}{_triple(ref_s):>20}",
        f"{'pairs per sub-catalog min/max/mean':<34}{_triple(sub_p):>16}{_triple(ref_p):>20}",
        "",
        f"{'memory (Table 1)':<42}{'entries':>36}{'bytes':>12}",
    ]
    for row in memory_table:
        lines.append(f"{row['layer']:<42}{row['entries']:>36}{row['bytes']:>12}")
    lines.append(f"{'total':<42}{'':>36}{stats['memory_bytes']['total']:>12}")
    lines.append("")
    source = "loaded from cache" if stats["from_cache"] else "built"
    lines.append(f"{source}; build took {stats['build_seconds']:.3f} s")
    for figure in stats.get("figures", []):
        lines.append(f"figure: {figure}")
    return "\n".join(lines)


def _triple(values: dict) -> str:
    mean = values.get("mean")
    return f"{values['min']}/{values['max']}/" + ("-" if mean is None else f"{mean:g}")


def _window_counts(ra, dec, window_deg: float = 6.0) -> np.ndarray:
    """Star counts in window_deg x window_deg RA/Dec windows (Dec rows from -90, RA columns from 0)."""
    ra_edges = np.linspace(0.0, 360.0, int(round(360.0 / window_deg)) + 1)
    dec_edges = np.linspace(-90.0, 90.0, int(round(180.0 / window_deg)) + 1)
    counts, _, _ = np.histogram2d(np.degrees(dec), np.degrees(ra), bins=(dec_edges, ra_edges))
    return counts


def _write_catalog_figures(catalog, directory, ra, dec) -> list[Path]:
    """Write the Fig. 3- and Fig. 4-like PNG figures into ``directory``; boresight (ra, dec) [rad] for Fig. 4."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from startrack.catalog.address import NEIGHBOUR_DIRECTIONS
    from startrack.catalog.hipparcos import load_star_catalog
    from startrack.catalog.navigation import candidate_mask

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    stars = load_star_catalog(catalog.params.epoch)
    keep, _ = candidate_mask(stars, catalog.params)

    # Fig. 3: homogenisation, counts per 6 x 6 deg window.
    candidate_counts = _window_counts(stars.ra[keep], stars.dec[keep])
    guide_counts = _window_counts(catalog.guide_ra, catalog.guide_dec)
    vmax = max(candidate_counts.max(), guide_counts.max())
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.8), gridspec_kw={"width_ratios": [1, 1, 0.7]})
    for ax, counts, title in (
        (axes[0], candidate_counts, f"candidates ({int(keep.sum())})"),
        (axes[1], guide_counts, f"guide stars ({catalog.n_guide})"),
    ):
        image = ax.imshow(counts, origin="lower", extent=(0, 360, -90, 90), aspect="auto", vmin=0, vmax=vmax,
                          cmap="viridis")  # fmt: skip
        ax.set_title(f"{title} per 6 x 6 deg window")
        ax.set_xlabel("right ascension [deg]")
        ax.set_ylabel("declination [deg]")
        fig.colorbar(image, ax=ax, label="stars per window")
    bins = np.arange(0, vmax + 2) - 0.5
    axes[2].hist(candidate_counts.ravel(), bins=bins, alpha=0.6, label="candidates")
    axes[2].hist(guide_counts.ravel(), bins=bins, alpha=0.6, label="guide stars")
    axes[2].set_xlabel("stars per window")
    axes[2].set_ylabel("windows")
    axes[2].set_title("distribution of window counts")
    axes[2].legend()
    fig.suptitle(f"Uniform guide-star selection (m_t = {catalog.params.mag_limit:g}, n_d = {catalog.params.n_d})")
    fig.tight_layout()
    homogenisation = directory / "catalog_homogenisation.png"
    fig.savefig(homogenisation, dpi=110)
    plt.close(fig)

    # Fig. 4: base points, the addressed sub-catalog and its four redundant neighbours, in the
    # gnomonic (tangent-plane) projection about the boresight, so that it reads the same at the poles.
    centre = int(catalog.sub_catalog_index(ra, dec))
    neighbours = np.atleast_1d(catalog.redundant_neighbours(ra, dec)).ravel()
    project = _gnomonic(ra, dec)
    fig, ax = plt.subplots(figsize=(9, 8.5))
    span = np.degrees(2.3 * catalog.rho_sub)
    ax.scatter(*project(catalog.base_vectors), s=6, c="0.6", label="base points")
    ax.scatter(*project(catalog.guide_vectors), s=4, c="0.2", marker=".", label="guide stars")
    colours = ("tab:orange", "tab:green", "tab:purple", "tab:brown")
    for b, colour, name in zip(neighbours, colours, NEIGHBOUR_DIRECTIONS):
        members = catalog.sub_catalog_stars(b)
        ax.scatter(*project(catalog.guide_vectors[members]), s=30, facecolors="none", edgecolors=colour,
                   label=f"{name} redundant sub-catalog {b}")  # fmt: skip
        ax.plot(*project(_small_circle(catalog.base_vectors[b], catalog.rho_sub)), "--", color=colour, lw=1.2)
    members = catalog.sub_catalog_stars(centre)
    ax.scatter(*project(catalog.guide_vectors[members]), s=18, c="tab:red",
               label=f"predicted sub-catalog {centre} ({members.size} stars)")  # fmt: skip
    ax.plot(*project(_small_circle(catalog.base_vectors[centre], catalog.rho_sub)), "-", color="tab:red", lw=1.5)
    ax.plot(*project(_small_circle(_unit(ra, dec), catalog.params.fov / 2)), ":", color="k", lw=1.0,
            label="field of view")  # fmt: skip
    ax.plot([0.0], [0.0], "k+", ms=14, mew=2, label="boresight")
    ax.set_xlim(span, -span)  # east to the left, as on the sky
    ax.set_ylim(-span, span)
    ax.set_aspect("equal")
    ax.set_xlabel("east of boresight [deg] (tangent plane)")
    ax.set_ylabel("north of boresight [deg]")
    ax.set_title(f"Sub-catalogs (rho_sub = {np.degrees(catalog.rho_sub):.1f} deg) around boresight "
                 f"RA {np.degrees(ra):.2f}, Dec {np.degrees(dec):.2f} deg")  # fmt: skip
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    subcatalogs = directory / "catalog_subcatalogs.png"
    fig.savefig(subcatalogs, dpi=110)
    plt.close(fig)
    return [homogenisation, subcatalogs]


def _unit(ra, dec):
    return np.array([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])


def _gnomonic(ra, dec):
    """Projection vectors (N, 3) -> angles east and north [deg] on the tangent plane at (ra, dec).

    Points more than 80 deg from the centre are dropped (NaN).
    """
    centre = _unit(ra, dec)
    east = np.array([-np.sin(ra), np.cos(ra), 0.0])
    north = np.cross(centre, east)

    def project(vectors):
        vectors = np.atleast_2d(vectors)
        depth = vectors @ centre
        depth = np.where(depth > np.cos(np.radians(80.0)), depth, np.nan)
        return np.degrees(np.arctan(vectors @ east / depth)), np.degrees(np.arctan(vectors @ north / depth))

    return project


def _small_circle(centre, radius):
    """Unit vectors (361, 3) on the small circle of angular ``radius`` [rad] around unit vector ``centre``."""
    helper = np.array([0.0, 0.0, 1.0]) if abs(centre[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(centre, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(centre, e1)
    t = np.linspace(0.0, 2.0 * np.pi, 361)[:, None]
    return np.cos(radius) * centre + np.sin(radius) * (np.cos(t) * e1 + np.sin(t) * e2)
