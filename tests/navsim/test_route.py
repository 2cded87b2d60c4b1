"""Routes by waypoints (navsim.truth.route): a leg is the ellipsoid's geodesic (against Karney's algorithms in
geographiclib, independent software), every waypoint is flown over, perfect sensors fly a route over the pole
exactly, and a route that cannot be flown is one clear line."""

import math

import numpy as np
import pytest
from geographiclib.geodesic import Geodesic

from navsim import cli
from navsim.earth.wander import ned_offset
from navsim.ins import strapdown
from navsim.truth import route as route_module
from navsim.truth import trajectory
from navsim.truth.route import MISS, Route, Waypoint
from startrack.base import units
from tests.navsim.test_bad_input_corpus import BASES, assert_one_clear_line
from tests.support import run_cli

#: (from, to) of legs at h = 0: mid-latitude, across the antimeridian, over the pole, beside it, 179 deg apart.
LEGS = [((45.0, 7.0), (50.0, 20.0)), ((10.0, 170.0), (-20.0, -160.0)), ((80.0, 0.0), (80.0, 180.0)),
        ((89.99, 45.0), (89.0, -100.0)), ((0.0, 0.0), (1.0, 179.0))]


@pytest.mark.parametrize("start, end", LEGS)
def test_a_leg_at_zero_height_is_the_ellipsoids_geodesic(start, end):
    """Length and initial azimuth against geographiclib (Karney 2013, to nanometres): the leg solves to MISS,
    its position is carried at 1 s steps (a few mm over 10 000 km): within 1 cm, and 1 cm over the length in
    azimuth."""
    speed = 250.0
    profile = Route((Waypoint(*start, 0.0, speed), Waypoint(*end, 0.0, speed))).profile()
    (straight,) = profile.segments
    inverse = Geodesic.WGS84.Inverse(*start, *end)
    assert straight.duration_s * speed == pytest.approx(inverse["s12"], abs=0.01)
    azimuth_error = (profile.start.heading_deg - inverse["azi1"] + 180.0) % 360.0 - 180.0
    assert abs(azimuth_error) * units.DEG * inverse["s12"] < 0.01


def _polar_route():
    """Four waypoints around the North Pole with turns of all sizes, a climb and a speed change."""
    return Route((Waypoint(85.0, 0.0, 1000.0, 200.0), Waypoint(89.9, 90.0, 1000.0, 200.0),
                  Waypoint(88.0, -170.0, 1500.0, 220.0), Waypoint(86.5, 100.0, 1500.0, 220.0)), bank_deg=25.0)


def test_every_waypoint_is_flown_over():
    """The truth at the IMU rate passes over each waypoint at its time within 2 mm (the solve's MISS at 1 s
    steps, and the carried position's difference between 1 s and 20 ms), at its height."""
    route = _polar_route()
    profile, times = route.solve()
    rate = 50.0
    kin = trajectory.kinematics(profile, rate)
    for waypoint, time in zip(route.waypoints[1:], times):
        k = min(int(time * rate), kin.t.size - 2)
        share = time * rate - k
        offsets = [ned_offset(waypoint.lat_deg * units.DEG, waypoint.lon_deg * units.DEG, waypoint.height_m,
                              kin.lat[j], kin.lon[j], kin.h[j]) for j in (k, k + 1)]
        miss = (1.0 - share) * offsets[0] + share * offsets[1]
        assert np.hypot(miss[0], miss[1]) < 2.0 * MISS + 1e-3
        assert abs(miss[2]) < 1e-6


def test_perfect_sensors_over_the_pole_exactly():
    """80 N, 0 E to 80 N, 180 E over the pole (3.1 h at 200 m/s, 50 Hz): the wander-azimuth INS on the truth's
    increments stays within 1 mm (today's aircraft: 0.3 mm in 1 h at 100 Hz), the track passing over the pole."""
    profile = Route((Waypoint(80.0, 0.0, 3000.0, 200.0), Waypoint(80.0, 180.0, 3000.0, 200.0))).profile()
    truth = trajectory.generate(profile, 50.0)
    assert math.degrees(truth.lat.max()) > 90.0 - 4.0 / 111e3  # the samples are 4 m apart
    nav = strapdown.initial_state(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0])
    log = strapdown.run(nav, truth.dtheta, truth.dv, truth.dt, baro_h=truth.h[1:], every=500)
    k = np.arange(0, truth.t.size, 500)
    error = ned_offset(log.lat, log.lon, log.h, truth.lat[k], truth.lon[k], truth.h[k])
    assert np.abs(error[:, :2]).max() < 1e-3


def test_a_routes_default_duration_is_whole_milliseconds():
    """A route's run length defaults to its flown time to the millisecond below, so a campaign written by one
    build of the Newton solve resumes under another; a profile of segments keeps its exact sum."""
    waypoints = [{"lat_deg": p.lat_deg, "lon_deg": p.lon_deg, "height_m": p.height_m, "speed_m_per_s": p.speed_m_per_s}
                 for p in _polar_route().waypoints]
    table = {"route": {"bank_deg": 25.0, "waypoints": waypoints}}
    flown = route_module.profile_of(table).duration
    assert route_module.flight_time(table) * 1000.0 == math.floor(flown * 1000.0)
    segments = {"start": {"lat_deg": 45.0, "lon_deg": 7.0, "height_m": 0.0, "speed_m_per_s": 100.0, "heading_deg": 0.0},
                "segments": [{"kind": "straight", "duration_s": 12.3456789}]}
    assert route_module.flight_time(segments) == route_module.profile_of(segments).duration


BAD_ROUTES = {
    "coincident": ("waypoints[1]", "coincides",
                   [(60.0, 10.0, 100.0), (60.0, 10.0, 100.0)], {}),
    "antipodal": ("waypoints[2]", "antipodal",
                  [(0.0, 0.0, 100.0), (45.0, 30.0, 100.0), (-45.0, -150.0, 100.0)], {}),
    "too fast to make the turn": ("waypoints[2]", "turn radius",
                                  [(60.0, 10.0, 300.0), (60.0, 12.0, 300.0), (60.01, 12.0, 300.0)], {}),
    "impossible bank": ("bank_deg", "60", [(60.0, 10.0, 100.0), (61.0, 10.0, 100.0)], {"bank_deg": 75.0}),
    "one waypoint": ("waypoints", "at least two", [(60.0, 10.0, 100.0)], {}),
}


@pytest.mark.parametrize("case", BAD_ROUTES, ids=list(BAD_ROUTES))
def test_a_route_that_cannot_be_flown_is_one_clear_line(tmp_path, capsys, case):
    culprit, reason, points, options = BAD_ROUTES[case]
    text = BASES["route"].read_text()
    head, tail = text.split("[trajectory.route]")
    route = "\n".join(f"{key} = {value}" for key, value in options.items())
    rows = ",\n".join(f"  {{ lat_deg = {lat}, lon_deg = {lon}, height_m = 500.0, speed_m_per_s = {speed} }}"
                      for lat, lon, speed in points)
    path = tmp_path / "route.toml"
    path.write_text(f"{head}[trajectory.route]\n{route}\nwaypoints = [\n{rows},\n]\n{tail[tail.index('[imu]'):]}")
    out = tmp_path / "out"
    status, err = run_cli(cli.main, ["run", path, "--out", out], capsys)
    assert_one_clear_line(status, err, culprit, out)
    assert reason in err


def test_a_route_with_segments_is_refused(tmp_path, capsys):
    text = BASES["route"].read_text().replace("[trajectory.route]", "[trajectory]\nsegments = [{ kind = \"straight\", "
                                                                      "duration_s = 10.0 }]\n\n[trajectory.route]")
    path = tmp_path / "both.toml"
    path.write_text(text)
    status, err = run_cli(cli.main, ["run", path, "--out", tmp_path / "out"], capsys)
    assert_one_clear_line(status, err, "not both", tmp_path / "out")


def test_segments_start_at_most_at_a_pole(tmp_path, capsys):
    """A segments trajectory starts anywhere up to a pole (near one it is carried in the free-azimuth frame:
    tests/navsim/test_polar_segments.py); beyond 90 deg is one line naming the key."""
    out = tmp_path / "out"
    status, err = run_cli(cli.main, ["run", BASES["navigation"], "--out", out, "--set", "trajectory.start.lat_deg=90.5"],
                          capsys)
    assert_one_clear_line(status, err, "lat_deg", out)
