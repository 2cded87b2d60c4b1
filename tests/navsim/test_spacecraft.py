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
from startrack import rotation as rot
from startrack import units
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
    in s, independent of navsim.orbit): ``origin`` (3,) with ``directions`` (N, 3), or (F, 3) with (F, K, 3)."""
    a, c = R_EARTH + height, (R_EARTH + height) * (1.0 - FLATTENING)
    scale = np.array([1.0 / a, 1.0 / a, 1.0 / c])
    o, u = np.asarray(origin) * scale, directions * scale
    o = o[:, None] if u.ndim == 3 else o
    A, B, C = np.sum(u * u, axis=-1), 2.0 * np.sum(o * u, axis=-1), np.sum(o * o, axis=-1) - 1.0
    disc = B * B - 4.0 * A * C
    return (disc >= 0.0) & ((-B + np.sqrt(np.maximum(disc, 0.0))) / (2.0 * A) > 0.0)


def _cone(axis, half_angle, count):
    """Unit directions (F, count + 1, 3): the unit axes ``axis`` (F, 3) and ``count`` rays on the cones of
    ``half_angle`` [rad] around them (180 rays: where the limb touches a 25 deg cone between two of them, 2 deg apart in
    azimuth, it is missed by < 0.005 deg, a tenth of the test's margin)."""
    e1 = np.cross(axis, np.where(np.abs(axis[:, :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    e2 = np.cross(axis, e1)
    phi = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)[:, None]
    ring = np.cos(half_angle) * axis[:, None] + np.sin(half_angle) * (np.cos(phi) * e1[:, None] + np.sin(phi) * e2[:, None])
    return np.concatenate([axis[:, None], ring], axis=1)


def _hits(origin, axis, angle, height, count=180, chunk=500):
    """(F, count + 1) whether the rays from ``origin`` (F, 3) along ``axis`` (F, 3) and on the cone of ``angle`` [rad]
    around it meet the ellipsoid raised by ``height`` [m] (any: it reaches within the angle; all: it covers the cone)."""
    return np.concatenate([_ray_hits_ellipsoid(origin[k:k + chunk], _cone(axis[k:k + chunk], angle, count), height)
                           for k in range(0, len(origin), chunk)])


def _independent_reasons(head, boresight, r, bodies, margin):
    """The reason each frame of a head (its table, boresights (F, 3)) at the geocentric positions ``r`` (F, 3) is
    excluded for by the independent geometry (the index of Sun, Moon, limb; −1: none; −2: a threshold within
    ``margin`` [rad], not judged), the geocentric Sun and Moon in ``bodies``; and {reason: [frames where it applies,
    frames out of its cone, frames in its cone with the body behind the Earth]}."""
    applies, judged, counts = [], np.ones(len(r), dtype=bool), {}
    for name, body in zip(("Sun", "Moon"), bodies):
        u = body - r
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        angle = np.arccos(np.clip(np.sum(u * boresight, axis=1), -1.0, 1.0))
        limit = np.radians(head[f"{name.lower()}_exclusion_deg"])
        near_earth = _hits(r, u, margin, 0.0, count=16)
        inside, outside, visible, hidden = angle < limit - margin, angle > limit + margin, ~near_earth.any(1), near_earth.all(1)
        applies.append(inside & visible)
        judged &= (inside & visible) | outside | hidden
        counts[name] = [int(np.sum(inside & visible)), int(np.sum(outside)), int(np.sum(inside & hidden))]
    height, limit = 1e3 * head["earth_limb_height_km"], np.radians(head["earth_exclusion_deg"])
    limb_in, limb_out = _hits(r, boresight, limit - margin, height).any(1), ~_hits(r, boresight, limit + margin, height).any(1)
    applies.append(limb_in)
    judged &= limb_in | limb_out
    counts["limb"] = [int(np.sum(limb_in)), int(np.sum(limb_out)), 0]
    expected = np.full(len(r), -1)
    for k in reversed(range(3)):
        expected[applies[k]] = k
    return np.where(judged, expected, -2), counts


def test_the_exclusions_are_those_of_an_independent_geometry_and_fuse_no_star(skyfield_sky):
    """An orbit of the ISS's TLE in nadir pointing (at the epoch the Sun 48 deg and the Moon 12 deg off the orbit's
    plane on the side of its normal, +n = −y_B) with a 20 deg pitch-up at 2 700 s, three heads each sweeping one reason
    across its threshold: "sun" from the zenith 48 deg towards +n (the Sun through its 30 deg cone once an orbit),
    "moon" 12 deg towards +n (the Moon through its 15 deg cone), "limb" along the track (the raised limb 17 deg below
    it before the pitch-up, 37 deg after, against 25; the Sun and the Moon pass its 60 and 40 deg cones, partly
    behind the Earth). The reason of every frame is the first of Sun, Moon, limb that applies by an independent
    geometry: skyfield's Sun and Moon (DE421) seen from skyfield's SGP4 position, each hidden when rays on a
    0.05 deg cone around it meet the ellipsoid; the limb where a ray on the exclusion cone meets the raised
    ellipsoid; frames within 0.05 deg of a threshold are not judged. Every reason has frames in and out of its
    cone (the Sun and the Moon also in it behind the Earth); every head fuses stars outside its excluded frames and
    none inside."""
    from skyfield.api import EarthSatellite

    data = read_scenario_file(TLE)
    data["duration_s"] = 5400.0
    data["pointing"]["offsets"] = [{"start_s": 2700.0, "pitch_deg": 20.0}]
    head = data["star_sensor"][0]
    data["star_sensor"] = [{**head, "name": "sun", "mounting_rotvec_deg": [132.0, 0.0, 0.0], "sun_exclusion_deg": 30.0},
                           {**head, "name": "moon", "mounting_rotvec_deg": [168.0, 0.0, 0.0], "moon_exclusion_deg": 15.0},
                           {**head, "name": "limb", "mounting_rotvec_deg": [0.0, 90.0, 0.0], "sun_exclusion_deg": 60.0,
                            "moon_exclusion_deg": 40.0, "earth_exclusion_deg": 25.0}]
    scenario = scenario_from_dict(data)
    prepared = prepare(scenario)
    run = simulate(prepared, 1)
    ts, eph = skyfield_sky
    when = ts.utc(2008, 9, 20, 12, 0, prepared.frames.t)
    r = EarthSatellite(*data["orbit"]["tle"], ts=ts).at(when).position.m.T
    earth = eph["earth"].at(when).position.m
    bodies = [(eph[name].at(when).position.m - earth).T for name in ("sun", "moon")]
    margin = np.radians(0.05)
    seen = {name: np.zeros(3, dtype=int) for name in ("Sun", "Moon", "limb")}
    for h, head in enumerate(scenario["star_sensor"]):
        sky = prepared.frames.heads[h]
        expected, counts = _independent_reasons(head, sky.boresight, r, bodies, margin)
        judged = expected > -2
        wrong = np.flatnonzero(judged & (sky.reason != expected))
        assert np.mean(judged) > 0.95 and not len(wrong), \
            f"head {head['name']}: {len(wrong)} frames (at t = {prepared.frames.t[wrong[:5]]} s) excluded for " \
            f"{sky.reason[wrong[:5]]}, the independent geometry's {expected[wrong[:5]]} (0 Sun, 1 Moon, 2 limb, -1 none)"
        for name in seen:
            seen[name] += counts[name]
        fused = run.series["head_measurements"][:, h]
        excluded = sky.reason >= 0
        assert excluded.any() and not fused[excluded].any() and fused[~excluded].mean() > 5.0, \
            f"head {head['name']}: {excluded.sum()} frames excluded, {fused[excluded].sum()} stars fused on them, " \
            f"{fused[~excluded].mean():.1f} a frame on the others"
    assert all(n[0] > 100 and n[1] > 100 for n in seen.values()) and seen["Sun"][2] > 0 and seen["Moon"][2] > 0, seen


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


#: The speed of light [m/s].
SPEED_OF_LIGHT = 299792458.0
#: The per-frame tolerance [arcsec] of the uncorrected aberration: a field's stars off its boresight (their centroid
#: ρ̄ up to ~3 deg for ten stars in a 20 deg field) turn the aberration's contraction β_∥ ρ of the field into a shift
#: β_∥ ρ̄ ≤ 20" x 0.05 = 1" (seen ≤ 1.2"); the orbit's term alone is 5.2" sin θ_orbit.
ABERRATION_TOLERANCE_ARCSEC = 1.5


def test_without_the_aberration_correction_the_attitude_is_off_by_the_aberration(skyfield_sky):
    """One head 45 deg from the zenith across the track, 300 s: with the correction the attitude stays at the stars'
    noise; without it, frame by frame, the error it adds (the same seed: the same stars and noise) is in the head's
    axes the rotation b × β that moves the field by the aberration, (v/c) sin θ towards the apex (9.0-10.6" here),
    v the spacecraft's barycentric velocity: the orbit's (central differences of its positions) plus the Earth's
    (skyfield, DE421), within :data:`ABERRATION_TOLERANCE_ARCSEC` after the filter's settling."""
    data = read_scenario_file(BASE)
    data["duration_s"] = 300.0
    data["pointing"].pop("offsets")
    data["star_sensor"] = data["star_sensor"][:1]
    data["filter"] = {"mounting": "ignore"}
    prepared = prepare(scenario_from_dict(data))
    with_it = simulate(prepared, 2)
    data["star_sensor"] = [{**h, "aberration_correction": False} for h in data["star_sensor"]]
    without = simulate(prepare(scenario_from_dict(data)), 2)
    assert with_it.summary["cross_boresight_rms_arcsec"] < 2.0
    ts, eph = skyfield_sky
    t = prepared.frames.t
    orbit = prepared.frames.r_I
    v = np.gradient(orbit, t, axis=0) + eph["earth"].at(ts.utc(2025, 3, 5, 0, 0, t)).velocity.m_per_s.T
    q_IS = rot.multiply(without.series["q_true"], prepared.q_BS[0])
    beta_S = rot.rotate(rot.conjugate(q_IS), v / SPEED_OF_LIGHT)
    expected = np.stack([-beta_S[:, 1], beta_S[:, 0]], axis=1)  # ẑ × β in the head's axes
    added = ((without.series["attitude_error"] - with_it.series["attitude_error"]) @ rot.to_matrix(prepared.q_BS[0]))[:, :2]
    miss = np.linalg.norm(added - expected, axis=1) / units.ARCSEC
    steady = t >= prepared.scenario["settle_s"]
    size = np.linalg.norm(expected, axis=1) / units.ARCSEC
    assert np.max(miss[steady]) < ABERRATION_TOLERANCE_ARCSEC, \
        f"{np.max(miss[steady]):.2f}\" from (v/c) sin θ at t = {t[steady][np.argmax(miss[steady])]} s (aberration " \
        f"{size.min():.1f}-{size.max():.1f}\")"


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
