"""Analytic limits the filter is checked against.

Farrenkopf's steady state (R. L. Farrenkopf, "Analytic steady-state accuracy solutions for two
common spacecraft attitude estimators", J. Guidance and Control 1(4), 1978; see also Markley &
Crassidis, *Fundamentals of Spacecraft Attitude Determination and Control*, 2014, §6.4): a
single-axis attitude/bias Kalman filter with gyro ARW σ_v [rad/√s], RRW σ_u [rad/s^(3/2)] and an
attitude measurement of σ_n [rad] every Δt [s], with the discrete model

    Φ = [[1, −Δt], [0, 1]],  Q = [[σ_v²Δt + σ_u²Δt³/3, −σ_u²Δt²/2], [−σ_u²Δt²/2, σ_u²Δt]],  H = [1, 0].

With S_u = σ_u Δt^(3/2)/σ_n and S_v = σ_v Δt^(1/2)/σ_n, the steady-state Riccati equation
reduces to the palindromic quartic x⁴ − S_u x³ − (2 + S_v² − S_u²/6) x² − S_u x + 1 = 0 in
x = (P⁻_θθ + σ_n²)^½ / σ_n, solved through y = x + 1/x:

    y = S_u/2 + (4 + S_v² + S_u²/12)^½,   x = (y + (y² − 4)^½) / 2,

    P⁺_θθ = σ_n² (1 − 1/x²),   P⁻_θθ = σ_n² (x² − 1),
    P⁺_bb = σ_u σ_n (x − 1/x)/√Δt − σ_u²Δt/2,   P⁻_bb = P⁺_bb + σ_u²Δt.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SteadyState:
    """Steady-state standard deviations: attitude [rad] and bias [rad/s], before and after an update."""

    attitude_pre: float
    attitude_post: float
    bias_pre: float
    bias_post: float


def farrenkopf_steady_state(arw, rrw, sigma_n, dt):
    """Farrenkopf's closed-form steady state of the attitude/bias filter (module docstring)."""
    s_u = rrw * dt**1.5 / sigma_n
    s_v = arw * np.sqrt(dt) / sigma_n
    y = 0.5 * s_u + np.sqrt(4.0 + s_v**2 + s_u**2 / 12.0)
    x = 0.5 * (y + np.sqrt(y * y - 4.0))
    p_post = sigma_n**2 * (1.0 - 1.0 / x**2)
    p_pre = sigma_n**2 * (x**2 - 1.0)
    b_post = rrw * sigma_n * (x - 1.0 / x) / np.sqrt(dt) - 0.5 * rrw**2 * dt
    b_pre = b_post + rrw**2 * dt
    return SteadyState(
        attitude_pre=float(np.sqrt(p_pre)),
        attitude_post=float(np.sqrt(p_post)),
        bias_pre=float(np.sqrt(b_pre)),
        bias_post=float(np.sqrt(b_post)),
    )
