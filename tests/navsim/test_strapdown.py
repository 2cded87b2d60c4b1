"""Strapdown mechanization: our trajectory generator's IMU integrated by ours reproduces the truth, and
the free-INS error dynamics follow their closed forms (Schuler period and amplitude, north gyro drift).

The free vertical channel is unstable (e-folding time √(a/2g) ≈ 570 s): runs longer than ~1 h damp it
with the baro loop fed by the true height (a perfect baro), as every real INS does."""

import numpy as np
import pytest
from scipy.optimize import curve_fit

from navsim.earth.gravity import normal_gravity
from navsim.earth.wgs84 import radii
from navsim.ins import strapdown
from navsim.truth import trajectory
from navsim.truth.segments import Hold, Profile, Start
from startrack.base import units
from startrack.base.errors import InputError
from startrack.geometry import rotation as rot
from tests.navsim.ins_helpers import aircraft_first_hour, attitude_errors, position_errors, trajectory_table


def _start(truth, q_nb=None):
    return strapdown.initial_state(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0],
                                   truth.q_nb[0] if q_nb is None else q_nb)


@pytest.fixture(scope="module")
def aircraft_hour():
    """The aircraft's first hour with its IMU at 100 Hz."""
    return trajectory.generate(aircraft_first_hour(), 100.0)


def test_our_imu_integrated_by_ours_reproduces_the_aircraft_truth(aircraft_hour):
    """1 h of flight, perfect sensors, free INS (vertical channel undamped): position within 0.1 m,
    velocity within 1 mm/s, attitude within 0.001"."""
    truth = aircraft_hour
    log = strapdown.run(_start(truth), truth.dtheta, truth.dv, truth.dt, every=100)
    errors = position_errors(log, truth, every=100)
    assert np.max(np.linalg.norm(errors, axis=1)) < 0.1
    assert np.max(np.abs(log.v_n - truth.v_n[::100])) < 1e-3
    assert np.max(np.abs(attitude_errors(log, truth, every=100))) < 1e-3 * units.ARCSEC


def test_stationary_day_stays_within_one_metre():
    """24 h at rest (45 deg N), perfect sensors at 5 Hz, baro-damped vertical: within 1 m."""
    truth = trajectory.generate(Profile(Start(45.0, 10.0, 150.0, heading_deg=40.0), (Hold(86400.0),)), 5.0)
    log = strapdown.run(_start(truth), truth.dtheta, truth.dv, truth.dt, baro_h=truth.h[1:], every=50)
    assert np.max(np.linalg.norm(position_errors(log, truth, every=50), axis=1)) < 1.0


@pytest.fixture(scope="module")
def equator_rest():
    """4 h at rest on the equator at 10 Hz: no Foucault coupling (ω_ie sin L = 0), so each horizontal
    channel is a pure Schuler loop."""
    return trajectory.generate(Profile(Start(0.0, 30.0, 0.0), (Hold(4 * 3600.0),)), 10.0)


def _schuler_fit(t, error, omega0):
    model = lambda t, a, b, c, w: a + b * np.cos(w * t) + c * np.sin(w * t)  # noqa: E731
    (a, b, c, w), _ = curve_fit(model, t, error, p0=[error.mean(), -error.mean(), 0.0, omega0])
    return 2.0 * np.pi / w, np.hypot(b, c)


def test_accelerometer_bias_gives_the_schuler_oscillation(equator_rest):
    """A north accelerometer bias ∇: δN(t) = (R∇/g)(1 − cos ω_s t), ω_s = √(g/R): period 84.4 min
    (within 0.5 %) and amplitude R∇/g (within 2 %)."""
    truth, bias = equator_rest, 1e-4
    dv = truth.dv + np.array([bias, 0.0, 0.0]) * truth.dt  # body x is north (heading 0, level)
    log = strapdown.run(_start(truth), truth.dtheta, dv, truth.dt, baro_h=truth.h[1:], every=10)
    r_m, g = radii(0.0)[0], normal_gravity(0.0, 0.0)
    period, amplitude = _schuler_fit(truth.t[::10], position_errors(log, truth, every=10)[:, 0], np.sqrt(g / r_m))
    assert period / 60.0 == pytest.approx(84.4, rel=0.005)
    assert period == pytest.approx(2.0 * np.pi * np.sqrt(r_m / g), rel=1e-4)
    assert amplitude == pytest.approx(r_m * bias / g, rel=0.02)


@pytest.mark.parametrize("lat_deg", [90.0, 89.99, -90.0, 0.0])
def test_accelerometer_bias_gives_the_schuler_oscillation_anywhere(lat_deg):
    """At a pole and beside it, the same closed form as on the equator with the Foucault term: at rest the
    horizontal error z = δN + i δE of a north accelerometer bias ∇ obeys z̈ − 2i f ż + ω_s² z = ∇ (f = ω_ie sin L,
    from −2ω_ie^n × δv), so z = ∇/ω_s² + e^(ift)(A cos Ωt + B sin Ωt), Ω = √(ω_s² + f²). Fitted with f known: the
    period 2π/Ω within 0.5 % and the offset R∇/g within 3 % (the issue's mid-latitude tolerances), and the
    ellipse's axes (A, B)·(1, f/Ω) as the closed form's. 3 h at 10 Hz; wander-azimuth mechanization throughout."""
    from navsim.earth.wgs84 import OMEGA_IE
    truth = trajectory.generate(Profile(Start(lat_deg, 30.0, 0.0), (Hold(3 * 3600.0),)), 10.0)
    bias = 1e-4
    dv = truth.dv + np.array([bias, 0.0, 0.0]) * truth.dt  # body x is north (heading 0, level)
    log = strapdown.run(_start(truth), truth.dtheta, dv, truth.dt, baro_h=truth.h[1:], every=10)
    lat = np.radians(lat_deg)
    r = np.sqrt(np.prod(radii(lat)))
    g, f = normal_gravity(lat, 0.0), OMEGA_IE * np.sin(lat)
    t, e = truth.t[::10], position_errors(log, truth, every=10)
    z = e[:, 0] + 1j * e[:, 1]

    def residual(omega):
        basis = np.stack([np.ones_like(t), np.exp(1j * f * t) * np.cos(omega * t), np.exp(1j * f * t) * np.sin(omega * t)], -1)
        c = np.linalg.lstsq(basis, z, rcond=None)[0]
        return np.sum(np.abs(basis @ c - z) ** 2), c

    omegas = np.sqrt(g / r) * np.linspace(0.97, 1.03, 601)
    omega = omegas[np.argmin([residual(w)[0] for w in omegas])]
    (offset, a, b) = residual(omega)[1]
    expected = np.sqrt(g / r + f * f)
    assert 2 * np.pi / omega == pytest.approx(2 * np.pi / expected, rel=0.005)
    assert abs(offset) == pytest.approx(r * bias / g, rel=0.03)
    assert a == pytest.approx(-offset, abs=0.03 * abs(offset))
    assert b == pytest.approx(1j * f / expected * offset, abs=0.03 * abs(offset))  # ż(0) = 0


def test_initial_tilt_gives_the_schuler_oscillation(equator_rest):
    """An initial tilt φ_N about north: δE(t) = −R φ_N (1 − cos ω_s t). (About north, because on the
    equator the east-tilt channel also exchanges with the heading error at the Earth rate.)"""
    truth, tilt = equator_rest, 20 * units.ARCSEC
    q_est = rot.multiply(rot.from_rotation_vector([-tilt, 0.0, 0.0]), truth.q_nb[0])  # C_est = (I − [φ×]) C
    log = strapdown.run(_start(truth, q_est), truth.dtheta, truth.dv, truth.dt, baro_h=truth.h[1:], every=10)
    r_n, g = radii(0.0)[1], normal_gravity(0.0, 0.0)
    period, amplitude = _schuler_fit(truth.t[::10], position_errors(log, truth, every=10)[:, 1], np.sqrt(g / r_n))
    assert period / 60.0 == pytest.approx(84.4, rel=0.005)
    assert amplitude == pytest.approx(r_n * tilt, rel=0.02)


def test_north_gyro_drift_gives_the_textbook_growth(equator_rest):
    """A north gyro drift ε: δE(t) = R ε (t − sin(ω_s t)/ω_s) (→ g ε t³/6 early, R ε t late), within 1 %."""
    truth, drift = equator_rest, units.deg_per_h_to_rad_per_s(0.01)
    dtheta = truth.dtheta + np.array([drift, 0.0, 0.0]) * truth.dt
    log = strapdown.run(_start(truth), dtheta, truth.dv, truth.dt, baro_h=truth.h[1:], every=10)
    r_n, g = radii(0.0)[1], normal_gravity(0.0, 0.0)
    w = np.sqrt(g / r_n)
    t = truth.t[::10]
    expected = r_n * drift * (t - np.sin(w * t) / w)
    east = position_errors(log, truth, every=10)[:, 1]
    assert np.max(np.abs(east - expected)) < 0.01 * np.max(expected)


def test_bad_start_is_named():
    with pytest.raises(InputError, match="lat"):
        strapdown.initial_state(2.0, 0.0, 0.0, np.zeros(3), [0, 0, 0, 1.0])
    with pytest.raises(InputError, match="height"):
        strapdown.initial_state(0.5, 0.0, -2000.0, np.zeros(3), [0, 0, 0, 1.0])
    with pytest.raises(InputError, match="baro_time_constant_s"):
        strapdown.baro_gains(0.0)


@pytest.mark.slow
def test_earth_rate_oscillation_in_the_ship_run():
    """24 h of the ship (35 N, 8 m/s, rolling, pitching, heaving), IMU at 10 Hz, a body-x gyro drift
    ε = 0.01 deg/h, baro-damped vertical. With the Schuler oscillation averaged out (84-min running
    mean), the position error is a line plus an oscillation at the sidereal day (the psi-angle
    equation ψ̇ = −ω_ie × ψ − ε: the drift's part across the Earth's axis turns at ω_ie) of amplitude
    R ε_⊥/ω_ie (within 5 %); periods of 20 h or 28 h fit four times worse."""
    from navsim.earth.wgs84 import OMEGA_IE
    ship = trajectory_table("free_ins_navigation_ship")
    table = {"start": ship["start"], "segments": [{**ship["segments"][0], "duration_s": 86400.0}]}
    truth = trajectory.generate(Profile.from_table(table), 10.0)
    drift = units.deg_per_h_to_rad_per_s(0.01)
    log = strapdown.run(_start(truth), truth.dtheta + np.array([drift, 0.0, 0.0]) * truth.dt, truth.dv, truth.dt,
                        baro_h=truth.h[1:], every=600)
    errors, t = position_errors(log, truth, every=600), truth.t[::600]
    mean = np.ones(84) / 84.0
    ts = np.convolve(t, mean, mode="valid")

    def fit(series, period_h):
        w = 2.0 * np.pi / (period_h * 3600.0)
        A = np.stack([np.ones_like(ts), ts, np.cos(w * ts), np.sin(w * ts)], axis=-1)
        c = np.linalg.lstsq(A, series, rcond=None)[0]
        return np.sqrt(np.mean((A @ c - series) ** 2)), np.hypot(c[2], c[3])

    sidereal_h = 2.0 * np.pi / OMEGA_IE / 3600.0
    lat, heading = np.radians(35.0), np.radians(60.0)
    drift_n = drift * np.array([np.cos(heading), np.sin(heading), 0.0])
    axis = np.array([np.cos(lat), 0.0, -np.sin(lat)])
    across = np.linalg.norm(drift_n - axis * (drift_n @ axis))
    for channel in (0, 1):
        series = np.convolve(errors[:, channel], mean, mode="valid")
        residual, amplitude = fit(series, sidereal_h)
        assert residual < 0.02 * amplitude
        assert min(fit(series, 20.0)[0], fit(series, 28.0)[0]) > 4.0 * residual
    assert fit(np.convolve(errors[:, 0], mean, mode="valid"), sidereal_h)[1] == pytest.approx(
        radii(lat)[0] * across / OMEGA_IE, rel=0.05)
