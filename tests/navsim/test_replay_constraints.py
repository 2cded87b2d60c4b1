"""A land vehicle's constraints in a replay: the rest detector's statistic is the chi-square of its derivation on white
noise, it finds the rest spans of a synthetic stop-and-go drive (road vibration while moving) and nothing else; the
ZUPT and the non-holonomic constraint shrink the error of an outage over the stop, and of the real car drive's; bad
constraint values are one InputError line."""

from pathlib import Path

import numpy as np
import pytest

from navsim.estimation.consistency import chi2_quantile
from navsim.replay import output, run, scenario, stationarity
from startrack import InputError
from tests.navsim import replay_helpers as rh

ROOT = Path(__file__).resolve().parents[2]
DRIVE = ROOT / "scenarios" / "replay_car_drive_0708.toml"
ON = ["replay.constraints.zupt=true", "replay.constraints.nhc=true"]
OFF = ["replay.constraints.zupt=false", "replay.constraints.nhc=false"]


def test_the_statistic_at_rest_is_the_chi_square_of_its_derivation():
    """4000 windows of 100 samples of white specific force (σ 0.05 m/s² on 1 g): W σ² T is χ²(3 (W − 1)) (its mean
    297 within 4.5 standard errors of the mean, √(2·297/4000)), and the share at rest is p = 0.99 within 4.5 binomial
    σ (0.7 %)."""
    rng = np.random.default_rng(11)
    W, count, sigma = 100, 4000, 0.05
    f = np.array([0.0, 0.0, -9.8]) + sigma * rng.standard_normal((W * count, 3))
    ends = np.arange(1, count + 1) * W
    T = stationarity.statistic(f, ends, W, sigma)
    assert abs(np.mean(W * T) - 297) < 4.5 * np.sqrt(2 * 297 / count)
    share = stationarity.at_rest(f, ends, W, sigma, 0.99).mean()
    assert abs(share - 0.99) < 4.5 * np.sqrt(0.99 * 0.01 / count)
    assert stationarity.threshold(W, 0.99) == pytest.approx(chi2_quantile(0.99, 297) / W)
    assert np.isnan(stationarity.statistic(f, [W - 1], W, sigma)[0])


@pytest.fixture(scope="module")
def stop_and_go(tmp_path_factory):
    """The stop-and-go drive (0.1 m/s² of road vibration while moving: five times the accelerometer noise per sample
    the detector is told of, its VRW/√Δt), an outage of 40 s over its stop, replayed with
    the constraints and without."""
    directory = tmp_path_factory.mktemp("stop_and_go")
    truth = rh.stop_and_go_truth()
    imu, fixes = rh.write_recording(directory, truth, vibration=0.1)
    toml = rh.replay_toml(directory, imu, fixes, outages="windows = [{start_s = 50.0, duration_s = 40.0}]")
    return truth, output.replay(toml, ON), output.replay(toml, OFF)


def test_the_detector_finds_the_rest_spans(stop_and_go):
    """Every fix epoch whose 1 s window moves is moving to the detector; of those wholly at rest (the start and the
    stop), at least 95 % are at rest (p = 0.99 of each: the expected misses 1 %, 5 % is beyond 4.5 binomial σ)."""
    truth, (_, _, series), _ = stop_and_go
    k = np.rint(series["t"] / truth.dt).astype(int)
    moved = np.array([rh.moving(truth)[max(0, i - 100):i].any() for i in k])
    assert not series["at_rest"][moved].any()
    still = ~moved & (k >= 100)
    assert still.sum() > 100 and series["at_rest"][still].mean() > 0.95


def test_the_constraints_shrink_the_outage_over_the_stop(stop_and_go):
    """The outage of 40 s over the stop: with ZUPT and NHC its max error below half the one without them (measured 1.5
    against 26 m), none of the constraints rejected, and the ZUPT's mean NIS not above the 99.95 % quantile of the mean
    of its count of χ²(3) (the filter not overconfident at rest; it is below 3: the ZUPT σ of 0.02 m/s is cautious)."""
    _, (_, on, series), (_, off, _) = stop_and_go
    assert on["outages"][0]["max_horizontal_m"] < 0.5 * off["outages"][0]["max_horizontal_m"]
    c = on["constraints"]
    assert c["zupt"]["rejected"] == 0 and c["nhc"]["rejected"] == 0 and c["nhc"]["accepted"] > 200
    n = c["zupt"]["accepted"]
    assert n > 100 and c["zupt"]["mean_nis"] < chi2_quantile(0.9995, 3 * n) / n
    assert off["constraints"]["zupt"]["accepted"] == 0 and (series["zupt"] == 1).sum() == n


def test_the_car_drive_in_short_is_better_with_the_constraints():
    """150 s of the real drive, one 30 s outage at 60 s: with the ZUPT and the non-holonomic constraint (the scenario's)
    the max horizontal error is below half of the one without them."""
    short = ["replay.imu.duration_s=150", "replay.outages.schedule.first_s=60.0", "replay.outages.schedule.lengths_s=[30.0]"]
    _, on, _ = output.replay(DRIVE, short + ON)
    _, off, _ = output.replay(DRIVE, short + OFF)
    assert on["constraints"]["nhc"]["accepted"] > 400
    assert on["outages"][0]["max_horizontal_m"] < 0.5 * off["outages"][0]["max_horizontal_m"]


@pytest.mark.parametrize("setting, message", [
    ("replay.constraints.zupt_window_s=0.01", "zupt_window_s: 0.01 s is fewer than two IMU intervals"),
    ("replay.constraints.nhc_sigma_m_per_s=-0.1", "nhc_sigma_m_per_s"),
    ("replay.constraints.zupt_probability=1.5", "zupt_probability"),
    ("replay.constraints.zupp=true", "zupp: unknown key"),
])
def test_bad_constraint_values_are_one_line(setting, message):
    with pytest.raises(InputError, match=message):
        run.rest_epochs(run.read(scenario.load(DRIVE, ["replay.imu.duration_s=150", "replay.outages.schedule.lengths_s=[10.0]", setting])["replay"]))
