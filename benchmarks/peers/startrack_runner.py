"""Run startrack's star identifier on benchmark frames; runs in the project's own .venv.

Catalog: the navigation catalog of 000 (:func:`startrack.catalog.navigation.load_navigation_catalog`)
for V <= ``--mag``, the 16 deg field and the frames' epoch, other parameters at their defaults;
built once and cached in :func:`startrack.base.cache_dir.cache_dir`.  Identifier:
``StarIdentifier(catalog, camera, centroid_sigma_px=...)`` with the benchmark's pinhole camera and
its stated centroid noise, other options at their defaults.

Frames without a prior: ``solve(uv, flux)`` (lost-in-space).  Frames with a prior: an identifier
restricted to the prior-based strategies (tracking, then the predicted sub-catalog with its
redundant neighbours), no lost-in-space fall-back -- the counterpart of tetra3rs's strict hint --
called with ``Prior(q_IS=prior)``; ``--methods subcatalog`` restricts it to the predicted sub-catalog
alone (000 §4: recognition from the predicted boresight).  The identifier's construction (catalog
tables and compiled kernels loaded) is timed apart and written as ``setup_ms`` to
``<out>.meta.json``.  Exit status 3 when the identifier is not importable yet.
"""

import sys
import time

import numpy as np
from runner_io import common_arguments, read_frames, run_frames, timed, write_meta
from scipy.spatial.transform import Rotation

NOT_IMPORTABLE = 3


def main():
    parser = common_arguments(__doc__.splitlines()[0])
    parser.add_argument("--mag", type=float, required=True, help="catalog magnitude limit m_t [V mag]")
    parser.add_argument("--epoch", type=float, required=True, help="catalog epoch [Julian year]")
    parser.add_argument("--centroid-sigma-px", type=float, required=True, help="centroid noise per axis [px]")
    parser.add_argument("--methods", default="tracking,subcatalog", help="strategies for frames with a prior")
    args = parser.parse_args()
    try:
        from startrack.identify.identifier import StarIdentifier
        from startrack.identify.prior import Prior
    except ImportError as error:
        print(f"startrack identifier not importable: {error}", file=sys.stderr)
        return NOT_IMPORTABLE
    from startrack.camera.model import Camera
    from startrack.catalog.navigation import NavigationCatalogParams, load_navigation_catalog

    fov = np.radians(args.fov_deg)
    camera = Camera.from_fov(fov, args.width, args.height)
    catalog = load_navigation_catalog(NavigationCatalogParams(mag_limit=args.mag, fov=fov, epoch=args.epoch))
    frames = read_frames(args.frames)
    tracking = any("prior_q_IS" in frame for frame in frames)
    start = time.perf_counter()
    identifier = StarIdentifier(catalog, camera, centroid_sigma_px=args.centroid_sigma_px,
                                **({"methods": tuple(args.methods.split(","))} if tracking else {}))
    setup_ms = 1e3 * (time.perf_counter() - start)
    print(f"  startrack: identifier built in {setup_ms:.0f} ms (kernels loaded in {identifier.load_ms:.0f} ms)")
    write_meta(args.out, setup_ms=setup_ms, kernels_ms=identifier.load_ms)

    def solve(frame):
        centroids = np.array(frame["centroids"], dtype=float).reshape(-1, 3)
        prior = Prior(q_IS=np.array(frame["prior_q_IS"])) if "prior_q_IS" in frame else None
        result, ms = timed(identifier.solve, centroids[:, :2], centroids[:, 2], prior)
        if not result.ok:
            return result.status, None, [], ms, result.method or None
        R_IS = Rotation.from_quat(result.q_IS).as_matrix()
        return "ok", R_IS, result.matches.tolist(), ms, result.method

    run_frames(frames, solve, args.out, "startrack")
    return 0


if __name__ == "__main__":
    sys.exit(main())
