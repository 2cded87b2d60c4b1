"""Segments at every latitude (issue 53 item 5): near a pole a segments trajectory is carried in the free-azimuth
level frame, elsewhere in the North frame bit for bit; a hold at and beside the pole has the free INS's Schuler
oscillation with the Foucault term at its closed form; a straight leg over the pole is a geodesic the INS follows."""

import math

import numpy as np
import pytest
from scipy.optimize import least_squares

from navsim.earth.gravity import normal_gravity
from navsim.earth.wander import displaced, ned_offset
from navsim.earth.wgs84 import OMEGA_IE, radii
from navsim.ins import strapdown
from navsim.simulation import run_batch
from navsim.truth import route, trajectory
from navsim.truth.level_frames import FreeAzimuth, North
from startrack import rotation as rot


def _segments(lat_deg, speed=0.0, heading_deg=0.0, segments=None):
    return {"start": {"lat_deg": lat_deg, "lon_deg": 30.0, "height_m": 0.0, "speed_m_per_s": speed,
                      "heading_deg": heading_deg},
            "segments": segments or [{"kind": "hold", "duration_s": 3600.0}]}


@pytest.mark.parametrize("table, frame", [
    (_segments(45.0), North), (_segments(88.99), North), (_segments(89.0), FreeAzimuth), (_segments(89.99), FreeAzimuth),
    (_segments(90.0), FreeAzimuth), (_segments(-90.0), FreeAzimuth),
    (_segments(88.9, 250.0, 90.0, [{"kind": "straight", "duration_s": 3600.0}]), North),  # 900 km along 88.9 N
    (_segments(88.0, 250.0, 0.0, [{"kind": "straight", "duration_s": 3600.0}]), FreeAzimuth),  # on to the pole
    (_segments(-85.0, 10.0, 180.0, [{"kind": "straight", "duration_s": 3600.0}]), North),  # 36 km: stops at 85.3 S
])
def test_the_frame_is_free_in_azimuth_only_near_a_pole(table, frame):
    """North wherever the track stays below 89 deg of latitude (what it was before, so those runs are unchanged),
    free in azimuth from the start when any of it comes nearer a pole."""
    assert type(route.profile_of(table).frame) is frame


#: A free INS at rest: turn-on accelerometer biases of 50 µg σ and nothing else (the initial errors fixed at 0, so
#: the error is the bias's forced response alone), the vertical held by a baro that corrects only vertical states.
HOLD = {
    "name": "pole_hold",
    "imu": {"rate_hz": 10.0, "gyro": {"bias_turn_on_deg_per_h": 0.0}, "accelerometer": {"bias_turn_on_micro_g": 50.0}},
    "baro": {"rate_hz": 1.0},
    "filter": {"initial_attitude_error_arcsec": [0.0, 0.0, 0.0], "initial_velocity_error_m_per_s": [0.0, 0.0, 0.0],
               "initial_position_error_m": [0.0, 0.0, 0.0]},
}


def _oscillation(t, z, omega0, f0):
    """(Ω, f, c) of the least-squares fit z ≈ c0 + e^(ift) (c1 cos Ωt + c2 sin Ωt) (complex z, c)."""
    def fit(p):
        basis = np.stack([np.ones_like(t), np.exp(1j * p[1] * t) * np.cos(p[0] * t),
                          np.exp(1j * p[1] * t) * np.sin(p[0] * t)], axis=-1)
        c = np.linalg.lstsq(basis, z, rcond=None)[0]
        return c, basis @ c - z
    def residual(p):
        r = fit(p)[1]
        return np.concatenate([r.real, r.imag])
    p = least_squares(residual, [omega0, 0.5 * f0], x_scale=[1e-3, 1e-4]).x
    return p[0], p[1], fit(p)[0]


@pytest.mark.parametrize("lat_deg", [89.99, 90.0, -90.0])
def test_a_one_hour_hold_at_the_pole_oscillates_at_the_closed_form(lat_deg):
    """`navsim run` of a 1 h hold: the horizontal error z = δN + i δE of the bias ∇ (its NED part ∇_N + i ∇_E) obeys
    z̈ − 2if ż + ω_s² z = ∇ (f = ω_ie sin L, the Foucault term of −2 ω_ie × δv; Titterton & Weston §12.2), so from
    rest z = (∇/ω_s²)[1 − e^(ift)(cos Ωt − i (f/Ω) sin Ωt)], Ω = √(ω_s² + f²). The series is that closed form within
    0.5 m (of a 500 m swing), the fitted period within 0.5 % of 2π/Ω (84.34 min, 0.17 % shorter than the equator's
    Schuler period at the same radius) and f within 1 % of ω_ie sin L."""
    table = dict(HOLD, trajectory=_segments(lat_deg))
    series = run_batch(table, [3])[0].series
    t, e = series["t"], series["position_error_m"]
    z = e[:, 0] + 1j * e[:, 1]
    lat = math.radians(lat_deg)
    ws2 = normal_gravity(lat, 0.0) / math.sqrt(np.prod(radii(lat)))
    f = OMEGA_IE * math.sin(lat)
    omega = math.sqrt(ws2 + f * f)
    bias = rot.rotate(series["q_nb_true"][0], series["accel_bias_true"][0])
    offset = (bias[0] + 1j * bias[1]) / ws2
    expected = offset * (1.0 - np.exp(1j * f * t) * (np.cos(omega * t) - 1j * f / omega * np.sin(omega * t)))
    assert abs(offset) > 100.0
    assert np.max(np.abs(z - expected)) < 0.5
    fitted_omega, fitted_f, c = _oscillation(t, z, math.sqrt(ws2), f)
    assert 2.0 * np.pi / fitted_omega == pytest.approx(2.0 * np.pi / omega, rel=0.005)
    assert fitted_f == pytest.approx(f, rel=0.01)
    assert c[0] == pytest.approx(offset, abs=0.01 * abs(offset))


def test_a_straight_leg_over_the_pole_is_a_geodesic_the_ins_follows():
    """From 89.5 N heading north at 250 m/s for 1000 s: the truth runs up the 30 E meridian over the pole and down
    the 150 W one (a geodesic: the free-azimuth frame's constant heading), its arc from the start V t at every
    sample within 1 mm (the meridian's arc by quadrature of dL/ds = 1/(R_M + h)); perfect sensors integrated by the
    wander-azimuth INS stay within 1 mm."""
    table = _segments(89.5, 250.0, 0.0, [{"kind": "straight", "duration_s": 1000.0}])
    truth = trajectory.generate(route.profile_of(table), 50.0)
    over = truth.lat > math.radians(89.9)
    assert np.any(np.abs(np.degrees(truth.lat) - 90.0) < 250.0 / 50.0 / 111e3)  # passes over the pole
    beyond = np.cumsum(np.diff(truth.lat) < 0) > 0
    lon = np.degrees(truth.lon[1:][~over[1:]])
    assert np.allclose(np.where(beyond[~over[1:]], lon + 180.0, lon) % 360.0, 30.0, atol=1e-9)
    grid = np.linspace(math.radians(88.0), math.pi / 2, 40001)
    arc = np.concatenate([[0.0], np.cumsum(np.diff(grid) * radii(0.5 * (grid[1:] + grid[:-1]))[0])])
    to_pole = arc[-1] - np.interp(truth.lat, grid, arc)  # the meridian's arc from L to the pole [m]
    flown = np.where(np.append(False, beyond), to_pole[0] + to_pole, to_pole[0] - to_pole)
    assert np.max(np.abs(flown - 250.0 * truth.t)) < 1e-3
    nav = strapdown.initial_state(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0])
    log = strapdown.run(nav, truth.dtheta, truth.dv, truth.dt, every=50)
    k = np.arange(0, truth.t.size, 50)
    assert np.abs(ned_offset(log.lat, log.lon, log.h, truth.lat[k], truth.lon[k], truth.h[k])[:, :2]).max() < 1e-3


def test_a_fix_at_the_pole_is_the_truth_displaced_along_its_ned():
    """The position fix's noise is a displacement along the truth's NED (no cos L divides it): at the pole and beside
    it, the offset of the displaced point in the truth's NED is the drawn noise within 10 nm (the two are each other's
    inverse to first order; what is left at 5 m is rounding)."""
    rng = np.random.default_rng(5)
    noise = 5.0 * rng.standard_normal((100, 2))
    for lat in (math.pi / 2, math.radians(89.999), -math.pi / 2, 0.3):
        lat_f, lon_f = displaced(lat, 1.0, 100.0, noise[:, 0], noise[:, 1])
        offset = ned_offset(lat_f, lon_f, np.full(100, 100.0), lat, 1.0, 100.0)
        assert np.max(np.abs(offset[:, :2] - noise)) < 1e-8


def test_position_fixes_at_the_pole_are_consistent():
    """Fixes of 3 m NED σ every second on a 10 min hold at 90 N (4 runs): the mean NIS per dof within 3σ of 1
    (σ = √(2/(3 · 2400))), as anywhere else -- the fix's noise is the displacement the filter's R describes."""
    table = {"name": "pole_fixes", "trajectory": _segments(90.0, segments=[{"kind": "hold", "duration_s": 600.0}]),
             "imu": {"rate_hz": 10.0, "gyro": {"preset": "navigation"}, "accelerometer": {"preset": "navigation"}},
             "aiding": {"position": {"rate_hz": 1.0, "sigma_ned_m": [3.0, 3.0, 5.0]}},
             "filter": {"initial_heading_sigma_deg": 0.05}}
    nis = np.concatenate([r.series["nis"] / r.series["nis_dof"] for r in run_batch(table, range(4))])
    assert nis.size == 2400 and abs(np.mean(nis) - 1.0) < 3.0 * math.sqrt(2.0 / (3.0 * nis.size))
