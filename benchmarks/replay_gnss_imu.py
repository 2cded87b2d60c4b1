"""The car drive of rtklibexplorer/GNSS_IMU replayed with GNSS outages of 10-60 s: navsim's replay (its strapdown INS
and navigation filter, aided by the RTK fixes outside the outages) with the scenario's ZUPT and non-holonomic
constraint and without them, a free INS (no aiding after the alignment) and the
peer's own loosely coupled filter on the same outages, each one's horizontal error against the held-out RTK fixes
(max and RMS per outage) and its wall time.

Data: examples/data/gnss_imu_drive_0708 (100 Hz MEMS IMU on a car roof, RTK fixes at 4 Hz, 545 s), the replay file
scenarios/replay_car_drive_0708.toml (outages of 10, 20, 30, 45 and 60 s, 40 s of aiding between them). The peer
(BSD-3-Clause) runs in its own venv through benchmarks/peers/gnss_imu_runner.py, with its ZUPT on (its default) and
off, its velocity matching off (it rewrites a coast after its end); its error is its solution (at the IMU rate, at
the antenna) interpolated to the reference fixes' times. Ours is the solution before the update at the fix epoch.

    python3 -m venv /tmp/peer && /tmp/peer/bin/pip install numpy scipy matplotlib
    git -C MIRROR archive HEAD src | tar -x -C /tmp/gnss_imu      # the peer's src/ (commit 8235ee6)
    python benchmarks/replay_gnss_imu.py [--peer-src /tmp/gnss_imu/src] [--peer-python /tmp/peer/bin/python] [--repeats 3]

Prints a table and writes benchmarks/results/replay_gnss_imu.json. Asserts nothing.
"""

import argparse
import json
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from navsim.earth.wander import ned_offset  # noqa: E402
from navsim.replay import fixes, output, run, scenario  # noqa: E402

SCENARIO = ROOT / "scenarios" / "replay_car_drive_0708.toml"
DATA = ROOT / "examples" / "data" / "gnss_imu_drive_0708"
RESULTS = ROOT / "benchmarks" / "results" / "replay_gnss_imu.json"
#: The scenario without its constraints (ZUPT, non-holonomic): navsim as it was before them.
UNCONSTRAINED = ["replay.constraints.zupt=false", "replay.constraints.nhc=false"]


def ours(overrides, repeats):
    """(summary, best wall seconds) of the replay with ``overrides`` (after one warm-up run: the kernels' cache)."""
    output.replay(SCENARIO, overrides)
    walls = []
    for _ in range(repeats):
        started = time.perf_counter()
        _, result, _ = output.replay(SCENARIO, overrides)
        walls.append(time.perf_counter() - started)
    return result, min(walls)


def read_solution(path):
    """(t [s GPST], lat, lon [rad], h [m]) of an RTKLIB solution the peer wrote (its σ columns are zeros)."""
    rows = [line.split() for line in Path(path).read_text().splitlines() if line.strip() and not line.startswith("%")]
    t = np.array([fixes.gpst_seconds(r[0], r[1]) for r in rows])
    values = np.array([[float(v) for v in r[2:5]] for r in rows])
    return t, np.radians(values[:, 0]), np.radians(values[:, 1]), values[:, 2]


def peer(peer_src, peer_python, windows_abs, zupt, work):
    """(rows like ours, wall seconds) of the peer with ``zupt`` on the outages ``windows_abs`` ([start, end] GPST)."""
    windows_file = work / "windows.json"
    windows_file.write_text(json.dumps(windows_abs))
    out = work / f"peer_zupt_{zupt}.pos"
    started = time.perf_counter()
    subprocess.run([peer_python, str(ROOT / "benchmarks" / "peers" / "gnss_imu_runner.py"), peer_src, str(DATA),
                    str(windows_file), str(out), "--zupt", zupt], check=True, capture_output=True, cwd=work)
    return out, time.perf_counter() - started


def errors_of(solution, reference, windows_abs):
    """Per outage: max and RMS horizontal error [m] of a solution (t, lat, lon, h) interpolated to the reference
    fixes' times inside it."""
    t, lat, lon, h = solution
    at = [np.interp(reference.t, t, x) for x in (lat, lon, h)]
    ned = ned_offset(*at, reference.lat, reference.lon, reference.h)
    horizontal = np.hypot(ned[:, 0], ned[:, 1])
    rows = []
    for start, end in windows_abs:
        inside = (reference.t >= start) & (reference.t < end)
        e = horizontal[inside]
        rows.append({"max_horizontal_m": float(e.max()), "rms_horizontal_m": float(np.sqrt(np.mean(e**2)))})
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer-src", default=None, help="the peer's src/ directory (skip the peer without it)")
    parser.add_argument("--peer-python", default="/tmp/peer/bin/python", help="the peer venv's python")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    config = scenario.load(SCENARIO)
    inputs = run.read(config["replay"])
    windows_abs = [[inputs.start + a, inputs.start + a + d] for a, d in inputs.windows]
    results = {"data": "rtklibexplorer/GNSS_IMU data/drive_0708 (commit 8235ee6, BSD-3-Clause)",
               "scenario": str(SCENARIO.relative_to(ROOT)), "machine": platform.processor() or platform.machine(),
               "python": platform.python_version(), "outages_s": inputs.windows.tolist(), "methods": {}}
    constrained, wall = ours([], args.repeats)
    results["methods"]["navsim replay, ZUPT + NHC"] = {"wall_seconds": round(wall, 3), "outages": constrained["outages"],
                                                       "rejected": constrained["updates"]["rejected"],
                                                       "constraints": constrained["constraints"]}
    aided, wall = ours(UNCONSTRAINED, args.repeats)
    results["methods"]["navsim replay"] = {"wall_seconds": round(wall, 3), "outages": aided["outages"],
                                           "rejected": aided["updates"]["rejected"]}
    free, wall = ours(UNCONSTRAINED + ["replay.outages.free_ins=true"], args.repeats)
    results["methods"]["navsim free INS"] = {"wall_seconds": round(wall, 3), "outages": free["outages"]}
    if args.peer_src:
        reference = fixes.read_pos(DATA / "gnss_1934_sf.pos")
        with tempfile.TemporaryDirectory() as work:
            for zupt in ("on", "off"):
                path, wall = peer(args.peer_src, args.peer_python, windows_abs, zupt, Path(work))
                rows = errors_of(read_solution(path), reference, windows_abs)
                results["methods"][f"peer GNSS_IMU, ZUPT {zupt}"] = {"wall_seconds": round(wall, 3), "outages": rows}
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(f"{'method':30s}" + "".join(f"{f'{d:.0f} s max/RMS':>20s}" for _, d in inputs.windows) + f"{'wall s':>10s}")
    for name, method in results["methods"].items():
        cells = "".join(f"{row['max_horizontal_m']:11.2f}/{row['rms_horizontal_m']:<8.2f}" for row in method["outages"])
        print(f"{name:30s}{cells}{method['wall_seconds']:10.2f}")
    print(f"written to {RESULTS}")


if __name__ == "__main__":
    main()
