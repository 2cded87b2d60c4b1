"""Run cedar-solve 0.5.1 (package ``tetra3``) on frames without a field of view; runs inside benchmarks/.venv-cedar.

Database: ``--database`` (a cedar-solve .npz; ``default`` is the one the package ships, 10-30 deg, V <= 8).
Solve: ``solve_from_centroids`` with the frame's centroids brightest first as (y, x) from the top-left
image corner (cedar's pixel centres are at half-integers: y = v + 0.5, x = u + 0.5), the image size,
no ``fov_estimate``, ``distortion`` from ``--distortion`` (a number, or ``LO,HI`` for cedar's distortion
search), ``solve_timeout`` from ``--timeout-ms``, ``return_matches=True``.

Output, one JSON per frame: ``id``, ``status``, ``R_IC`` (3x3, rows: the image axes x, y and the centre
direction's frame as columns of R, from cedar's RA, Dec, Roll of the image centre, :func:`cedar_runner.cedar_axes_to_R_IS`),
``fov_deg`` (cedar's field of view), ``matches`` [[centroid index, HIP], ...] and ``solve_ms`` (wall time
of the solver call alone).
"""

import argparse
import json
import logging
import sys
import time

import numpy as np

from cedar_runner import cedar_axes_to_R_IS
from runner_io import nearest_indices, read_frames, timed, write_meta


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", required=True, help="frames, JSON Lines")
    parser.add_argument("--out", required=True, help="results, JSON Lines")
    parser.add_argument("--database", default="default", help="cedar-solve database .npz, or 'default'")
    parser.add_argument("--distortion", default="0", help="a distortion, or LO,HI to search (cedar's convention)")
    parser.add_argument("--timeout-ms", type=float, default=5000.0, help="cedar's solve_timeout [ms]")
    args = parser.parse_args()
    import tetra3
    from tetra3 import tetra3 as cedar

    logging.disable(logging.INFO)
    start = time.perf_counter()
    solver = tetra3.Tetra3() if args.database == "default" else tetra3.Tetra3(load_database=args.database)
    properties = solver.database_properties
    write_meta(args.out, setup_ms=1e3 * (time.perf_counter() - start),
               database={key: float(properties[key]) for key in ("min_fov", "max_fov", "star_max_magnitude")})
    parts = [float(x) for x in args.distortion.split(",")]
    distortion = parts[0] if len(parts) == 1 else tuple(parts)
    frames = read_frames(args.frames)
    statuses = {cedar.MATCH_FOUND: "ok", cedar.NO_MATCH: "no_match", cedar.TIMEOUT: "timeout", cedar.TOO_FEW: "too_few"}
    with open(args.out, "w") as out:
        for n, frame in enumerate(frames):
            uv = np.array([c[:2] for c in frame["centroids"]], dtype=float).reshape(-1, 2)
            yx = uv[:, ::-1] + 0.5
            size = (frame["height"], frame["width"])
            try:
                if n == 0:  # warm-up: lazy initialisation is not a solve
                    solver.solve_from_centroids(yx, size, distortion=distortion, solve_timeout=args.timeout_ms)
                result, ms = timed(solver.solve_from_centroids, yx, size, distortion=distortion,
                                   solve_timeout=args.timeout_ms, return_matches=True)
            except Exception as error:  # a peer's failure is a measured outcome, not a harness crash
                out.write(json.dumps({"id": frame["id"], "status": "error", "solve_ms": None,
                                      "reason": f"{type(error).__name__}: {error}"}) + "\n")
                continue
            record = {"id": frame["id"], "status": statuses.get(result["status"], "error"), "solve_ms": ms}
            if record["status"] == "ok":
                index = nearest_indices(yx, result["matched_centroids"])
                record.update(R_IC=cedar_axes_to_R_IS(result["RA"], result["Dec"], result["Roll"]).tolist(),
                              fov_deg=float(result["FOV"]),
                              matches=[[int(i), int(h)] for i, h in zip(index, result["matched_catID"])])
            out.write(json.dumps(record) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
