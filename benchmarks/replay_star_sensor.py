"""A replay with a simulated star sensor against one without, over a long GNSS outage: the attitude (heading above
all) and horizontal error of each against the truth of a synthetic recording.

The recording is the replay tests' (tests/navsim/replay_helpers.py, seeded): the project's own truth of a 170 s car
drive (20 s at rest, two turns), its exact IMU increments with constant biases and white noise the filter's model,
4 Hz fixes of 2 cm σ and the truth's attitude at 10 Hz as the reference (``reference.csv``; an honest reference: the
simulation's truth, not a replay's own solution). One outage of 120 s from 40 s. The star sensor: attitude fixes of
5" cross-boresight and 40" about a boresight at the zenith, at 1 and at 10 Hz, seed 0; "not applied" draws the same
frames but does not use them (the replay without a star sensor: the same solution).

    python benchmarks/replay_star_sensor.py [--write DIR]   # DIR keeps the recording and its replay.toml

Prints a table and writes benchmarks/results/replay_star_sensor.json. Asserts nothing.
"""

import argparse
import json
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from navsim.replay import output
from tests.navsim import replay_helpers as rh

RESULTS = ROOT / "benchmarks" / "results" / "replay_star_sensor.json"
OUTAGE = "windows = [{start_s = 40.0, duration_s = 120.0}]"
#: The cases; the last one's replay.toml is the one ``--write`` leaves.
CASES = {"not applied": {"rate_hz": 1.0, "apply": False}, "10 Hz": {"rate_hz": 10.0}, "1 Hz": {"rate_hz": 1.0}}


def case(directory, imu, fixes, reference, keys):
    """(the case's row, wall seconds of its second run: the first compiles the kernels)."""
    path = rh.replay_toml(directory, imu, fixes, outages=OUTAGE, extra=rh.star_table(reference, **keys))
    output.replay(path)
    started = time.perf_counter()
    _, result, series = output.replay(path)
    wall = time.perf_counter() - started
    inside = series["star_outage"] == 0
    error = np.degrees(np.abs(series["star_attitude_error"][inside]))
    block = result["star_sensor"]
    return {"frames": block["frames"], "accepted": block["accepted"], "rejected": block["rejected"],
            "nis_mean": block["nis_mean"], "outage_max_heading_error_deg": float(error[:, 2].max()),
            "outage_max_tilt_error_deg": float(error[:, :2].max()),
            "outage_heading_sigma_end_deg": block["outages"][0]["heading_sigma_end_deg"],
            "outage_max_horizontal_m": result["outages"][0]["max_horizontal_m"],
            "outage_sigma_horizontal_end_m": result["outages"][0]["sigma_horizontal_end_m"], "wall_seconds": wall}, path


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", type=Path, help="keep the recording and its replay.toml in this directory")
    args = parser.parse_args()
    directory = args.write or Path(tempfile.mkdtemp(prefix="replay-star-"))
    directory.mkdir(parents=True, exist_ok=True)
    truth = rh.car_truth()
    imu, fixes = rh.write_recording(directory, truth)
    reference = rh.write_reference(directory, truth)
    rows = {}
    for name, keys in CASES.items():
        rows[name], path = case(directory, imu, fixes, reference, keys)
    print(f"{'star sensor':12s} {'frames':>6s} {'NIS':>5s} {'heading max':>12s} {'tilt max':>9s} {'heading 1σ':>11s} "
          f"{'horiz. max':>10s} {'wall':>6s}")
    for name, r in rows.items():
        nis = "-" if r["nis_mean"] is None else f"{r['nis_mean']:.2f}"
        print(f"{name:12s} {r['frames']:6d} {nis:>5s} {r['outage_max_heading_error_deg']:10.4f}° "
              f"{r['outage_max_tilt_error_deg']:8.4f}° {r['outage_heading_sigma_end_deg']:10.4f}° "
              f"{r['outage_max_horizontal_m']:8.2f} m {r['wall_seconds']:5.2f} s")
    if args.write:
        print(f"the recording and {path.name} (the last case's) are in {directory}")
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps({"outage_s": [40.0, 120.0], "cases": rows, "machine": platform.machine(),
                                   "python": platform.python_version()}, indent=2) + "\n")


if __name__ == "__main__":
    main()
