"""The reports of star-aided navigation (SINS/CNS): the run report's "Star sensor aiding" section
(the horizontal error against the analytic-horizon floor, the aberration, the mounting estimate, the
observability of each state) and `navsim budget` (one error source at a time in the truth under the
scenario's own filter: the parts add up to the total; its accelerometer-bias and gravity parts against
eq. (1) in straight and level flight over one Schuler period)."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from navsim import cli
from navsim.kinds import resolve_scenario
from navsim.navigation import run as ins_simulation
from navsim.truth.sky import SkyTruth
from startrack.base import units
from startrack.base.errors import InputError
from startrack.geometry import rotation as rot
from tests.support import pdf_text, run_cli

#: Straight and level at 100 m/s for one Schuler period (5063 s; the Schuler mean is then the floor
#: plus what the oscillation leaves), IMU at 10 Hz, star fixes at 1 Hz, a baro for the vertical
#: channel, a constant deflection of the vertical, a mounting error.
LEVEL = """
name = "level_sins_cns"
seed = 3
epoch_utc = "2024-01-15T20:00:00"
settle_s = 0.0

[trajectory]
start = { lat_deg = 45.0, lon_deg = 7.0, height_m = 1000.0, speed_m_per_s = 100.0, heading_deg = 30.0 }
segments = [{ kind = "straight", duration_s = 5063.0 }]

[imu]
rate_hz = 10.0
gyro = { bias_turn_on_deg_per_h = 0.03, arw_deg_per_sqrt_h = 0.001 }
accelerometer = { bias_turn_on_micro_g = 100.0, vrw_m_per_s_per_sqrt_h = 2.94e-4 }

[baro]
rate_hz = 1.0
noise_sigma_m = 5.0

[gravity]
model = "constant"
xi_arcsec = 5.0
eta_arcsec = -3.0

[star_sensor]
measurement = "attitude"
rate_hz = 1.0
fov_deg = 16.0
attitude_sigma_cross_arcsec = 5.0
attitude_sigma_roll_arcsec = 30.0
mounting_rotvec_deg = [180.0, 0.0, 0.0]
misalignment_arcsec = [30.0, -20.0, 60.0]

[filter]
initial_tilt_sigma_arcsec = 30.0
initial_heading_sigma_deg = 0.1
initial_velocity_sigma_m_per_s = 0.01
initial_position_sigma_m = 1.0
initial_mounting_sigma_arcsec = 120.0
"""


@pytest.fixture
def level(tmp_path):
    path = tmp_path / "level.toml"
    path.write_text(LEVEL, encoding="utf-8")
    return path


def test_run_report_has_the_star_sensor_section(level, tmp_path, capsys):
    out = tmp_path / "run"
    status, err = run_cli(cli.main, ["run", level, "--out", out, "--set", "duration_s=600", "--report"], capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    floor = summary["celestial"]["horizon_floor"]
    text, pages = pdf_text(out / "report.pdf")
    assert "Star sensor aiding" in text and "analytic-horizon floor of eq. (1)" in text
    assert f"mean horizontal error is {floor['position_error_mean_m']:.2f} m against a floor of {floor['floor_m']:.2f} m" in text
    assert "position error if uncorrected" in text and "aberration corrected yes" in text
    assert "mounting μ x arcsec 30.00" in text and "Star-sensor mounting error μ: truth" in text
    assert "Observability: σ_end/σ_0 per error state" in text and "The least-observed directions" in text
    assert "Reduced below 10 %:" in text


def test_truth_off_switches_the_truth_not_the_filter(level):
    """``truth_off`` zeroes the named sources in the truth alone: the filter's models (its Q and P0
    come from the gyro and accelerometer models, its R from the star record) are the scenario's, and
    every other draw is the same (the gyro record, the star noise)."""
    scenario = resolve_scenario(level, {"duration_s": 60.0})
    whole = ins_simulation.prepare(scenario)
    quiet = ins_simulation.prepare(scenario, truth_off={"accel_bias", "gravity", "mounting", "initial", "aiding"})
    assert (quiet.gyro, quiet.accel) == (whole.gyro, whole.accel)
    a, b = (ins_simulation.simulate(p, 11).series for p in (whole, quiet))
    assert np.array_equal(a["error_sigma_initial"], b["error_sigma_initial"])  # P0
    assert np.abs(a["accel_bias_true"]).max() > units.micro_g_to_si(10.0) and not b["accel_bias_true"].any()
    assert np.array_equal(a["gyro_bias_true"], b["gyro_bias_true"])
    assert a["gravity_disturbance_true"].any() and not b["gravity_disturbance_true"].any()
    assert a["mounting_true"].any() and not b["mounting_true"].any()
    assert np.linalg.norm(a["position_error_m"][0]) > 0.1 > 100.0 * np.linalg.norm(b["position_error_m"][0])  # x0, baro
    sky = SkyTruth.of(whole.truth, whole.orientation, whole.grid.frame_k)
    noisy, exact = (ins_simulation._star_run(p, sky, np.random.SeedSequence(5), None)[0].record()
                    for p in (whole, dataclasses.replace(whole, truth_off=frozenset({"star_noise"}))))
    assert np.array_equal(noisy.R_S, exact.R_S)  # the filter's R
    noise = units.rad_to_arcsec(rot.to_rotation_vector(rot.multiply(rot.conjugate(exact.fixes), noisy.fixes)))
    assert np.sqrt(np.mean(noise ** 2, axis=0)) == pytest.approx([5.0, 5.0, 30.0], rel=0.2)
    with pytest.raises(InputError, match="unknown source"):
        ins_simulation.prepare(scenario, truth_off={"baro"})


@pytest.mark.slow  # 20 runs of a Monte Carlo budget (~1 min); the covariance budget's tests stay in the default suite
def test_budget_parts_add_up_and_follow_eq_1(level, tmp_path, capsys):
    """Two runs per source under the scenario's own filter, the mounting calibrated (ignored by the
    filter, zero in the truth): in straight and level flight over one Schuler period the parts add up —
    per run the parts' Schuler-mean error vectors sum to the total's (measured: 0.2 m in 1.1 km), and
    over the runs their root-sum-square is the total's within 15 % (measured: 6 % for the Schuler mean;
    the runs' cross terms, ∇ against the constant deflection, are what remains) — and the
    accelerometer-bias part's Schuler-mean error is R·∇/g, the gravity part's R times the deflection
    (measured: 1 % and 0.5 %; asserted within 15 %). A second call resumes (runs nothing again)."""
    out = tmp_path / "budget"
    argv = ["budget", level, "--out", out, "--method", "montecarlo", "--runs", "2", "--workers", "1", "--set",
            'filter.mounting="ignore"',
            "--set", "star_sensor.misalignment_arcsec=[0.0, 0.0, 0.0]"]
    status, err = run_cli(cli.main, argv, capsys)
    assert status == 0, err
    budget = json.loads((out / "budget.json").read_text())
    parts = {row["key"]: row for row in budget["parts"]}
    assert set(parts) == {"accel_bias", "gravity", "star_noise", "mounting", "aberration", "refraction",
                          "refraction_correction", "inertial", "initial", "aiding"}
    assert parts["mounting"]["status"] == "absent" and parts["refraction"]["status"] == "absent"
    assert parts["accel_bias"]["truth_off"] == ["aiding", "gravity", "inertial", "initial", "mounting", "refraction",
                                                "star_noise"]
    for key in ("accel_bias", "gravity"):
        assert parts[key]["schuler_mean_m"] == pytest.approx(parts[key]["prediction_m"], rel=0.15), key
    assert parts["accel_bias"]["prediction_m"] > 300.0 and parts["gravity"]["prediction_m"] > 100.0
    rss, total = budget["root_sum_square"], budget["total"]
    assert total["runs"] == 2 and "aberration" not in rss["parts"] and "refraction_correction" not in rss["parts"]
    assert rss["ratio_to_total"]["schuler_mean_m"] == pytest.approx(1.0, abs=0.15)
    assert rss["ratio_to_total"]["rms_m"] == pytest.approx(1.0, abs=0.15)
    assert budget["superposition"]["residual_m"] < 0.01 * budget["superposition"]["total_m"]
    campaign = json.loads((out / "parts" / "initial" / "campaign.json").read_text())
    assert campaign["truth_off"] == ["accel_bias", "aiding", "gravity", "inertial", "mounting", "refraction", "star_noise"]
    assert campaign["scenario_data"]["filter"] == json.loads((out / "parts" / "total" / "campaign.json").read_text())[
        "scenario_data"]["filter"]
    text, _ = pdf_text(out / "budget.pdf")
    assert "Error budget: level_sins_cns" in text and "root-sum-square of the parts" in text
    assert f"its ratio to the total {rss['ratio_to_total']['schuler_mean_m']:.3f}" in text
    # the covariance budget part by part against these runs: each source alone under the same filter
    compared = tmp_path / "covariance_budget"
    status, err = run_cli(cli.main, ["budget", level, "--out", compared, "--compare", out, *argv[10:]], capsys)
    assert status == 0, err
    comparison = json.loads((compared / "budget.json").read_text())["comparison"]
    assert set(comparison) == {key for key, row in parts.items() if row["status"] == "run"} | {"total"}
    for key, part in comparison.items():
        assert part["runs"] == 2 and part["inside_family"] == part["checks"], key
    assert "Against the Monte Carlo budget" in pdf_text(compared / "budget.pdf")[0]
    mtime = (out / "parts" / "total" / "runs" / "run_00000" / "summary.json").stat().st_mtime_ns
    status, err = run_cli(cli.main, argv, capsys)
    assert status == 0, err
    assert (out / "parts" / "total" / "runs" / "run_00000" / "summary.json").stat().st_mtime_ns == mtime


MONTE_CARLO = ["--method", "montecarlo"]


@pytest.mark.parametrize("scenario, extra, message", [
    ("base_constant.toml", MONTE_CARLO, "not a navigation scenario"),
    ("base_navigation.toml", MONTE_CARLO, "no [star_sensor] table"),
    ("base_sins_cns.toml", [*MONTE_CARLO, "--runs", "0"], "--runs must be from 1"),
    ("base_sins_cns.toml", [*MONTE_CARLO, "--workers", "0"], "--workers must be at least 1"),
    ("base_sins_cns.toml", ["--runs", "5"], "--runs: Monte Carlo options"),
    ("base_sins_cns.toml", ["--method", "guess"], "--method guess: must be one of covariance, montecarlo"),
    ("base_sins_cns.toml", [*MONTE_CARLO, "--compare", "."], "--compare: checks a covariance budget against a Monte Carlo one"),
    ("base_sins_cns.toml", ["--compare", "."], "not a Monte Carlo budget directory"),
])
def test_budget_bad_input(scenario, extra, message, tmp_path, capsys):
    out = tmp_path / "budget"
    path = Path(__file__).resolve().parent / "data" / scenario
    status, err = run_cli(cli.main, ["budget", path, "--out", out, *extra], capsys)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
