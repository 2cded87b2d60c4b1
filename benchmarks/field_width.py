"""Any field width (issue 32, item 3): rendered wide fisheye frames (60-120 deg) and narrow frames (2-5 deg)
solved blind by the plate solver.

Wide set: ``--frames`` frames per lens, 1024 x 768 and 1600 x 1067 px, field across the width uniform in
60-120 deg, the fisheye lenses of the equidistant model with radial terms (equidistant k = 0, equisolid
k1 = -1/24, k2 = 1/1920; stereographic k1 = 1/12, k2 = 1/120; each k1 jittered by +-0.02), rendered from the
Hipparcos-2 stars to V 8.5 (``startrack.image.synthetic.rendered_sky``), detected as ``startrack solve`` does and
solved with the default search (no field of view given).  Narrow set: pinhole frames of 2-5 deg (|k1| <=
0.1), 1024 x 768 px, rendered from the Gaia DR3 sky to G 10 (``startrack.catalog.gaia``: the stars a real
narrow frame shows, not only Hipparcos's) in a 2 s exposure (a telephoto lens or small telescope: the
default sensor's 0.1 s sees to V ~ 8, this one to V ~ 10.5) and solved with the default search too.

Outcome per frame: solved (the image centre within max(0.1 deg, 3 px) of the truth), imprecise (within 1 deg),
wrong (an answer more than 1 deg off) or failed (no answer); the solve's wall time.  The solver's clock is the
real one: run on a quiet machine.  Writes ``benchmarks/results/field_width.json``; asserts nothing.

    .venv/bin/python benchmarks/field_width.py [--frames 20] [--seed 1] [--only wide|narrow]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

LENSES = {"equidistant": (0.0, 0.0), "equisolid": (-1.0 / 24.0, 1.0 / 1920.0), "stereographic": (1.0 / 12.0, 1.0 / 120.0)}
SIZES = ((1024, 768), (1600, 1067))
#: Exposure [s] of the narrow frames (module text).
NARROW_EXPOSURE_S = 2.0


def _centre_error(result, camera, q_IS):
    """Angle [rad] between the solved and the true direction of the image centre."""
    centre = [[(camera.width - 1) / 2.0, (camera.height - 1) / 2.0]]
    from startrack.geometry.rotation import to_matrix

    truth = to_matrix(q_IS) @ camera.unproject(centre)[0]
    solved = to_matrix(result.q_IS) @ result.camera.unproject(centre)[0]
    return math.acos(min(1.0, float(truth @ solved)))


def _solve(solver, sky, fov_hint=None):
    from startrack.image.detection import detect

    found = detect(sky.image, mesh_px=64, saturation_dn=sky.full_scale, reject_single_pixels=True, reject_extended=True)
    sigma = np.hypot(found.sigma_u, found.sigma_v) / math.sqrt(2.0)
    start = time.perf_counter()
    result = solver.solve(found.uv, sky.camera.width, sky.camera.height, found.flux, sigma)
    return result, time.perf_counter() - start, len(found.uv)


def _outcome(result, camera, q_IS):
    if not result.ok:
        return "failed", None
    error = _centre_error(result, camera, q_IS)
    precise = max(0.1 * math.pi / 180.0, 3.0 * camera.fov_x / camera.width)
    return ("solved" if error <= precise else "imprecise" if error <= math.pi / 180.0 else "wrong"), error


def _frames_wide(rng, n):
    from startrack.base.units import DEG
    from startrack.camera.model import Camera

    for lens, (k1, k2) in LENSES.items():
        for _ in range(n):
            width, height = SIZES[int(rng.integers(len(SIZES)))]
            fov = float(rng.uniform(60.0, 120.0))
            focal = Camera.from_fov(fov * DEG, width, height, projection="fisheye").focal_px
            yield lens, fov, Camera(width, height, focal, k1=k1 + float(rng.uniform(-0.02, 0.02)), k2=k2, projection="fisheye")


def _frames_narrow(rng, n):
    from startrack.base.units import DEG
    from startrack.camera.model import Camera

    for _ in range(n):
        fov = float(rng.uniform(2.0, 5.0))
        yield "pinhole", fov, Camera.from_fov(fov * DEG, 1024, 768, k1=float(rng.uniform(-0.1, 0.1)))


def run_set(name, frames, stars, solver, rng, sensor=None):
    from startrack.image.synthetic import rendered_sky

    rows = []
    for lens, fov, camera in frames:
        sky = rendered_sky(camera, stars, rng, sensor)
        result, seconds, detections = _solve(solver, sky)
        outcome, error = _outcome(result, camera, sky.q_IS)
        rows.append({"set": name, "lens": lens, "fov_deg": fov, "size": [camera.width, camera.height], "k1": camera.k1,
                     "detections": detections, "outcome": outcome, "seconds": seconds,
                     "centre_error_arcsec": None if error is None else math.degrees(error) * 3600.0,
                     "projection": result.camera.projection if result.ok else None,
                     "reason": None if result.ok else result.reason})
        print(f"{name:6s} {lens:13s} {fov:6.1f} deg {camera.width}x{camera.height}: {outcome:9s} {seconds * 1e3:7.0f} ms"
              + ("" if error is None else f"  centre {math.degrees(error) * 3600.0:7.1f}\"  {result.camera.projection}"),
              flush=True)
    return rows


def summary(rows):
    out = {}
    for name in sorted({row["set"] for row in rows}):
        chosen = [row for row in rows if row["set"] == name]
        counts = {key: sum(row["outcome"] == key for row in chosen) for key in ("solved", "imprecise", "wrong", "failed")}
        seconds = np.array([row["seconds"] for row in chosen])
        out[name] = {"frames": len(chosen), **counts, "success": counts["solved"] / len(chosen),
                     "median_ms": float(np.median(seconds) * 1e3), "max_ms": float(seconds.max() * 1e3)}
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20, help="frames per lens (wide) and in the narrow set")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--only", choices=("wide", "narrow"))
    args = parser.parse_args()
    from startrack.catalog.hipparcos import load_star_catalog
    from startrack.identify.plate_solver import PlateSolver

    wide_rng, narrow_rng = (np.random.default_rng(s) for s in np.random.SeedSequence(args.seed).spawn(2))
    rows, solver = [], PlateSolver(progress=True)  # the default search, 2-160 deg
    if args.only in (None, "wide"):
        rows += run_set("wide", _frames_wide(wide_rng, args.frames), load_star_catalog(2000.0).brighter_than(8.5),
                        solver, wide_rng)
    if args.only in (None, "narrow"):
        from startrack.catalog.gaia import load_gaia_catalog
        from startrack.image.render import SensorModel

        rows += run_set("narrow", _frames_narrow(narrow_rng, args.frames), load_gaia_catalog(2000.0),
                        solver, narrow_rng,
                        SensorModel(exposure_s=NARROW_EXPOSURE_S))
    result = {"frames_per_set": args.frames, "seed": args.seed, "summary": summary(rows), "rows": rows}
    print(json.dumps(result["summary"], indent=1))
    path = Path(__file__).resolve().parent / "results" / "field_width.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
