"""Solving images with no field of view given: startrack's plate solver and cedar-solve 0.5.1 side by side.

Frame sets (issue 18), every one detected once by startrack's detection (mesh background, single
pixels dropped, full scale from the bit depth; :mod:`startrack.commands.detect`) and given to both
solvers as the same centroids, brightest first, with the image size and nothing else:

* real: the eight ESA frames of ``../shared/realsky/`` (tetra3's test data, 11.4 deg; truth: cedar-solve's
  own no-FOV solutions in reference.json, whose Alt40_Azi45 attitude is ~90" off);
* synthetic: frames rendered by :func:`startrack.image.synthetic.rendered_sky` (1024 x 768, field of
  view uniform in 8-30 deg, radial distortion k1 uniform in +-0.2, Hipparcos-2 stars V <= 8.5);
* jpeg: rendered frames (10-33 deg) scaled to 8 bits and JPEG-compressed at quality 60-95
  (:func:`~startrack.image.synthetic.as_jpeg`), the block noise of an ordinary camera's JPEG;
* crowd: 1000-5000 false detections (uniform or clustered, :func:`~startrack.image.synthetic.noise_crowd`)
  on a 33 deg frame, alone (nothing must be answered) or with the 150 brightest stars of the field.

Scores, per solver and set: success = answered and the pointing of the image centre within 60" of the
truth (real: 120", the reference's own error on one frame); wrong = answered with the pointing more
than 0.1 deg off (or, for a crowd without stars, answered at all); the field-of-view error of the
successes (cedar's FOV and startrack's :attr:`~startrack.camera.model.Camera.angular_width`, both the angle
the width subtends); solve ms = wall time of the solver call alone (centroids in, answer out),
median / p95 / max.  cedar-solve runs in its own venv (``sh benchmarks/peers/setup_venvs.sh``) with its
database for 8-30 deg, V <= 8 built once from the same Hipparcos-2 stars (``generate_database`` at its
defaults), its 5 s timeout, once without and once with its distortion search (-0.2, 0.1).  startrack
runs with its defaults (2-160 deg, 1 s budget).

One-shot wall time: ``startrack solve IMAGE`` in a new process on a warm cache (median of 20), the same
command handed to a running ``startrack serve`` (median of 20), and, with
``--baseline DIR`` (a checkout of the code before issue 18: ``git archive <commit> | tar -x -C DIR``),
that code's ``startrack solve IMAGE --fov-deg 11.42 --width 1024 --height 768`` (it needed the
geometry) in the same run.  A camera pipeline's latency: ``startrack solve --batch - --json`` fed the
image's path on stdin 200 times, per frame from the line written to the answer read, interleaved with the
same detection and solve called in process (the median of the pairs' differences is the stream's own cost).
Measures, never asserts.

Run:  python benchmarks/real_solve.py [--synthetic 60] [--jpeg 20] [--crowds 20] [--seed 0] [--baseline DIR]
      python benchmarks/real_solve.py --latency-only   (the one-shot and the stream alone)
Writes benchmarks/results/real_solve.json; frames and raw results under benchmarks/work/real_solve/.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
REALSKY = ROOT.parent / "shared" / "realsky"
sys.path.insert(0, str(HERE))

from startrack.base.units import ARCSEC, DEG  # noqa: E402
from startrack.camera.model import Camera  # noqa: E402
from startrack.commands.detect import detect_frame  # noqa: E402
from startrack.geometry.attitude_angles import matrix_from_radec_roll  # noqa: E402
from startrack.image.files import Frame, read_frame  # noqa: E402

WIDTH, HEIGHT = 1024, 768
SUCCESS_ANGLE = {"real": 120.0 * ARCSEC}
DEFAULT_SUCCESS_ANGLE = 60.0 * ARCSEC
WRONG_ANGLE = 0.1 * DEG
#: startrack solve's default detection.
DETECTION = {"background": None, "sigma_n": None, "a": 5.0, "centroider": "threshold", "min_pixels": 1,
             "mesh_px": 64, "reject_single_pixels": True, "reject_extended": True,
             "saturation_dn": None}
CEDAR_CONFIGS = {"cedar-solve": "0", "cedar-solve (distortion search)": "-0.2,0.1"}


# ----------------------------------------------------------------------------------- frames
def _record(frame_id, set_name, found, truth):
    """A frame line: centroids [u, v, flux, sigma] brightest first, image size, truth."""
    sigma = np.hypot(found.sigma_u, found.sigma_v) / np.sqrt(2.0)
    centroids = np.column_stack([found.uv, found.flux, sigma])
    return {"id": frame_id, "set": set_name, "width": WIDTH, "height": HEIGHT,
            "centroids": np.round(centroids, 5).tolist(), **truth}


def _centre_truth(camera, q_IS):
    """R_IC (image-centre frame, the frame plate solvers report) and the field of view of a true camera."""
    ra_dec_roll = camera.center_radec_roll(q_IS)
    return {"R_IC": matrix_from_radec_roll(*ra_dec_roll).tolist(), "fov_deg": math.degrees(camera.angular_width)}


def real_frames():
    """The eight ESA frames, detected, with cedar-solve's reference solutions as truth."""
    reference = json.loads((REALSKY / "reference.json").read_text())
    frames = []
    for name, ref in sorted(reference.items()):
        found = detect_frame(read_frame(REALSKY / ref["file"]), DETECTION)
        R = matrix_from_radec_roll(*np.radians([ref["ra_deg"], ref["dec_deg"], ref["roll_deg"]]))
        frames.append(_record(name, "real", found, {"R_IC": R.tolist(), "fov_deg": ref["fov_deg"]}))
    return frames


def synthetic_frames(n, seed, jpeg):
    """``n`` rendered frames (8-30 deg, |k1| <= 0.2), or JPEG-compressed ones (10-33 deg), detected."""
    from startrack.catalog.hipparcos import load_star_catalog
    from startrack.image.synthetic import as_jpeg, rendered_sky

    stars = load_star_catalog(2000.0).brighter_than(8.5)
    frames = []
    for k in range(n):
        rng = np.random.default_rng(np.random.SeedSequence([seed, 2 if jpeg else 1, k]))
        fov = rng.uniform(10.0, 33.0) if jpeg else rng.uniform(8.0, 30.0)
        camera = Camera.from_fov(fov * DEG, WIDTH, HEIGHT, k1=rng.uniform(-0.2, 0.2))
        sky = rendered_sky(camera, stars, rng)
        image, scale = (as_jpeg(sky.image, sky.full_scale, int(rng.integers(60, 96))), 255.0) if jpeg \
            else (sky.image, sky.full_scale)
        found = detect_frame(Frame(image, scale), DETECTION)
        frames.append(_record(f"{'jpeg' if jpeg else 'synthetic'}-{k:03d}", "jpeg" if jpeg else "synthetic", found,
                              _centre_truth(camera, sky.q_IS)))
    return frames


def crowd_frames(n, seed):
    """``n`` crowds of 1000-5000 false detections on a 33 deg frame, every other one with its 150 brightest stars."""
    from startrack.catalog.hipparcos import load_star_catalog
    from startrack.image.synthetic import noise_crowd, random_attitude

    stars = load_star_catalog(2000.0).brighter_than(8.0)
    camera = Camera.from_fov(33.0 * DEG, WIDTH, HEIGHT)
    frames = []
    for k in range(n):
        rng = np.random.default_rng(np.random.SeedSequence([seed, 3, k]))
        uv, flux = noise_crowd(int(rng.integers(1000, 5001)), WIDTH, HEIGHT, rng, clusters=int(rng.integers(0, 3)) * 20)
        q_IS, with_stars = random_attitude(rng), bool(k % 2)
        truth = {"R_IC": None, "fov_deg": None}
        if with_stars:
            seen = camera.stars_in_field(q_IS, stars.vectors)
            seen = seen[np.argsort(stars.v_mag[seen], kind="stable")][:150]
            uv = np.vstack([camera.project(q_IS, stars.vectors[seen])[0] + rng.normal(0.0, 0.3, (seen.size, 2)), uv])
            flux = np.concatenate([50.0 * 10.0 ** (-0.4 * (stars.v_mag[seen] - 8.0)), flux])
            truth = _centre_truth(camera, q_IS)
        order = np.argsort(-flux, kind="stable")
        centroids = np.column_stack([uv[order], flux[order], np.full(len(uv), 0.5)])
        frames.append({"id": f"crowd-{k:03d}", "set": "crowd", "width": WIDTH, "height": HEIGHT,
                       "centroids": np.round(centroids, 5).tolist(), **truth})
    return frames


# ----------------------------------------------------------------------------------- solvers
def startrack_record(solver, frame, warm_up=False):
    """The result record of a :class:`startrack.identify.plate_solver.PlateSolver` on a frame's centroids, the
    solve call timed alone (``warm_up``: solved once before, lazy initialisation is not a solve)."""
    c = np.array(frame["centroids"], dtype=float).reshape(-1, 4)
    call = (c[:, :2], frame["width"], frame["height"], c[:, 2], c[:, 3])
    if warm_up:
        solver.solve(*call)
    begin = time.perf_counter_ns()
    result = solver.solve(*call)
    record = {"id": frame["id"], "status": result.status, "solve_ms": (time.perf_counter_ns() - begin) / 1e6}
    if result.ok:
        camera = result.calibration.camera
        record.update(R_IC=matrix_from_radec_roll(*camera.center_radec_roll(result.q_IS)).tolist(),
                      fov_deg=math.degrees(camera.angular_width), matches=result.matches.tolist())
    return record


def run_startrack(frames):
    """Results of :class:`startrack.identify.plate_solver.PlateSolver` (defaults), the solve call timed alone."""
    from startrack.identify.plate_solver import PlateSolver

    start = time.perf_counter()
    solver = PlateSolver()
    setup_ms = 1e3 * (time.perf_counter() - start)
    return [startrack_record(solver, frame, n == 0) for n, frame in enumerate(frames)], setup_ms


def run_cedar(frames_path, out_path, database, distortion):
    """(results, None) of cedar-solve's runner in its venv, or (None, why it could not run)."""
    python = HERE / ".venv-cedar" / "bin" / "python"
    if not python.exists():
        return None, "no virtualenv benchmarks/.venv-cedar: run sh benchmarks/peers/setup_venvs.sh"
    command = [str(python), str(HERE / "peers" / "cedar_plate_runner.py"), "--frames", str(frames_path), "--out",
               str(out_path), "--database", str(database), f"--distortion={distortion}"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        return None, (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
    with open(out_path) as stream:
        return [json.loads(line) for line in stream if line.strip()], None


def cedar_database(work, epoch, fov_range_deg=(8.0, 30.0)):
    """The cedar-solve database for the field-of-view range [deg], V <= 8 from the benchmark's Hipparcos-2
    file (built once)."""
    import star_id

    low, high = fov_range_deg
    path = work / f"cedar-fov{low:g}-{high:g}-v8.npz"
    if not path.is_file():
        catalog = star_id.write_peer_catalogs(work, epoch) / "hip_main.dat"
        code = ("import logging, sys, tetra3; logging.disable(logging.INFO); tetra3.Tetra3(load_database=None)"
                ".generate_database(max_fov=float(sys.argv[3]), min_fov=float(sys.argv[4]), star_catalog=sys.argv[1], "
                "star_max_magnitude=8.0, epoch_proper_motion=None, save_as=sys.argv[2])")
        print(f"  cedar-solve: building its database {path.name} (once)", flush=True)
        subprocess.run([str(HERE / ".venv-cedar" / "bin" / "python"), "-c", code, str(catalog),
                        str(path.with_suffix("")), str(high), str(low)], check=True)
    return path


# ----------------------------------------------------------------------------------- scores
def _angle(R_a, R_b):
    R = np.asarray(R_a).T @ np.asarray(R_b)
    return math.acos(max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0)))


def score(frames, results):
    """Per set: frames, success, wrong, no answer, solve ms (median, p95, max), FOV error of the successes."""
    by_id = {r["id"]: r for r in results}
    out = {}
    for set_name in dict.fromkeys(f["set"] for f in frames):
        rows = [(f, by_id.get(f["id"])) for f in frames if f["set"] == set_name]
        success, wrong, times, fov_errors, angles = 0, 0, [], [], []
        for frame, result in rows:
            if result is None:
                continue
            if result["solve_ms"] is not None:
                times.append(result["solve_ms"])
            if result["status"] != "ok":
                continue
            if frame["R_IC"] is None:
                wrong += 1
                continue
            angle = _angle(frame["R_IC"], result["R_IC"])
            if angle > WRONG_ANGLE:
                wrong += 1
            elif angle <= SUCCESS_ANGLE.get(set_name, DEFAULT_SUCCESS_ANGLE):
                success += 1
                angles.append(angle / ARCSEC)
                fov_errors.append(100.0 * abs(result["fov_deg"] / frame["fov_deg"] - 1.0))
        out[set_name] = {
            "frames": len(rows), "answerable": sum(f["R_IC"] is not None for f, _ in rows), "success": success,
            "wrong": wrong, "errors": sum(r is not None and r["status"] == "error" for _, r in rows),
            "solve_ms": {"median": float(np.median(times)), "p95": float(np.percentile(times, 95)),
                         "max": float(np.max(times))} if times else None,
            "centre_error_arcsec": {"median": float(np.median(angles)) if angles else None,
                                    "max": float(np.max(angles)) if angles else None},
            "fov_error_percent": {"median": float(np.median(fov_errors)) if fov_errors else None,
                                  "max": float(np.max(fov_errors)) if fov_errors else None}}
    return out


def per_frame(frames, results):
    """The real frames one by one: centre error [arcsec], FOV error [%], status."""
    by_id = {r["id"]: r for r in results}
    rows = {}
    for frame in frames:
        if frame["set"] != "real":
            continue
        result = by_id[frame["id"]]
        row = {"status": result["status"], "solve_ms": result["solve_ms"] or 0.0}
        if result["status"] == "ok":
            row["centre_error_arcsec"] = _angle(frame["R_IC"], result["R_IC"]) / ARCSEC
            row["fov_error_percent"] = 100.0 * (result["fov_deg"] / frame["fov_deg"] - 1.0)
            row["matches"] = len(result.get("matches", []))
        rows[frame["id"]] = row
    return rows


# ----------------------------------------------------------------------------------- one-shot wall time
def one_shot_ms(command, env=None, repeats=20):
    """Median wall time [ms] of ``command`` in new processes, after one warm-up run (warm caches)."""
    subprocess.run(command, capture_output=True, env=env)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, env=env)
        times.append(1e3 * (time.perf_counter() - start))
        if done.returncode != 0:
            return None, done.stderr.strip()[-200:]
    return float(np.median(times)), None


NUMBA_FLOOR = """from numba import njit
@njit(cache=True)
def f(x):
    return x + 1
f(1)
"""


def numba_floor_ms():
    """Wall time [ms] of the least a new process running compiled code pays: Python, numba's import and one
    kernel loaded from numba's cache (the median of 20 after a warm-up that writes the cache)."""
    with tempfile.TemporaryDirectory(prefix="numba-floor", dir="/tmp") as folder:
        script = Path(folder) / "kernel.py"
        script.write_text(NUMBA_FLOOR)
        return one_shot_ms([sys.executable, str(script)])[0]


def one_shot(image, baseline):
    """One-shot wall times of ``startrack solve IMAGE``: in its own process (``after_ms``), handed to a running
    ``startrack serve`` (``served_ms``) and, with a baseline checkout, before issue 18."""
    startrack = [str(Path(sys.executable).parent / "startrack"), "solve", str(image)]
    after, failure = one_shot_ms(startrack, {**os.environ, "STARTRACK_USE_SERVER": "0"})
    out = {"image": image.name, "after_ms": after, "after_error": failure, "before_ms": None}
    with tempfile.TemporaryDirectory(prefix="st", dir="/tmp") as folder:
        env = {**os.environ, "STARTRACK_SERVE_SOCKET": str(Path(folder) / "serve.sock")}
        server = subprocess.Popen(startrack[:1] + ["serve"], env=env, stderr=subprocess.PIPE, text=True)
        try:
            server.stderr.readline()  # "listening on ..."
            out["served_ms"], out["served_error"] = one_shot_ms(startrack, env)
        finally:
            server.terminate()
            server.wait()
    out["floor_ms"] = numba_floor_ms()
    if baseline is not None:
        env = {**os.environ, "PYTHONPATH": str(Path(baseline).resolve())}
        command = [sys.executable, "-m", "startrack.cli", "solve", str(image), "--fov-deg", "11.42", "--width", "1024",
                   "--height", "768"]
        out["before_ms"], out["before_error"] = one_shot_ms(command, env)
    return out


def stream_latency(image, frames=200):
    """Per-frame wall time [ms] of ``startrack solve --batch - --json`` (a long-lived solver fed IMAGE's path
    on stdin, from the line written to the answer read) beside the same detection and solve called in this
    process, interleaved frame by frame (``frames`` pairs after one warm-up each, so that the machine's
    drifts fall on both alike): medians and the median of the pairs' differences, the stream's own cost."""
    from startrack.commands import build_parser
    from startrack.commands.detect import detection_options
    from startrack.commands.solve import frame_solver
    from startrack.commands.solve_input import image_frame

    args = build_parser().parse_args(["solve", str(image)])
    solver, options = frame_solver(args), detection_options(args)
    command = [str(Path(sys.executable).parent / "startrack"), "solve", "--batch", "-", "--json"]
    stream = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)

    def in_process():
        start = time.perf_counter()
        solver.solve(image_frame(image, options), None)
        return 1e3 * (time.perf_counter() - start)

    def streamed():
        start = time.perf_counter()
        stream.stdin.write(f"{image}\n")
        stream.stdin.flush()
        answer = json.loads(stream.stdout.readline())
        return 1e3 * (time.perf_counter() - start), answer["status"]

    in_process(), streamed()
    inside, times = [], []
    for _ in range(frames):
        inside.append(in_process())
        ms, status = streamed()
        if status != "ok":
            break
        times.append(ms)
    stream.stdin.close()
    stream.wait()
    pairs = np.array(times) - np.array(inside[:len(times)])
    return {"image": image.name, "frames": len(times), "stream_ms": float(np.median(times)) if times else None,
            "in_process_ms": float(np.median(inside)),
            "overhead_ms": float(np.median(pairs)) if times else None,
            "overhead_ms_quartiles": [float(q) for q in np.percentile(pairs, [25, 75])] if times else None}


# ----------------------------------------------------------------------------------- main
def _fmt(value, spec):
    return "-" if value is None else format(value, spec)


def _print(scores, one):
    sets = list(next(iter(scores.values())).keys())
    print(f"{'solver':<34} {'set':<10} {'frames':>6} {'success':>8} {'wrong':>6} {'ms med':>8} {'p95':>8} {'max':>9} "
          f"{'centre med/max [as]':>20} {'FOV err med/max [%]':>20}")
    for name, per_set in scores.items():
        for set_name in sets:
            m = per_set[set_name]
            c, f, ms = m["centre_error_arcsec"], m["fov_error_percent"], m["solve_ms"] or {"median": None, "p95": None,
                                                                                             "max": None}
            print(f"{name:<34} {set_name:<10} {m['answerable']:>3}/{m['frames']:<3} {m['success']:>8} {m['wrong']:>6} "
                  f"{_fmt(ms['median'], '.2f'):>8} {_fmt(ms['p95'], '.2f'):>8} {_fmt(ms['max'], '.1f'):>9} "
                  f"{_fmt(c['median'], '.1f'):>9}/{_fmt(c['max'], '<9.1f')} "
                  f"{_fmt(f['median'], '.4f'):>9}/{_fmt(f['max'], '<9.4f')}")
    print(f"\none-shot `startrack solve {one['image']}` (new process, warm cache, median of 20): after {one['after_ms']:.0f} ms "
          f"(one cached numba kernel in a new process: {one['floor_ms']:.0f} ms), handed to a running `startrack serve` "
          f"{one['served_ms']:.0f} ms"
          + (f", before (issue 17 code, with --fov-deg/--width/--height) {one['before_ms']} ms" if one["before_ms"] else ""))


def _print_stream(stream):
    low, high = stream["overhead_ms_quartiles"]
    print(f"stream `startrack solve --batch - --json` fed {stream['image']} {stream['frames']} times, interleaved with "
          f"the same detection + solve in process: {stream['stream_ms']:.2f} ms vs {stream['in_process_ms']:.2f} ms "
          f"per frame (medians), the stream's own {stream['overhead_ms']:+.2f} ms (median of the pairs, "
          f"quartiles {low:+.2f} / {high:+.2f})")


def latency_only(args):
    """The one-shot and stream measurements alone, written over those entries of ``args.out``."""
    image = REALSKY / "2019-07-29T204726_Alt60_Azi135_Try1.tiff"
    one, stream = one_shot(image, args.baseline), stream_latency(image)
    print(f"one-shot `startrack solve {one['image']}` (new process, warm cache, median of 20): {one['after_ms']:.0f} ms "
          f"(a new process running one cached numba kernel: {one['floor_ms']:.0f} ms); handed to a running "
          f"`startrack serve`: {one['served_ms']:.0f} ms")
    _print_stream(stream)
    output = json.loads(args.out.read_text()) if args.out.is_file() else {}
    output.update(one_shot=one, stream=stream,
                  latency_utc=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"))
    args.out.write_text(json.dumps(output, indent=1, allow_nan=False) + "\n")
    print(f"wrote {args.out}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--synthetic", type=int, default=60, help="rendered frames")
    parser.add_argument("--jpeg", type=int, default=20, help="JPEG-compressed rendered frames")
    parser.add_argument("--crowds", type=int, default=20, help="crowds of false detections (every other with stars)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--baseline", help="checkout of the code before issue 18, for the one-shot 'before'")
    parser.add_argument("--out", type=Path, default=HERE / "results" / "real_solve.json")
    parser.add_argument("--work", type=Path, default=HERE / "work" / "real_solve")
    parser.add_argument("--latency-only", action="store_true",
                        help="measure only the one-shot and the stream (their entries of --out replaced)")
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    if args.latency_only:
        return latency_only(args)
    print("frames: real, synthetic, jpeg, crowd (detected once, the same centroids for every solver)", flush=True)
    frames = real_frames() + synthetic_frames(args.synthetic, args.seed, False) + synthetic_frames(args.jpeg, args.seed, True) \
        + crowd_frames(args.crowds, args.seed)
    frames_path = args.work / f"frames-seed{args.seed}.jsonl"
    frames_path.write_text("".join(json.dumps(f) + "\n" for f in frames))
    results, solvers = {}, {}
    print("running startrack", flush=True)
    results["startrack"], setup_ms = run_startrack(frames)
    solvers["startrack"] = {"setup_ms": setup_ms}
    database = cedar_database(args.work, 2000.0) if (HERE / ".venv-cedar").exists() else None
    for name, distortion in CEDAR_CONFIGS.items():
        print(f"running {name}", flush=True)
        records, failure = run_cedar(frames_path, args.work / f"results-{name.split()[0]}-{distortion}.jsonl", database,
                                     distortion) if database else (None, "no cedar venv")
        if records is None:
            solvers[name] = {"available": False, "reason": failure}
            print(f"  {name}: not run ({failure})")
            continue
        results[name] = records
        solvers[name] = {"available": True, "distortion": distortion, "database": database.name}
    scores = {name: score(frames, records) for name, records in results.items()}
    real = {name: per_frame(frames, records) for name, records in results.items()}
    one = one_shot(REALSKY / "2019-07-29T204726_Alt60_Azi135_Try1.tiff", args.baseline)
    stream = stream_latency(REALSKY / "2019-07-29T204726_Alt60_Azi135_Try1.tiff")
    _print(scores, one)
    _print_stream(stream)
    for name, rows in real.items():
        print(f"\n{name}, real frames: centre error [arcsec], FOV error [%] vs cedar-solve's reference")
        for frame_id, row in rows.items():
            detail = (f"{row['centre_error_arcsec']:7.1f}  {row['fov_error_percent']:+.4f}  {row['matches']} stars"
                      if row["status"] == "ok" else row["status"])
            print(f"  {frame_id}: {detail}  {row['solve_ms']:.2f} ms")
    output = {"benchmark": "solving images with no field of view given, startrack vs cedar-solve (issue 18)",
              "utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "machine": {"python": platform.python_version(), "platform": platform.platform(), "cpus": os.cpu_count()},
              "config": {"synthetic": args.synthetic, "jpeg": args.jpeg, "crowds": args.crowds, "seed": args.seed,
                         "success_arcsec": {"real": 120.0, "other": 60.0}, "wrong_deg": 0.1},
              "solvers": solvers, "results": scores, "real_frames": real, "one_shot": one, "stream": stream}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(output, indent=1, allow_nan=False) + "\n")
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
