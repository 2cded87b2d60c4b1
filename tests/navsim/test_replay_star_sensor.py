"""A replay with a simulated star sensor (``[replay.star_sensor]``): on a synthetic recording of the project's truth, its
reference attitude the truth's, the star fixes keep the heading bounded over a 120 s GNSS outage, the filter is
consistent with them (attitude error inside its σ, NIS chi-square with 3 dof), a replay without the table is the old
one, and bad reference input is one line and exit status 2 through the CLI."""

import calendar
import json

import numpy as np
import pytest
from astropy.time import Time
from scipy.spatial.transform import Rotation

from navsim.earth.frames import gpst_epoch_utc
from navsim.replay import output
from startrack import InputError
from tests.navsim import replay_helpers as rh
from tests.navsim.test_replay_cli import navsim_cli

#: One outage of 120 s after the alignment (22 s): two turns inside it.
OUTAGE = "windows = [{start_s = 40.0, duration_s = 120.0}]"


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    directory = tmp_path_factory.mktemp("star")
    truth = rh.car_truth()
    imu, fixes = rh.write_recording(directory, truth)
    return truth, directory, imu, fixes, rh.write_reference(directory, truth)


def _replay(recording, **keys):
    _, directory, imu, fixes, reference = recording
    extra = rh.star_table(reference, **keys) if keys else ""
    return output.replay(rh.replay_toml(directory, imu, fixes, outages=OUTAGE, extra=extra))


@pytest.fixture(scope="module")
def runs(recording):
    """(with the star sensor at 1 Hz, the same frames drawn but not applied, no star-sensor table)."""
    return _replay(recording, rate_hz=1.0), _replay(recording, rate_hz=1.0, apply=False), _replay(recording)


def _error_against_truth(truth, series):
    """φ (F, 3) [rad] of the solution before each star frame against the truth's attitude (scipy), NED axes."""
    k = np.rint(series["star_t"] / truth.dt).astype(int)  # the replay starts at the truth's first sample
    est, true = Rotation.from_quat(series["star_q_nb"]), Rotation.from_quat(truth.q_nb[k])
    return -(est * true.inv()).as_rotvec()


def test_the_star_sensor_bounds_the_heading_in_a_long_outage(recording, runs):
    """Over the 120 s outage the heading error against the truth stays inside 3.5σ of the filter's heading σ at every
    frame (per frame P(|z| > 3.5) = 5e-4) with the star sensor, its σ that of a 40" roll fix about a boresight at the
    zenith (below 0.02 deg); without it the heading drifts by more than twenty times as much."""
    truth = recording[0]
    (_, with_stars, s), (_, without, w), _ = runs
    inside = s["star_outage"] == 0
    assert inside.sum() == 120
    error = _error_against_truth(truth, s)
    np.testing.assert_allclose(error, s["star_attitude_error"], atol=1e-9)  # the log's reference is the truth's
    assert (np.abs(error[inside]) < 3.5 * s["star_attitude_sigma"][inside]).all()
    assert (np.degrees(s["star_attitude_sigma"][inside, 2]) < 0.02).all()
    heading_with = np.abs(error[inside, 2]).max()
    heading_without = np.abs(_error_against_truth(truth, w)[inside, 2]).max()
    assert heading_without > 20 * heading_with
    row, free_row = with_stars["star_sensor"]["outages"][0], without["star_sensor"]["outages"][0]
    assert row["max_heading_error_deg"] == pytest.approx(np.degrees(heading_with))
    assert free_row["max_heading_error_deg"] == pytest.approx(np.degrees(heading_without))
    # the held heading bounds the position too: the outage's horizontal error far below the drift without
    assert with_stars["outages"][0]["max_horizontal_m"] < 0.1 * without["outages"][0]["max_horizontal_m"]


def test_the_star_updates_nis_is_chi_square_3(runs):
    """The mean NIS of the N star frames within 3σ of 3, σ = √(2·3 / N) (the mean of N independent chi-square(3)
    values of a consistent filter: the recording's noise is the filter's model)."""
    (_, result, series), _, _ = runs
    block = result["star_sensor"]
    n = block["frames"]
    assert n == series["star_t"].size == 172 and block["accepted"] + block["rejected"] == n
    assert abs(block["nis_mean"] - 3.0) < 3.0 * np.sqrt(6.0 / n)
    assert block["nis_mean"] == pytest.approx(np.mean(series["star_nis"]))


def test_without_the_table_the_replay_is_the_old_one(runs):
    """No star-sensor table: no star keys, and the same solution as frames drawn but not applied (the sensor only
    watches); its summary without a star_sensor block."""
    _, (_, _, watched), (_, plain_summary, plain) = runs
    assert "star_sensor" not in plain_summary and not any(name.startswith("star_") for name in plain)
    for name in ("lat", "lon", "h", "q_nb", "sigma_ned"):
        np.testing.assert_array_equal(plain[name], watched[name])
    assert (watched["star_accepted"] == -1).all() and np.isnan(watched["star_nis"]).all()


def test_gpst_to_utc_against_astropy():
    """The UTC of GPST seconds since 1970 (18 leap seconds from 2017, 17 in 2016) as astropy's ``gps`` scale has it."""
    for gpst in (1_700_000_000.25, calendar.timegm((2016, 6, 1, 12, 0, 0))):
        expected = Time(gpst - 315964800.0, format="gps").utc.isot
        assert gpst_epoch_utc(gpst)[:23] == expected
    with pytest.raises(InputError, match="not GPST seconds since 1970"):
        gpst_epoch_utc(1000.0)


def _edited_reference(recording, path, edit):
    rows = recording[4].read_text().splitlines()
    path.write_text("\n".join(edit(rows)) + "\n")
    return path


@pytest.mark.parametrize("edit, message", [
    (None, "reference attitude file not found"),
    (lambda rows: rows[:3] + ["nan," + rows[3].split(",", 1)[1]] + rows[4:], "ref.csv: row 4 is not finite"),
    (lambda rows: rows[:3] + [rows[1]] + rows[4:], "ref.csv: time not increasing at row 4"),
    (lambda rows: [f"{float(r.split(',')[0]) + 1e4:.3f}," + r.split(",", 1)[1] for r in rows],
     "does not cover the recording's fixes"),
])
def test_bad_reference_is_one_line_and_exit_2(recording, tmp_path, edit, message):
    _, _, imu, fixes, _ = recording
    reference = tmp_path / "ref.csv"
    if edit is not None:
        _edited_reference(recording, reference, edit)
    path = rh.replay_toml(tmp_path, imu, fixes, outages=OUTAGE, extra=rh.star_table(reference))
    done = navsim_cli("replay", path, "--out", tmp_path / "out")
    assert done.returncode == 2, done.stdout
    assert "Traceback" not in done.stderr and done.stderr.strip().count("\n") == 0
    assert message in done.stderr


def test_the_run_directory_holds_the_star_frames(runs, tmp_path):
    """summary.json's star_sensor block and the star_* series in timeseries.npz."""
    data, result, series = runs[0]
    output.write(tmp_path, data, result, series)
    written = json.loads((tmp_path / "summary.json").read_text())
    assert written["star_sensor"]["frames"] == 172 and written["star_sensor"]["applied"]
    with np.load(tmp_path / "timeseries.npz", allow_pickle=False) as npz:
        assert {"star_t", "star_nis", "star_accepted", "star_attitude_error", "star_attitude_sigma",
                "star_outage"} <= set(npz.files)


def test_a_time_not_gpst_is_one_line(recording, tmp_path):
    """Fixes and IMU on a clock from 0 (not GPST since 1970): the star sensor cannot place the Earth; one line."""
    truth, _, _, _, _ = recording
    imu, fixes = rh.write_recording(tmp_path, truth)
    for path in (imu, fixes):
        rows = np.loadtxt(path, delimiter=",", ndmin=2)
        rows[:, -1 if path == imu else 0] -= rh.T0
        np.savetxt(path, rows, delimiter=",", fmt="%.12f")
    reference = rh.write_reference(tmp_path, truth)
    table = np.loadtxt(reference, delimiter=",")
    table[:, 0] -= rh.T0
    np.savetxt(reference, table, delimiter=",", fmt="%.12f")
    with pytest.raises(InputError, match="replay.star_sensor: the Earth's orientation needs the fixes' time in GPST"):
        output.replay(rh.replay_toml(tmp_path, imu, fixes, outages=OUTAGE, extra=rh.star_table(reference)))
