"""The spacecraft kind (issue 51): the filter's fast path against the step-by-step loop with several heads, the
exclusions against an independent geometry (skyfield's Sun and Moon from JPL DE421, the limb by rays on the cone of
each exclusion angle against the ellipsoid), no star fused from an excluded head, the stars behind the Earth hidden,
two heads 90 deg apart against one (the roll about the boresight), the cost of not correcting the orbit's aberration,
the same seed giving the same run, the reports, the overrides of an array of heads."""

from pathlib import Path

import numpy as np
import pytest

from navsim import cli
from navsim.earth.wgs84 import A as R_EARTH
from navsim.earth.wgs84 import F as FLATTENING
from navsim.kinds import load_scenario, scenario_from_dict
from navsim.orbit.earth_disc import EarthDisc
from navsim.scenario import read_scenario_file
from navsim.simulation import prepare, simulate
from tests.support import pdf_text, run_cli

DATA = Path(__file__).resolve().parent / "data"
BASE, TARGETS, TLE = DATA / "base_spacecraft.toml", DATA / "base_spacecraft_targets.toml", DATA / "base_spacecraft_tle.toml"


@pytest.fixture(scope="module")
def two_heads():
    return prepare(load_scenario(BASE))


def test_the_fast_path_equals_the_step_by_step_loop_with_two_heads_of_stars(two_heads):
    fast, steps = simulate(two_heads, 7), simulate(two_heads, 7, compiled=False)
    for key in ("q_est", "bias_est", "P_diag", "nees", "nis", "n_accepted", "innovation_rms"):
        assert np.array_equal(fast.series[key], steps.series[key], equal_nan=True), key


def test_the_fast_path_equals_the_step_by_step_loop_with_two_heads_of_fixes():
    data = read_scenario_file(TARGETS)
    second = {**data["star_sensor"][0], "mounting_rotvec_deg": [0.0, 20.0, 0.0], "misalignment_sigma_arcsec": 30.0}
    data["star_sensor"].append(second)
    data["filter"] = {"mounting": "estimate"}
    prepared = prepare(scenario_from_dict(data))
    fast, steps = simulate(prepared, 3), simulate(prepared, 3, compiled=False)
    for key in ("q_est", "P_diag", "nees", "nis", "nis_dof", "n_measurements", "innovation_rms"):
        assert np.array_equal(fast.series[key], steps.series[key], equal_nan=True), key
    assert fast.series["n_measurements"].max() == 2


def test_the_same_seed_gives_the_same_run(two_heads):
    a, b = simulate(two_heads, 5), simulate(two_heads, 5)
    assert all(np.array_equal(a.series[k], b.series[k], equal_nan=True) for k in a.series)
    assert {k: v for k, v in a.summary.to_json().items() if k != "timing"} == \
           {k: v for k, v in b.summary.to_json().items() if k != "timing"}


def _ray_hits_ellipsoid(origin, directions, height):
    """True for the rays origin + s u (s > 0) that meet the ellipsoid of semi-axes a + h, (a + h)(1 − f) (a quadratic
    in s, independent of navsim.orbit)."""
    a, c = R_EARTH + height, (R_EARTH + height) * (1.0 - FLATTENING)
    scale = np.array([1.0 / a, 1.0 / a, 1.0 / c])
    o, u = origin * scale, directions * scale
    A, B, C = np.sum(u * u, axis=-1), 2.0 * np.sum(o * u, axis=-1), np.sum(o * o) - 1.0
    disc = B * B - 4.0 * A * C
    return (disc >= 0.0) & ((-B + np.sqrt(np.maximum(disc, 0.0))) / (2.0 * A) > 0.0)


def _cone(axis, half_angle, count=720):
    """Unit directions (count, 3) on the cone of ``half_angle`` [rad] around the unit ``axis``."""
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    phi = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)[:, None]
    return np.cos(half_angle) * axis + np.sin(half_angle) * (np.cos(phi) * e1 + np.sin(phi) * e2)


def _limb_within(origin, axis, angle, height):
    """True when the raised ellipsoid reaches within ``angle`` [rad] of the unit ``axis`` seen from ``origin``: a ray on
    the cone of that half-angle, or the axis itself, meets it."""
    return bool(_ray_hits_ellipsoid(origin, _cone(axis, angle), height).any() or _ray_hits_ellipsoid(origin, axis[None], height)[0])


def test_the_exclusions_are_those_of_an_independent_geometry_and_fuse_no_star(skyfield_sky):
    """An orbit of the ISS's TLE in nadir pointing, one head tilted to the horizon and one at the zenith: each frame's
    Sun and Moon (skyfield, DE421, seen from skyfield's SGP4 position) within the exclusion angles, and the limb where a
    ray on the exclusion cone meets the raised ellipsoid; frames within 0.05 deg of a threshold are not judged."""
    from skyfield.api import EarthSatellite

    data = read_scenario_file(TLE)
    data["duration_s"] = 5400.0
    data["star_sensor"] = [{**data["star_sensor"][0], "name": "low", "mounting_rotvec_deg": [-95.0, 0.0, 0.0],
                            "sun_exclusion_deg": 45.0, "moon_exclusion_deg": 20.0, "earth_exclusion_deg": 25.0},
                           {**data["star_sensor"][0], "name": "zenith", "sun_exclusion_deg": 60.0}]
    scenario = scenario_from_dict(data)
    prepared = prepare(scenario)
    run = simulate(prepared, 1)
    ts, eph = skyfield_sky
    t = prepared.frames.t
    when = ts.utc(2008, 9, 20, 12, 0, t)
    satellite = EarthSatellite(*data["orbit"]["tle"], ts=ts).at(when)
    r = satellite.position.m.T
    earth = eph["earth"].at(when).position.m
    sun = (eph["sun"].at(when).position.m - earth).T - r
    moon = (eph["moon"].at(when).position.m - earth).T - r
    margin = np.radians(0.05)
    checked = {"Sun": 0, "Moon": 0, "limb": 0}
    for h, head in enumerate(scenario["star_sensor"]):
        boresight = prepared.frames.heads[h].boresight
        for name, body, limit in (("Sun", sun, head["sun_exclusion_deg"]), ("Moon", moon, head["moon_exclusion_deg"])):
            u = body / np.linalg.norm(body, axis=1, keepdims=True)
            angle = np.arccos(np.clip(np.sum(u * boresight, axis=1), -1.0, 1.0))
            hidden = np.array([_ray_hits_ellipsoid(r[k], u[k][None], 0.0)[0] for k in range(len(t))])
            inside, clear = (angle < np.radians(limit) - margin) & ~hidden, angle > np.radians(limit) + margin
            excluded = prepared.frames.heads[h].reason >= 0
            assert np.all(excluded[inside]) and not np.any((prepared.frames.heads[h].reason == ("Sun", "Moon").index(name))[clear])
            checked[name] += int(inside.sum())
        height = 1e3 * head["earth_limb_height_km"]
        limit = np.radians(head["earth_exclusion_deg"])
        for k in range(0, len(t), 7):
            limb_in = _limb_within(r[k], boresight[k], limit - margin, height)
            limb_out = not _limb_within(r[k], boresight[k], limit + margin, height)
            reason = prepared.frames.heads[h].reason[k]
            if limb_in:
                assert reason >= 0
                checked["limb"] += 1
            if limb_out:
                assert reason != 2
        # an excluded frame fuses no star of that head
        assert not np.any(run.series["head_measurements"][prepared.frames.heads[h].reason >= 0, h])
    assert checked["Sun"] > 0 and checked["limb"] > 0, checked


def test_the_earth_hides_exactly_the_stars_behind_its_raised_ellipsoid():
    rng = np.random.default_rng(4)
    r = np.array([[0.0, 0.0, 6.9e6], [7.2e6, 0.0, 0.0], [3.0e6, 3.0e6, 5.6e6]])
    disc = EarthDisc(r, 80e3)
    for k in range(len(r)):
        u = rng.standard_normal((4000, 3))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        assert np.array_equal(disc.hides(u, np.full(len(u), k)), _ray_hits_ellipsoid(r[k], u, 80e3))


def _heads_run(seed, heads):
    data = read_scenario_file(BASE)
    data["duration_s"] = 600.0
    data["pointing"].pop("offsets")
    data["star_sensor"] = [{**h, "sun_exclusion_deg": 0.0, "misalignment_sigma_arcsec": 0.0} for h in data["star_sensor"][:heads]]
    data["filter"] = {"mounting": "ignore"}
    return simulate(prepare(scenario_from_dict(data)), seed)


def test_two_heads_at_90_deg_remove_one_heads_roll_weakness():
    """One 20 deg head: its roll about the boresight 2-3 times its cross-boresight error |δθ_xy| (seen: 1.96-2.98 over
    three seeds; per axis 3-4: the stars' lever arm is the field's half-width, and the body's turn at the orbital rate
    carries part of the well-measured axes into the roll); two heads 90 deg apart: each one's roll below its
    cross-boresight error (seen: 0.72-0.83), within the issue's 1.5x."""
    one = [_heads_run(seed, 1).summary["heads"][0]["roll_to_cross_boresight"] for seed in range(3)]
    two = [h["roll_to_cross_boresight"] for seed in range(3) for h in _heads_run(seed, 2).summary["heads"]]
    assert min(one) > 1.5 and max(two) < 1.0, (one, two)


def test_without_the_aberration_correction_the_attitude_is_off_by_the_aberration():
    """The orbit's 7.6 km/s and the Earth's 30 km/s move the stars by up to ~26"; without the correction the attitude
    error grows to that size, with it it stays at the stars' noise."""
    data = read_scenario_file(BASE)
    data["duration_s"] = 300.0
    with_it = simulate(prepare(scenario_from_dict(data)), 2).summary
    data["star_sensor"] = [{**h, "aberration_correction": False} for h in data["star_sensor"]]
    without = simulate(prepare(scenario_from_dict(data)), 2).summary
    assert with_it["cross_boresight_rms_arcsec"] < 2.0
    assert 8.0 < without["cross_boresight_rms_arcsec"] < 40.0


def test_a_run_and_its_report(tmp_path, capsys):
    out = tmp_path / "run"
    status, _ = run_cli(cli.main, ["run", BASE, "--out", out, "--report", tmp_path / "run.pdf"], capsys)
    assert status == 0
    text, pages = pdf_text(tmp_path / "run.pdf")
    assert "Star-sensor heads" in text and "Orbit and pointing" in text and pages >= 3


def test_a_campaign_and_its_report(tmp_path, capsys):
    status, _ = run_cli(cli.main, ["montecarlo", TARGETS, "--runs", 2, "--out", tmp_path / "mc", "--workers", 1], capsys)
    assert status == 0
    status, _ = run_cli(cli.main, ["report", tmp_path / "mc", "-o", tmp_path / "mc.pdf"], capsys)
    assert status == 0
    assert "Star-sensor heads over the runs" in pdf_text(tmp_path / "mc.pdf")[0]


def test_a_head_is_overridden_by_its_index(tmp_path, capsys):
    scenario = load_scenario(BASE, ["star_sensor.1.fov_deg=12.0"])
    assert scenario["star_sensor"][1]["fov_deg"] == 12.0 and scenario["star_sensor"][0]["fov_deg"] == 20.0
    status, err = run_cli(cli.main, ["run", BASE, "--out", tmp_path / "out", "--set", "star_sensor.x.fov_deg=12.0"], capsys)
    assert status == 2 and "star_sensor.x.fov_deg" in err and "not an index" in err
