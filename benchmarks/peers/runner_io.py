"""Input/output shared by the solver runners of ``benchmarks/star_id.py`` (numpy and stdlib only).

The runners execute inside the peers' own virtualenvs (cedar-solve pins numpy < 2), so they
cannot import startrack.  Each reads frames (JSON Lines written by ``benchmarks/star_id_frames.py``)
and writes one result per frame, JSON Lines::

    {"id", "status": "ok" | "no_match" | "too_few" | "timeout" | "error", "q_IS": [x, y, z, w] or null,
     "matches": [[centroid index, HIP], ...], "solve_ms", "mode": "lost_in_space" | "tracking" (the
     frame has a prior), "method": the solver's strategy that answered (or null), "reason": text
     (status "error" only)}

``q_IS`` is scalar-last and rotates sensor-frame vectors into ICRS (docs/design.md); sensor frame
+x along image columns, +y along rows (down), +z boresight.  ``solve_ms`` is the wall-clock time
of the solver call alone, measured the same way for every solver (:func:`timed`).
"""

import argparse
import json
import time
import traceback

import numpy as np


def common_arguments(description):
    """Argument parser with the options every runner takes."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--frames", required=True, help="frames, JSON Lines")
    parser.add_argument("--out", required=True, help="results, JSON Lines")
    parser.add_argument("--fov-deg", type=float, required=True, help="field of view across the width [deg]")
    parser.add_argument("--fov-max-error-deg", type=float, required=True, help="FOV uncertainty given to the solver")
    parser.add_argument("--width", type=int, required=True)
    parser.add_argument("--height", type=int, required=True)
    parser.add_argument("--work", required=True, help="directory for the solver's database")
    return parser


def read_frames(path):
    with open(path) as stream:
        return [json.loads(line) for line in stream if line.strip()]


def quaternion_from_matrix(R):
    """Scalar-last unit quaternion (w >= 0) of the rotation matrix R (Shepperd's method)."""
    R = np.asarray(R, dtype=float)
    trace = np.trace(R)
    candidates = np.array([R[0, 0], R[1, 1], R[2, 2], trace])
    k = int(np.argmax(candidates))
    if k == 3:
        w = 0.5 * np.sqrt(1.0 + trace)
        q = np.array([(R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w), w])
    else:
        i, j, m = k, (k + 1) % 3, (k + 2) % 3
        s = 0.5 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[m, m])
        q = np.empty(4)
        q[i] = s
        q[j] = (R[j, i] + R[i, j]) / (4 * s)
        q[m] = (R[m, i] + R[i, m]) / (4 * s)
        q[3] = (R[m, j] - R[j, m]) / (4 * s)
    q /= np.linalg.norm(q)
    return q if q[3] >= 0 else -q


def timed(call, *args, **kwargs):
    """(result, milliseconds) of ``call(*args, **kwargs)``: the solver call alone is timed."""
    start = time.perf_counter_ns()
    result = call(*args, **kwargs)
    return result, (time.perf_counter_ns() - start) / 1e6


def run_frames(frames, solve, out_path, progress_label):
    """Call ``solve(frame) -> (status, R_IS or None, matches, solve_ms, method)`` on every frame.

    ``solve`` times the solver call alone with :func:`timed` (input conversion excluded); the first
    frame is solved once more before the timed pass (warm-up: lazy initialisation is not a solve).
    A solver exception becomes status "error" with its message, never a crash of the run.
    """
    if frames:
        try:
            solve(frames[0])
        except Exception:  # reported by the timed pass below
            pass
    with open(out_path, "w") as out:
        for n, frame in enumerate(frames):
            try:
                status, R_IS, matches, solve_ms, method = solve(frame)
                reason = None
            except Exception as error:  # a peer's failure is a measured outcome, not a harness crash
                status, R_IS, matches, solve_ms, method = "error", None, [], None, None
                reason = "".join(traceback.format_exception_only(type(error), error)).strip()
            record = {
                "id": frame["id"],
                "status": status,
                "q_IS": None if R_IS is None else [float(x) for x in quaternion_from_matrix(R_IS)],
                "matches": [[int(i), int(h)] for i, h in matches],
                "solve_ms": solve_ms,
                "mode": "tracking" if "prior_q_IS" in frame else "lost_in_space",
                "method": method,
            }
            if reason is not None:
                record["reason"] = reason
            out.write(json.dumps(record) + "\n")
            if (n + 1) % 250 == 0:
                print(f"  {progress_label}: {n + 1}/{len(frames)} frames", flush=True)


def write_meta(out_path, **fields):
    """Write ``fields`` (e.g. ``setup_ms``: database or kernel loading, timed apart from the solves) to
    ``<out_path>.meta.json`` beside the results."""
    with open(str(out_path) + ".meta.json", "w") as stream:
        json.dump(fields, stream)


def nearest_indices(points, targets):
    """Index into ``points`` (N, 2) of the nearest point to each of ``targets`` (M, 2)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    targets = np.asarray(targets, dtype=float).reshape(-1, 2)
    d2 = np.sum((targets[:, None, :] - points[None, :, :]) ** 2, axis=-1)
    return np.argmin(d2, axis=1)
