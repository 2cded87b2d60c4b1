"""Linear covariance analysis of navigation scenarios (navsim.navigation.covariance): a filter whose model is
the truth's gets its own P back, the sources' shares add up to the total, and a mismodelled filter's true
RMS departs from its σ as Monte Carlo runs of the same scenario do."""

import json
from pathlib import Path

import numpy as np
import pytest

from navsim import cli
from navsim.kinds import resolve_scenario
from navsim.simulation import covariance
from navsim.output import read_npz
from navsim.simulation import run_batch
from tests.support import pdf_text, run_cli

ROOT = Path(__file__).resolve().parents[2]

SCENARIO = "scenarios/sins_cns_aircraft_vector.toml"
#: Ten minutes of straight flight at a 50 Hz IMU (one covariance interval per 1 Hz frame).
SHORT = ("duration_s=600", "imu.rate_hz=50", "filter.covariance_interval=50")
#: Equal to the filter's model: no mounting error (the filter ignores the mounting) and no other truth-only term.
MATCHED = (*SHORT, "filter.mounting=ignore", "star_sensor.misalignment_arcsec=[0, 0, 0]")
#: Monte Carlo runs of the checks against the runs.
RUNS = 40


@pytest.mark.parametrize("scenario, overrides", [(SCENARIO, MATCHED), ("scenarios/paper000_high_dynamic.toml", ("duration_s=30",))])
def test_a_filter_whose_model_is_the_truth_gets_its_own_covariance(scenario, overrides):
    analysis = covariance(scenario, overrides)
    # every truth state is the filter's but the mounting (zero, never excited): the same recursion on the same
    # numbers, so the true covariance is the filter's to rounding
    assert np.allclose(analysis.diag_f[0], analysis.filter_diag, rtol=1e-9, atol=0.0)
    scale = np.sqrt(np.einsum("kii,kjj->kij", analysis.filter_block, analysis.filter_block))
    assert np.max(np.abs(analysis.block[0] - analysis.filter_block) / scale) < 1e-9
    assert np.allclose(analysis.nees, analysis.nees_dof, rtol=1e-9)


def test_the_sources_shares_add_up_to_the_total():
    scenario = resolve_scenario(SCENARIO, SHORT)
    total, split = covariance(scenario), covariance(scenario, split=True)
    assert split.sources == ("initial", "inertial", "accel_bias", "gravity", "mounting", "star_noise", "aiding")
    # one linear recursion driven by each source alone: the parts add up to rounding
    assert np.allclose(split.diag_f.sum(axis=0), total.diag_f[0], rtol=1e-9)
    assert np.allclose(split.mean.sum(axis=0), total.mean[0], rtol=1e-9, atol=1e-15)
    for name, share in split.mean_square().items():
        assert np.allclose(share.sum(axis=0), total.mean_square()[name][0], rtol=1e-9), name
    # the mounting's error is the scenario's given value: a mean, no variance
    mounting = split.sources.index("mounting")
    assert np.all(split.diag_t[mounting] == 0.0) and np.any(split.mean[mounting] != 0.0)


def _runs(scenario, overrides):
    return [result.series for result in run_batch(scenario, range(RUNS), overrides, threads=2)]


ATTITUDE = "scenarios/paper000_high_dynamic.toml"
#: The gate at its widest: the analysis fuses every star, as a run does once its filter has converged (with the
#: default gate the first frames' stars are rejected while an ignored mounting's error exceeds the prior σ: the runs
#: then converge late, which no linear analysis follows).
WIDE_GATE = "filter.gate_probability=0.999999999"


@pytest.mark.parametrize("scenario, overrides, departs", [
    # an uncalibrated mounting the filter ignores: the star sensor's 30", -45", 90" misalignment tilts and turns
    # the attitude far beyond the filter's σ
    pytest.param(SCENARIO, (*SHORT, "filter.mounting=ignore", WIDE_GATE), ("tilt", "heading"),
                 marks=pytest.mark.slow),  # 40 runs each (~15 s): the attitude kind's case stays in the default suite
    # a filter that trusts its measurements four times too much (every σ halved): the baro's error, taken for
    # half of what it is, leaves the vertical channel's true error well above the filter's σ (the attitude, held
    # by the mounting's and the level's uncertainty in straight flight, hardly moves)
    pytest.param(SCENARIO, (*SHORT, "filter.measurement_noise_scale=0.5", WIDE_GATE), ("vertical_position", "vertical_velocity"),
                 marks=pytest.mark.slow),
    # the attitude kind: a 20", -30", 40" mounting error the MEKF does not carry, over 000's high-dynamic profile
    (ATTITUDE, ("duration_s=30", "settle_s=3", "star_sensor.misalignment_arcsec=[20.0, -30.0, 40.0]", WIDE_GATE),
     ("attitude", "cross_boresight", "roll")),
])
def test_a_mismodelled_filter_departs_from_its_sigma_as_monte_carlo_does(scenario, overrides, departs):
    checked = resolve_scenario(scenario, overrides)
    analysis = covariance(checked)
    comparison = analysis.compare(_runs(scenario, overrides))
    # every RMS of the runs inside the family-wise 95 % band of a RUNS-run RMS around the analysis's
    assert comparison["inside_family"] == comparison["checks"]
    summary = analysis.summary(checked)
    for name in departs:
        assert summary["quantities"][name]["true_over_filter_final"] > 1.3, name
        final = comparison["quantities"][name]["rows"][-1]
        sigma = summary["quantities"][name]["filter_sigma_final"]
        assert final["montecarlo"] / sigma > 1.3, name


LEVEL = Path(__file__).resolve().parent / "data" / "sins_cns_level.toml"
SHORT_LEVEL = ("--set", "duration_s=600", "--set", "settle_s=60", "--set", 'filter.mounting="ignore"')


def test_covariance_command_writes_the_analysis_and_its_report(tmp_path, capsys):
    out = tmp_path / "cov"
    status, err = run_cli(cli.main, ["covariance", LEVEL, "--out", out, *SHORT_LEVEL, "--report"], capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["format"] == "navsim.covariance-summary/1" and summary["kind"] == "navigation"
    assert set(summary["quantities"]) == {"horizontal_position", "vertical_position", "horizontal_velocity",
                                          "vertical_velocity", "tilt", "heading"}
    series = read_npz(out / "timeseries.npz")
    assert series["t"][-1] == 600.0 and series["state_rms"].shape == (600, len(summary["filter_states"]))
    text, _ = pdf_text(out / "report.pdf")
    assert "Covariance analysis: sins_cns_level" in text
    status, err = run_cli(cli.main, ["report", out, "-o", tmp_path / "again.pdf"], capsys)
    assert status == 0, err


@pytest.mark.parametrize("argv, message", [
    (["covariance", ROOT / "scenarios" / "paper003_precision.toml"], "a static study"),
    (["covariance", LEVEL, *SHORT_LEVEL, "--compare", LEVEL.parent], "not a campaign directory"),
    (["sweep", LEVEL, "--vary", "star_sensor.no_such_key=1,2", "--metric", "horizontal_position"], "no_such_key"),
    (["sweep", LEVEL, "--vary", "star_sensor.fov_deg=16,wide", "--metric", "horizontal_position"], "fov_deg"),
    (["sweep", LEVEL, "--vary", "star_sensor.fov_deg=", "--metric", "horizontal_position"], "no values (an empty grid)"),
    (["sweep", LEVEL, "--vary", "star_sensor.fov_deg=8,16", "--metric", "speed"], "--metric speed: unknown"),
    (["sweep", LEVEL, "--vary", "star_sensor.fov_deg=8,16", "--metric", "tilt@5h"], "inside the run"),
    (["sweep", LEVEL, "--vary", "star_sensor.fov_deg=8,16", "--metric", "tilt@soon"], "a number of s, min or h"),
    (["sweep", LEVEL, "--vary", "star_sensor.fov_deg=8,16", "--metric", "tilt", "--runs", "5"], "--runs: a Monte Carlo"),
])
def test_covariance_and_sweep_bad_input(argv, message, tmp_path, capsys):
    out = tmp_path / "out"
    if argv[0] == "sweep":
        argv = [*argv, *SHORT_LEVEL]
    status, err = run_cli(cli.main, [*argv, "--out", out], capsys)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_an_interrupted_sweep_resumes_without_recomputing_finished_points(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", LEVEL, "--vary", "star_sensor.attitude_sigma_cross_arcsec=2,10", "--metric", "tilt@300",
            "--requirement", "5", "--out", out, "--workers", "1", *SHORT_LEVEL]
    status, err = run_cli(cli.main, argv, capsys)
    assert status == 0, err
    result = json.loads((out / "sweep.json").read_text())
    assert [p["values"] for p in result["points"]] == [[2], [10]] and result["points"][0]["t"] == 300.0
    assert result["points"][0]["value"] < result["points"][1]["value"]  # a noisier star sensor, a larger tilt
    first = out / "points" / "point_00000.json"
    mtime = first.stat().st_mtime_ns
    (out / "points" / "point_00001.json").unlink()  # as if stopped before the second point
    status, err = run_cli(cli.main, argv, capsys)
    assert status == 0, err
    assert first.stat().st_mtime_ns == mtime
    assert json.loads((out / "sweep.json").read_text())["points"] == result["points"]
    assert (out / "sweep.csv").read_text().splitlines()[0] == "star_sensor.attitude_sigma_cross_arcsec,tilt [arcsec],filter sigma [arcsec]"
    text, _ = pdf_text(out / "sweep.pdf")
    assert "Trade sweep: sins_cns_level" in text
    status, err = run_cli(cli.main, [*argv[:4], "--metric", "heading", *argv[6:]], capsys)
    assert status == 2 and "holds a sweep of another request" in err


def test_fixed_truth_errors_are_the_mean_error_the_runs_share():
    """A turn-on bias and initial errors given as values (PSINS's imuerrset/avperrset) instead of σ: every run has
    them, and the analysis carries them as its mean error; the runs' mean error and RMS agree with it."""
    overrides = ("duration_s=600", "settle_s=60", 'filter.mounting="ignore"', "imu.accelerometer.bias_fixed_micro_g=[100.0, -50.0, 0.0]",
                 "imu.gyro.bias_fixed_deg_per_h=[0.03, 0.0, -0.03]", "filter.initial_attitude_error_arcsec=[20.0, -10.0, 60.0]",
                 "filter.initial_position_error_m=[30.0, 0.0, 5.0]")
    analysis = covariance(LEVEL, overrides)
    runs = [result.series for result in run_batch(LEVEL, range(RUNS), overrides, threads=2)]
    comparison = analysis.compare(runs)
    assert comparison["inside_family"] == comparison["checks"]
    mean, sigma = analysis.mean.sum(axis=0)[-1, :9], np.sqrt(analysis.block[0, -1].diagonal())
    J = analysis.quantities["horizontal_position"].rows[-1]  # (δL, δλ) -> (north, east) metres at the end
    expected = J @ mean
    spread = np.abs(J @ sigma) / np.sqrt(RUNS)  # the σ of a RUNS-run mean of each component
    position = np.mean([run["position_error_m"][-1, 0:2] for run in runs], axis=0)
    assert np.all(np.abs(expected) > 10 * spread)  # the fixed errors dominate the runs' spread
    assert np.all(np.abs(position - expected) < 4 * spread)
