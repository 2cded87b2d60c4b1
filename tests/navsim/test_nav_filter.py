"""Navigation error-state filter: F against a numerical linearisation of the nonlinear navigation
equations (every sign of the φ convention), Φ and Q_d against scipy's expm and Van Loan's integral,
and the filter's behaviour."""

import numpy as np
import pytest
from scipy.linalg import expm

from navsim.earth.frames import earth_rate_n, transport_rate_n
from navsim.earth.gravity import normal_gravity
from navsim.earth.wgs84 import radii
from navsim.estimation import nav_kernels
from startrack import rotation as rot

LAT, LON, H = 0.7, 0.3, 3000.0
V = np.array([150.0, -80.0, 5.0])
Q_NB = rot.normalize([0.1, -0.05, 0.6, 0.8])
OMEGA_B = np.array([0.02, -0.03, 0.05])
F_B = np.array([1.5, -0.7, -9.9])


def _skew(v):
    return rot.skew(np.asarray(v, dtype=float))


def _rates(state, omega_b, f_b):
    """Nonlinear navigation equations (Groves eqs. 5.46 (rate form), 5.54, 2.111):
    (L̇, λ̇, ḣ, v̇, Ċ_nb) for a state (L, λ, h, v, C)."""
    lat, lon, h, v, C = state
    r_m, r_n = radii(lat)
    w_ie = np.array(earth_rate_n(lat))
    w_en = np.array(transport_rate_n(lat, h, v[0], v[1]))
    v_dot = C @ f_b + np.array([0.0, 0.0, normal_gravity(lat, h)]) - np.cross(2 * w_ie + w_en, v)
    C_dot = C @ _skew(omega_b) - _skew(w_ie + w_en) @ C
    return v[0] / (r_m + h), v[1] / ((r_n + h) * np.cos(lat)), -v[2], v_dot, C_dot


def _error_rate(dx, n):
    """Rate of the error state when the estimate differs from the truth by the error dx."""
    C = rot.to_matrix(Q_NB)
    truth = (LAT, LON, H, V, C)
    est = (LAT + dx[6], LON + dx[7], H + dx[8], V + dx[3:6], (np.eye(3) - _skew(dx[0:3])) @ C)
    omega_est, f_est = OMEGA_B + dx[9:12], F_B + dx[12:15]
    if n > 15:
        omega_est = omega_est + OMEGA_B * dx[15:18]
        f_est = f_est + F_B * dx[18:21]
    r_true, r_est = _rates(truth, OMEGA_B, F_B), _rates(est, omega_est, f_est)
    # [φ×] = I − C_est Cᵀ  =>  [φ̇×] = −(Ċ_est Cᵀ + C_est Ċᵀ)
    M = -(r_est[4] @ C.T + est[4] @ r_true[4].T)
    rate = np.zeros(n)
    rate[0:3] = 0.5 * np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]])
    rate[3:6] = r_est[3] - r_true[3]
    rate[6:9] = np.array(r_est[:3]) - np.array(r_true[:3])
    return rate


@pytest.mark.parametrize("n", [15, 21])
def test_f_is_the_linearisation_of_the_navigation_equations(n):
    """Each column of F equals the central difference of the nonlinear error rate (all signs of
    φ, Coriolis, transport rate, gravity gradient, bias and scale-factor columns)."""
    C = rot.to_matrix(Q_NB)
    F = nav_kernels.continuous_f(LAT, H, V, C @ F_B, C, C * OMEGA_B, C * F_B, n)
    scale = np.array([1e-6] * 3 + [1e-3] * 3 + [1e-7, 1e-7, 1e-2] + [1e-7] * 3 + [1e-5] * 3 + [1e-5] * (n - 15))
    numeric = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = scale[j]
        numeric[:, j] = (_error_rate(e, n) - _error_rate(-e, n)) / (2 * scale[j])
    tolerance = 1e-6 * np.abs(numeric).max(axis=0) + 1e-13
    assert np.all(np.abs(F - numeric) <= tolerance[None, :]), np.argwhere(np.abs(F - numeric) > tolerance[None, :])


def _f_and_q(n=21):
    C = rot.to_matrix(Q_NB)
    F = nav_kernels.continuous_f(LAT, H, V, C @ F_B, C, C * OMEGA_B, C * F_B, n)
    q_c = np.array([1e-9] * 3 + [1e-6] * 3 + [0.0] * 3 + [1e-14] * 3 + [1e-10] * 3 + [1e-12] * (n - 15))
    return F, q_c


@pytest.mark.parametrize("dt", [0.01, 0.1, 0.5])
def test_transition_matches_expm(dt):
    F, q_c = _f_and_q()
    Phi, _ = nav_kernels.discretize(F, q_c, dt)
    exact = expm(F * dt)
    assert np.max(np.abs(Phi - exact)) <= 1e-6 * dt * np.abs(exact).max()


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
    assert np.max(np.abs(Q - exact) / scale) < 1e-5
