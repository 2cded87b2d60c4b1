"""Run cedar-solve 0.5.1 (package ``tetra3``) on benchmark frames; runs inside benchmarks/.venv-cedar.

Database: ``Tetra3.generate_database`` over the hip_main.dat-style file that ``benchmarks/star_id.py``
writes from Hipparcos-2 (positions already at the frames' epoch, proper motions zero, so
``epoch_proper_motion=None``), single scale at the sensor's field, stars V <= ``--mag``; built once
and kept as ``cedar-<catalog hash>-fov<F>-v<M>.npz`` in ``--work``.

Solve: ``solve_from_centroids`` with the centroids brightest first as (y, x) from the top-left
image corner (cedar's pixel centres are at half-integers, so y = v + 0.5, x = u + 0.5), the
image size, ``fov_estimate`` and ``fov_max_error``, ``return_matches=True``; other options at
their defaults.  cedar-solve has no tracking mode: frames with a prior are refused by star_id.py.

Attitude: cedar returns RA, Dec of the boresight and Roll, the angle of its image axes about the
boresight; its camera axes (i boresight, j = -x, k = -y in our image axes) are
j = cos(roll) E + sin(roll) N, k = -sin(roll) E + cos(roll) N (E, N: local east, north), from
which R_IS = [-j, -k, i] (columns: sensor x, y, z in ICRS).
"""

import hashlib
import logging
import sys
import time
from pathlib import Path

import numpy as np

from runner_io import common_arguments, nearest_indices, read_frames, run_frames, timed, write_meta


def cedar_axes_to_R_IS(ra_deg, dec_deg, roll_deg):
    """R_IS (3, 3) from cedar's boresight RA, Dec and Roll [deg] (see the module docstring)."""
    ra, dec, roll = np.radians([ra_deg, dec_deg, roll_deg])
    boresight = np.array([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])
    east = np.array([-np.sin(ra), np.cos(ra), 0.0])
    north = np.array([-np.sin(dec) * np.cos(ra), -np.sin(dec) * np.sin(ra), np.cos(dec)])
    j = np.cos(roll) * east + np.sin(roll) * north
    k = -np.sin(roll) * east + np.cos(roll) * north
    return np.column_stack([-j, -k, boresight])


def load_or_build_database(tetra3_module, catalog, work, fov_deg, mag):
    """A Tetra3 instance with the database of ``catalog`` (built and saved on first use)."""
    digest = hashlib.sha256(Path(catalog).read_bytes()).hexdigest()[:12]
    path = Path(work) / f"cedar-{digest}-fov{fov_deg:g}-v{mag:g}.npz"
    if not path.is_file():
        print(f"  cedar-solve: building the database {path.name} (once)", flush=True)
        builder = tetra3_module.Tetra3(load_database=None)
        builder.generate_database(max_fov=fov_deg, star_catalog=str(catalog), star_max_magnitude=mag,
                                  epoch_proper_motion=None, save_as=path.with_suffix(""))
    return tetra3_module.Tetra3(load_database=path)


def main():
    parser = common_arguments(__doc__.splitlines()[0])
    parser.add_argument("--catalog", required=True, help="hip_main.dat-style star file")
    parser.add_argument("--mag", type=float, required=True, help="faintest V [mag] in the database")
    args = parser.parse_args()
    import tetra3
    from tetra3 import tetra3 as cedar

    logging.getLogger("tetra3").setLevel(logging.WARNING)
    start = time.perf_counter()
    solver = load_or_build_database(tetra3, args.catalog, args.work, args.fov_deg, args.mag)
    write_meta(args.out, setup_ms=1e3 * (time.perf_counter() - start))
    logging.getLogger("tetra3.Tetra3").setLevel(logging.WARNING)
    for handler in logging.getLogger("tetra3.Tetra3").handlers:
        handler.setLevel(logging.WARNING)
    size = (args.height, args.width)

    def solve(frame):
        if "prior_q_IS" in frame:
            raise ValueError("cedar-solve has no tracking mode")
        uv = np.array(frame["centroids"], dtype=float).reshape(-1, 3)[:, :2]
        yx = uv[:, ::-1] + 0.5
        result, ms = timed(solver.solve_from_centroids, yx, size, fov_estimate=args.fov_deg,
                           fov_max_error=args.fov_max_error_deg, return_matches=True)
        status = {cedar.MATCH_FOUND: "ok", cedar.NO_MATCH: "no_match", cedar.TIMEOUT: "timeout",
                  cedar.TOO_FEW: "too_few"}.get(result["status"], "error")
        if status != "ok":
            return status, None, [], ms, None
        R_IS = cedar_axes_to_R_IS(result["RA"], result["Dec"], result["Roll"])
        index = nearest_indices(yx, result["matched_centroids"])
        return status, R_IS, list(zip(index.tolist(), result["matched_catID"])), ms, "lost_in_space"

    run_frames(read_frames(args.frames), solve, args.out, "cedar-solve")
    return 0


if __name__ == "__main__":
    sys.exit(main())
