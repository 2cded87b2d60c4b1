"""A day-capable star sensor in the loop (scenarios/sins_cns_aircraft_day.toml, navsim.sensors.star_prior): a
narrow SWIR field at 12 km sees a few stars by day and names them one by one with the INS's prior; at sea level a
visible sensor sees none and the summary says why; bad input."""

import json
from pathlib import Path

import numpy as np
import pytest

from navsim import cli
from startrack.image.sensor_photometry import SensorPhotometry
from startrack.photometry.bands import band
from startrack.photometry.detectors import detector
from tests.support import run_cli

DAY = Path(__file__).parents[2] / "scenarios" / "sins_cns_aircraft_day.toml"
SEA_LEVEL_VISIBLE = ["trajectory.start.height_m = 0.0", 'star_sensor.band = "V"',
                     'star_sensor.photometry.detector = "silicon_cmos"']


def day_run(tmp_path, capsys, name, *overrides):
    """(summary, console output) of the day scenario's first 5 min with ``overrides``."""
    argv = ["run", DAY, "--out", tmp_path / name, "--set", "duration_s = 300.0"]
    for override in overrides:
        argv += ["--set", override]
    status, err = run_cli(cli.main, argv, capsys)
    assert status == 0, err
    return json.loads((tmp_path / name / "summary.json").read_text()), capsys.readouterr().out


def test_by_day_at_12_km_the_swir_sensor_names_its_few_stars_with_the_prior(tmp_path, capsys):
    """The first 5 min (the Sun 39° up, 80° from the boresight): the H-band limit at the boresight is ~4.5, a few
    stars per frame, each detection either named by the prior or left; none named wrong (the truth checks every
    match); the filter consistent (its NEES mean within the 21-dof band's 95 % limits over 300 frames)."""
    summary, _ = day_run(tmp_path, capsys, "day")
    sky, ident = summary["celestial"]["sky"], summary["celestial"]["star_identification"]
    assert sky["frames_sun_up"] == 300 and 4.0 < sky["limiting_mag"]["median"] < 5.0
    assert ident["wrong"] == 0 and ident["wrong_probability_max"] <= 1e-3
    assert ident["frames_identified"] >= 0.9 * ident["frames_detected"] > 200
    assert ident["stars_identified"] >= 0.8 * ident["stars_detected"] - 0.5 * 300  # the false detections left
    assert summary["identification"]["per_mode"]["prior"]["frames"] == ident["frames_identified"]
    lo, hi = summary["nees"]["band_95"]
    assert 0.5 * 21 < summary["nees"]["mean"] < 1.5 * 21 and summary["nees"]["fraction_in_band"] > 0.8


def test_at_sea_level_a_visible_sensor_sees_no_star_by_day_and_the_summary_says_why(tmp_path, capsys):
    """The same flight at sea level with a silicon V-band sensor: the daylit sky (V ~4.3 mag/arcsec², the measured
    1.8-4.7 of a daylit sky 10-100° from the Sun) fills every pixel in the exposure: no limiting magnitude, no star,
    and every frame is put down to the sky."""
    summary, _ = day_run(tmp_path, capsys, "sea", *SEA_LEVEL_VISIBLE)
    sky = summary["celestial"]["sky"]
    assert sky["hours_with_stars"] == 0.0 and sky["limiting_mag"]["median"] is None
    assert 3.5 < sky["sky_background_mag"]["median"] < 5.0
    assert sky["frames_without_stars"]["sky fills the pixels"] == 300
    assert summary["celestial"]["star_identification"]["stars_identified"] == 0


def test_the_magnitude_sigma_reaches_poisson_for_bright_stars():
    """σ_m = 1.0857 √(N + 4π σ² v)/N: a bright star on a dark sky is photon-limited (1.0857/√N), a faint one on a bright
    sky background-limited (1.0857 √(4π σ² v)/N)."""
    p = SensorPhotometry(band=band("H"), detector=detector("ingaas_swir"), aperture_area=7.85e-3, transmission=0.8,
                         exposure_s=0.01, psf_sigma_px=0.8, pixel_scale=8e-5, detection_sigmas=5.0)
    n = p.star_electrons(np.array([-3.0]))
    assert p.magnitude_sigma(np.array([-3.0]), 0.0)[0] == pytest.approx(1.0857 / np.sqrt(n[0]), rel=0.02)
    sky = 1e8
    faint = p.magnitude_sigma(np.array([6.0]), sky)[0]
    n6, v = p.star_electrons(6.0), p.pixel_variance(sky)
    assert faint == pytest.approx(1.0857 * np.sqrt(4.0 * np.pi * 0.64 * v) / n6, rel=0.02)


@pytest.mark.parametrize("override, message", [
    ('star_sensor.fidelity = "image"', "star_sensor.identification.method: 'prior' identifies"),
    ("star_sensor.identification.max_wrong_probability = 0.5", "max_wrong_probability"),
    ('star_sensor.identification.method = "guess"', "star_sensor.identification.method"),
    ("star_sensor.refraction.pressure_error_percent = 80.0", "pressure_error_percent"),
])
def test_bad_identification_and_refraction_keys_are_one_clear_line(tmp_path, capsys, override, message):
    status, err = run_cli(cli.main, ["run", DAY, "--out", tmp_path / "bad", "--set", override], capsys)
    assert status != 0 and message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "bad").exists()


def test_the_sensor_prior_turns_the_field_by_the_refraction_states_sigma():
    """The prior of the day sensor's identification (``NavFilter.sensor_prior``) carries the refraction consider
    state: its attitude covariance exceeds the same filter's without the state by σ_ε² g gᵀ (to 1e-9 of it), g = R_SI ρ
    the boresight's refraction rotation in sensor axes: about a horizontal axis, |g| = ΔZ of the boresight 50° up at
    12 km (12.4", eq. 1 of navsim.earth.refraction) within 1 % (the aberrated boresight against the catalog one)."""
    import dataclasses

    from navsim.earth.frames import local_up
    from navsim.earth.orientation import EarthOrientation
    from navsim.earth.refraction import refraction_angle
    from navsim.estimation.nav_filter import NavFilter
    from navsim.kinds import resolve_scenario
    from navsim.navigation import build
    from startrack.geometry import rotation as rot
    scenario = resolve_scenario(str(DAY), [])
    gyro, accel = build.imu(scenario)
    lat, lon, h = np.radians(40.0), np.radians(-10.0), 12000.0
    q_nb = rot.from_rotation_vector(np.array([0.0, 0.0, np.radians(90.0)]))  # heading east, level
    orientation = EarthOrientation.compute(scenario["epoch_utc"], np.array([0.0]))
    config = build.filter_config(scenario, gyro, accel, lat, h, 0.01, orientation)
    plain = dataclasses.replace(config, P0=config.P0[:-1, :-1],
                                star_sensor=dataclasses.replace(config.star_sensor, refraction_sigma=0.0))
    start = (lat, lon, h, np.array([0.0, 250.0, 0.0]), q_nb)
    with_state, without = NavFilter(*start, config), NavFilter(*start, plain)
    assert with_state.layout.refraction == with_state.layout.n - 1 and without.layout.refraction < 0
    prior = with_state.sensor_prior()
    extra = prior.P_theta - without.sensor_prior().P_theta
    values, vectors = np.linalg.eigh(extra)
    sigma = config.star_sensor.refraction_sigma
    g = vectors[:, -1] * np.sqrt(values[-1]) / sigma
    np.testing.assert_allclose(extra, sigma**2 * np.outer(g, g), atol=1e-9 * values[-1])
    up = local_up(orientation.c_ie[0], lat, lon)
    boresight = rot.rotate(prior.q_IS, np.array([0.0, 0.0, 1.0]))
    rho = rot.rotate(prior.q_IS, g)
    assert abs(rho @ up) < 1e-3 * np.linalg.norm(rho) and abs(rho @ boresight) < 1e-3 * np.linalg.norm(rho)
    a, b = build.modelled_air(scenario).coefficients(np.array([h]))
    assert np.linalg.norm(g) == pytest.approx(refraction_angle(boresight[None, :], up[None, :], a, b)[0], rel=0.01)


def _limiting_magnitude(*overrides):
    """The median limiting magnitude at the boresight over the day flight's first minute (``navsim sky``'s)."""
    from navsim.kinds import resolve_scenario
    from navsim.navigation.availability import star_availability

    return float(np.median(star_availability(resolve_scenario(str(DAY), ["duration_s=60.0", *overrides])).series["limiting_mag"]))


def test_a_preset_fills_what_the_scenario_leaves_and_yields_to_what_it_sets():
    """``star_sensor.preset`` (navsim.scenario.star_sensor_presets): the day scenario's SWIR sensor comes from
    ``swir_day_3deg`` (limiting H 4.5, its design value); the 1° preset (150 mm on pixels of a ninth of the solid
    angle) reaches deeper by less than the background-limited gain 2.5 log10((150/100)·3) = 1.63 mag (its read and
    dark noise weigh more on the fainter sky per pixel) and more than 1 mag (measured 1.26); a key the scenario sets
    wins over the preset's."""
    from navsim.kinds import resolve_scenario

    checked = resolve_scenario(str(DAY), [])["star_sensor"]
    assert checked["preset"] == "swir_day_3deg" and checked["fov_deg"] == 3.0 and checked["band"] == "H"
    assert checked["image"]["width_px"] == 640 and checked["photometry"]["aperture_mm"] == 100.0
    wide = _limiting_magnitude()
    narrow = _limiting_magnitude('star_sensor.preset="swir_day_1deg"')
    assert wide == pytest.approx(4.5, abs=0.1)
    assert 1.0 < narrow - wide < 2.5 * np.log10(1.5 * 3.0)
    own = resolve_scenario(str(DAY), ["star_sensor.fov_deg=2.0", "star_sensor.photometry.aperture_mm=80.0"])["star_sensor"]
    assert own["fov_deg"] == 2.0 and own["photometry"]["aperture_mm"] == 80.0 and own["photometry"]["detector"] == "ingaas_swir"


def test_an_unknown_preset_is_one_clear_line(tmp_path, capsys):
    status, err = run_cli(cli.main, ["run", DAY, "--out", tmp_path / "o", "--set", 'star_sensor.preset = "nonsense"'], capsys)
    assert status == 2 and "star_sensor.preset" in err and "swir_day_3deg" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()
