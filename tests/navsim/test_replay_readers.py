"""The replay's readers: the RTKLIB .pos parser against rows read by hand, the IMU CSV with its counter mapped to GPS
time by the time-tag file, the gap detection and the fill across a gap, the outage schedule."""

from pathlib import Path

import numpy as np
import pytest

from navsim.replay import fixes, outages, recording
from startrack import InputError, units

DATA = Path(__file__).resolve().parents[2] / "examples" / "data" / "gnss_imu_drive_0708"
#: 2025-07-08 00:00:00 GPST in seconds since 1970: 2025-01-01 is 1 735 689 600 s, then 181 + 7 days.
JULY_8 = 1_735_689_600 + 188 * 86_400


def test_pos_rows_read_by_hand():
    """The first line: 2025/07/08 19:34:18.499 40.0966268 -105.1474483 1601.4740000 Q 1, sdn 0.0098995, sdu 0.01,
    vn 0.01, ve -0.002, vu 0.009 (up), sdvn 0.0586899; the last 19:43:27.499 and Q 1."""
    f = fixes.read_pos(DATA / "gnss_1934_sf.pos", qualities=(1, 2))
    assert f.t[0] == pytest.approx(JULY_8 + 19 * 3600 + 34 * 60 + 18.499, abs=1e-6)
    assert np.degrees(f.lat[0]) == pytest.approx(40.0966268, abs=1e-9)
    assert np.degrees(f.lon[0]) == pytest.approx(-105.1474483, abs=1e-9)
    assert f.h[0] == 1601.474
    np.testing.assert_allclose(f.sigma[0], [0.0098995, 0.0098995, 0.01])
    np.testing.assert_allclose(f.v_n[0], [0.01, -0.002, -0.009])  # NEU in the file, NED here
    np.testing.assert_allclose(f.v_sigma[0], [0.0586899] * 3)
    assert f.t[-1] == pytest.approx(JULY_8 + 19 * 3600 + 43 * 60 + 27.499, abs=1e-6)
    assert len(f) == 2197 and (f.quality == 2).sum() == 8  # 2189 RTK fixes and 8 float epochs
    assert len(fixes.read_pos(DATA / "gnss_1934_sf.pos")) == 2189
    assert np.allclose(np.diff(f.t), 0.25)


def test_counter_mapped_to_gps_time_by_the_tag():
    """The tag holds the GPST of the first row, 1 752 003 261 s + 0.854 s, and the last tick 548 731 ms; the counter runs
    261 906 to 810 496 ms over 54 860 rows: the grid's interval is 548.731 s / 54 859 (the IMU clock 257 ppm slow)."""
    start, last = recording.read_time_tag(DATA / "imu_1934.csv.tag")
    assert start == pytest.approx(1_752_003_261.854, abs=1e-6) and last == 548.731
    imu = recording.read_imu(DATA / "imu_1934.csv", list(recording.CHANNELS), "rates", "g", "deg/s", "ms",
                             DATA / "imu_1934.csv.tag", -0.125)
    assert imu.t0 == pytest.approx(start - 0.125, abs=1e-9)
    assert imu.dt == pytest.approx(548.731 / 54_859, rel=1e-12)
    assert imu.samples.shape == (54_859, 6) and imu.gaps.shape == (0, 2)
    # the second row: 0.116, 0.031, 0.985 g; -0.359, 0.946, 0.168 deg/s (gyro first in a sample)
    np.testing.assert_allclose(imu.samples[0, :3], np.radians([-0.359, 0.946, 0.168]))
    np.testing.assert_allclose(imu.samples[0, 3:], np.array([0.116, 0.031, 0.985]) * units.STANDARD_GRAVITY)


def _log(path, times, values):
    np.savetxt(path, np.column_stack([values, times]), delimiter=",", fmt="%.10g")
    return path


def test_a_gap_is_reported_and_crossed_by_its_length(tmp_path):
    """Rows every 10 ms with rows 6-9 missing: one gap of 50 ms starting at 40 ms; the grid keeps 10 ms, its length is
    the log's, the 4 intervals added hold the sample before the gap (rates) or the gap's own mean (increments)."""
    t = np.delete(np.arange(21) * 0.01, [5, 6, 7, 8])
    rng = np.random.default_rng(1)
    values = rng.normal(size=(t.size, 6))
    rates = recording.read_imu(_log(tmp_path / "r.csv", t, values), list(recording.CHANNELS), "rates", "m/s2", "rad/s", "s")
    np.testing.assert_allclose(rates.gaps, [[0.04, 0.05]])
    assert rates.dt == pytest.approx(0.01) and rates.samples.shape[0] == 20 and rates.filled.sum() == 4
    np.testing.assert_array_equal(rates.samples[4:8], np.repeat(rates.samples[3:4], 4, axis=0))
    assert rates.end == pytest.approx(0.2)
    increments = recording.read_imu(_log(tmp_path / "i.csv", t, values), list(recording.CHANNELS), "increments", "m/s",
                                    "rad", "s")
    gap_row = np.concatenate([values[5, 3:], values[5, :3]]) / 0.05  # the row after the gap: its Δ over 50 ms
    np.testing.assert_allclose(increments.samples[4:9], np.repeat(gap_row[None, :], 5, axis=0))


@pytest.mark.parametrize("edit, message", [
    (lambda v, t: (np.where(np.arange(v.size).reshape(v.shape) == 13, np.nan, v), t), "row 3 is not finite"),
    (lambda v, t: (v, np.where(np.arange(t.size) == 4, t[2], t)), "time not increasing at row 5"),
    (lambda v, t: (np.column_stack([v[:, :4], np.full(t.size, 0.3), v[:, 5:]]), t), "column gyro_y is constant"),
])
def test_bad_logs(tmp_path, edit, message):
    t = np.arange(10) * 0.01
    values, t = edit(np.random.default_rng(2).normal(size=(10, 6)), t)
    with pytest.raises(InputError, match=message):
        recording.read_imu(_log(tmp_path / "bad.csv", t, values), list(recording.CHANNELS), "rates", "g", "deg/s", "s")


def test_unknown_unit_and_missing_file(tmp_path):
    with pytest.raises(InputError, match="accel_unit: unknown unit 'furlong/s2' for rates"):
        recording.read_imu(DATA / "imu_1934.csv", list(recording.CHANNELS), "rates", "furlong/s2", "deg/s", "ms")
    with pytest.raises(InputError, match="IMU log not found"):
        recording.read_imu(tmp_path / "none.csv", list(recording.CHANNELS), "rates", "g", "deg/s", "ms")


def test_pos_without_fixes(tmp_path):
    lines = (DATA / "gnss_1934_sf.pos").read_text().splitlines()
    floats = [line for line in lines if line.startswith("%") or line.split()[5] == "2.0000000"]
    (tmp_path / "float.pos").write_text("\n".join(floats) + "\n")
    with pytest.raises(InputError, match="no fixes of quality 1 \\(qualities present: 2\\)"):
        fixes.read_pos(tmp_path / "float.pos")


def test_outage_schedule_and_checks():
    """Lengths 10, 20, 30 s from 60 s with 40 s between: starts 60, 110, 170."""
    windows = outages.scheduled(60.0, [10.0, 20.0, 30.0], 40.0)
    np.testing.assert_allclose(windows, [[60, 10], [110, 20], [170, 30]])
    assert outages.checked(windows, 40.0, 500.0).tolist() == windows.tolist()
    np.testing.assert_array_equal(outages.held_out(np.array([59.0, 60.0, 69.9, 70.0, 199.0]), windows), [-1, 0, 0, -1, 2])
    with pytest.raises(InputError, match="outside the recording after its alignment"):
        outages.checked([[450.0, 60.0]], 40.0, 500.0)
    with pytest.raises(InputError, match="overlap"):
        outages.checked([[100.0, 30.0], [120.0, 10.0]], 40.0, 500.0)
