"""Navigation error-state filter: F against a numerical linearisation of the nonlinear navigation
equations (every sign of the φ convention), Φ and Q_d against scipy's expm and Van Loan's integral,
and the filter's behaviour."""

import numpy as np
import pytest
from scipy.linalg import expm

from navsim.earth import wander
from navsim.earth.gravity import normal_gravity
from navsim.earth.wgs84 import OMEGA_IE, radii
from navsim.estimation import nav_kernels
from startrack.geometry import rotation as rot

LAT, LON, H, ALPHA = 0.7, 0.3, 3000.0, 0.9
V = np.array([150.0, -80.0, 5.0])
Q_WB = rot.normalize([0.1, -0.05, 0.6, 0.8])
OMEGA_B = np.array([0.02, -0.03, 0.05])
F_B = np.array([1.5, -0.7, -9.9])


def _skew(v):
    return rot.skew(np.asarray(v, dtype=float))


def _rates(state, omega_b, f_b):
    """Nonlinear navigation equations in a free-azimuth w frame (Ċ_ew = C_ew [ρ×], ρ_z = 0; ḣ = −v_z;
    v̇ = C_wb f + g − (2ω_ie + ρ) × v; Ċ_wb = C_wb [ω×] − [(ω_ie + ρ)×] C_wb), written out from the frame
    definitions: ρ from the NED transport rate turned by the wander angle (Groves eq. 5.44)."""
    C_ew, h, v, C = state
    lat, _, alpha = (float(x) for x in wander.frame_angles(C_ew))
    ca, sa = np.cos(alpha), np.sin(alpha)
    C_nw = np.array([[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]])
    r_m, r_n = radii(lat)
    v_n = C_nw @ v
    rho = C_nw.T @ np.array([v_n[1] / (r_n + h), -v_n[0] / (r_m + h), 0.0])
    w_ie = C_ew.T @ np.array([0.0, 0.0, OMEGA_IE])
    v_dot = C @ f_b + np.array([0.0, 0.0, normal_gravity(lat, h)]) - np.cross(2 * w_ie + rho, v)
    return C_ew @ _skew(rho), -v[2], v_dot, C @ _skew(omega_b) - _skew(w_ie + rho) @ C


def _rk4(state, omega_b, f_b, tau):
    def add(x, k, a):
        return tuple(xi + a * ki for xi, ki in zip(x, k))
    k1 = _rates(state, omega_b, f_b)
    k2 = _rates(add(state, k1, tau / 2), omega_b, f_b)
    k3 = _rates(add(state, k2, tau / 2), omega_b, f_b)
    k4 = _rates(add(state, k3, tau), omega_b, f_b)
    return tuple(x + tau / 6 * (a + 2 * b + 2 * c + d) for x, a, b, c, d in zip(state, k1, k2, k3, k4))


def _errors(est, truth):
    """The error state's first nine entries by their definitions (nav_kernels' module docstring): δθ the turn of the
    true normal into the estimated one in the estimated w axes, φ and δv against the truth turned by it."""
    C_ew, h, v, C = est
    C_ew_t, h_t, v_t, C_t = truth
    turn = wander.normal_turn(-C_ew_t[:, 2], -C_ew[:, 2])
    R = expm(_skew(turn))
    M = (C_ew @ C) @ (C_ew_t @ C_t).T @ R.T  # = I − [φ_e×]
    phi_e = 0.5 * np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]]) * -1.0
    return np.concatenate([C_ew.T @ phi_e, C_ew.T @ (C_ew @ v - R @ (C_ew_t @ v_t)), (C_ew.T @ turn)[0:2], [h - h_t]])


def _error_rate(dx, n, lat, alpha):
    """Rate of the error state, by central differences in time of two nonlinear propagations (RK4 over ±τ,
    extrapolated to τ → 0), when the estimate differs from the truth by the error dx."""
    C_ew = rot.to_matrix(wander.q_ew(lat, LON, alpha))
    C = rot.to_matrix(Q_WB)
    truth = (C_ew, H, V, C)
    est = (C_ew @ expm(_skew([dx[6], dx[7], 0.0])), H + dx[8], V + dx[3:6], expm(-_skew(dx[0:3])) @ C)
    omega_est, f_est = OMEGA_B + dx[9:12], F_B + dx[12:15]
    if n > 15:
        omega_est = omega_est + OMEGA_B * dx[15:18]
        f_est = f_est + F_B * dx[18:21]
    def central(tau):
        ahead = _errors(_rk4(est, omega_est, f_est, tau), _rk4(truth, OMEGA_B, F_B, tau))
        behind = _errors(_rk4(est, omega_est, f_est, -tau), _rk4(truth, OMEGA_B, F_B, -tau))
        return (ahead - behind) / (2 * tau)

    rate = np.zeros(n)
    rate[0:9] = (4.0 * central(0.05) - central(0.1)) / 3.0  # Richardson: the τ² truncation removed
    return rate


@pytest.mark.parametrize("place", [(0.7, 0.9), (np.pi / 2, 0.4), (np.radians(89.99), -2.0)], ids=["mid", "pole", "89.99"])
@pytest.mark.parametrize("n", [15, 21])
def test_f_is_the_linearisation_of_the_navigation_equations(n, place):
    """Each column of F equals the central difference of the error's rate by its definitions (every sign of φ,
    Coriolis, transport rate and its curvature terms, gravity gradient, bias and scale-factor columns), at mid
    latitude, at the pole and beside it, in a w frame turned from north."""
    C_ew = rot.to_matrix(wander.q_ew(place[0], LON, place[1]))
    C = rot.to_matrix(Q_WB)
    F = nav_kernels.continuous_f(C_ew, H, V, C @ F_B, C, C * OMEGA_B, C * F_B, nav_kernels.layout(n > 15), 0.0)
    scale = np.array([1e-6] * 3 + [1e-3] * 3 + [1e-7, 1e-7, 1e-2] + [1e-7] * 3 + [1e-5] * 3 + [1e-5] * (n - 15))
    numeric = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = scale[j]
        numeric[:, j] = (_error_rate(e, n, *place) - _error_rate(-e, n, *place)) / (2 * scale[j])
    # the reference's own error, measured: the rounding of two propagated rotations over a 1e-7 rad position step,
    # divided by 2τ, leaves up to 2.3e-3 of a column's largest entry (at the pole; 1.1e-3 at mid latitude, 1.1e-4 at
    # 89.99 deg; halving τ doubles it, the truncation shrinks as τ⁴ after the extrapolation): 3e-3 of each column
    tolerance = 3e-3 * np.abs(numeric).max(axis=0) + 1e-13
    assert np.all(np.abs(F[0:9] - numeric[0:9]) <= tolerance[None, :]), np.argwhere(np.abs(F[0:9] - numeric[0:9]) > tolerance[None, :])


def _f_and_q(n=21):
    C = rot.to_matrix(Q_WB)
    C_ew = rot.to_matrix(wander.q_ew(LAT, LON, ALPHA))
    F = nav_kernels.continuous_f(C_ew, H, V, C @ F_B, C, C * OMEGA_B, C * F_B, nav_kernels.layout(n > 15), 0.0)
    q_c = np.array([1e-9] * 3 + [1e-6] * 3 + [0.0] * 3 + [1e-14] * 3 + [1e-10] * 3 + [1e-12] * (n - 15))
    return F, q_c


@pytest.mark.parametrize("dt", [0.01, 0.1, 0.5])
def test_transition_matches_expm(dt):
    F, q_c = _f_and_q()
    Phi, _ = nav_kernels.discretize(F, q_c, dt)
    exact = expm(F * dt)
    # the fifth-order series leaves its first omitted term (FΔt)⁶/6! (all of the error seen, 3.3e-14 at 0.5 s:
    # F is nearly nilpotent): twice it, and 50 ulp of rounding
    omitted = np.abs(np.linalg.matrix_power(F * dt, 6)).max() / 720
    assert np.max(np.abs(Phi - exact)) <= 2 * omitted + 1e-14 * np.abs(exact).max()


@pytest.mark.parametrize("dt", [0.01, 0.1, 0.5])
def test_process_noise_matches_van_loan(dt):
    """Q_d = ∫₀^Δt e^(Fs) Q e^(Fᵀs) ds from the matrix exponential of [[−F, Q], [0, Fᵀ]] Δt
    (Van Loan 1978): Q_d = Φ · (upper-right block)."""
    F, q_c = _f_and_q()
    n = F.shape[0]
    block = np.zeros((2 * n, 2 * n))
    block[:n, :n], block[:n, n:], block[n:, n:] = -F, np.diag(q_c), F.T
    E = expm(block * dt)
    exact = E[n:, n:].T @ E[:n, n:]
    _, Q = nav_kernels.discretize(F, q_c, dt)
    scale = np.sqrt(np.outer(np.diag(exact), np.diag(exact))) + 1e-30
    # the series stops at L_5 Δt⁶/6!: twice its first omitted term L_6 Δt⁷/7! (all of the error seen, 6.1e-10 of
    # the correlations at 0.5 s), and 1e-13 for the rounding of the Van Loan exponential (9e-16 seen at 0.01 s)
    L = np.diag(q_c)
    for _ in range(6):
        L = F @ L + L @ F.T
    omitted = np.max(np.abs(L) * dt**7 / 5040 / scale)
    assert np.max(np.abs(Q - exact) / scale) < 2 * omitted + 1e-13


# --- the filter at work -------------------------------------------------------------------------

import copy  # noqa: E402
import re  # noqa: E402
from dataclasses import replace  # noqa: E402

from navsim.estimation.consistency import chi2_band  # noqa: E402
from navsim.estimation.nav_filter import ImuNoise, NavFilter, NavFilterConfig  # noqa: E402
from navsim.replay import alignment  # noqa: E402
from navsim.sensors.accelerometer import AccelerometerModel  # noqa: E402
from navsim.sensors.gyro import GyroModel  # noqa: E402
from navsim.simulation import prepare, run_batch, simulate  # noqa: E402
from navsim.truth import trajectory  # noqa: E402
from navsim.truth.segments import Profile  # noqa: E402
from startrack.base.errors import InputError  # noqa: E402

TURNS = {"start": {"lat_deg": 40.0, "lon_deg": 10.0, "height_m": 1000.0, "speed_m_per_s": 100.0, "heading_deg": 0.0},
         "segments": [{"kind": "straight", "duration_s": 60.0},
                      {"kind": "turn", "heading_change_deg": 90.0, "rate_deg_per_s": 3.0},
                      {"kind": "straight", "duration_s": 60.0},
                      {"kind": "turn", "heading_change_deg": -180.0, "rate_deg_per_s": 3.0},
                      {"kind": "climb", "height_change_m": 300.0, "rate_m_per_s": 5.0},
                      {"kind": "turn", "heading_change_deg": 90.0, "rate_deg_per_s": 3.0},
                      {"kind": "accelerate", "speed_m_per_s": 150.0, "acceleration_m_per_s2": 1.0},
                      {"kind": "straight", "duration_s": 60.0}]}
#: The tactical IMU with only the errors the 15-state filter models: turn-on bias, bias random walk and
#: white noise (no Gauss-Markov part, scale factor or misalignment).
MATCHED = {"preset": "tactical", "bias_instability_deg_per_h": 0.0, "scale_factor_ppm": 0.0, "misalignment_arcsec": 0.0}
MATCHED_ACCEL = {"preset": "tactical", "bias_instability_micro_g": 0.0, "scale_factor_ppm": 0.0, "misalignment_arcsec": 0.0}
#: 7 min of turns, climb and acceleration: a tactical IMU at 50 Hz and 1 Hz position fixes of 3 m.
AIDED_TURNS = {
    "name": "aided_turns", "trajectory": TURNS,
    "imu": {"rate_hz": 50.0, "gyro": MATCHED, "accelerometer": MATCHED_ACCEL},
    "aiding": {"position": {"rate_hz": 1.0, "sigma_ned_m": [3.0, 3.0, 3.0]}},
    "filter": {"initial_tilt_sigma_arcsec": 180.0, "initial_heading_sigma_deg": 0.3, "initial_velocity_sigma_m_per_s": 0.1,
               "initial_position_sigma_m": 5.0},
}


def _check_campaign(results):
    """NEES of the run average inside its two-sided 95 % chi-square band (time mean, and at >= 80 %
    of the fixes), no divergent run, and the accelerometer bias within 3σ at the end (>= 97 % of the
    run-axis cases, expected 99.7 %) with its horizontal σ reduced by the turns."""
    runs = len(results)
    nees = np.array([r.series["nees"] for r in results]).mean(axis=0)
    low, high = chi2_band(15, runs)
    assert results[0].summary["nees"]["dof"] == 15
    assert low <= nees.mean() <= high
    assert np.mean((nees >= low) & (nees <= high)) >= 0.8
    error, sigma = (np.array([r.series[name] for r in results]) for name in ("error_state", "error_sigma"))
    assert np.all(np.isfinite(error)) and not np.any(np.abs(error) > 10 * sigma)
    calibration = [r.summary["imu_calibration"]["accel_bias_micro_g"] for r in results]
    assert np.mean(np.abs([c["normalised_error"] for c in calibration]) <= 3.0) >= 0.97
    assert np.all(sigma[:, -1, 12:14] < 0.7 * sigma[:, 0, 12:14])


def test_position_aided_campaign_is_consistent():
    """50 runs of 7 min of turns, climb and acceleration, tactical IMU at 50 Hz, 1 Hz fixes of 3 m."""
    _check_campaign(run_batch(AIDED_TURNS, range(50)))


@pytest.mark.parametrize("overrides", [
    {},
    {"baro": {"rate_hz": 2.0, "noise_sigma_m": 2.0}, "imu.gyro.preset": "tactical", "filter.measurement_noise_scale": 1.3},
    {"aiding": {}, "baro": {"rate_hz": 1.0}, "imu.gyro.scale_factor_ppm": 100.0, "filter.covariance_interval": 7},
])
def test_compiled_fast_path_equals_the_step_by_step_loop(overrides):
    """The navigation filter's whole-record path gives, to the last bit, what the loop's frame-by-frame
    predict and updates give: position and baro in one frame, 21 states, a free INS with a baro."""
    prepared = prepare(AIDED_TURNS, overrides)
    fast, steps = simulate(prepared, 5), simulate(prepared, 5, compiled=False)
    assert fast.series.keys() == steps.series.keys()
    for name in fast.series:
        np.testing.assert_array_equal(fast.series[name], steps.series[name], err_msg=name)


def _samples(dtheta, dv, dt):
    """IMU samples (interval means) of increments."""
    return np.hstack([dtheta, dv]) / dt


def test_perfect_imu_and_perfect_start_stay_on_the_truth():
    """No sensor error and no initial error: the filter's solution is the truth (to 1 mm) and each
    fix's NIS is ~ 0."""
    truth = trajectory.generate(Profile.from_table(TURNS), 50.0)
    noise = ImuNoise(arw=1e-5, vrw=1e-4, gyro_bias_rw=1e-8, accel_bias_rw=1e-6)
    P = np.diag([1e-8] * 3 + [1e-4] * 3 + [1e-14, 1e-14, 1.0] + [1e-12] * 3 + [1e-8] * 3)
    f = NavFilter(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0], NavFilterConfig(P, noise, truth.dt))
    for k0 in range(0, truth.dtheta.shape[0], 50):
        f.predict(_samples(truth.dtheta[k0:k0 + 50], truth.dv[k0:k0 + 50], truth.dt), truth.dt)
        k1 = min(k0 + 50, truth.dtheta.shape[0])
        result = f.update_position(truth.lat[k1], truth.lon[k1], truth.h[k1], 3.0)
        assert result.nis[0] < 1e-6 and np.all(np.abs(result.z) < 1e-3)  # the innovation in metres
    lat, lon, h = f.position
    assert abs(h - truth.h[-1]) < 1e-3 and abs(lat - truth.lat[-1]) * 6.4e6 < 1e-3
    assert np.max(np.abs(f.v_n - truth.v_n[-1])) < 1e-4


def test_baro_update_pulls_the_height():
    noise = ImuNoise(arw=1e-5, vrw=1e-3)
    P = np.diag([1e-6] * 3 + [1e-2] * 3 + [1e-12, 1e-12, 100.0] + [1e-10] * 3 + [1e-6] * 3)
    f = NavFilter(0.5, 0.1, 120.0, np.zeros(3), [0, 0, 0, 1.0], NavFilterConfig(P, noise, 0.01))
    result = f.update_baro(100.0, 1.0)  # rounding level below: the scalar Kalman update's closed form
    assert result.accepted[0] and result.nis[0] == pytest.approx(400.0 / 101.0)
    assert f.position[2] == pytest.approx(100.0 + 20.0 / 101.0)
    assert np.sqrt(f.P[8, 8]) == pytest.approx(np.sqrt(100.0 / 101.0))
    rejected = f.update_baro(0.0, 1.0)
    assert not rejected.accepted[0] and f.position[2] == pytest.approx(100.0 + 20.0 / 101.0)


def test_velocity_update_is_the_kalman_update():
    """A NED velocity of σ (0.1, 0.2, 0.3) m/s against a P with velocity-attitude-bias correlations (wander angle 0
    at the start: w is NED): NIS, P and the corrected velocity are the textbook update's, K = P Hᵀ (H P Hᵀ + R)⁻¹
    with H = [0 I 0] on δv (numpy), and the update is gated like the others."""
    noise = ImuNoise(arw=1e-5, vrw=1e-3)
    rng = np.random.default_rng(4)
    A = rng.normal(size=(15, 15)) * 0.1
    P = np.diag([1e-4] * 3 + [0.5] * 3 + [1.0] * 3 + [1e-6] * 3 + [1e-3] * 3) + A @ A.T * 1e-3
    f = NavFilter(0.5, 0.1, 120.0, np.array([1.0, 2.0, 0.0]), [0, 0, 0, 1.0], NavFilterConfig(P, noise, 0.01))
    P0, v0 = f.P, f.v_n.copy()
    measured, sigma = np.array([1.5, 1.6, 0.2]), np.array([0.1, 0.2, 0.3])
    H = np.zeros((3, 15))
    H[:, 3:6] = np.eye(3)
    S = H @ P0 @ H.T + np.diag(sigma**2)
    K = P0 @ H.T @ np.linalg.inv(S)
    z = v0 - measured
    result = f.update_velocity(measured, sigma)
    assert result.accepted[0] and result.nis[0] == pytest.approx(z @ np.linalg.solve(S, z), rel=1e-9)
    np.testing.assert_allclose(f.v_n, v0 - (K @ z)[3:6], rtol=0, atol=1e-9)
    np.testing.assert_allclose(f.P, P0 - K @ S @ K.T, rtol=0, atol=1e-9)
    assert not f.update_velocity(measured + 100.0, sigma).accepted[0]


def _skew(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def _body_lateral_vertical(C_nb, v_n):
    """(v_b)_y,z of a body attitude C_nb and NED velocity: what the non-holonomic constraint says is zero."""
    return (C_nb.T @ v_n)[1:]


def test_body_velocity_update_is_the_kalman_update_with_the_attitude_coupling():
    """The non-holonomic update on a car at 15 m/s, yawed 40 deg and pitched 3 deg, with a correlated P (wander angle 0
    at the start: w is NED): H is the finite-difference derivative of z = ŷ − y with respect to the error state
    (the truth built from the estimate by the filter's own convention: C_nb,true = exp([φ×]) C_nb,est, v_true = v̂ − δv,
    the rest of the state not entering), and NIS, P and the corrected velocity and attitude are the textbook update's
    with that H (numpy); the update is gated at 2 dof."""
    noise = ImuNoise(arw=1e-5, vrw=1e-3)
    rng = np.random.default_rng(7)
    A = rng.normal(size=(15, 15)) * 0.1
    P = np.diag([1e-4] * 3 + [0.05] * 3 + [1.0] * 3 + [1e-6] * 3 + [1e-3] * 3) + A @ A.T * 1e-4
    q_nb = alignment.q_nb(0.01, 0.05, 0.7)
    v_n = np.array([15.0 * np.cos(0.75), 15.0 * np.sin(0.75), 0.3])  # 3 deg of sideslip, a little climb
    f = NavFilter(0.5, 0.1, 120.0, v_n, q_nb, NavFilterConfig(P, noise, 0.01))
    P0, v0, C0 = f.P, f.v_n.copy(), rot.to_matrix(f.q_nb)
    y0 = _body_lateral_vertical(C0, v0)
    H = np.zeros((2, 15))
    step = 1e-6
    for i in range(6):
        dx = np.zeros(3)
        dx[i % 3] = step
        phi, dv = (dx, np.zeros(3)) if i < 3 else (np.zeros(3), dx)
        plus = y0 - _body_lateral_vertical(expm(_skew(phi)) @ C0, v0 - dv)
        minus = y0 - _body_lateral_vertical(expm(-_skew(phi)) @ C0, v0 + dv)
        H[:, i] = (plus - minus) / (2 * step)
    _, H_kernel = nav_kernels.body_velocity_terms(f._nav, 15)
    np.testing.assert_allclose(H_kernel, H, rtol=0, atol=1e-6)  # 15 m/s × (1e-6)² of the central difference
    sigma = np.array([0.1, 0.2])
    S = H @ P0 @ H.T + np.diag(sigma**2)
    K = P0 @ H.T @ np.linalg.inv(S)
    result = f.update_body_velocity(np.zeros(2), sigma)
    assert result.accepted[0] and result.nis[0] == pytest.approx(y0 @ np.linalg.solve(S, y0), rel=1e-6)
    dx = K @ y0
    np.testing.assert_allclose(f.v_n, v0 - dx[3:6], rtol=0, atol=1e-7)
    np.testing.assert_allclose(rot.to_matrix(f.q_nb), expm(_skew(dx[0:3])) @ C0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(f.P, P0 - K @ S @ K.T, rtol=0, atol=1e-9)
    assert np.abs(_body_lateral_vertical(rot.to_matrix(f.q_nb), f.v_n)).max() < np.abs(y0).max()
    assert not f.update_body_velocity(np.array([30.0, 0.0]), sigma).accepted[0]


def test_bad_filter_input_is_named():
    noise = ImuNoise(arw=1e-5, vrw=1e-3)
    with pytest.raises(InputError, match="filter.P: must be 15x15"):
        NavFilter(0.5, 0.1, 0.0, np.zeros(3), [0, 0, 0, 1.0], NavFilterConfig(np.eye(9), noise, 0.01))


def test_scale_factor_states_are_estimated_within_three_sigma():
    """21 states on the 7-min turns with tactical scale factors (gyro 100 ppm, accelerometer 300 ppm)
    and no misalignment: every scale factor ends within 3σ, no σ grows, and the vertical
    accelerometer's (sensing g throughout) is the best observed in 7 min."""
    truth = trajectory.generate(Profile.from_table(TURNS), 50.0)
    off = {"bias_instability_sigma": 0.0, "misalignment_sigma": 0.0}
    gyro = replace(GyroModel.preset("tactical", 50.0), **off, scale_factor_sigma=100e-6)
    accel = replace(AccelerometerModel.preset("tactical", 50.0), **off, scale_factor_sigma=300e-6)
    g_seed, a_seed = np.random.SeedSequence(4).spawn(2)
    g_rec, a_rec = gyro.measure(truth.dtheta / truth.dt, g_seed), accel.measure(truth.dv / truth.dt, a_seed)
    sigma0 = np.array([np.radians(0.05)] * 2 + [np.radians(0.3)] + [0.1] * 3 + [5.0 / 6.4e6] * 2 + [5.0]
                      + [gyro.bias_turn_on_sigma] * 3 + [accel.bias_turn_on_sigma] * 3 + [100e-6] * 3 + [300e-6] * 3)
    noise = ImuNoise(gyro.arw, accel.vrw, gyro.filter_rrw, accel.filter_bias_rw)
    f = NavFilter(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0],
                  NavFilterConfig(np.diag(sigma0**2), noise, truth.dt, estimate_scale_factors=True))
    for k in range(0, truth.dtheta.shape[0], 50):
        f.predict(np.hstack([g_rec.omega[k:k + 50], a_rec.force[k:k + 50]]), truth.dt)
        f.update_position(truth.lat[k + 50], truth.lon[k + 50], truth.h[k + 50], 3.0)
    s_g, s_a = f.scale_factors
    error = np.concatenate([np.diag(g_rec.matrix) - 1.0 - s_g, np.diag(a_rec.matrix) - 1.0 - s_a])
    sigma = np.sqrt(np.diag(f.P)[15:21])
    assert np.all(np.abs(error) <= 3.0 * sigma)
    assert np.all(sigma <= np.array([100e-6] * 3 + [300e-6] * 3)) and sigma[5] < 0.9 * 300e-6


def test_a_navigation_scenario_is_validated_like_a_file():
    """The scenario dictionary's cross-key rules: a fix faster than the IMU, a free INS too long for its
    vertical channel, a turn that cannot be flown."""
    bad = [({"aiding.position.rate_hz": 100.0}, "faster than the IMU"),
           ({"aiding": {}, "trajectory.segments": [{"kind": "straight", "duration_s": 4000.0}]}, "needs a [baro] table"),
           ({"trajectory.segments": [{"kind": "turn", "heading_change_deg": 90.0, "rate_deg_per_s": 3.0, "bank_deg": 10.0}]},
            "cannot be flown")]
    for overrides, message in bad:
        with pytest.raises(InputError, match=re.escape(message)):
            prepare(copy.deepcopy(AIDED_TURNS), overrides)
