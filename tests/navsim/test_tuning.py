"""`navsim tune`: fitting Q and R restores consistency and recovers a known mis-tuning."""

import subprocess
import sys
from pathlib import Path

import pytest

from navsim.campaign.tuning import tune
from tests.support import HANG_S

ROOT = Path(__file__).resolve().parents[2]


def mistuned(base):
    base["duration_s"] = 120.0
    base["star_sensor"]["rate_hz"] = 1.0
    base["filter"]["arw_deg_per_sqrt_h"] = 0.05  # the gyro flown has 0.1: Q is 4x too small
    return base


def test_tune_recovers_the_arw_ratio_and_restores_consistency(base_scenario):
    result = tune(mistuned(base_scenario), runs=20)
    first, last = result.steps[0], result.steps[-1]
    assert first.nees_per_dof > 2.0
    assert last.nees_per_dof == pytest.approx(1.0, abs=0.1)
    assert last.nis_per_dof == pytest.approx(1.0, abs=0.1)
    assert last.process_noise_scale == pytest.approx(4.0, rel=0.2)  # (0.1 / 0.05)²
    assert last.measurement_noise_scale == pytest.approx(1.0, rel=0.1)
    assert last.errors["cross-boresight RMS"][0] < first.errors["cross-boresight RMS"][0]


def test_tune_command_prints_the_settings_to_use():
    done = subprocess.run([sys.executable, "-m", "navsim.cli", "tune", "scenarios/paper000_high_dynamic.toml", "--runs", "2",
                           "--evaluations", "3", "--set", "duration_s=5"], cwd=ROOT, capture_output=True, text=True,
                          timeout=HANG_S)
    assert done.returncode == 0, done.stderr
    assert "use: --set filter.process_noise_scale=" in done.stdout
    assert "before: NEES/dof" in done.stdout
