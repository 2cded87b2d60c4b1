"""``startrack solve`` on frames of a calibrated camera: the camera given (--fov-deg, --camera) beside the
identification layer called directly and beside the camera refitted per frame (the plate solver, as the
command line did before issue 24).

Frames (``tests/pinhole_frames.py``, made without the project's camera or identification code): an ideal
pinhole, V <= 6 at J2000.0, 0-3 false stars; 500 frames of 16 deg / 1024 px with 0.1 px centroid noise
and 300 of 12 deg / 512 px with 0.05 px.  Each command-line mode runs once per set as one
``startrack solve --batch FRAMES.jsonl --json`` process; the identification layer
(:class:`startrack.identify.calibrated.CalibratedSolver`, the identifier of ``benchmarks/star_id.py``
with the stated centroid sigma) runs in this process on the same frames.

Metrics per mode and set: identified (status ok, every HIP right), false (ok, some HIP wrong), the
answers beyond 6 sigma of the bound (Mahalanobis distance of the error), the attitude error of the camera's frame S (dtheta = rotvec(R_est^T R_true)) across (|(x, y)|) and about
(|z|) the boresight, median and p95 [arcsec], RMS / CRB across and about (CRB: the pixel-noise Fisher
information of the stars matched), the median reported sigma across [arcsec], the median solve time
[ms] (the solver's own ``solve_ms``) and the wall time of the process.  Measures, never asserts.

Run:  python benchmarks/solve_given_camera.py [--frames16 500] [--frames12 300] [--seed 24]
Writes benchmarks/results/solve_given_camera.json; frames go under benchmarks/work/solve_given_camera/.
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from startrack.base.units import ARCSEC  # noqa: E402
from startrack.catalog.hipparcos import load_star_catalog  # noqa: E402
from tests.pinhole_frames import Pinhole, attitude_error, make_frame, pixel_crb  # noqa: E402


def frame_sets(args, stars):
    """name -> (camera, centroid sigma [px], frames)."""
    specs = {"16deg_1024px": (Pinhole(16.0, 1024, 1024), 0.1, args.frames16, 0),
             "12deg_512px": (Pinhole(12.0, 512, 512), 0.05, args.frames12, 1)}
    out = {}
    for name, (camera, sigma, n, index) in specs.items():
        rng = np.random.default_rng([args.seed, index])
        out[name] = (camera, sigma, [make_frame(camera, stars, rng, sigma, max_false=3) for _ in range(n)])
    return out


def write_inputs(folder, camera, frames):
    folder.mkdir(parents=True, exist_ok=True)
    batch, camera_file = folder / "frames.jsonl", folder / "camera.toml"
    batch.write_text("".join(json.dumps({"id": k, "centroids": np.column_stack([f.uv, f.flux]).tolist()}) + "\n"
                             for k, f in enumerate(frames)))
    camera_file.write_text(f"[camera]\nwidth_px = {camera.width}\nheight_px = {camera.height}\n"
                           f"focal_px = {float(camera.focal_px)!r}\n")
    return batch, camera_file


def cli_modes(camera, sigma, camera_file):
    size = ["--width", str(camera.width), "--height", str(camera.height)]
    return {
        "cli --fov-deg (given)": ["--fov-deg", str(camera.fov_deg), *size],
        "cli --camera (given)": ["--camera", str(camera_file)],
        "cli --camera --refit focal,centre,k1 (the pre-issue-24 --camera)": ["--camera", str(camera_file), "--refit",
                                                                              "focal,centre,k1"],
        "cli --fov-hint-deg (unknown camera; the pre-issue-24 --fov-deg)": ["--fov-hint-deg", str(camera.fov_deg), *size],
    }


def run_cli(batch, extra, sigma):
    command = [sys.executable, "-m", "startrack.cli", "solve", "--batch", str(batch), *extra,
               "--centroid-sigma-px", str(sigma), "--json"]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - start
    return [json.loads(line) for line in done.stdout.splitlines()], wall


def run_layer(camera, sigma, frames):
    from startrack.camera.model import Camera
    from startrack.identify.calibrated import CalibratedSolver

    solver = CalibratedSolver(Camera.from_fov(np.radians(camera.fov_deg), camera.width, camera.height),
                              centroid_sigma_px=sigma)
    records = []
    for k, frame in enumerate(frames):
        records.append(solver.solve(frame.uv, camera.width, camera.height, frame.flux).to_dict(k))
    return records


def score(camera, sigma, frames, records, vectors):
    """Metrics of one mode on one set (module text): identified = ok with every HIP right, false = ok with
    some HIP wrong; the errors over the identified, and how many lie beyond 6 sigma of the bound."""
    false = 0
    errors, bounds, reported, times, distance = [], [], [], [], []
    for frame, record in zip(frames, records):
        times.append(record["solve_ms"])
        if record["status"] != "ok":
            continue
        if any(h not in frame.members[i] for i, h in record["matches"]):
            false += 1
            continue
        error = attitude_error(frame.q_IS, np.array(record["q_IS"]))
        crb = pixel_crb(camera, frame.q_IS, np.array([vectors[h] for _, h in record["matches"]]), sigma)
        errors.append(error)
        bounds.append(np.diag(crb))
        distance.append(float(np.sqrt(error @ np.linalg.solve(crb, error))))
        reported.append(np.hypot(*record["sigma_arcsec"][:2]) / np.sqrt(2.0))
    ok = len(errors)
    errors, bounds = np.array(errors).reshape(-1, 3), np.array(bounds).reshape(-1, 3)
    across, about = np.hypot(errors[:, 0], errors[:, 1]) / ARCSEC, np.abs(errors[:, 2]) / ARCSEC
    ratio = (lambda e, b: float(np.sqrt(np.mean(e**2) / np.mean(b)))) if ok else (lambda e, b: None)
    statuses = {s: sum(r["status"] == s for r in records) for s in {r["status"] for r in records}}
    return {"frames": len(frames), "identified": ok, "false": false, "statuses": statuses,
            "beyond_6_sigma_of_bound": int(np.sum(np.array(distance) > 6.0)),
            "cross_boresight_arcsec": _percentiles(across), "roll_arcsec": _percentiles(about),
            "rms_over_crb_cross_boresight": ratio(errors[:, :2], bounds[:, :2]),
            "rms_over_crb_roll": ratio(errors[:, 2], bounds[:, 2]),
            "reported_sigma_cross_arcsec_median": float(np.median(reported)) if reported else None,
            "solve_ms_median": float(np.median(times)) if times else None}


def _percentiles(values):
    if not len(values):
        return {"median": None, "p95": None}
    return {"median": float(np.median(values)), "p95": float(np.percentile(values, 95))}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames16", type=int, default=500)
    parser.add_argument("--frames12", type=int, default=300)
    parser.add_argument("--seed", type=int, default=24)
    args = parser.parse_args()
    stars = load_star_catalog(2000.0)
    vectors = dict(zip(stars.hip.tolist(), stars.vectors))
    work = HERE / "work" / "solve_given_camera"
    results = {}
    for name, (camera, sigma, frames) in frame_sets(args, stars).items():
        batch, camera_file = write_inputs(work / name, camera, frames)
        rows = {"identification layer (CalibratedSolver)": (run_layer(camera, sigma, frames), None)}
        for mode, extra in cli_modes(camera, sigma, camera_file).items():
            rows[mode] = run_cli(batch, extra, sigma)
        results[name] = {}
        for mode, (records, wall) in rows.items():
            results[name][mode] = {**score(camera, sigma, frames, records, vectors), "wall_s": wall}
            r = results[name][mode]
            print(f"{name:13s} {mode:68s} ok {r['identified']}/{r['frames']} false {r['false']} beyond 6 sigma "
                  f"{r['beyond_6_sigma_of_bound']}  across median "
                  f"{r['cross_boresight_arcsec']['median']}  RMS/CRB {r['rms_over_crb_cross_boresight']} / "
                  f"{r['rms_over_crb_roll']}  sigma {r['reported_sigma_cross_arcsec_median']}  "
                  f"{r['solve_ms_median']} ms  wall {wall}", flush=True)
    out = {"benchmark": "solve_given_camera", "utc": datetime.datetime.now(datetime.timezone.utc).isoformat(),
           "machine": {"python": platform.python_version(), "processor": platform.processor() or platform.machine()},
           "config": vars(args), "results": results}
    path = HERE / "results" / "solve_given_camera.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
