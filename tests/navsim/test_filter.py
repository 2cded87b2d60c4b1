"""The MEKF against independent references: filterpy, expm, the discrete Riccati equation,
Farrenkopf's closed form, chi-square bands of NEES/NIS over Monte Carlo runs."""

import copy

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter
from scipy.linalg import expm, solve_discrete_are
from scipy.stats import chi2

import navsim
from navsim.estimation import kernels, linalg
from navsim.estimation.analytic import farrenkopf_steady_state
from navsim.estimation.attitude_filter import AttitudeFilter, AttitudeFilterConfig
from navsim.sensors.star_sensor import isotropic_covariance
from startrack.base import units
from startrack.geometry import rotation as rot

RNG = np.random.default_rng(3)


def random_spd(n):
    A = RNG.standard_normal((n, n))
    return A @ A.T * 1e-6 + np.eye(n) * 1e-8


def _rate_jacobian(omega):
    """D(ω) (3 x 9): δK ω for δk = (scale factors x, y, z; k_xy, k_xz, k_yx, k_yz, k_zx, k_zy)."""
    D = np.zeros((3, 9))
    D[[0, 1, 2], [0, 1, 2]] = omega
    for c, (i, j) in enumerate([(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]):
        D[i, 3 + c] = omega[j]
    return D


@pytest.mark.parametrize("n_sf, n_gm", [(3, 0), (3, 6), (0, 6)])
def test_transition_is_the_exponential_of_the_error_dynamics(n_sf, n_gm):
    """Φ = expm(F Δt) for δθ̇ = −[ω×]δθ − δb − D(ω) δk (δK ω = D(ω) δk; Pittelkau 2001)."""
    omega = np.array([0.3, -0.5, 0.2])
    dt = 0.1
    columns = list(range(3)) * (n_sf > 0) + list(range(3, 9)) * (n_gm > 0)
    n = 6 + len(columns)
    F = np.zeros((n, n))
    F[0:3, 0:3] = -rot.skew(omega)
    F[0:3, 3:6] = -np.eye(3)
    F[0:3, 6:] = -_rate_jacobian(omega)[:, columns]
    model = _model(1e-4, 1e-6, n_sf=n_sf, n_gm=n_gm)
    # rounding level: Φ's closed form is the exact exponential (and its small-angle series, (ωΔt)⁴ ~ 1e-29 off)
    np.testing.assert_allclose(kernels.transition(omega, dt, n, model), expm(F * dt), atol=1e-14)
    np.testing.assert_allclose(kernels.transition(omega * 1e-6, dt, 6, _model(1e-4, 1e-6)), expm(_f6(omega * 1e-6) * dt),
                               atol=1e-14)


def _model(arw, rrw, cal_rw=0.0, n_sf=0, n_gm=0, gm_sigma=0.0, gm_tau=np.inf):
    return kernels.FilterModel(arw=arw, rrw=rrw, gm_sigma=gm_sigma, gm_tau=gm_tau, cal_rw=cal_rw, q_scale=1.0,
                               n_bi=3 * int(gm_sigma > 0), n_sf=n_sf, n_gm=n_gm, mounting=False)


def test_gauss_markov_bias_states_against_expm_and_van_loan():
    """Total bias b and its Gauss-Markov part g: ḃ = w_u − g/τ + w_g, ġ = −g/τ + w_g, E[w_g²] = 2σ_g²/τ.
    Φ against expm and Q against the Van Loan integral at the gyro step, to first order in Δt/τ."""
    omega, dt, tau = np.array([0.3, -0.5, 0.2]), 0.01, 100.0
    arw, rrw, sigma_g = 1e-4, 1e-6, 5e-6
    F = np.zeros((9, 9))
    F[0:3, 0:3], F[0:3, 3:6] = -rot.skew(omega), -np.eye(3)
    F[3:6, 6:9] = F[6:9, 6:9] = -np.eye(3) / tau
    model = _model(arw, rrw, gm_sigma=sigma_g, gm_tau=tau)
    # twice the leading neglected term of Φ_θg, [ω×]² Δt⁴ / (24 τ) (1.6e-12; observed 1.4e-12), and 50 ulp of
    # Φ's unit entries for the rounding of either side
    np.testing.assert_allclose(kernels.transition(omega, dt, 9, model), expm(F * dt),
                               atol=omega @ omega * dt**4 / (12 * tau) + 1e-14)
    q_g = 2 * sigma_g**2 / tau
    W = np.zeros((9, 9))
    W[0:3, 0:3] = np.eye(3) * arw**2
    W[3:6, 3:6] = np.eye(3) * (rrw**2 + q_g)
    W[3:6, 6:9] = W[6:9, 3:6] = W[6:9, 6:9] = np.eye(3) * q_g
    F0 = F.copy()
    F0[0:3, 0:3] = 0.0  # Farrenkopf's Q is the zero-rate integral
    B = expm(np.block([[-F0, W], [np.zeros((9, 9)), F0.T]]) * dt)
    Q_van_loan = B[9:, 9:].T @ B[:9, 9:]
    Q = kernels.process_noise(model, dt, 9)
    scale = np.sqrt(np.outer(np.diag(Q_van_loan), np.diag(Q_van_loan)))
    # The Gauss-Markov terms are first order in Δt/τ (their neglected part is Δt/τ of them: allow twice that);
    # Farrenkopf's blocks are exact (1e-12 of the correlations: rounding of the Van Loan exponential, 1e-13 seen).
    Q_gm = Q - kernels.process_noise(_model(arw, rrw), dt, 9)
    np.testing.assert_array_less(np.abs(Q - Q_van_loan) / scale, 2 * dt / tau * np.abs(Q_gm) / scale + 1e-12)


def _f6(omega):
    F = np.zeros((6, 6))
    F[0:3, 0:3] = -rot.skew(omega)
    F[0:3, 3:6] = -np.eye(3)
    return F


def test_process_noise_is_the_van_loan_integral():
    """Farrenkopf's Q equals ∫ Φ(s) G W Gᵀ Φ(s)ᵀ ds at zero rate (Van Loan's method)."""
    arw, rrw, dt = 1e-4, 1e-6, 0.5
    F = _f6(np.zeros(3))
    W = np.diag([arw**2] * 3 + [rrw**2] * 3)
    A = np.block([[-F, W], [np.zeros((6, 6)), F.T]]) * dt
    B = expm(A)
    Phi = B[6:, 6:].T
    Q_van_loan = Phi @ B[:6, 6:]
    # rounding level: Farrenkopf's Q is the exact zero-rate integral (expm of the Van Loan block limits it)
    np.testing.assert_allclose(kernels.process_noise(_model(arw, rrw), dt, 6), Q_van_loan, rtol=1e-10, atol=1e-30)


def test_predict_and_update_equal_filterpy():
    """One step through our kernels equals filterpy's KalmanFilter.predict/update (Joseph form)."""
    n = 15
    P = random_spd(n)
    omega_measured = np.array([[0.1, 0.2, -0.05]])
    b = np.array([1e-4, -2e-4, 5e-5])
    K = np.array([[1e-4, 2e-4, -1e-4], [3e-4, 0.0, 1e-4], [-2e-4, 5e-5, -1e-4]])
    dt, arw, rrw, cal_rw = 0.1, 1e-4, 1e-6, 1e-5
    q0 = rot.from_rotation_vector([0.1, 0.2, 0.3])
    model = _model(arw, rrw, cal_rw, n_sf=3, n_gm=6)
    x0 = np.concatenate([q0, b, K.ravel(), [0.0, 0.0, 0.0, 1.0]])
    _, P_pred = kernels.predict(x0, P, omega_measured, dt, model)
    omega = np.linalg.solve(np.eye(3) + K, omega_measured[0] - b)  # the corrected rate
    kf = KalmanFilter(dim_x=n, dim_z=4)
    kf.P = P.copy()
    kf.predict(F=kernels.transition(omega, dt, n, model), Q=kernels.process_noise(model, dt, n))
    np.testing.assert_allclose(P_pred, kf.P, rtol=1e-12, atol=1e-24)  # rounding level: the same Φ P Φᵀ + Q, re-associated
    H = RNG.standard_normal((4, n))
    R = np.diag([1e-9, 2e-9, 1e-9, 3e-9])
    z = RNG.standard_normal(4) * 1e-4
    dx, P_post = linalg.joseph_update(P_pred, H, R, z, np.ones(n, bool))
    kf.update(z.reshape(-1, 1), R=R, H=H)
    # rounding level: the same Joseph form, re-associated (rounding amplified by cond(S))
    np.testing.assert_allclose(dx, kf.x[:, 0], rtol=1e-10, atol=1e-20)
    np.testing.assert_allclose(P_post, kf.P, rtol=1e-10, atol=1e-24)


def _steady_state_filter(omega, dt, steps_per_fix, arw, rrw, sigma_n, n_fixes=30000):
    P0 = np.diag([1e-4] * 3 + [1e-10] * 3)
    filt = AttitudeFilter([0, 0, 0, 1.0], np.zeros(3), AttitudeFilterConfig(P0=P0, arw=arw, rrw=rrw))
    R_S = np.eye(3) * sigma_n**2
    omega_measured = np.tile(omega, (steps_per_fix, 1))
    for _ in range(n_fixes):
        filt.predict(omega_measured, dt)
        P_pre = filt.P.copy()
        filt.update_attitude(filt.q, R_S)  # z = 0: the covariance recursion alone
    return P_pre, filt.P


@pytest.mark.parametrize("omega_deg_per_s", [0.0, 0.86, 5.0])
def test_steady_state_matches_riccati_and_farrenkopf(omega_deg_per_s):
    """6-state filter, constant rate, fixes every Δt: P equals solve_discrete_are (same Φ, Q) and
    the attitude/bias σ match Farrenkopf's single-axis closed form within 5 %."""
    arw, rrw = units.arw_to_si(0.1), units.rrw_to_si(1.0)
    sigma_n, dt = units.arcsec_to_rad(10.0), 0.1
    omega = np.radians([omega_deg_per_s, -0.5 * omega_deg_per_s, 0.3 * omega_deg_per_s])
    P_pre, P_post = _steady_state_filter(omega, dt, 1, arw, rrw, sigma_n)
    F = kernels.transition(omega, dt, 6, _model(arw, rrw))
    Q = kernels.process_noise(_model(arw, rrw), dt, 6)
    H = np.hstack([np.eye(3), np.zeros((3, 3))])
    P_dare = solve_discrete_are(F.T, H.T, Q, np.eye(3) * sigma_n**2)
    # 30000 fixes leave the recursion ρ^60000 = 6e-8 of its start's offset from the fixed point (ρ = 0.99972,
    # the closed-loop spectral radius; 1.1e-7 seen): 1e-6 of the variances, far below what matters
    np.testing.assert_allclose(np.diag(P_pre), np.diag(P_dare), rtol=1e-6)
    scale = 1.0 / np.sqrt(np.outer(np.diag(P_dare), np.diag(P_dare)))
    np.testing.assert_allclose(P_pre * scale, P_dare * scale, atol=1e-6)  # correlations, likewise
    analytic = farrenkopf_steady_state(arw, rrw, sigma_n, dt)
    assert np.sqrt(np.diag(P_post)[:3]) == pytest.approx([analytic.attitude_post] * 3, rel=0.05)
    assert np.sqrt(np.diag(P_pre)[:3]) == pytest.approx([analytic.attitude_pre] * 3, rel=0.05)
    assert np.sqrt(np.diag(P_post)[3:]) == pytest.approx([analytic.bias_post] * 3, rel=0.05)


def test_steady_state_with_gyro_faster_than_the_fixes():
    """Ten gyro steps per fix accumulate the same Q: still Farrenkopf with Δt = the fix interval."""
    arw, rrw = units.arw_to_si(0.1), units.rrw_to_si(1.0)
    sigma_n = units.arcsec_to_rad(10.0)
    _, P_post = _steady_state_filter(np.zeros(3), 0.01, 10, arw, rrw, sigma_n)
    analytic = farrenkopf_steady_state(arw, rrw, sigma_n, 0.1)
    assert np.sqrt(P_post[0, 0]) == pytest.approx(analytic.attitude_post, rel=0.05)
    assert np.sqrt(P_post[3, 3]) == pytest.approx(analytic.bias_post, rel=0.05)


def _monte_carlo(scenario, runs, first_seed=0):
    results = [navsim.run(scenario, seed=first_seed + k) for k in range(runs)]
    nees = np.array([r.series["nees"] for r in results])
    t = results[0].series["t"]
    return results, nees, t


def _assert_nees_consistent(nees, t, settle_s, dof=6, min_fraction=0.9):
    runs = nees.shape[0]
    lo, hi = chi2.ppf([0.025, 0.975], runs * dof) / runs
    average = nees[:, t >= settle_s].mean(axis=0)
    assert lo <= average.mean() <= hi, (average.mean(), lo, hi)
    assert np.mean((average >= lo) & (average <= hi)) >= min_fraction


def test_monte_carlo_nees_and_nis_in_chi_square_bands(base_scenario):
    """50 runs: the run-averaged NEES (6 dof) lies in its 95 % band on average and at ≥ 90 % of
    the frames; the NIS per degree of freedom averages 1."""
    results, nees, t = _monte_carlo(base_scenario, 50)
    _assert_nees_consistent(nees, t, settle_s=6.0)
    nis = np.concatenate([r.series["nis"] for r in results])
    dof = np.concatenate([r.series["nis_dof"] for r in results])
    lo, hi = chi2.ppf([0.025, 0.975], dof.sum()) / dof.sum()
    assert lo <= np.nansum(nis) / dof.sum() <= hi


def test_consistent_on_the_30_deg_per_s_profile_of_000(base_scenario):
    """000's sinusoidal profile (peak 30 deg/s), tactical gyro at 100 Hz with its scale factors
    estimated, star vectors at 10 Hz: NEES in band across 20 runs, no rejections, no divergence."""
    scenario = copy.deepcopy(base_scenario)
    scenario.update(duration_s=30.0)
    scenario["truth"] = {"profile": "sinusoidal_axis", "rate_hz": 400.0,
                         "sinusoidal_axis": {"axis": [0.7071067811865476, 0.5, 0.5], "theta0_deg": 60.0,
                                             "amplitude_deg": 30.0, "angular_frequency_rad_per_s": 1.0}}
    scenario["gyro"] = {"preset": "tactical", "rate_hz": 100.0, "misalignment_arcsec": 0.0}
    scenario["star_sensor"] = {"measurement": "stars", "rate_hz": 10.0, "fov_deg": 16.0, "star_sigma_arcsec": 5.0}
    scenario["filter"] = {"initial_attitude_sigma_deg": 0.2, "scale_factor": "estimate"}
    results, nees, t = _monte_carlo(scenario, 20)
    _assert_nees_consistent(nees, t, settle_s=3.0)
    for r in results:
        assert r.summary["updates"]["rejected"] <= 2
        assert r.summary["cross_boresight_rms_arcsec"] < 5.0


def test_torque_free_tumble_with_10_arcsec_fixes(base_scenario):
    """A 0.86 deg/s torque-free tumble through full turns (where an MRP-based UKF switches shadow
    sets): the MEKF has no such switch and stays consistent with 10 arcsec fixes."""
    scenario = copy.deepcopy(base_scenario)
    scenario.update(duration_s=600.0)
    w = 0.86 / np.sqrt(3)
    scenario["truth"] = {"profile": "rigid_body", "rate_hz": 20.0,
                         "rigid_body": {"inertia_kg_m2": [[900.0, 0, 0], [0, 800.0, 0], [0, 0, 600.0]],
                                        "initial_rate_deg_per_s": [w, w, w]}}
    scenario["star_sensor"].update(attitude_sigma_cross_arcsec=10.0, attitude_sigma_roll_arcsec=10.0, rate_hz=1.0)
    results, nees, t = _monte_carlo(scenario, 12)
    angle_turned = np.degrees(np.linalg.norm(rot.attitude_error(results[0].series["q_true"][0], results[0].series["q_true"]), axis=1))
    assert angle_turned.max() > 179.0
    _assert_nees_consistent(nees, t, settle_s=60.0, min_fraction=0.85)
    for r in results:
        err = np.linalg.norm(r.series["attitude_error"], axis=1)
        sigma = np.sqrt(r.series["P_diag"][:, :3].sum(axis=1))
        assert np.all(err[t >= 60.0] < 5 * sigma[t >= 60.0])


def test_one_star_update_only_shrinks_the_two_axes_across_it():
    P0 = np.diag([1e-6] * 3 + [1e-10] * 3)
    filt = AttitudeFilter([0, 0, 0, 1.0], np.zeros(3), AttitudeFilterConfig(P0=P0, arw=1e-5, rrw=1e-8))
    star = np.array([[0.0, 0.0, 1.0]])  # along z_S = z_B
    result = filt.update_stars(star, star, isotropic_covariance(star, units.arcsec_to_rad(5.0)))
    assert result.n_accepted == 1
    assert filt.P[2, 2] == pytest.approx(1e-6, rel=1e-12)  # rounding level: exactly unobserved in exact arithmetic
    assert filt.P[0, 0] < 1e-8 and filt.P[1, 1] < 1e-8


def test_two_stars_make_the_attitude_fully_observable():
    """Stars on z and 0.1 rad away along x: the roll σ is √2 σ / sin 0.1 (the second star's
    cross-track residual carries roll and the x tilt the first star fixes to σ)."""
    P0 = np.diag([1e-2] * 3 + [1e-10] * 3)
    sigma = units.arcsec_to_rad(5.0)
    filt = AttitudeFilter([0, 0, 0, 1.0], np.zeros(3), AttitudeFilterConfig(P0=P0, arw=1e-5, rrw=1e-8))
    stars = np.array([[0.0, 0.0, 1.0], [np.sin(0.1), 0.0, np.cos(0.1)]])
    filt.update_stars(stars, stars, isotropic_covariance(stars, sigma))
    assert np.sqrt(filt.P[2, 2]) == pytest.approx(np.sqrt(2.0) * sigma / np.sin(0.1), rel=0.01)
    assert np.all(np.sqrt(np.diag(filt.P)[:2]) < 1.01 * sigma)


def test_a_star_update_moves_the_estimate_to_the_truth():
    """Noise-free stars and a 90 arcsec initial error: one update leaves only the second-order
    linearisation error (< 0.1 arcsec)."""
    q_true = rot.from_rotation_vector([2e-4, -3e-4, 2.5e-4])
    filt = AttitudeFilter([0, 0, 0, 1.0], np.zeros(3), AttitudeFilterConfig(P0=np.diag([1e-6] * 3 + [1e-10] * 3), arw=1e-5, rrw=1e-8))
    ref_I = np.array([[0, 0, 1.0], [0.1, 0, 1.0], [0, 0.12, 1.0], [-0.08, -0.05, 1.0]])
    ref_I /= np.linalg.norm(ref_I, axis=1, keepdims=True)
    obs_S = rot.rotate(rot.conjugate(q_true), ref_I)
    filt.update_stars(ref_I, obs_S, isotropic_covariance(obs_S, units.arcsec_to_rad(0.01)))
    assert units.rad_to_arcsec(np.linalg.norm(rot.attitude_error(filt.q, q_true))) < 0.1


def test_gating_rejects_an_outlier_and_leaves_the_state_alone():
    P0 = np.diag([units.arcsec_to_rad(20.0) ** 2] * 3 + [1e-10] * 3)
    filt = AttitudeFilter([0, 0, 0, 1.0], np.zeros(3), AttitudeFilterConfig(P0=P0, arw=1e-5, rrw=1e-8, gate_probability=0.9999))
    outlier = rot.from_rotation_vector(np.radians([1.0, 0, 0]))
    P_before = filt.P.copy()
    result = filt.update_attitude(outlier, np.eye(3) * units.arcsec_to_rad(10.0) ** 2)
    assert result.n_rejected == 1 and result.nis[0] > 1e3
    np.testing.assert_array_equal(filt.q, [0, 0, 0, 1.0])
    np.testing.assert_array_equal(filt.P, P_before)


def test_misalignment_state_is_estimated_under_rotation(base_scenario):
    """The mounting error enters the attitude residual like a bias times [ω×], so it separates
    from the gyro bias only when the rate changes direction: rotate about x, then y, then z."""
    scenario = copy.deepcopy(base_scenario)
    scenario.update(duration_s=180.0)
    segments = [{"duration_s": 60.0, "rate_deg_per_s": rate} for rate in ([3.0, 0, 0], [0, 3.0, 0], [0, 0, 3.0])]
    scenario["truth"] = {"profile": "rate_segments", "rate_hz": 40.0, "rate_segments": {"segments": segments}}
    scenario["star_sensor"].update(misalignment_arcsec=[60.0, -40.0, 90.0], attitude_sigma_roll_arcsec=10.0)
    scenario["filter"].update(mounting="estimate", initial_mounting_sigma_arcsec=120.0)
    result = navsim.run(scenario, seed=1)
    sigma_m = units.rad_to_arcsec(np.sqrt(result.series["P_diag"][-1, 6:9]))
    assert np.all(sigma_m < 20.0)  # from 120 arcsec
    lo, hi = result.summary["nees"]["band_95"]
    assert lo < result.summary["nees"]["mean"] < hi


def test_attitude_fix_joseph_shortcut_equals_the_general_form():
    P = random_spd(9)
    R = np.diag([1e-9, 2e-9, 4e-9])
    z = RNG.standard_normal(3) * 1e-4
    H = np.hstack([np.eye(3), np.zeros((3, 6))])
    dx, P_general = linalg.joseph_update(P, H, R, z, np.ones(9, bool))
    dx_short, P_short = kernels.joseph_update_attitude(P, R, z, np.ones(9, bool))
    # rounding level: the same Joseph-form algebra, the product with H = [I 0] written out
    np.testing.assert_allclose(dx_short, dx, rtol=1e-10, atol=1e-20)
    np.testing.assert_allclose(P_short, P_general, rtol=1e-9, atol=1e-24)


def test_quadratic_forms_equal_a_linear_solve():
    P = np.array([random_spd(6) for _ in range(20)])
    e = RNG.standard_normal((20, 6)) * 1e-4
    expected = np.einsum("ni,ni->n", e, np.linalg.solve(P, e[..., None])[..., 0])
    # rounding level (times cond P): a Cholesky solve against LAPACK's LU of the same matrices
    np.testing.assert_allclose(linalg.quadratic_forms(P, e), expected, rtol=1e-9)
