"""Star identification side by side: startrack, cedar-solve 0.5.1 and tetra3rs 0.14.0 on the same frames.

Frames (``benchmarks/star_id_frames.py``): pinhole 16 deg, 1024 x 1024, Hipparcos-2 stars V <= 6 at
J2000.0, 0.1 px centroid noise; sets main (0-3 false, 0-2 missing stars), clean (none), stress
(0-10 false, 0-5 missing), and a tracking sweep (the first frames of main with a prior attitude
off by 0.5, 1, 2, 5, 7 deg).  Every solver runs in its own process -- the peers in their own
virtualenvs (``sh benchmarks/peers/setup_venvs.sh``) -- reads the same frames and writes one
result per frame (``benchmarks/peers/runner_io.py``); a solver that is not installed or not
importable is reported as missing and the others still run.

Peer databases are built from the same Hipparcos-2 stars, written here in each peer's input
format: a hip_main.dat-style file for cedar-solve and the Gaia DR3 binary layout for tetra3rs
(positions at J2000.0 with proper motion applied by startrack, proper-motion columns zero), single
scale at the 16 deg field, V <= 6.  Each solver is told the field of view to within
``--fov-max-error-deg`` (0.16 deg, 1 %).

Metrics per solver and frame set:

* success: status ok, attitude within 1 arcmin of the truth and every matched HIP right (a blended
  centroid may be matched to any of its members); false: status ok but not a success, split into
  attitude > 1 arcmin off and attitude right but some HIP wrong (e.g. a centroid matched to a
  neighbouring catalogue star);
* attitude error of the successes in sensor axes, dtheta = rotvec(R_true^T R_est): cross-boresight
  |(dx, dy)| and roll |dz| [arcsec], median and p95, beside the Cramer-Rao bound of the same frames
  computed from the stars the solver matched correctly.  The bound is the pixel-noise Fisher
  information F = sum_i J_i^T J_i / sigma_px^2 with J_i = d(u_i, v_i)/d(dtheta) of the pinhole
  projection (sigma_px = 0.1 px); on the boresight it reduces to P = [sum sigma^-2 (I - b b^T)]^-1
  with sigma = sigma_px / f.  Reported as the median/p95 of errors drawn from N(0, P) per frame
  (200 draws each) and as the ratio RMS(error) / RMS(bound);
* solve ms: wall-clock time of the solver call alone, median, p95, max over all frames.

Reference row "truth-SVD": the SVD attitude from every true star centroid with its true HIP (told
the answer; checks the Cramer-Rao column, RMS/CRB ~ 1).

Tracking: success and false rate per prior error (cedar-solve has no tracking mode).  Sub-catalog
(startrack only, 000 §4): the same prior frames identified by the predicted sub-catalog with its 4
redundant neighbours alone (no tracking, no full-sky fall-back), its median time beside our full-sky
median on the main set of the same run.  Each solver's set-up (database or compiled kernels loaded)
is timed apart from the solves and reported as ``setup_ms``.  Goals of issues 6 and 17 are evaluated
for startrack (met or by how much not).  Measures, never asserts.

Run:  python benchmarks/star_id.py [--frames 500] [--tracking-frames 500] [--seed 0]
Writes benchmarks/results/star_id.json; frames, catalogs, databases and raw results go under
benchmarks/work/star_id/ (git-ignored).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import struct
import subprocess
import sys
import time
import zlib
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import star_id_frames as sif  # noqa: E402

from startrack.base.units import ARCSEC  # noqa: E402
from startrack.catalog.hipparcos import load_star_catalog  # noqa: E402

FALSE_MATCH_ANGLE = 60.0 * ARCSEC  # 1 arcmin
CRB_DRAWS_PER_FRAME = 200
SET_NAMES = ("main", "clean", "stress")
REFERENCE = "truth-SVD"


# ----------------------------------------------------------------------------------- solvers
def _solver_table():
    """name -> how to run it: interpreter, runner script, star file, tracking mode, set-up hint."""
    peers = HERE / "peers"
    return {
        "startrack": {"python": Path(sys.executable), "runner": peers / "startrack_runner.py", "catalog": None,
                      "tracking": True, "subcatalog": True,
                      "setup": "the startrack identification layer (startrack.identify)"},
        "cedar-solve": {"python": HERE / ".venv-cedar" / "bin" / "python", "runner": peers / "cedar_runner.py",
                        "catalog": "hip_main.dat", "tracking": False, "distribution": "cedar-solve",
                        "setup": "sh benchmarks/peers/setup_venvs.sh"},
        "tetra3rs": {"python": HERE / ".venv-tetra3rs" / "bin" / "python", "runner": peers / "tetra3rs_runner.py",
                     "catalog": "hip2_gdr3.bin", "tracking": True, "distribution": "tetra3rs",
                     "setup": "sh benchmarks/peers/setup_venvs.sh"},
    }


def _peer_version(python, distribution):
    code = f"import importlib.metadata as m; print(m.version({distribution!r}))"
    done = subprocess.run([str(python), "-c", code], capture_output=True, text=True)
    return done.stdout.strip() if done.returncode == 0 else None


# ----------------------------------------------------------------------------------- catalog files
def _sexagesimal(value, width_degrees, decimals, signed):
    sign = "-" if value < 0 else "+"
    value = abs(value)
    whole = int(value)
    minutes_total = (value - whole) * 60.0
    minutes = int(minutes_total)
    seconds = round((minutes_total - minutes) * 60.0, decimals)
    if seconds >= 60.0:
        seconds -= 60.0
        minutes += 1
    if minutes >= 60:
        minutes -= 60
        whole += 1
    text = f"{whole:0{width_degrees}d} {minutes:02d} {seconds:0{3 + decimals}.{decimals}f}"
    return (sign + text) if signed else text


def write_hip_main(path, stars):
    """A hip_main.dat-style file (ESA I/239 layout, '|' separated) of ``stars``.

    Fields 1-14 of the I/239 ReadMe are written, the ones cedar-solve's loader reads being HIP
    (2), Vmag (6), RAdeg (9), DEdeg (10), pmRA (13) and pmDE (14): positions at the catalog's epoch,
    proper motions 0.00 (already applied), V of :mod:`startrack.catalog.hipparcos`.
    """
    ra_deg, dec_deg = np.degrees(stars.ra), np.degrees(stars.dec)
    lines = []
    for hip, ra, dec, v in zip(stars.hip.tolist(), ra_deg.tolist(), dec_deg.tolist(), stars.v_mag.tolist()):
        lines.append(
            f"H|{hip:12d}| |{_sexagesimal(ra / 15.0, 2, 2, False)}|{_sexagesimal(dec, 2, 1, True)}|{v:5.2f}| | |"
            f"{ra:12.8f}|{dec:+12.8f}| |       |{0.0:8.2f}|{0.0:8.2f}|\n"
        )
    Path(path).write_text("".join(lines))


def write_gdr3_binary(path, stars):
    """``stars`` in the Gaia DR3 binary layout tetra3rs reads (see benchmarks/peers/tetra3rs_runner.py).

    source_id = HIP, RA/Dec [deg] at the catalog's epoch, magnitude = V, proper motions zero.
    """
    record = np.dtype([("source_id", "<i8"), ("ra", "<f8"), ("dec", "<f8"), ("mag", "<f4"),
                       ("pmra", "<f4"), ("pmdec", "<f4")])
    table = np.zeros(len(stars), dtype=record)
    table["source_id"] = stars.hip
    table["ra"] = np.degrees(stars.ra)
    table["dec"] = np.degrees(stars.dec)
    table["mag"] = stars.v_mag
    with open(path, "wb") as stream:
        stream.write(b"GDR3" + struct.pack("<I", 1) + struct.pack("<Q", len(stars)))
        stream.write(table.tobytes())


def write_peer_catalogs(work, epoch):
    """The two peer star files of all Hipparcos-2 stars at ``epoch`` in ``work`` (written once)."""
    paths = {"hip_main.dat": write_hip_main, "hip2_gdr3.bin": write_gdr3_binary}
    folder = work / f"catalog-J{epoch:g}"
    folder.mkdir(parents=True, exist_ok=True)
    stars = None
    for name, writer in paths.items():
        if not (folder / name).is_file():
            stars = load_star_catalog(epoch) if stars is None else stars
            temporary = folder / (name + ".tmp")
            writer(temporary, stars)
            temporary.replace(folder / name)
    return folder


# ----------------------------------------------------------------------------------- evaluation
def pixel_crb(b_S, focal_px, sigma_px):
    """Cramer-Rao covariance [rad^2] of the attitude error in sensor axes from pixel noise.

    b_S (n, 3) true unit vectors in S; pinhole u = cx + f x/z, v = cy + f y/z with independent
    N(0, sigma_px^2) noise per axis.  A small error rotation dtheta moves b to b + b x dtheta, so
    J_i = d(u, v)/d(b) [b x] and P = [sum_i J_i^T J_i]^-1 sigma_px^2.
    """
    x, y, z = b_S[:, 0], b_S[:, 1], b_S[:, 2]
    zero = np.zeros_like(z)
    d_uv_d_b = (focal_px / z)[:, None, None] * np.stack(
        [np.stack([np.ones_like(z), zero, -x / z], -1), np.stack([zero, np.ones_like(z), -y / z], -1)], -2)
    cross = np.stack([np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)], -2)
    jac = d_uv_d_b @ cross  # (n, 2, 3)
    fisher = np.einsum("nki,nkj->ij", jac, jac) / sigma_px**2
    return np.linalg.inv(fisher)


def _percentiles(values, scale=1.0):
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return {"median": None, "p95": None}
    return {"median": float(np.median(values) / scale), "p95": float(np.percentile(values, 95) / scale)}


def evaluate(frames, results, stars, camera, rng):
    """Metrics of one solver on one frame list (see the module docstring)."""
    vector_of = dict(zip(stars.hip.tolist(), stars.vectors))
    by_id = {r["id"]: r for r in results}
    errors, bounds, draws, bounded, times, matched = [], [], [], [], [], []
    n_success = n_false = n_far = n_missing_result = 0
    statuses, methods, first_error = {}, {}, None
    for frame in frames:
        result = by_id.get(frame["id"])
        if result is None:
            n_missing_result += 1
            continue
        statuses[result["status"]] = statuses.get(result["status"], 0) + 1
        if result["status"] == "error" and first_error is None:
            first_error = f'{frame["id"]}: {result.get("reason", "")}'.strip()
        if result["solve_ms"] is not None:
            times.append(result["solve_ms"])
        if result["status"] != "ok" or result["q_IS"] is None:
            continue
        R_true = Rotation.from_quat(frame["q_IS"])
        dtheta = (R_true.inv() * Rotation.from_quat(result["q_IS"])).as_rotvec()
        truth = frame["hip"]
        allowed = {(i, h) for i, h in frame["blend_hip"]}
        right = [(i, h) for i, h in result["matches"]
                 if 0 <= i < len(truth) and h >= 0 and (truth[i] == h or (i, h) in allowed)]
        if np.linalg.norm(dtheta) > FALSE_MATCH_ANGLE:
            n_false += 1
            n_far += 1
            continue
        if len(right) != len(result["matches"]):
            n_false += 1
            continue
        n_success += 1
        methods[result.get("method")] = methods.get(result.get("method"), 0) + 1
        matched.append(len(right))
        errors.append(dtheta)
        if len(right) >= 2:
            b_S = R_true.inv().apply(np.array([vector_of[h] for _, h in right]))
            P = pixel_crb(b_S, camera.focal_px, sif.CENTROID_SIGMA_PX)
            bounds.append(np.diag(P))
            bounded.append(len(errors) - 1)
            draws.append(rng.multivariate_normal(np.zeros(3), P, size=CRB_DRAWS_PER_FRAME))
    n = len(frames)
    metrics = {
        "frames": n,
        "success_rate": n_success / n if n else None,
        "false_rate": n_false / n if n else None,
        "false_count": n_false,
        "false_attitude_count": n_far,
        "wrong_hip_only_count": n_false - n_far,
        "statuses": statuses,
        "success_methods": {str(k): v for k, v in methods.items()},
        "first_error": first_error,
        "missing_results": n_missing_result,
        "matched_stars_median": float(np.median(matched)) if matched else None,
        "solve_ms": {**_percentiles(times), "max": float(np.max(times)) if times else None,
                     "mean": float(np.mean(times)) if times else None},
    }
    if errors:
        errors = np.array(errors)
        cross, roll = np.hypot(errors[:, 0], errors[:, 1]), np.abs(errors[:, 2])
        metrics["cross_boresight_arcsec"] = _percentiles(cross, ARCSEC)
        metrics["roll_arcsec"] = _percentiles(roll, ARCSEC)
        if bounds:
            bounds, draws = np.array(bounds), np.concatenate(draws)
            cross_b, roll_b = cross[bounded], roll[bounded]  # the frames with a bound
            metrics["crb_cross_boresight_arcsec"] = _percentiles(np.hypot(draws[:, 0], draws[:, 1]), ARCSEC)
            metrics["crb_roll_arcsec"] = _percentiles(np.abs(draws[:, 2]), ARCSEC)
            metrics["rms_over_crb_cross_boresight"] = float(
                np.sqrt(np.mean(cross_b**2) / np.mean(bounds[:, 0] + bounds[:, 1])))
            metrics["rms_over_crb_roll"] = float(np.sqrt(np.mean(roll_b**2) / np.mean(bounds[:, 2])))
    return metrics


def reference_results(frames, stars, camera):
    """Results of the truth-matched SVD refit: every star centroid with its true HIP, Wahba by SVD.

    Not a solver (it is told the answer): the attitude accuracy the centroids allow, against which
    the Cramer-Rao column is checked (its RMS/CRB should be 1).
    """
    vector_of = dict(zip(stars.hip.tolist(), stars.vectors))
    records = []
    for frame in frames:
        pairs = [(i, h) for i, h in enumerate(frame["hip"]) if h >= 0]
        uv = np.array([frame["centroids"][i][:2] for i, _ in pairs])
        ref_I = np.array([vector_of[h] for _, h in pairs])
        R_IS = Rotation.align_vectors(ref_I, camera.unproject(uv))[0]
        records.append({"id": frame["id"], "status": "ok", "q_IS": R_IS.as_quat().tolist(), "matches": pairs,
                        "solve_ms": None, "mode": "reference"})
    return records


# ----------------------------------------------------------------------------------- goals
def _goal(name, target, measured, met, shortfall):
    return {"goal": name, "target": target, "measured": measured, "met": bool(met), "shortfall": shortfall}


#: Issue 17: largest solve time [ms] of any frame, and the sub-catalog/full-sky median ratio.
MAX_MS_GOAL = 5.0
SUBCATALOG_RATIO_GOAL = 0.25


def evaluate_goals(results, tracking, subcatalog=None):
    """Issue 6 and 17 goals for startrack against the peers measured in this run (met, or by how much not)."""
    ours = results.get("startrack")
    if not ours:
        return []
    peers = {name: sets for name, sets in results.items() if name not in ("startrack", REFERENCE) and sets}
    goals = []
    for set_name in SET_NAMES:
        mine = ours.get(set_name)
        if not mine:
            continue
        best = max((sets[set_name]["success_rate"] for sets in peers.values() if set_name in sets), default=None)
        if best is not None:
            goals.append(_goal(f"{set_name}: success >= best peer", best, mine["success_rate"],
                               mine["success_rate"] >= best, max(0.0, best - mine["success_rate"])))
        limit = 0.001 if set_name == "stress" else 0.0
        goals.append(_goal(f"{set_name}: false-match rate <= {limit:.1%}", limit, mine["false_rate"],
                           mine["false_rate"] <= limit, max(0.0, mine["false_rate"] - limit)))
        t3 = peers.get("tetra3rs", {}).get(set_name)
        if t3 and t3["solve_ms"]["median"] is not None and mine["solve_ms"]["median"] is not None:
            goals.append(_goal(f"{set_name}: median ms <= tetra3rs", t3["solve_ms"]["median"],
                               mine["solve_ms"]["median"], mine["solve_ms"]["median"] <= t3["solve_ms"]["median"],
                               max(0.0, mine["solve_ms"]["median"] - t3["solve_ms"]["median"])))
        p95_limit = {"main": 1.0, "stress": 2.0}.get(set_name)
        if p95_limit is not None and mine["solve_ms"]["p95"] is not None:
            goals.append(_goal(f"{set_name}: p95 ms <= {p95_limit:g}", p95_limit, mine["solve_ms"]["p95"],
                               mine["solve_ms"]["p95"] <= p95_limit, max(0.0, mine["solve_ms"]["p95"] - p95_limit)))
        if mine["solve_ms"]["max"] is not None:
            goals.append(_goal(f"{set_name}: max ms <= {MAX_MS_GOAL:g}", MAX_MS_GOAL, mine["solve_ms"]["max"],
                               mine["solve_ms"]["max"] <= MAX_MS_GOAL, max(0.0, mine["solve_ms"]["max"] - MAX_MS_GOAL)))
        for axis in ("cross_boresight", "roll"):
            ratio = mine.get(f"rms_over_crb_{axis}")
            if ratio is not None:
                goals.append(_goal(f"{set_name}: RMS {axis} error <= 1.1 x CRB", 1.1, ratio, ratio <= 1.1,
                                   max(0.0, ratio - 1.1)))
    for prior, metrics in (tracking.get("startrack") or {}).items():
        goals.append(_goal(f"tracking, prior error {prior} deg: success 100 %", 1.0, metrics["success_rate"],
                           metrics["success_rate"] >= 1.0, 1.0 - metrics["success_rate"]))
    full_sky = (ours.get("main") or {}).get("solve_ms", {}).get("median")
    for prior, metrics in (subcatalog or {}).items():
        goals.append(_goal(f"sub-catalog, prior error {prior} deg: success 100 %", 1.0, metrics["success_rate"],
                           metrics["success_rate"] >= 1.0, 1.0 - metrics["success_rate"]))
        median = metrics["solve_ms"]["median"]
        if full_sky and median is not None:
            ratio = median / full_sky
            goals.append(_goal(f"sub-catalog, prior error {prior} deg: median <= {SUBCATALOG_RATIO_GOAL:g} x full-sky median",
                               SUBCATALOG_RATIO_GOAL, ratio, ratio <= SUBCATALOG_RATIO_GOAL,
                               max(0.0, ratio - SUBCATALOG_RATIO_GOAL)))
    return goals


# ----------------------------------------------------------------------------------- report
def _fmt(value, spec, missing="-"):
    return missing if value is None else format(value, spec)


def print_subcatalog(subcatalog, full_sky_ms):
    """The sub-catalog sweep of startrack beside its full-sky median on the main set."""
    print(f"\nstartrack predicted sub-catalog alone (000 §4): success (false), median / p95 / max ms, median / "
          f"full-sky median ({_fmt(full_sky_ms, '.3f')} ms, main set)")
    for prior, m in subcatalog.items():
        ms = m["solve_ms"]
        ratio = None if not full_sky_ms or ms["median"] is None else ms["median"] / full_sky_ms
        print(f"  prior {prior:>4} deg: {m['success_rate']:6.1%} ({m['false_rate']:4.1%})  {_fmt(ms['median'], '.3f')} / "
              f"{_fmt(ms['p95'], '.3f')} / {_fmt(ms['max'], '.2f')} ms  ratio {_fmt(ratio, '.2f')}")


def print_tables(results, tracking, solvers, set_names):
    for name, info in solvers.items():
        if not info["available"]:
            print(f"{name}: MISSING ({info['reason']})")
        elif info.get("setup_ms") is not None:
            print(f"{name}: set-up {info['setup_ms']:.0f} ms (database or kernels loaded; not part of any solve)")
    columns = [("solver", "<12"), ("set", "<7"), ("success", ">8"), ("false", ">6"), ("att,HIP", ">7"), ("cross med/p95 [as]", ">18"),
               ("CRB med/p95", ">12"), ("roll med/p95 [as]", ">17"), ("CRB med/p95", ">12"),
               ("RMS/CRB x, roll", ">16"), ("ms med", ">7"), ("p95", ">7"), ("max", ">8")]
    header = " ".join(format(title, spec) for title, spec in columns)
    print(header)
    print("-" * len(header))
    for name, sets in results.items():
        for set_name in set_names:
            m = sets.get(set_name)
            if m is None:
                continue
            cb, cbb = m.get("cross_boresight_arcsec", {}), m.get("crb_cross_boresight_arcsec", {})
            rl, rlb = m.get("roll_arcsec", {}), m.get("crb_roll_arcsec", {})
            print(f"{name:<12} {set_name:<7} {m['success_rate']:8.1%} {m['false_rate']:6.1%} "
                  f"{m['false_attitude_count']:>3},{m['wrong_hip_only_count']:<3} "
                  f"{_fmt(cb.get('median'), '.2f'):>8}/{_fmt(cb.get('p95'), '.2f'):<9} "
                  f"{_fmt(cbb.get('median'), '.2f'):>5}/{_fmt(cbb.get('p95'), '.2f'):<6} "
                  f"{_fmt(rl.get('median'), '.1f'):>7}/{_fmt(rl.get('p95'), '.1f'):<9} "
                  f"{_fmt(rlb.get('median'), '.1f'):>5}/{_fmt(rlb.get('p95'), '.1f'):<6} "
                  f"{_fmt(m.get('rms_over_crb_cross_boresight'), '.2f'):>7}, {_fmt(m.get('rms_over_crb_roll'), '.2f'):<7} "
                  f"{_fmt(m['solve_ms']['median'], '.3f'):>7} {_fmt(m['solve_ms']['p95'], '.3f'):>7} "
                  f"{_fmt(m['solve_ms']['max'], '.2f'):>8}")
    for name, sets in results.items():
        for set_name, m in sets.items():
            if m["first_error"]:
                print(f"  {name} {set_name}: {m['statuses'].get('error', 0)} frames with status error, "
                      f"first: {m['first_error']}")
    if tracking:
        priors = sorted({p for sets in tracking.values() for p in sets}, key=float)
        print("\ntracking: success (false) vs prior attitude error [deg]; median ms")
        print(f"{'solver':<12} " + " ".join(f"{p + ' deg':>16}" for p in priors))
        for name, sets in tracking.items():
            cells = [f"{sets[p]['success_rate']:6.1%} ({sets[p]['false_rate']:4.1%}) "
                     f"{_fmt(sets[p]['solve_ms']['median'], '.2f')}" if p in sets else "-" for p in priors]
            print(f"{name:<12} " + " ".join(f"{c:>16}" for c in cells))
            answered = {}
            for p in priors:
                for method, count in sets[p]["success_methods"].items():
                    answered.setdefault(method, []).append(f"{p}: {count}")
            if len(answered) > 1:
                print(f"{'':<12} successes by method: " + "; ".join(f"{m} ({', '.join(c)})" for m, c in answered.items()))


# ----------------------------------------------------------------------------------- main
def _run_solver(name, info, frames_path, out_path, args, catalog_folder, extra=()):
    command = [str(info["python"]), str(info["runner"]), "--frames", str(frames_path), "--out", str(out_path),
               "--fov-deg", str(sif.FOV_DEG), "--fov-max-error-deg", str(args.fov_max_error_deg),
               "--width", str(sif.WIDTH_PX), "--height", str(sif.HEIGHT_PX), "--work", str(args.work)]
    if info["catalog"] is not None:
        command += ["--catalog", str(catalog_folder / info["catalog"]), "--mag", str(sif.V_MAX)]
    else:
        command += ["--mag", str(sif.V_MAX), "--epoch", str(sif.CATALOG_EPOCH),
                    "--centroid-sigma-px", str(sif.CENTROID_SIGMA_PX)]
    command += list(extra)
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True)
    for line in done.stdout.splitlines():
        print(line)
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()[-1:] or [f"exit status {done.returncode}"]
        return None, tail[0]
    with open(out_path) as stream:
        records = [json.loads(line) for line in stream if line.strip()]
    print(f"  {name}: {len(records)} frames of {frames_path.name} in {time.perf_counter() - start:.1f} s", flush=True)
    return records, None


def _crb_rng(seed, solver, set_name):
    """The generator of the Cramer-Rao draws of one (solver, set): independent of the other solvers run."""
    return np.random.default_rng(np.random.SeedSequence([seed, zlib.crc32(f"{solver}/{set_name}".encode())]))


#: Passes over the prior frames: the solver's tracking mode, and (startrack) the sub-catalog alone.
PRIOR_PASSES = {"tracking": (), "subcatalog": ("--methods", "subcatalog")}


def run_and_score(name, info, frame_sets, frame_paths, args, catalog_folder, stars, camera):
    """({set: metrics, "tracking"/"subcatalog": {prior: metrics}, "setup_ms"}, None) of one solver, or (None,
    why it could not run)."""
    scored = {}
    passes = list(SET_NAMES) + [p for p in PRIOR_PASSES if info.get(p)]
    for set_name in passes:
        frames_name = "tracking" if set_name in PRIOR_PASSES else set_name
        frames_path = frame_paths[frames_name]
        out_path = args.work / f"results-{name}-{set_name}-seed{args.seed}.jsonl"
        if args.reuse and out_path.is_file() and out_path.stat().st_mtime > frames_path.stat().st_mtime:
            print(f"reusing {out_path.name}", flush=True)
            records = sif.read_jsonl(out_path)
        else:
            print(f"running {name} on {set_name} ({len(frame_sets[frames_name])} frames)", flush=True)
            records, failure = _run_solver(name, info, frames_path, out_path, args, catalog_folder,
                                           PRIOR_PASSES.get(set_name, ()))
            if records is None:
                return None, failure
        if set_name == "main":
            meta = Path(str(out_path) + ".meta.json")
            scored["setup_ms"] = json.loads(meta.read_text()).get("setup_ms") if meta.is_file() else None
        if set_name in PRIOR_PASSES:
            scored[set_name] = {}
            for error_deg in sif.TRACKING_PRIOR_ERRORS_DEG:
                subset = [f for f in frame_sets["tracking"] if f["prior_error_deg"] == error_deg]
                label = f"{error_deg:g}"
                scored[set_name][label] = evaluate(subset, records, stars, camera,
                                                   _crb_rng(args.seed, name, f"{set_name}{label}"))
        else:
            scored[set_name] = evaluate(frame_sets[set_name], records, stars, camera,
                                        _crb_rng(args.seed, name, set_name))
    return scored, None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=500, help="frames per set (main, clean, stress)")
    parser.add_argument("--tracking-frames", type=int, default=None,
                        help="main-set frames per prior error in the tracking sweep (default: --frames)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--fov-max-error-deg", type=float, default=0.16, help="FOV uncertainty told to the solvers")
    parser.add_argument("--solvers", default="startrack,cedar-solve,tetra3rs", help="comma-separated subset")
    parser.add_argument("--reuse", action="store_true",
                        help="reuse a solver's raw results when newer than its frames (re-score without re-running)")
    parser.add_argument("--out", type=Path, default=HERE / "results" / "star_id.json")
    parser.add_argument("--work", type=Path, default=HERE / "work" / "star_id")
    args = parser.parse_args()
    n_tracking = args.frames if args.tracking_frames is None else args.tracking_frames
    args.work.mkdir(parents=True, exist_ok=True)

    print(f"generating frames: {args.frames} per set, {n_tracking} x {len(sif.TRACKING_PRIOR_ERRORS_DEG)} "
          f"tracking, seed {args.seed}", flush=True)
    stars = sif.benchmark_stars()
    camera = sif.benchmark_camera()
    frame_sets = {name: sif.generate_frames(name, args.frames, args.seed, stars, camera) for name in SET_NAMES}
    main_frames = frame_sets["main"]
    if n_tracking > len(main_frames):
        main_frames = sif.generate_frames("main", n_tracking, args.seed, stars, camera)
    frame_sets["tracking"] = sif.tracking_frames(main_frames[:n_tracking], seed=args.seed)
    frame_paths = {name: sif.write_jsonl(args.work / f"frames-{name}-seed{args.seed}.jsonl", frames)
                   for name, frames in frame_sets.items()}
    catalog_folder = write_peer_catalogs(args.work, sif.CATALOG_EPOCH)

    table = _solver_table()
    solvers, results, tracking, subcatalog = {}, {}, {}, {}
    for name in [s.strip() for s in args.solvers.split(",") if s.strip()]:
        info = dict(table[name], available=True, reason=None)
        if not info["python"].exists():
            info["available"], info["reason"] = False, f"no virtualenv at {info['python'].parent.parent}: run {info['setup']}"
        else:
            if "distribution" in info:
                info["version"] = _peer_version(info["python"], info["distribution"])
            scored, failure = run_and_score(name, info, frame_sets, frame_paths, args, catalog_folder, stars, camera)
            if scored is None:
                info["available"], info["reason"] = False, failure
                print(f"  {name}: not run ({failure})", flush=True)
            else:
                results[name] = {set_name: scored[set_name] for set_name in SET_NAMES}
                info["setup_ms"] = scored.get("setup_ms")
                if "tracking" in scored:
                    tracking[name] = scored["tracking"]
                if "subcatalog" in scored:
                    subcatalog[name] = scored["subcatalog"]
        solvers[name] = {key: (os.path.relpath(value, HERE.parent) if isinstance(value, Path) else value)
                         for key, value in info.items()}

    results[REFERENCE] = {name: evaluate(frame_sets[name], reference_results(frame_sets[name], stars, camera),
                                         stars, camera, _crb_rng(args.seed, REFERENCE, name)) for name in SET_NAMES}
    print(f"\n{args.frames} frames per set, seed {args.seed}, FOV told to +-{args.fov_max_error_deg:g} deg; "
          f"success/false over all frames; errors of the successes [arcsec]; solve ms of the solver call")
    print_tables(results, tracking, solvers, SET_NAMES)
    print(f"({REFERENCE}: every true star centroid with its true HIP, SVD refit -- the accuracy reference, not a solver)")
    if "startrack" in subcatalog:
        print_subcatalog(subcatalog["startrack"], results["startrack"]["main"]["solve_ms"]["median"])
    goals = evaluate_goals(results, tracking, subcatalog.get("startrack"))
    if goals:
        print("\ngoals (issues 6 and 17) for startrack:")
        for goal in goals:
            state = "met" if goal["met"] else f"NOT met, short by {goal['shortfall']:.4g}"
            print(f"  {goal['goal']}: measured {goal['measured']:.4g} vs {goal['target']:.4g} -> {state}")
    output = {
        "benchmark": "star identification, startrack vs cedar-solve vs tetra3rs (issues 6 and 17)",
        "utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": {"python": platform.python_version(), "platform": platform.platform(),
                    "cpus": os.cpu_count()},
        "config": {"frames_per_set": args.frames, "tracking_frames_per_prior": n_tracking, "seed": args.seed,
                   "fov_deg": sif.FOV_DEG, "width_px": sif.WIDTH_PX, "height_px": sif.HEIGHT_PX,
                   "v_max": sif.V_MAX, "centroid_sigma_px": sif.CENTROID_SIGMA_PX, "epoch": sif.CATALOG_EPOCH,
                   "fov_max_error_deg": args.fov_max_error_deg,
                   "sets": {name: {"max_false": s.max_false, "max_missing": s.max_missing}
                            for name, s in sif.FRAME_SETS.items()},
                   "false_star_v_range": list(sif.FALSE_STAR_V_RANGE), "blend_radius_px": sif.BLEND_RADIUS_PX,
                   "tracking_prior_errors_deg": list(sif.TRACKING_PRIOR_ERRORS_DEG),
                   "false_match_angle_arcsec": FALSE_MATCH_ANGLE / ARCSEC},
        "solvers": solvers,
        "results": results,
        "tracking": tracking,
        "subcatalog": subcatalog,
        "goals": goals,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(output, indent=1, allow_nan=False) + "\n")
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
