"""Plate solving under impairments: startrack, astrometry.net, cedar-solve and tetra3rs on the same centroids.

Frames (:mod:`sky_impairments`): ``--frames`` scenes (1024 x 768, field of view uniform in
``--fov-range-deg``, default 8-60 deg, radial distortion |k1| <= 0.1, random attitude, Hipparcos-2 stars
V <= 9 rendered through startrack's sensor model), each rendered once per impairment level — centroid
noise, brightness-order noise, false stars, hot pixels, satellite and aircraft streaks, a cloud, a
light-pollution gradient, moonlight, defocus, trees in the foreground, JPEG quality — and the eight
real ESA frames of ``../shared/realsky`` (truth: cedar-solve's reference solutions, one ~90" off).
Every frame is detected once by startrack's detection (``startrack solve``'s defaults) and every solver
gets the same centroids, brightest first, with the image size and the field-of-view range
(startrack: ``PlateSolver(fov_range=...)`` with its 1 s budget per frame, and as ``startrack-10s`` with
10 s, the CPU time astrometry.net is given; astrometry.net: ``--scale-low/--scale-high``; cedar-solve:
its database built for the range, distortion search -0.2..0.1; tetra3rs: a multi-scale database and
its field-of-view sweep over the range).  Peers: ``make bench`` (benchmarks/peers/setup_venvs.sh) and the
Debian packages astrometry.net and astrometry-data-tycho2-10-19; a missing peer is reported, not fatal.

Scores per solver and bin (impairment x level): success = answered with the image-centre frame
(pointing and roll) within max(0.1 deg, 3 px) of the truth; wrong = the image centre's direction more than
1 deg off (another part of the sky: a false identification); imprecise = the answers between (the right
field, a poor fit: roll or pointing off by more than 3 px);
no answer; the successes' attitude error [arcsec] (median, max: how well each solver fits a distorted field);
time per frame (median, max): the solver call alone (astrometry.net: its process).  Measures, never
asserts.

Resumable: frames are written once to ``--work``, each solver's results appended frame by frame (peers in
chunks of 25), and a rerun solves only the frames without a result.

Run:  python benchmarks/plate_solve_robustness.py [--frames 10] [--seed 0] [--only cloud trees ...]
Writes benchmarks/results/plate_solve_robustness.json and .png (success per level, one panel per impairment).
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
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE / "peers"))

import real_solve  # noqa: E402
import sky_impairments as sky  # noqa: E402
from astrometry_net import solve as astrometry_solve  # noqa: E402
from astrometry_net import unavailable as astrometry_unavailable  # noqa: E402

from startrack.base.units import ARCSEC, DEG  # noqa: E402
from startrack.commands.detect import detect_frame  # noqa: E402
from startrack.image.files import Frame  # noqa: E402

CATALOG_MAG = 9.0
PEER_MAG = 8.0
CHUNK = 25
#: startrack-10s: startrack with a 10 s budget per frame (astrometry.net is given 10 s of CPU, cedar-solve 5 s).
SOLVERS = ("startrack", "startrack-10s", "astrometry.net", "cedar-solve", "tetra3rs")
#: Success: the image-centre frame within max(SUCCESS_DEG, SUCCESS_PX pixels); wrong: the centre beyond WRONG_DEG.
SUCCESS_DEG, SUCCESS_PX, WRONG_DEG = 0.1, 3.0, 1.0


# ----------------------------------------------------------------------------------- frames
def impaired_frame(seed, k, name, level_index, stars, fov_range):
    """The frame record of scene k under impairment ``name`` at its level ``level_index``."""
    impairment = sky.IMPAIRMENTS[name]
    level = impairment.levels[level_index]
    scene = sky.scene(seed, k, fov_range)
    rng = np.random.default_rng(np.random.SeedSequence([seed, k, list(sky.IMPAIRMENTS).index(name), level_index]))
    exposure = sky.exposure_of(scene)
    if impairment.stage == "pixels":
        impairment.function(exposure, level, rng)
    image, full_scale = sky.expose(scene, stars, exposure, rng)
    found = detect_frame(Frame(image, full_scale), real_solve.DETECTION)
    sigma = np.hypot(found.sigma_u, found.sigma_v) / np.sqrt(2.0)
    centroids = np.column_stack([found.uv, found.flux, sigma]).reshape(-1, 4)
    if impairment.stage == "centroids":
        centroids = impairment.function(centroids, level, rng)
    return {"id": f"{name}-{level_index}-{k:03d}", "set": name, "level": level, "width": sky.WIDTH,
            "height": sky.HEIGHT, "centroids": np.round(centroids, 5).tolist(),
            **real_solve._centre_truth(scene.camera, scene.q_IS)}


def all_frames(args, names):
    """Every frame of the run (read from the work folder when written before)."""
    path = args.work / f"frames-seed{args.seed}-fov{args.fov_range_deg[0]:g}-{args.fov_range_deg[1]:g}.jsonl"
    frames = {}
    if path.is_file():
        with open(path) as stream:
            frames = {f["id"]: f for f in map(json.loads, stream)}
    wanted = [(name, j, k) for name in names if name != "real"
              for j in range(len(sky.IMPAIRMENTS[name].levels)) for k in range(args.frames)]
    missing = [w for w in wanted if f"{w[0]}-{w[1]}-{w[2]:03d}" not in frames]
    if missing:
        from startrack.catalog.hipparcos import load_star_catalog

        stars = load_star_catalog(2000.0).brighter_than(CATALOG_MAG)
        with open(path, "a") as stream:
            for n, (name, j, k) in enumerate(missing):
                frame = impaired_frame(args.seed, k, name, j, stars, args.fov_range_deg)
                stream.write(json.dumps(frame) + "\n")
                frames[frame["id"]] = frame
                if (n + 1) % 20 == 0 or n + 1 == len(missing):
                    print(f"  frames: {n + 1}/{len(missing)} rendered and detected", flush=True)
    chosen = [frames[f"{name}-{j}-{k:03d}"] for name, j, k in wanted]
    return chosen + ([f | {"level": 0} for f in real_solve.real_frames()] if "real" in names else [])


# ----------------------------------------------------------------------------------- solvers
def _done(path):
    if not path.is_file():
        return {}
    with open(path) as stream:
        return {r["id"]: r for r in map(json.loads, stream) if r.get("id")}


def _append(path, records):
    with open(path, "a") as stream:
        for record in records:
            stream.write(json.dumps(record) + "\n")


def startrack_records(frames, fov_range, budget_s=1.0):
    """startrack's PlateSolver over the range with a time budget per frame [s], one frame at a time (first
    frame solved twice: warm-up)."""
    from startrack.identify.plate_solver import PlateSolver

    solver = PlateSolver(fov_range=(fov_range[0] * DEG, fov_range[1] * DEG), time_budget_s=budget_s)
    for n, frame in enumerate(frames):
        yield [real_solve.startrack_record(solver, frame, n == 0)]


def astrometry_records(frames, fov_range, work, cpulimit):
    for frame in frames:
        yield [astrometry_solve(frame, work / "astrometry", fov_range, cpulimit)]


def _peer_records(frames, work, label, command):
    """Chunks of a peer runner's records (the runner reads --frames, writes --out)."""
    for start in range(0, len(frames), CHUNK):
        chunk = frames[start:start + CHUNK]
        frames_path, out_path = work / f"pending-{label}.jsonl", work / f"out-{label}.jsonl"
        frames_path.write_text("".join(json.dumps(f) + "\n" for f in chunk))
        done = subprocess.run(command + ["--frames", str(frames_path), "--out", str(out_path)], capture_output=True,
                              text=True)
        if done.returncode != 0:
            raise RuntimeError((done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1])
        with open(out_path) as stream:
            yield [json.loads(line) for line in stream if line.strip()]


def cedar_records(frames, fov_range, work):
    database = real_solve.cedar_database(work, 2000.0, fov_range)
    command = [str(HERE / ".venv-cedar" / "bin" / "python"), str(HERE / "peers" / "cedar_plate_runner.py"),
               "--database", str(database), "--distortion=-0.2,0.1"]
    yield from _peer_records(frames, work, "cedar", command)


def tetra3rs_records(frames, fov_range, work):
    import star_id

    catalog = star_id.write_peer_catalogs(work, 2000.0) / "hip2_gdr3.bin"
    command = [str(HERE / ".venv-tetra3rs" / "bin" / "python"), str(HERE / "peers" / "tetra3rs_plate_runner.py"),
               "--catalog", str(catalog), "--mag", str(PEER_MAG), "--work", str(work), "--fov-range-deg",
               *map(str, fov_range)]
    yield from _peer_records(frames, work, "tetra3rs", command)


def unavailable(name):
    """Why a solver cannot run here (None: it can)."""
    venv = {"cedar-solve": ".venv-cedar", "tetra3rs": ".venv-tetra3rs"}.get(name)
    if venv and not (HERE / venv / "bin" / "python").exists():
        return f"no virtualenv benchmarks/{venv}: run sh benchmarks/peers/setup_venvs.sh"
    return astrometry_unavailable() if name == "astrometry.net" else None


def run_solver(name, frames, args):
    """Every frame's result of solver ``name`` (solving only the frames without one in the work folder)."""
    path = args.work / f"results-{name}-seed{args.seed}.jsonl"
    done = _done(path)
    pending = [f for f in frames if f["id"] not in done]
    if pending:
        print(f"running {name}: {len(pending)} frames ({len(done)} done before)", flush=True)
        fov = tuple(args.fov_range_deg)
        records = {"startrack": lambda: startrack_records(pending, fov),
                   "startrack-10s": lambda: startrack_records(pending, fov, 10.0),
                   "astrometry.net": lambda: astrometry_records(pending, fov, args.work, args.cpulimit),
                   "cedar-solve": lambda: cedar_records(pending, fov, args.work),
                   "tetra3rs": lambda: tetra3rs_records(pending, fov, args.work)}[name]()
        count, last = 0, time.monotonic()
        for chunk in records:
            _append(path, chunk)
            done.update({r["id"]: r for r in chunk})
            count += len(chunk)
            if time.monotonic() - last > 20 or count == len(pending):
                print(f"  {name}: {count}/{len(pending)}", flush=True)
                last = time.monotonic()
    return done


# ----------------------------------------------------------------------------------- scores
def score_bins(frames, results):
    """Per bin (impairment, level): frames, success, imprecise, wrong, no answer, the successes' attitude
    error [arcsec] (median, max) and solve ms (median, max)."""
    bins = {}
    for frame in frames:
        result = results.get(frame["id"])
        row = bins.setdefault((frame["set"], frame["level"]), {"frames": 0, "success": 0, "imprecise": 0, "wrong": 0,
                                                                "no_answer": 0, "angles": [], "ms": []})
        row["frames"] += 1
        if result is None or result["status"] != "ok":
            row["no_answer"] += 1
        else:
            angle = real_solve._angle(frame["R_IC"], result["R_IC"])
            if angle <= max(SUCCESS_DEG * DEG, SUCCESS_PX * math.radians(frame["fov_deg"]) / frame["width"]):
                row["success"] += 1
                row["angles"].append(angle / ARCSEC)
            else:
                centre = math.acos(np.clip(np.asarray(frame["R_IC"])[:, 2] @ np.asarray(result["R_IC"])[:, 2], -1.0, 1.0))
                row["wrong" if centre > WRONG_DEG * DEG else "imprecise"] += 1
        if result is not None and result.get("solve_ms") is not None:
            row["ms"].append(result["solve_ms"])
    for row in bins.values():
        angles, times = row.pop("angles"), row.pop("ms")
        row["error_arcsec"] = {"median": float(np.median(angles)), "max": float(np.max(angles))} if angles else None
        row["solve_ms"] = {"median": float(np.median(times)), "max": float(np.max(times))} if times else None
    return bins


def markdown(scores, names):
    """The README table: success / wrong per solver and bin."""
    solvers = list(scores)
    lines = ["| impairment | level | " + " | ".join(solvers) + " |", "|---|---|" + "---|" * len(solvers)]
    for name in names:
        unit = "" if name == "real" else sky.IMPAIRMENTS[name].unit
        for (set_name, level), row in scores[solvers[0]].items():
            if set_name != name:
                continue
            cells = []
            for solver in solvers:
                r = scores[solver][(set_name, level)]
                notes = [f"{r[k]} {k}" for k in ("wrong", "imprecise") if r[k]]
                cells.append(f"{r['success']}/{r['frames']}" + (f" ({', '.join(notes)})" if notes else ""))
            label = f"{level:g} {unit}" if name not in ("none", "real") else "-"
            lines.append(f"| {name} | {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def plot(scores, names, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [n for n in names if n not in ("none", "real")]
    if not panels:
        return
    columns = 4
    rows = math.ceil(len(panels) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(4 * columns, 3 * rows), squeeze=False)
    for axis, name in zip(axes.flat, panels):
        for solver, bins in scores.items():
            levels = [level for (set_name, level) in bins if set_name == name]
            rate = [bins[(name, level)]["success"] / bins[(name, level)]["frames"] for level in levels]
            wrong = [bins[(name, level)]["wrong"] / bins[(name, level)]["frames"] for level in levels]
            line, = axis.plot(range(len(levels)), rate, "o-", label=solver)
            if any(wrong):
                axis.plot(range(len(levels)), wrong, "x:", color=line.get_color())
            axis.set_xticks(range(len(levels)), [f"{level:g}" for level in levels])
        axis.set_title(f"{name} ({sky.IMPAIRMENTS[name].unit})", fontsize=9)
        axis.set_ylim(-0.03, 1.03)
    for axis in list(axes.flat)[len(panels):]:
        axis.axis("off")
    axes.flat[0].set_ylabel("success (o) / wrong (x)")
    axes.flat[0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


# ----------------------------------------------------------------------------------- main
def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=10, help="scenes per impairment level")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--fov-range-deg", type=float, nargs=2, default=(8.0, 60.0))
    parser.add_argument("--only", nargs="+", choices=[*sky.IMPAIRMENTS, "real"], help="these impairments only")
    parser.add_argument("--solvers", nargs="+", choices=SOLVERS, default=SOLVERS)
    parser.add_argument("--cpulimit", type=float, default=10.0, help="astrometry.net's CPU limit per frame [s]")
    parser.add_argument("--out", type=Path, default=HERE / "results" / "plate_solve_robustness.json")
    parser.add_argument("--work", type=Path, default=HERE / "work" / "plate_solve_robustness")
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    names = args.only or [*sky.IMPAIRMENTS, "real"]
    frames = all_frames(args, names)
    print(f"{len(frames)} frames", flush=True)
    scores, solvers = {}, {}
    for name in args.solvers:
        why = unavailable(name)
        solvers[name] = {"available": why is None, **({"reason": why} if why else {})}
        if why:
            print(f"{name}: not run ({why})", flush=True)
            continue
        scores[name] = score_bins(frames, run_solver(name, frames, args))
    table = markdown(scores, names)
    print(table)
    output = {"benchmark": "plate solving under impairments (issue 32 item 5)",
              "utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "machine": {"python": platform.python_version(), "platform": platform.platform(), "cpus": os.cpu_count()},
              "config": {"frames_per_level": args.frames, "seed": args.seed, "fov_range_deg": list(args.fov_range_deg),
                         "k1_max": sky.K1_MAX, "catalog_mag": CATALOG_MAG, "peer_mag": PEER_MAG,
                         "astrometry_cpulimit_s": args.cpulimit,
                         "levels": {n: {"unit": i.unit, "levels": list(i.levels)} for n, i in sky.IMPAIRMENTS.items()},
                         "success": f"attitude of the image centre within max({SUCCESS_DEG} deg, {SUCCESS_PX} px)",
                         "wrong": f"the image centre's direction more than {WRONG_DEG} deg off"},
              "solvers": solvers,
              "results": {solver: [{"impairment": s, "level": level, **row} for (s, level), row in bins.items()]
                          for solver, bins in scores.items()},
              "table": table}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(output, indent=1, allow_nan=False) + "\n")
    if scores:
        plot(scores, names, args.out.with_suffix(".png"))
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
