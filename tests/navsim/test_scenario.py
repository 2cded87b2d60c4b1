"""Scenario validation: every bad input is one InputError naming the file, the key and the problem."""

import copy

import pytest

from navsim.kinds import load_scenario, scenario_from_dict
from navsim.scenario import parse_override
from startrack.base.errors import InputError


def check(data, overrides=()):
    return scenario_from_dict(data, overrides, source="s.toml")


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda d: d.update(colour="red"), "s.toml: colour: unknown key"),
        (lambda d: d["gyro"].update(arw_deg_per_sqrt_hour=0.1), "s.toml: gyro.arw_deg_per_sqrt_hour: unknown key"),
        (lambda d: d.pop("duration_s"), "s.toml: duration_s: missing required key"),
        (lambda d: d["gyro"].pop("rate_hz"), "s.toml: gyro.rate_hz: missing required key"),
        (lambda d: d.update(duration_s="long"), "s.toml: duration_s: must be a number, got 'long'"),
        (lambda d: d["gyro"].update(rate_hz=-100.0), "s.toml: gyro.rate_hz: must be > 0, got -100.0"),
        (lambda d: d["star_sensor"].update(fov_deg=0.0), "s.toml: star_sensor.fov_deg: must be > 0, got 0.0"),
        (lambda d: d["gyro"].update(arw_deg_per_sqrt_h=-0.1), "s.toml: gyro.arw_deg_per_sqrt_h: must be >= 0"),
        (lambda d: d["truth"].update(profile="spin"), "s.toml: truth.profile: must be one of"),
        (lambda d: d["truth"]["constant_rate"].update(rate_deg_per_s=[1, 2]), "must be a list of 3 numbers"),
        (lambda d: d["truth"]["constant_rate"].update(rate_deg_per_s=[1, float("nan"), 2]), "finite numbers"),
        (lambda d: d["star_sensor"].update(rate_hz=3.0), "star_sensor.rate_hz: 3 Hz must divide gyro.rate_hz = 10 Hz"),
        (lambda d: d["truth"].update(rate_hz=25.0), "truth.rate_hz: 25 Hz must be an integer multiple"),
        (lambda d: d["truth"].update(profile="sinusoidal_axis"), "truth.sinusoidal_axis: missing table"),
        (lambda d: d.update(settle_s=100.0), "settle_s: must be shorter than duration_s"),
        (lambda d: d["filter"].update(gate_probability=1.5), "filter.gate_probability: must be <="),
        (lambda d: d["filter"].update(scale_factor="yes"), "must be one of estimate, consider, ignore"),
        (lambda d: d["truth"].update(initial_q_IB=[0, 0, 0, 0]), "quaternion must have a non-zero norm"),
    ],
)
def test_bad_values_name_the_file_key_and_problem(base_scenario, mutate, message):
    data = copy.deepcopy(base_scenario)
    mutate(data)
    with pytest.raises(InputError) as error:
        check(data)
    assert message in str(error.value)
    assert "\n" not in str(error.value)


def test_other_profile_tables_are_refused(base_scenario):
    base_scenario["truth"]["sinusoidal_axis"] = {"axis": [1, 0, 0], "amplitude_deg": 1.0,
                                                 "angular_frequency_rad_per_s": 1.0}
    with pytest.raises(InputError, match="truth.sinusoidal_axis: given, but truth.profile is 'constant_rate'"):
        check(base_scenario)


def test_rigid_body_inertia_must_be_positive_definite(base_scenario):
    base_scenario["truth"] = {"profile": "rigid_body", "rigid_body": {
        "inertia_kg_m2": [[1, 0, 0], [0, -1, 0], [0, 0, 1]], "initial_rate_deg_per_s": [0, 0, 1]}}
    with pytest.raises(InputError, match="symmetric positive definite"):
        check(base_scenario)


def test_defaults_are_filled_and_rates_checked(base_scenario):
    scenario = check(base_scenario)
    assert scenario["settle_s"] == pytest.approx(6.0)
    assert scenario["filter"]["gate_probability"] == 0.9999
    assert scenario["star_sensor"]["fidelity"] == "vector"


def test_overrides_are_validated_like_the_file(base_scenario):
    assert check(base_scenario, ["gyro.rate_hz=20", "star_sensor.rate_hz=5"])["gyro"]["rate_hz"] == 20.0
    with pytest.raises(InputError, match="gyro.rate_hz: must be > 0"):
        check(base_scenario, ["gyro.rate_hz=-5"])
    with pytest.raises(InputError, match="gyro.ratehz: unknown key"):
        check(base_scenario, ["gyro.ratehz=20"])
    with pytest.raises(InputError, match="expected KEY=VALUE"):
        check(base_scenario, ["gyro.rate_hz"])


def test_parse_override_reads_toml_values():
    assert parse_override("a.b=1.5") == (["a", "b"], 1.5)
    assert parse_override("a=[1, 2, 3]") == (["a"], [1, 2, 3])
    assert parse_override("a=true") == (["a"], True)
    assert parse_override("a=stars") == (["a"], "stars")


def test_files_missing_or_broken(tmp_path):
    with pytest.raises(InputError, match="scenario file not found"):
        load_scenario(tmp_path / "nope.toml")
    broken = tmp_path / "broken.toml"
    broken.write_text("name = 'x'\nduration_s = = 3\n")
    with pytest.raises(InputError, match="broken.toml: invalid TOML"):
        load_scenario(broken)
    with pytest.raises(InputError, match="is a directory"):
        load_scenario(tmp_path)


def test_shipped_scenarios_are_valid():
    """Every file of scenarios/ by its loader: a simulation scenario by its kind's, a replay (a ``[replay]`` table) by
    navsim.replay's, which ``navsim run`` refuses in one line."""
    from pathlib import Path

    from navsim.replay import scenario as replay_file

    files = sorted((Path(__file__).resolve().parents[2] / "scenarios").glob("*.toml"))
    assert files
    for path in files:
        if "[replay." in path.read_text():
            assert replay_file.load(path)["name"]
            with pytest.raises(InputError, match="a replay of a recording, not a simulation scenario"):
                load_scenario(path)
        else:
            assert load_scenario(path).name
