"""`navsim imu fit` end to end on long static logs, beside allantools' overlapping Allan deviation of the same data.

Logs of the tactical gyro and accelerometer presets (navsim.sensors, seeded), written as .npy (t, 3 gyro axes in
deg/s, 3 accelerometer axes in m/s²): a 3-hour 100 Hz log (1.08e6 samples x 6 axes) and a 1e7-sample one. Measured:
- the command end to end (`navsim imu fit LOG --units gyro=deg/s --out DIR --plot FILE.pdf` in a fresh process:
  start-up, reading, the Allan deviation, the covariance of the estimates, the fit, the block, the plot), the
  median of ``--repeats`` after one run that loads the compiled kernels;
- its Allan deviation alone (all six axes at the octave cluster times, `navsim.inertial_log.allan`);
- allantools.oadev of the same six axes at the same cluster times.

    python benchmarks/imu_fit.py [--repeats 3]

Prints a table and writes benchmarks/results/imu_fit.json (with the machine's load average: the cores may be
shared). Asserts nothing.
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import allantools
import numpy as np

from navsim.inertial_log import allan
from navsim.sensors.accelerometer import AccelerometerModel
from navsim.sensors.gyro import GyroModel
from startrack import units

ROOT = Path(__file__).resolve().parents[1]
RATE_HZ = 100.0
LOGS = {"3 h at 100 Hz": 1_080_000, "1e7 samples": 10_000_000}


def write_log(path, samples):
    gyro = GyroModel.preset("tactical", RATE_HZ).measure(np.zeros((samples, 3)), 1).omega / units.DEG
    force = AccelerometerModel.preset("tactical", RATE_HZ).measure(np.tile([0.0, 0.0, -9.8], (samples, 1)), 2).force
    np.save(path, np.column_stack([np.arange(1, samples + 1) / RATE_HZ, gyro, force]))
    return np.column_stack([gyro * units.DEG, force])


def command_seconds(log, out, repeats):
    """Median wall seconds of the command in a fresh process (after one warm run)."""
    argv = [sys.executable, "-m", "navsim.cli", "imu", "fit", str(log), "--units", "gyro=deg/s", "--out", str(out),
            "--plot", str(out.with_suffix(".pdf"))]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    subprocess.run(argv, check=True, capture_output=True, env=env, cwd=ROOT)
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True, env=env, cwd=ROOT)
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def adev_seconds(axes):
    """(ours, allantools') seconds of the six axes' Allan deviation, and their largest relative difference."""
    sizes = allan.cluster_sizes(axes.shape[0])
    allan.overlapping_avar(axes[:1000, 0], RATE_HZ, allan.cluster_sizes(1000))  # the kernel loaded
    started = time.perf_counter()
    ours = [np.sqrt(allan.overlapping_avar(axes[:, k], RATE_HZ, sizes)) for k in range(6)]
    ours_s = time.perf_counter() - started
    started = time.perf_counter()
    theirs = [allantools.oadev(axes[:, k], rate=RATE_HZ, data_type="freq", taus=sizes / RATE_HZ)[1] for k in range(6)]
    theirs_s = time.perf_counter() - started
    return ours_s, theirs_s, float(max(np.max(np.abs(a / b - 1.0)) for a, b in zip(ours, theirs)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, samples in LOGS.items():
            log = Path(tmp) / f"log_{samples}.npy"
            axes = write_log(log, samples)
            ours_s, theirs_s, difference = adev_seconds(axes)
            rows[label] = {"samples": samples, "axes": 6,
                           "command_s": command_seconds(log, Path(tmp) / f"fit_{samples}", args.repeats),
                           "adev_s": ours_s, "allantools_oadev_s": theirs_s, "adev_max_relative_difference": difference}
            print(f"{label:<14} {samples:>9} samples x 6: navsim imu fit {rows[label]['command_s']:6.2f} s end to end; "
                  f"Allan deviation {ours_s:5.2f} s, allantools oadev {theirs_s:6.2f} s (largest difference "
                  f"{difference:.1e})", flush=True)
    result = {"benchmark": "imu_fit", "rate_hz": RATE_HZ, "repeats": args.repeats, "logs": rows,
              "machine": {"python": platform.python_version(), "processor": platform.processor() or platform.machine(),
                          "cpus": os.cpu_count(), "load_average_1_5_15_min": os.getloadavg()}}
    path = ROOT / "benchmarks" / "results" / "imu_fit.json"
    path.write_text(json.dumps(result, indent=2) + "\n")
    print(f"written to {path}")


if __name__ == "__main__":
    main()
