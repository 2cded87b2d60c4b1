"""The Sun and the Moon take frames from the star sensor (star_sensor.sun_exclusion_deg, moon_exclusion_deg,
min_elevation_deg; navsim.navigation.exclusion): a frame is excluded exactly when skyfield (JPL DE421) puts the
body inside the cone, the run fuses nothing then, the summary counts it, and the covariance analysis takes the
same frames away."""

from pathlib import Path

import numpy as np
import pytest

from navsim.kinds import resolve_scenario
from navsim.simulation import covariance, prepare, run_batch
from startrack.base.errors import InputError

LEVEL = Path(__file__).resolve().parent / "data" / "sins_cns_level.toml"
#: Straight and level at 11 km due east over the equator through local noon at the March equinox: the boresight
#: (the local vertical) passes 0.06 deg from the Sun, 52 min inside its 10 deg cone; then at 14.5 deg S through the
#: full Moon's culmination on 2026-05-01: 6.2 deg from it, 41 min inside the cone.
NOON = ("epoch_utc=\"2026-03-20T11:15:00\"", "trajectory.start.lat_deg=0.0", "trajectory.start.lon_deg=0.0",
        "trajectory.segments=[{kind=\"straight\", duration_s=5400.0}]", "star_sensor.sun_exclusion_deg=10.0")
MOON = ("epoch_utc=\"2026-05-01T22:45:00\"", "trajectory.start.lat_deg=-14.5", "trajectory.start.lon_deg=0.0",
        "trajectory.segments=[{kind=\"straight\", duration_s=5400.0}]", "star_sensor.moon_exclusion_deg=10.0")
#: Frames whose angle from skyfield lies this near the cone's edge may go either way (the two ephemerides and
#: the boresight's tilt in the flight differ by less).
EDGE_DEG = 0.01


def _zenith_angles(series, epoch, body, skyfield_sky):
    """skyfield's angle [deg] of ``body`` from the local vertical along the run's true track."""
    from skyfield.api import wgs84

    ts, eph = skyfield_sky
    year, month, day, hour, minute = int(epoch[:4]), int(epoch[5:7]), int(epoch[8:10]), int(epoch[11:13]), int(epoch[14:16])
    when = ts.utc(year, month, day, hour, minute, series["t"])
    site = wgs84.latlon(np.degrees(series["lat_true"]), np.degrees(series["lon_true"]), elevation_m=series["h_true"])
    observer = (eph["earth"] + site).at(when)
    altitude = observer.observe(eph[body]).apparent().altaz()[0].degrees
    return 90.0 - altitude


@pytest.mark.parametrize("overrides, body, reason", [(NOON, "sun", "Sun in the exclusion cone"),
                                                      (MOON, "moon", "Moon in the exclusion cone")])
def test_the_frames_with_the_body_in_the_cone_fuse_nothing(overrides, body, reason, skyfield_sky):
    scenario = resolve_scenario(LEVEL, overrides)
    (result,) = run_batch(scenario, [0], ())
    series, sky = result.series, result.summary.celestial["sky"]
    angle = _zenith_angles(series, scenario["epoch_utc"], body, skyfield_sky)
    inside, clear = angle < 10.0 - EDGE_DEG, angle > 10.0 + EDGE_DEG
    assert 600 < inside.sum() < 5400 - 600  # a block of the flight, with frames before and after it
    fix = series["nis_dof"] > 1  # the frame's update took an attitude fix (3 dof) beside the baro's height (1)
    assert not np.any(fix[inside]) and np.mean(fix[clear]) > 0.99  # (a fix the gate rejects now and then)
    assert sky["frames_excluded"][reason] == pytest.approx(inside.sum(), abs=int(np.sum(~inside & ~clear)))
    # the analysis takes the same frames: it equals the analysis with an outage over the run's excluded block
    excluded = prepare(scenario).star_sensor.faults.excluded_s  # one block, checked against skyfield above
    assert np.all(np.diff(excluded) == 1.0)
    outage = f"faults.outages=[{{start_s={excluded.min() - 0.5}, end_s={excluded.max() + 0.5}}}]"
    analysis = covariance(scenario)
    scripted = covariance(scenario, (f"star_sensor.{body}_exclusion_deg=0.0", outage))
    assert np.allclose(analysis.diag_f, scripted.diag_f, rtol=1e-9, atol=0.0)


def test_the_run_report_draws_the_sky(tmp_path, capsys):
    from navsim import cli
    from tests.support import pdf_text, run_cli

    out = tmp_path / "run"
    argv = ["run", LEVEL, "--out", out, "--report", *[a for o in NOON for a in ("--set", o)], "--set", "duration_s=4000"]
    status, err = run_cli(cli.main, argv, capsys)
    assert status == 0, err
    text, _ = pdf_text(out / "report.pdf")
    assert "The Sun comes within 0.0" in text and "(Sun in the exclusion cone)" in text


def test_no_exclusion_by_default_and_bad_angles_are_named():
    scenario = resolve_scenario(LEVEL, NOON[:-1])
    assert scenario["star_sensor"]["sun_exclusion_deg"] == 0.0 and scenario["star_sensor"]["min_elevation_deg"] == -90.0
    for key, value in (("sun_exclusion_deg", -1.0), ("moon_exclusion_deg", 181.0), ("min_elevation_deg", 91.0)):
        with pytest.raises(InputError, match=f"star_sensor.{key}"):
            resolve_scenario(LEVEL, (f"star_sensor.{key}={value}",))
