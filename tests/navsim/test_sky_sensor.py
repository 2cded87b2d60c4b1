"""A star sensor with a light budget in a navigation run (navsim.sensors.frame_sky, navsim.navigation.sky_background,
navsim.navigation.availability): the sky decides which stars each frame shows and each star's σ, the same at vector
fidelity, in the covariance analysis and in ``navsim sky``; at image fidelity the frame carries the sky's level;
bad input."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

from navsim import cli
from navsim.kinds import scenario_from_dict
from navsim.navigation import run as navigation_run
from navsim.navigation.availability import star_availability
from navsim.truth.sky import SkyTruth
from startrack.base import units
from tests.support import pdf_text, run_cli

DATA = Path(__file__).parent / "data"
BASE = DATA / "base_sins_cns_photometry.toml"
NIGHT, NOON = "2024-01-15T20:00:00", "2024-01-15T11:30:00"


def scenario(epoch=NIGHT, **star_sensor):
    """The corpus' light-budget SINS/CNS (20 s at 11 km, 45 N 7 E) at ``epoch`` with a visible CMOS sensor (V)."""
    data = tomllib.loads(BASE.read_text())
    data["epoch_utc"] = epoch
    data["star_sensor"] |= {"band": "V", "photometry": {"aperture_mm": 25.0}, "max_stars": 50, **star_sensor}
    return scenario_from_dict(data, source="sky.toml")


def observed(prepared):
    """The noise-free :class:`~navsim.sensors.star_vector.StarFrames` of a prepared run's star sensor, as a run draws
    them (the truth's attitudes and observer velocities at the frames)."""
    grid = prepared.grid
    sky = SkyTruth.of(prepared.truth, prepared.orientation, grid.frame_k)
    return prepared.star_sensor.start(0, sky.q_IB, grid.frame_k * grid.dt, sky.v_I, noise=False).record().stars


def test_the_sky_decides_the_stars_and_their_sigma():
    """At night a 25 mm visible sensor at 11 km sees tens of stars, each with the σ of its SNR (the fainter, the
    larger: σ rises with the star's magnitude frame by frame, 0.3-1.6" for V <= 6); at noon it sees none -- the sky
    fills its pixels."""
    night = navigation_run.prepare(scenario())
    stars = observed(night)
    assert np.all(stars.counts >= 10)
    sigma = stars.sigma[stars.offsets[0]:stars.offsets[1]]
    assert np.all(np.diff(sigma) >= 0.0)  # brightest as seen first: on one sky and trail σ never falls down the list
    assert sigma.max() > 3.0 * sigma.min() and units.rad_to_arcsec(sigma.max()) < 5.0  # V 0-6 on a 56"/px sensor
    noon = navigation_run.prepare(scenario(NOON))
    assert np.all(noon.star_sensor.sky.sky_e_per_px_s * 0.1 > noon.star_sensor.photometry.detector.full_well_e)
    assert observed(noon).counts.sum() == 0


def test_the_run_the_covariance_analysis_and_navsim_sky_see_the_same_stars():
    """The stars per frame of a run's sensor (before the filter), of ``navsim sky`` (the covariance analysis's nominal
    and sensor) are the same frames and the same number of stars with the same σ."""
    sc = scenario(max_stars=10)
    prepared = navigation_run.prepare(sc)
    run_stars = observed(prepared)
    availability = star_availability(sc)
    assert np.array_equal(availability.series["stars"], run_stars.counts)
    median = [np.median(run_stars.sigma[a:b]) for a, b in zip(run_stars.offsets[:-1], run_stars.offsets[1:])]
    assert np.allclose(availability.series["star_sigma_arcsec"], units.rad_to_arcsec(np.array(median)), rtol=1e-9)
    result = navigation_run.simulate(prepared, 3)
    sky = result.summary.celestial["sky"]
    assert sky["band"] == "V" and sky["hours_with_stars"] == pytest.approx(len(run_stars.counts) / 3600.0)
    assert np.array_equal(result.series["limiting_mag"], prepared.star_sensor.sky.limiting_magnitude())


def test_a_twilight_shows_fewer_stars_than_the_night():
    """The same sensor (the catalog to V = 8) in the twilight, the Sun 5.5 deg below the horizon, sees fewer than half
    the stars of the night (measured 37 against 260) and its limiting magnitude is a magnitude brighter (6.3 against
    8.9); 15 min earlier, the Sun 3 deg down, the sky still fills its pixels."""
    dusk = navigation_run.prepare(scenario("2024-01-15T16:45:00", mag_limit=8.0, max_stars=500))
    night = navigation_run.prepare(scenario(mag_limit=8.0, max_stars=500))
    assert observed(dusk).counts.mean() < 0.5 * observed(night).counts.mean()
    assert dusk.star_sensor.sky.limiting_magnitude().max() < night.star_sensor.sky.limiting_magnitude().min() - 1.0
    sunset = navigation_run.prepare(scenario("2024-01-15T16:30:00", mag_limit=8.0))
    assert observed(sunset).counts.sum() == 0


@pytest.mark.parametrize("override, culprit", [
    ({"epoch_utc": "1850-01-01T00:00:00"}, "epoch_utc"),
    ({"star_sensor.band": "K"}, "band"),
    ({"star_sensor.photometry.detector": "photographic_plate"}, "detector"),
    ({"star_sensor.image.zero_point_e_per_s": 1.0e6}, "zero_point_e_per_s"),
    ({"star_sensor.sun_exclusion_deg": 200.0}, "sun_exclusion_deg"),
])
def test_bad_sky_input_is_one_clear_line(tmp_path, capsys, override, culprit):
    """An epoch outside the ephemerides (erfa.epv00: 1900-2100), a band or detector that does not exist, a zero point
    the light budget sets, an exclusion angle out of range: one line naming the key, exit 2, nothing written."""
    (key, value), = override.items()
    text = f'"{value}"' if isinstance(value, str) else repr(value)
    out = tmp_path / "out"
    status, err = run_cli(cli.main, ["run", BASE, "--out", out, "--set", f"{key}={text}"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and culprit in err and "Traceback" not in err, err
    assert not out.exists() or not any(out.iterdir())


def test_navsim_sky_prints_and_typesets_the_availability(tmp_path, capsys):
    """``navsim sky`` prints the totals and one row an hour, and with --report the PDF; an attitude scenario or a
    navigation scenario without a star sensor is one clear line."""
    pdf = tmp_path / "sky.pdf"
    assert cli.main(["sky", str(BASE), "--report", str(pdf)]) == 0
    printed = capsys.readouterr().out
    assert "stars in" in printed and "limiting mag" in printed and str(pdf) in printed
    text, pages = pdf_text(pdf)
    assert "Star availability" in text and pages >= 1
    attitude = Path(__file__).parents[2] / "scenarios" / "demo.toml"
    status, err = run_cli(cli.main, ["sky", attitude], capsys)
    assert status == 2 and "not a navigation scenario" in err and len(err.strip().splitlines()) == 1
    bare = tmp_path / "bare.toml"
    bare.write_text(BASE.read_text().split("[star_sensor]")[0])
    status, err = run_cli(cli.main, ["sky", bare], capsys)
    assert status == 2 and "no [star_sensor]" in err


def image_scenario(epoch):
    """The corpus' image-fidelity SINS/CNS (256 x 256 px over 16 deg) with a light budget, no faults."""
    data = tomllib.loads((DATA / "base_sins_cns.toml").read_text())
    data["epoch_utc"], data["faults"] = epoch, {}
    data["star_sensor"] |= {"photometry": {"aperture_mm": 25.0}, "image": {"width_px": 256, "height_px": 256,
                                                                           "exposure_s": 0.05}}
    return scenario_from_dict(data, source="image_sky.toml")


def test_image_frames_carry_the_sky():
    """At image fidelity each frame's pixels hold the sky's level: an empty frame of the night's model has the
    background (bias + (sky + dark) t / gain) and noise (√(read² + sky + dark) / gain) the light budget says, to
    their sampling errors on 65 536 pixels (0.1 DN and 0.5 %, within 3σ), and the run identifies and fuses stars
    (3 or more in 30 of its 33 frames, measured);
    20 min after sunset the sky fills the pixels (they sit at the well) and no star is detected."""
    from startrack.image.render import render

    night = navigation_run.prepare(image_scenario(NIGHT))
    model, budget = night.star_sensor.frame_model(0), night.star_sensor.photometry
    sky = night.star_sensor.sky.sky_e_per_px_s[0]
    empty = render(model, 256, 256, (), np.random.default_rng(0))
    background = 100.0 + budget.background_e(sky) / model.gain_e_per_dn
    noise = np.sqrt(budget.pixel_variance(sky)) / model.gain_e_per_dn
    assert empty.mean() == pytest.approx(background, abs=3.0 * noise / 256.0 + 0.5)  # + rounding to whole DN
    assert empty.std() == pytest.approx(noise, rel=3.0 * np.sqrt(0.5 / 65536.0) + 0.01)
    fused = navigation_run.simulate(night, 1).series["n_stars"]
    assert np.mean(fused >= 3) > 0.8  # all but the frames of the turn's roll-in and roll-out (smeared, blended)
    dusk = navigation_run.prepare(image_scenario("2024-01-15T16:45:00"))
    series = navigation_run.simulate(dusk, 1).series
    assert not series["n_detected"].any() and np.all(np.isinf(series["limiting_mag"]))


def test_the_ships_hours_with_stars_follow_the_sun():
    """scenarios/sins_cns_ship.toml (its first 9 h: midnight to after sunrise at 35 N, 30 W in January) has no scripted
    outage: every frame of the night holds stars, none once the Sun is 2 deg above the horizon, and the last frames with
    stars are in the morning twilight, the Sun between 12 and 0 deg below the horizon."""
    from navsim.kinds import load_scenario

    ship = load_scenario(Path(__file__).parents[2] / "scenarios" / "sins_cns_ship.toml", ["duration_s=32400"])
    assert "outages" not in ship.data["faults"] or not ship["faults"]["outages"]
    series = star_availability(ship).series
    sun = np.degrees(series["sun_elevation"])
    stars = series["stars"]
    assert np.all(stars[sun < -18.0] > 0) and not stars[sun > 2.0].any()
    last = sun[np.flatnonzero(stars)[-1]]
    assert -12.0 < last < 0.0
