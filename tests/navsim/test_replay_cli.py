"""`navsim replay`: the run directory it writes, and bad input, each one line on stderr and exit status 2."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pypdf
import pytest

from tests.support import HANG_S

ROOT = Path(__file__).resolve().parents[2]
DRIVE = ROOT / "scenarios" / "replay_car_drive_0708.toml"
DATA = ROOT / "examples" / "data" / "gnss_imu_drive_0708"
SHORT = ["--set", "replay.imu.duration_s=100", "--set", "replay.outages.schedule.lengths_s=[20.0]"]


def navsim_cli(*args):
    return subprocess.run([sys.executable, "-m", "navsim.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, timeout=HANG_S)


def test_replay_writes_its_run_directory(tmp_path):
    done = navsim_cli("replay", DRIVE, "--out", tmp_path / "r", *SHORT, "--report")
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["kind"] == "replay" and summary["outages"][0]["duration_s"] == 20.0
    assert summary["outages"][0]["fixes"] == 80 and summary["imu"]["gaps"] == 0
    with np.load(tmp_path / "r" / "timeseries.npz", allow_pickle=False) as series:
        assert {"t", "lat", "lon", "h", "error_ned", "sigma_ned", "held_out", "outage"} <= set(series.files)
        assert series["held_out"].sum() == 80
    assert json.loads((tmp_path / "r" / "navsim-output.json").read_text()) == {"kind": "replay"}
    assert "outage    60.0 s +  20.0 s" in done.stdout
    text = pypdf.PdfReader(tmp_path / "r" / "report.pdf").pages[0].extract_text()
    assert "Replay: replay_car_drive_0708" in text and "60.0 20.0 80" in text  # the outage's row of the table


def _copy(tmp_path, imu_rows=None, pos_lines=None):
    """The drive's replay file and data copied into ``tmp_path``, the IMU log's rows or the solution's lines edited."""
    for name in ("imu_1934.csv", "imu_1934.csv.tag", "gnss_1934_sf.pos"):
        shutil.copy(DATA / name, tmp_path / name)
    if imu_rows is not None:
        lines = (tmp_path / "imu_1934.csv").read_text().splitlines()
        (tmp_path / "imu_1934.csv").write_text("\n".join(imu_rows(lines)) + "\n")
    if pos_lines is not None:
        lines = (tmp_path / "gnss_1934_sf.pos").read_text().splitlines()
        (tmp_path / "gnss_1934_sf.pos").write_text("\n".join(pos_lines(lines)) + "\n")
    text = DRIVE.read_text().replace("../examples/data/gnss_imu_drive_0708/", "")
    (tmp_path / "replay.toml").write_text(text)
    return tmp_path / "replay.toml"


def _nan_row(lines):
    return lines[:3] + ["nan,0.027,1.013,-0.671,3.082,0.198,261936"] + lines[4:]


def _time_back(lines):
    return lines[:3] + [lines[3].rsplit(",", 1)[0] + ",261900"] + lines[4:]


def _constant_gyro_z(lines):
    return [",".join(line.split(",")[:5] + ["0.5", line.split(",")[6]]) for line in lines]


def _float_only(lines):
    return [line for line in lines if line.startswith("%") or line.split()[5] != "1.0000000"]


@pytest.mark.parametrize("edit, extra, message", [
    ({"imu_rows": _nan_row}, [], "imu_1934.csv: row 4 is not finite"),
    ({"imu_rows": _time_back}, [], "imu_1934.csv: time not increasing at row 4"),
    ({"imu_rows": _constant_gyro_z}, [], "imu_1934.csv: column gyro_z is constant over the whole log"),
    ({}, ["--set", "replay.imu.accel_unit=furlong"], "accel_unit: unknown unit 'furlong' for rates"),
    ({}, ["--set", "replay.imu.file=none.csv"], "none.csv: IMU log not found"),
    ({"pos_lines": _float_only}, [], "gnss_1934_sf.pos: no fixes of quality 1 (qualities present: 2)"),
    ({}, ["--set", "replay.outages.schedule.first_s=520"], "is outside the recording after its alignment"),
    ({}, ["--set", "replay.outages.schedule.first_s=10"], "is outside the recording after its alignment"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, edit, extra, message):
    done = navsim_cli("replay", _copy(tmp_path, **edit), "--out", tmp_path / "out", *extra)
    assert done.returncode == 2, done.stdout
    assert "Traceback" not in done.stderr and done.stderr.strip().count("\n") == 0
    assert message in done.stderr


def test_missing_replay_file(tmp_path):
    done = navsim_cli("replay", tmp_path / "missing.toml", "--out", tmp_path / "out")
    assert done.returncode == 2 and "missing.toml: scenario file not found" in done.stderr
