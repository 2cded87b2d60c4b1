"""`navsim run`: the command-line contract of docs/design.md, reproducibility and bad input."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import navsim
from tests.support import HANG_S

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "scenarios" / "paper000_high_dynamic.toml"  # vector fidelity: fast


def navsim_cli(*args):
    return subprocess.run([sys.executable, "-m", "navsim.cli", *map(str, args)], capture_output=True,
                          text=True, cwd=ROOT, timeout=HANG_S)


def test_run_writes_summary_and_timeseries(tmp_path):
    out = tmp_path / "run"
    done = navsim_cli("run", DEMO, "--out", out, "--seed", "3", "--set", "duration_s=5")
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    for key in ("scenario", "seed", "duration_s", "attitude_error_rms_arcsec", "cross_boresight_rms_arcsec",
                "roll_rms_arcsec", "bias_error_final_deg_per_h", "nees", "updates", "timing"):
        assert key in summary
    assert "wall_seconds" in summary["timing"]  # a wall-clock figure, reported not asserted (speed: benchmarks/)
    assert summary["seed"] == 3 and summary["duration_s"] == 5.0
    assert set(summary["nees"]) >= {"mean", "fraction_in_band", "band_95"}
    with np.load(out / "timeseries.npz", allow_pickle=False) as data:
        assert {"t", "q_true", "q_est", "P_diag", "bias_true", "bias_est", "nis", "nees"} <= set(data.files)
        assert data["q_est"].shape == (10, 4)  # 5 s at 2 Hz
    assert "cross-boresight" in done.stdout


def test_same_seed_gives_identical_files_at_image_fidelity(tmp_path):
    """Rendering, identification and stacking draw from the seed too; only the timing differs."""
    image = ["--set", "duration_s=3", "--set", "star_sensor.fidelity=image", "--set", "star_sensor.max_stars=10"]
    for name in ("a", "b"):
        assert navsim_cli("run", DEMO, "--out", tmp_path / name, "--seed", "7", *image).returncode == 0
    for name in ("timeseries.npz", "frame.npy", "frame_detections.json", "scenario.json"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name
    a, b = (json.loads((tmp_path / n / "summary.json").read_text()) for n in ("a", "b"))
    assert a.pop("timing") != b.pop("timing") and a == b
    assert (tmp_path / "a" / "timing.npz").is_file()


def test_same_seed_gives_identical_files(tmp_path):
    for name in ("a", "b"):
        assert navsim_cli("run", DEMO, "--out", tmp_path / name, "--seed", "7", "--set", "duration_s=4").returncode == 0
    assert (tmp_path / "a" / "timeseries.npz").read_bytes() == (tmp_path / "b" / "timeseries.npz").read_bytes()
    a, b = (json.loads((tmp_path / n / "summary.json").read_text()) for n in ("a", "b"))
    a.pop("timing"), b.pop("timing")  # wall-clock figures: the one part a seed does not fix
    assert a == b
    assert navsim_cli("run", DEMO, "--out", tmp_path / "c", "--seed", "8", "--set", "duration_s=4").returncode == 0
    assert (tmp_path / "a" / "timeseries.npz").read_bytes() != (tmp_path / "c" / "timeseries.npz").read_bytes()


@pytest.mark.parametrize(
    "args, message",
    [
        (["run", "missing.toml", "--out", "{out}"], "missing.toml: scenario file not found"),
        (["run", DEMO, "--out", "{out}", "--set", "gyro.rate_hz=-1"], "paper000_high_dynamic.toml: gyro.rate_hz: must be > 0"),
        (["run", DEMO, "--out", "{out}", "--set", "gyro.colour=1"], "paper000_high_dynamic.toml: gyro.colour: unknown key"),
        (["run", DEMO, "--out", "{out}", "--set", "star_sensor.fov_deg=0"], "star_sensor.fov_deg: must be > 0"),
        (["run", DEMO, "--out", "{out}", "--set", "duration_s=nan"], "duration_s: must be a finite number"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(tmp_path, args, message):
    done = navsim_cli(*[str(a).replace("{out}", str(tmp_path / "o")) for a in args])
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert done.stderr.strip().count("\n") == 0
    assert message in done.stderr


def test_python_api_returns_summary_and_arrays():
    result = navsim.run(DEMO, seed=2, overrides={"duration_s": 3.0, "star_sensor.measurement": "attitude"})
    assert result.summary["measurement"] == "attitude"
    assert result.series["q_est"].shape == (6, 4)
    again = navsim.run(DEMO, seed=2, overrides={"duration_s": 3.0, "star_sensor.measurement": "attitude"})
    np.testing.assert_array_equal(result.series["q_est"], again.series["q_est"])
