"""Bad input of a SINS/CNS scenario (issue 16) through the command line: a star sensor faster than the
IMU, a boresight below the horizon for the whole flight and an outage longer than the flight each end
``navsim run`` and ``navsim montecarlo`` with one line naming the key, a non-zero exit, no traceback
and nothing written in --out; their edges (an outage that leaves the last seconds, a boresight above
the horizon only in a bank, however short against the flight) are accepted."""

from pathlib import Path

import numpy as np
import pytest

from navsim import cli
from navsim.kinds import load_scenario
from navsim.navigation.scenario import boresight_elevation
from startrack.base.errors import InputError
from tests.support import run_cli

BASE = Path(__file__).resolve().parent / "data" / "base_sins_cns.toml"
#: The base flies 33 s: 10 s straight, a 15 deg turn to the right at 1.5 deg/s (about 34 deg of bank
#: with its roll-in and roll-out), 10 s straight.
DURATION_S = 33.0
#: Mountings (rotation vector, deg) of the sensor's +z in the body: along +z (down) in level flight,
#: below the horizon all the flight; along the left wing 10 deg down, above the horizon in the bank.
DOWN, LEFT_WING_LOW = [0.0, 0.0, 0.0], [80.0, 0.0, 0.0]
#: A star sensor alone (no faults) on the base flight, for the cases that only look at the validation.
NO_FAULTS = {"faults.outages": [], "faults.attitude_jumps": [], "faults.false_star_storms": [],
             "faults.gyro_bias_steps": [], "faults.dropped_frames_s": [], "faults.tracking_failure_probes": None}

BAD = [
    ("star_sensor.rate_hz=40", "star_sensor.rate_hz", "faster than the IMU"),
    (f"star_sensor.mounting_rotvec_deg={DOWN}", "star_sensor.mounting_rotvec_deg", "below the horizon"),
    ("faults.outages=[{start_s = 0.0, end_s = 40.0}]", "faults.outages[0]", "longer than the flight"),
    ("faults.outages=[{start_s = 5.0, end_s = 100.0}]", "faults.outages[0]", "longer than the flight"),
    (f"faults.outages=[{{start_s = 0.0, end_s = {DURATION_S}}}]", "faults.outages[0]", "longer than the flight"),
    ("faults.outages=[{start_s = 15.0, end_s = 40.0}, {start_s = 0.0, end_s = 15.0}]", "faults.outages",
     "cover the whole flight"),
]


def command(name, out, setting):
    extra = ["--runs", 2, "--workers", 1] if name == "montecarlo" else []
    return [name, BASE, "--out", out, "--set", setting, *extra]


@pytest.mark.parametrize("name", ["run", "montecarlo"])
@pytest.mark.parametrize("setting, key, reason", BAD, ids=[case[0] for case in BAD])
def test_bad_sins_cns_input_is_one_line_naming_the_key_and_writes_nothing(tmp_path, capsys, name, setting, key, reason):
    out = tmp_path / "out"
    status, err = run_cli(cli.main, command(name, out, setting), capsys)
    assert status not in (0, None), err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("navsim: error:") and key in lines[0] and reason in lines[0], err
    assert not out.exists() or not any(out.iterdir()), f"{out} was written"


def test_the_base_flight_lasts_what_the_cases_assume():
    assert load_scenario(BASE)["duration_s"] == pytest.approx(DURATION_S)


@pytest.mark.parametrize("name", ["run", "montecarlo"])
@pytest.mark.parametrize("setting", ["faults.outages=[{start_s = 0.0, end_s = 30.0}]",
                                     "faults.outages=[{start_s = 12.0, end_s = 40.0}, {start_s = 0.0, end_s = 10.0}]",
                                     f"star_sensor.mounting_rotvec_deg={LEFT_WING_LOW}"],
                         ids=["outage of all but the last 3 s", "two outages with a gap",
                              "boresight above the horizon only in the bank"])
def test_the_edges_are_accepted_and_run(tmp_path, capsys, name, setting):
    out = tmp_path / "out"
    status, err = run_cli(cli.main, command(name, out, setting), capsys)
    assert status == 0, err
    assert (out / "navsim-output.json").is_file()


def test_a_boresight_below_the_horizon_but_in_a_short_bank_of_a_long_flight_is_accepted():
    """The elevation is sampled on every segment too: a 10 s turn after 14 h of straight flight (a 1 Hz
    IMU keeps the run small) is not missed between the flight's samples."""
    segments = [{"kind": "straight", "duration_s": 50000.0},
                {"kind": "turn", "heading_change_deg": 15.0, "rate_deg_per_s": 1.5},
                {"kind": "straight", "duration_s": 10.0}]
    overrides = {**NO_FAULTS, "imu.rate_hz": 1.0, "trajectory.segments": segments}
    elevation = np.degrees(boresight_elevation(load_scenario(BASE, {**overrides,
                                                                    "star_sensor.mounting_rotvec_deg": LEFT_WING_LOW}).data))
    assert elevation.min() == pytest.approx(-10.0, abs=0.1)
    assert elevation.max() > 20.0
    with pytest.raises(InputError, match="below the horizon for the whole flight"):
        load_scenario(BASE, {**overrides, "star_sensor.mounting_rotvec_deg": DOWN})
