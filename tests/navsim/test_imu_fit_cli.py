"""`navsim imu fit` through the command line: a CSV log in datasheet units to the [imu] block, JSON and plot; bad
input as one line and exit 2."""

import json
import tomllib

import numpy as np
import pytest

from navsim.sensors.gyro import GyroModel
from startrack import units
from tests.navsim.test_cli import navsim_cli

RATE_HZ = 50.0
ARW_DEG_PER_SQRT_H = 0.2


def _log(samples=2**15, seed=3):
    """t [s], gyro [deg/s], accelerometer [g] of a static unit: white noise only."""
    model = GyroModel(rate_hz=RATE_HZ, arw=float(units.arw_to_si(ARW_DEG_PER_SQRT_H)))
    gyro = model.measure(np.zeros((samples, 3)), seed).omega / units.DEG
    rng = np.random.default_rng(seed)
    force = np.array([0.0, 0.0, -1.0]) + 1e-4 * rng.standard_normal((samples, 3))
    return np.column_stack([np.arange(1, samples + 1) / RATE_HZ, gyro, force])


def _csv(path, table):
    np.savetxt(path, table, delimiter=",", header="time,wx,wy,wz,fx,fy,fz", comments="")
    return path


def test_a_csv_log_gives_the_block_the_summary_and_the_plot(tmp_path):
    log = _csv(tmp_path / "static.csv", _log())
    done = navsim_cli("imu", "fit", log, "--units", "gyro=deg/s,accel=g", "--out", tmp_path / "fit",
                      "--plot", tmp_path / "allan.png")
    assert done.returncode == 0, done.stderr
    block = tomllib.loads((tmp_path / "fit" / "imu.toml").read_text())["imu"]
    summary = json.loads((tmp_path / "fit" / "fit.json").read_text())
    assert block["rate_hz"] == RATE_HZ and summary["format"] == "navsim.imu-fit/1"
    sigma = summary["sensors"]["gyro"]["N"]["sigma"]
    assert block["gyro"]["arw_deg_per_sqrt_h"] == pytest.approx(ARW_DEG_PER_SQRT_H, abs=4.0 * sigma)  # the worst of 3 axes
    white = 1e-4 * units.STANDARD_GRAVITY / np.sqrt(RATE_HZ) * np.sqrt(units.HOUR)  # σ/√rate: white samples, m/s/√h
    assert block["accelerometer"]["vrw_m_per_s_per_sqrt_h"] == pytest.approx(white, rel=0.02)  # 2 %: the worst of three axes, each σ_N ~ 0.3 %
    assert block["gyro"]["rrw_deg_per_h_per_sqrt_h"] == 0.0  # absent from the log: not resolved
    assert (tmp_path / "allan.png").read_bytes()[:4] == b"\x89PNG"
    assert "[imu]" in done.stdout


def _fails(tmp_path, table_or_path, *options, suffix=".csv"):
    path = table_or_path
    if not isinstance(table_or_path, (str, type(tmp_path))):
        path = _csv(tmp_path / f"log{suffix}", table_or_path)
    done = navsim_cli("imu", "fit", path, *options)
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    return done.stderr


def test_a_log_with_nan_rows(tmp_path):
    table = _log(2**10)
    table[[17, 40], 2] = np.nan
    assert "2 rows hold NaN or infinite values (the first is row 18)" in _fails(tmp_path, table)


def test_time_that_does_not_increase(tmp_path):
    table = _log(2**10)
    table[100, 0] = table[98, 0]
    assert "the time is not increasing at row 101" in _fails(tmp_path, table)


def test_an_unknown_unit(tmp_path):
    assert "unknown gyro unit" in _fails(tmp_path, _log(2**10), "--units", "gyro=furlong/s")


def test_a_constant_column(tmp_path):
    table = _log(2**10)
    table[:, 5] = 0.0
    assert "column ay is constant" in _fails(tmp_path, table)


def test_a_missing_file(tmp_path):
    assert "no such file" in _fails(tmp_path, tmp_path / "absent.csv")


def test_a_log_too_short_for_any_cluster(tmp_path):
    assert "too short for the Allan fit" in _fails(tmp_path, _log(10))




def test_a_matlab_file_with_several_variables_needs_its_variable_and_a_skipped_column(tmp_path):
    from scipy import io

    io.savemat(tmp_path / "log.mat", {"imu": _log(2**10), "other": np.zeros(2)})
    assert "holds imu, other; name the log's with --variable" in _fails(tmp_path, tmp_path / "log.mat")
    done = navsim_cli("imu", "fit", tmp_path / "log.mat", "--variable", "imu", "--columns", "skip,gx,gy,gz,skip,skip,skip",
                      "--rate-hz", RATE_HZ, "--units", "gyro=deg/s")
    assert done.returncode == 0, done.stderr
    assert "gyro = {" in done.stdout and "accelerometer" not in done.stdout.split("[imu]")[1]
