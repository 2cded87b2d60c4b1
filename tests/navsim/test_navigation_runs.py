"""Navigation scenarios (the INS) through every command: the free INS at rest against the Schuler closed
forms (the errors over a batch and the filter's own σ), the same seed giving the same files, `navsim
run --report`, `montecarlo` + `report`, `tune`, and the position-aided 50-run campaign of the shipped
scenario (slow)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from navsim import cli
from navsim.earth.gravity import normal_gravity
from navsim.earth.wgs84 import radii
from navsim.navigation.records import RunSummary
from navsim.simulation import run_batch
from startrack.base import units
from tests.support import HANG_S, pdf_text

ROOT = Path(__file__).resolve().parents[2]
BASE = Path(__file__).resolve().parent / "data" / "base_navigation.toml"

#: σ of the free INS test: gyro and accelerometer turn-on biases [deg/h, µg], initial tilt [arcsec],
#: heading [deg], velocity [m/s] and position [m].
GYRO_BIAS, ACCEL_BIAS, TILT, HEADING, VELOCITY, POSITION = 0.05, 50.0, 20.0, 0.05, 0.02, 1.0
#: Two hours at rest on the equator, an IMU with turn-on biases only, and a baro for the vertical channel
#: (it updates the vertical states only: the horizontal channels stay free).
FREE_AT_REST = {
    "name": "free_at_rest",
    "trajectory": {"start": {"lat_deg": 0.0, "lon_deg": 30.0}, "segments": [{"kind": "hold", "duration_s": 7200.0}]},
    "imu": {"rate_hz": 10.0, "gyro": {"bias_turn_on_deg_per_h": GYRO_BIAS},
            "accelerometer": {"bias_turn_on_micro_g": ACCEL_BIAS}},
    "baro": {"rate_hz": 1.0},
    "filter": {"initial_tilt_sigma_arcsec": TILT, "initial_heading_sigma_deg": HEADING,
               "initial_velocity_sigma_m_per_s": VELOCITY, "initial_position_sigma_m": POSITION},
}


def north_sigma(t):
    """σ of the north position error [m] of the free INS at rest on the equator, heading north.

    On the equator at rest the north channel (δN, δv_N, the east tilt φ_E) and the heading error φ_D
    form a closed system, untouched by the vertical channel (so the baro tells nothing of it): the
    Schuler loop, ω_s² = γ/R_M, and the Earth-rate loop between φ_E and φ_D (Titterton & Weston ch. 12):

        δṄ = δv_N,  δv̇_N = γ φ_E + ∇_N,  φ̇_E = −δv_N/R_M + Ω φ_D − ε_E,  φ̇_D = −Ω φ_E − Ω δN/R_M − ε_D,

    with constant biases; σ(t)² = [e^(At) P0 e^(Aᵀt)]_NN for the independent initial errors and biases."""
    from scipy.linalg import expm

    from navsim.earth.wgs84 import OMEGA_IE

    r_m, g, omega = radii(0.0)[0], normal_gravity(0.0, 0.0), OMEGA_IE
    A = np.zeros((7, 7))  # δN, δv_N, φ_E, φ_D, ∇_N, ε_E, ε_D
    A[0, 1] = 1.0
    A[1, 2], A[1, 4] = g, 1.0
    A[2, 1], A[2, 3], A[2, 5] = -1.0 / r_m, omega, -1.0
    A[3, 0], A[3, 2], A[3, 6] = -omega / r_m, -omega, -1.0
    gyro, accel = units.deg_per_h_to_rad_per_s(GYRO_BIAS), units.micro_g_to_si(ACCEL_BIAS)
    P0 = np.diag(np.square([POSITION, VELOCITY, TILT * units.ARCSEC, HEADING * units.DEG, accel, gyro, gyro]))
    return np.array([np.sqrt((expm(A * t_k) @ P0 @ expm(A * t_k).T)[0, 0]) for t_k in np.atleast_1d(t)])


def test_free_ins_at_rest_follows_the_closed_forms():
    """40 runs of 2 h: the north error's RMS over the runs at 30, 60, 90 and 120 min is the closed-form
    σ (within 35 %: the RMS of 40 normal draws is within 3 x 11 % of σ), and the filter's own σ is the
    closed form within 1 % (its covariance propagates the same linear dynamics, from its general
    15-state F)."""
    results = run_batch(FREE_AT_REST, range(40))
    t = results[0].series["t"]
    at = np.searchsorted(t, [1800.0, 3600.0, 5400.0, 7200.0])
    north = np.array([r.series["position_error_m"][at, 0] for r in results])
    expected = north_sigma(t[at])
    np.testing.assert_allclose(np.sqrt(np.mean(north**2, axis=0)), expected, rtol=0.35)
    filter_sigma = results[0].series["error_sigma"][at, 6]  # σ of δN [m]
    np.testing.assert_allclose(filter_sigma, expected, rtol=0.01)
    assert expected[-1] > 2000.0  # the gyro drift's growth dominates after 2 h


def run_cli(argv, capsys):
    status = cli.main([str(a) for a in argv])
    return status, capsys.readouterr()


def test_the_same_seed_gives_the_same_files(tmp_path, capsys):
    for name in ("a", "b"):
        assert run_cli(["run", BASE, "--out", tmp_path / name, "--seed", "4"], capsys)[0] == 0
    assert (tmp_path / "a" / "timeseries.npz").read_bytes() == (tmp_path / "b" / "timeseries.npz").read_bytes()
    summaries = [json.loads((tmp_path / name / "summary.json").read_text()) for name in ("a", "b")]
    for summary in summaries:
        summary.pop("timing")
    assert summaries[0] == summaries[1]


def test_run_and_report_of_a_navigation_scenario(tmp_path, capsys):
    status, out = run_cli(["run", BASE, "--out", tmp_path / "run", "--report", tmp_path / "run.pdf"], capsys)
    assert status == 0
    assert "horizontal error" in out.out and "aiding: position, baro" in out.out
    summary = RunSummary.read(tmp_path / "run" / "summary.json")
    assert summary.kind == "navigation" and summary["nees"]["dof"] == 24  # 15 + 6 scale factors + 3 gravity consider states
    text, _ = pdf_text(tmp_path / "run.pdf")
    for heading in ("Navigation run report: corpus_navigation", "Key results", "Ground track", "Navigation errors",
                    "IMU error estimates", "Filter consistency"):
        assert heading in text
    assert f"horizontal position error at the end is {summary['position_error_m']['horizontal']['final']:.2f} m" in text


def test_campaign_and_its_report(tmp_path, capsys):
    out = tmp_path / "mc"
    status, printed = run_cli(["montecarlo", BASE, "--runs", "4", "--workers", "1", "--out", out], capsys)
    assert status == 0 and "CEP50" in printed.out
    summary = json.loads((out / "summary.json").read_text())
    finals = [json.loads(p.read_text())["position_error_m"]["horizontal"]["final"]
              for p in sorted((out / "runs").glob("run_*/summary.json"))]
    assert summary["position_error_m"]["horizontal"]["cep50"] == pytest.approx(np.median(finals))
    assert summary["nees"]["dof"] == 24 and summary["divergent_runs"] == []
    assert run_cli(["report", out, "-o", tmp_path / "mc.pdf"], capsys)[0] == 0
    text, _ = pdf_text(tmp_path / "mc.pdf")
    for phrase in ("Monte Carlo campaign report: corpus_navigation", "CEP50", "Horizontal error over time",
                   "Position error envelopes", "Filter consistency over runs"):
        assert phrase in text


def test_tune_judges_a_navigation_scenario(capsys):
    """The navigation kind through `navsim tune`: its headline errors in the table, its NEES/dof and NIS/dof with their
    intervals in the verdict (the verdict itself: tests/navsim/test_tuning.py)."""
    status, printed = run_cli(["tune", BASE, "--runs", "2", "--evaluations", "3"], capsys)
    assert status == 0
    assert "horizontal RMS" in printed.out.splitlines()[0]
    assert "NEES/dof" in printed.out and "NIS/dof" in printed.out and "95 % interval [" in printed.out
    assert "no change proposed" in printed.out or "use: --set filter.process_noise_scale=" in printed.out


@pytest.mark.slow
def test_position_aided_campaign_of_the_shipped_scenario(tmp_path):
    """`navsim montecarlo` on scenarios/position_aided_aircraft.toml (2 h, tactical IMU, 1 Hz fixes of
    3 m), 50 runs: the run-averaged NEES (15 dof) inside its 95 % band on average and at >= 80 % of the
    frames, no divergent run, the accelerometer biases within 3σ at the end (>= 97 % of run-axes)."""
    out = tmp_path / "aided"
    done = subprocess.run([sys.executable, "-m", "navsim.cli", "montecarlo", "scenarios/position_aided_aircraft.toml",
                           "--runs", "50", "--workers", "2", "--out", str(out)], cwd=ROOT, capture_output=True, text=True,
                          timeout=HANG_S)
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    nees = summary["nees"]
    assert nees["dof"] == 15 and nees["runs"] == 50
    assert nees["band_95"][0] <= nees["mean"] <= nees["band_95"][1]
    assert nees["fraction_in_band"] >= 0.8
    assert summary["divergent_runs"] == []
    assert summary["imu_calibration"]["accel_bias_micro_g"]["within_3_sigma"] >= 0.97


def test_tune_needs_measurements():
    """A free INS without a baro has no NIS to fit: one clear error, not a search on nothing."""
    from navsim.campaign.tuning import tune
    from startrack.base.errors import InputError

    short = {**FREE_AT_REST, "trajectory": {**FREE_AT_REST["trajectory"], "segments": [{"kind": "hold", "duration_s": 60.0}]}}
    with pytest.raises(InputError, match="filter tuning needs measurements"):
        tune({key: value for key, value in short.items() if key != "baro"}, runs=1)


def test_along_and_cross_track_errors_resolve_the_horizontal_error_on_the_course():
    """``track_metres``: due east the along-track error is the east error and the cross-track error (right of the
    track: south) is −north; due north they are north and east; any course keeps the horizontal size; at rest the
    course is the body's heading."""
    from navsim.navigation.summary import track_metres
    from startrack.geometry import rotation as rot
    error = np.array([[3.0, 4.0], [3.0, 4.0], [-1.0, 2.0], [3.0, 4.0]])
    v_n = np.array([[0.0, 250.0, 0.0], [10.0, 0.0, 1.0], [7.0, -7.0, 0.0], [0.0, 0.0, 0.0]])
    q_nb = rot.from_rotation_vector(np.array([[0.0, 0.0, 0.3]] * 3 + [[0.0, 0.0, np.pi / 2]]))  # the last faces east
    track = track_metres(error, v_n, q_nb)
    np.testing.assert_allclose(track[0], [4.0, -3.0], atol=1e-12)
    np.testing.assert_allclose(track[1], [3.0, 4.0], atol=1e-12)
    np.testing.assert_allclose(np.hypot(*track.T), np.hypot(*error.T), rtol=1e-12)
    np.testing.assert_allclose(track[2], [(-7.0 - 14.0) / np.hypot(7.0, 7.0), (-7.0 + 14.0) / np.hypot(7.0, 7.0)],
                               atol=1e-12)
    np.testing.assert_allclose(track[3], [4.0, -3.0], atol=1e-12)
