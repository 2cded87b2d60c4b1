"""`navsim tune`: fitting Q and R restores consistency and recovers a known mis-tuning; a filter the runs cannot tell
from a consistent one is left alone, saying why; each evaluation is printed as it ends."""

import numpy as np
import pytest

from navsim import cli
from navsim.campaign import tuning
from navsim.campaign.tuning import batch_statistics, tune
from navsim.kinds import resolve_scenario
from navsim.simulation import run_batch
from startrack import InputError

#: A consistent attitude filter, cheap to run: 120 s, a 1 Hz star sensor (NEES/dof 1.00, NIS/dof 1.00 over 20 runs).
SCENARIO_TOML = """
name = "tuning-test"
duration_s = 120.0
seed = 0
[truth]
profile = "constant_rate"
rate_hz = 40.0
constant_rate = { rate_deg_per_s = [0.5, -0.3, 0.8] }
[gyro]
rate_hz = 10.0
arw_deg_per_sqrt_h = 0.1
rrw_deg_per_h_per_sqrt_h = 0.5
bias_turn_on_deg_per_h = 5.0
[star_sensor]
measurement = "attitude"
rate_hz = 1.0
fov_deg = 16.0
attitude_sigma_cross_arcsec = 10.0
attitude_sigma_roll_arcsec = 30.0
[filter]
initial_attitude_sigma_deg = 0.2
"""


def consistent(base):
    base["duration_s"] = 120.0
    base["star_sensor"]["rate_hz"] = 1.0
    return base


def mistuned(base):
    consistent(base)["filter"]["arw_deg_per_sqrt_h"] = 0.05  # the gyro flown has 0.1: Q is 4x too small
    return base


def test_tune_recovers_the_arw_ratio_and_restores_consistency(base_scenario):
    result = tune(mistuned(base_scenario), runs=20)
    first, last = result.steps[0], result.steps[-1]
    assert first.nees_per_dof > 2.0 and first.nees_interval[0] > 1.0 and result.change_proposed
    assert last.nees_per_dof == pytest.approx(1.0, abs=0.1)
    assert last.nis_per_dof == pytest.approx(1.0, abs=0.1)
    assert last.process_noise_scale == pytest.approx(4.0, rel=0.2)  # (0.1 / 0.05)²
    assert last.measurement_noise_scale == pytest.approx(1.0, rel=0.1)
    assert last.errors["cross-boresight RMS"][0] < first.errors["cross-boresight RMS"][0]


def batches_of_four(scenario, batches, overrides=()):
    """The tuning statistics of ``batches`` disjoint batches of 4 seeded runs (one prepare for all)."""
    results = run_batch(scenario, range(4 * batches), overrides=overrides)
    settle = resolve_scenario(scenario)["settle_s"]
    return [batch_statistics(results[4 * k: 4 * k + 4], settle) for k in range(batches)]


def test_four_runs_leave_a_consistent_filter_alone_and_change_a_process_noise_a_tenth_too_small(base_scenario):
    """A consistent filter: 1 lies inside both 95 % intervals (NEES/dof and NIS/dof, Student's t over 4 runs) in at
    least 90 % of batches when the intervals hold their coverage (two of 95 %): here >= 32 of 40 (a binomial count
    of 40 at 0.9 falls below 32 with 2 % chance; 38 measured). With Q scaled by 0.1 (NEES/dof near 5, NIS/dof near
    1.5) no batch is left alone."""
    scenario = consistent(base_scenario)
    left_alone = sum(step.consistent for step in batches_of_four(scenario, 40))
    assert left_alone >= 32
    assert not any(step.consistent for step in batches_of_four(scenario, 40, {"filter.process_noise_scale": 0.1}))


def test_a_process_noise_a_tenth_too_small_is_fitted_back_from_four_runs(base_scenario):
    result = tune(consistent(base_scenario), runs=4, seed=4, overrides=["filter.process_noise_scale=0.1"])
    first, last = result.steps[0], result.steps[-1]
    assert result.change_proposed and first.nees_interval[0] > 1.0
    assert last.process_noise_scale == pytest.approx(1.0, rel=0.5)  # back to the gyro's own Q, within 4 runs' reach
    assert abs(last.nees_per_dof - 1.0) < 0.05 and abs(last.nis_per_dof - 1.0) < 0.05


def test_one_run_gives_no_interval_so_tune_refuses_it(base_scenario):
    with pytest.raises(InputError, match="at least 2"):
        tune(consistent(base_scenario), runs=1)


def test_tune_proposes_no_change_on_a_consistent_filter_and_says_why(tmp_path, capsys):
    path = tmp_path / "consistent.toml"
    path.write_text(SCENARIO_TOML)
    assert cli.main(["tune", str(path), "--runs", "4", "--seed", "4"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 3  # the header, the one evaluation, the verdict
    assert out[-1].endswith("4 runs cannot tell these from 1; no change proposed")
    assert out[-1].startswith("NEES/dof ") and ", 95 % interval [" in out[-1] and "NIS/dof " in out[-1]


def test_tune_prints_each_evaluation_as_it_ends_and_the_settings_to_use(tmp_path, capsys, monkeypatch):
    """Before each batch after the first, the rows of every evaluation so far are already on stdout."""
    path = tmp_path / "mistuned.toml"
    path.write_text(SCENARIO_TOML)
    printed_before = []

    def batch(*args, **kwargs):
        printed_before.append(capsys.readouterr().out)
        return run_batch(*args, **kwargs)

    monkeypatch.setattr(tuning, "run_batch", batch)
    assert cli.main(["tune", str(path), "--runs", "4", "--evaluations", "4", "--set", "filter.process_noise_scale=0.1"]) == 0
    out = capsys.readouterr().out
    assert printed_before[0] == ""
    for k, text in enumerate(printed_before[1:]):
        rows = text.splitlines()
        assert rows[-1].split()[0] == str(k)  # evaluation k's row, printed before batch k + 1 started
    assert len(printed_before) == 4
    assert "before: NEES/dof" in out and "after (step" in out and "use: --set filter.process_noise_scale=" in out


def test_the_json_of_a_tuning_holds_the_intervals_and_the_verdict(tmp_path, capsys):
    import json

    path = tmp_path / "consistent.toml"
    path.write_text(SCENARIO_TOML)
    assert cli.main(["tune", str(path), "--runs", "4", "--seed", "4", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)  # nothing but the JSON on stdout
    step = result["steps"][0]
    assert result["change_proposed"] is False and step["runs"] == 4
    assert step["nees_interval"][0] <= 1.0 <= step["nees_interval"][1]
    assert np.isclose(step["nees_per_dof"], np.mean(step["nees_interval"]))  # t: symmetric about the mean


def test_tune_statistics_are_the_runs_own_means(base_scenario):
    """NEES/dof: the mean of each run's steady NEES mean over its dof; NIS/dof: of each run's NIS sum over its dof."""
    scenario = resolve_scenario(consistent(base_scenario))
    results, settle = run_batch(scenario, range(3)), scenario["settle_s"]
    stats = batch_statistics(results, settle)
    nees = [np.mean(r.series["nees"][r.series["t"] >= settle]) / 6 for r in results]
    nis = []
    for r in results:
        kept = np.isfinite(r.series["nis"]) & (r.series["t"] >= settle)
        nis.append(r.series["nis"][kept].sum() / r.series["nis_dof"][kept].sum())
    assert stats.nees_per_dof == pytest.approx(np.mean(nees), rel=1e-12)
    assert stats.nis_per_dof == pytest.approx(np.mean(nis), rel=1e-12)
    assert stats.runs == 3


def terminal_stderr(argv):
    """(stdout, stderr) of ``navsim argv`` run with its stderr on an 80-column pseudo-terminal (stdout piped)."""
    import fcntl
    import os
    import pty
    import struct
    import subprocess
    import sys
    import termios

    from tests.support import HANG_S

    leader, follower = pty.openpty()
    fcntl.ioctl(leader, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))  # a new pty is 0 columns wide
    done = subprocess.Popen([sys.executable, "-m", "navsim.cli", *argv], stdout=subprocess.PIPE, stderr=follower)
    os.close(follower)
    chunks = []
    while True:
        try:
            chunk = os.read(leader, 4096)
        except OSError:  # the terminal closed with the process
            break
        if not chunk:
            break
        chunks.append(chunk)
    out = done.communicate(timeout=HANG_S)[0]
    os.close(leader)
    return out.decode(), b"".join(chunks).decode(errors="replace")


def test_tune_shows_its_runs_on_a_terminal_and_nothing_with_quiet(tmp_path):
    path = tmp_path / "consistent.toml"
    path.write_text(SCENARIO_TOML)
    out, err = terminal_stderr(["tune", str(path), "--runs", "4", "--seed", "4"])
    assert "evaluation 0" in err and "/4" in err and "no change proposed" in out
    out, err = terminal_stderr(["tune", str(path), "--runs", "4", "--seed", "4", "--quiet"])
    assert err == "" and "no change proposed" in out
