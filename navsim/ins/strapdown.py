"""Strapdown mechanization in the local-level NED frame, compiled (numba), one IMU interval per step.

State vector ``nav`` (float64, :data:`SIZE`): [L, λ, h | v_N, v_E, v_D | q_nb (4, scalar-last) |
previous Δθ (3) | previous Δv (3) | baro-loop acceleration correction u]. Each step takes the
increments Δθ, Δv [rad, m/s] of one interval of length dt [s] and updates, in this order
(Savage 1998, Parts 1 and 2; Groves, 2nd ed., §5.4-5.5):

1. coning: α = Δθ + (1/12) Δθ_prev × Δθ (two-sample, previous-interval form; Savage Part 1,
   Ignagni 1990 algorithm with one previous sample);
2. velocity in the body frame at t_(k−1): Δv_b = Δv + ½ Δθ × Δv + ⅙ Δθ × (Δθ × Δv) (rotation, to
   second order) + (1/12)(Δθ_prev × Δv + Δv_prev × Δθ) (sculling; Savage Part 2);
3. specific-force increment in n: Δv_sf^n = C_nb Δv_b − ½ ζ × C_nb Δv_b, ζ = ω_in^n dt
   (the rotation of the n frame over the interval);
4. velocity: v_k = v_(k−1) + Δv_sf^n + [g_n − (2 ω_ie^n + ω_en^n) × v] dt (Groves eq. 5.54), the
   bracket at the interval midpoint by one predictor-corrector pass;
5. position by the trapezoid rule (Groves eq. 5.56): h, then L with R_M(L_(k−1)), then λ with
   R_N(L_k);
6. attitude: q_nb,k = q(−ζ) ⊗ q_nb,(k−1) ⊗ q(α), q(·) the quaternion of a rotation vector.

Optional barometric damping of the vertical channel (the third-order loop of Widnall & Sinha 1980):
with δh = h − h_baro,
ḣ ← ḣ − k1 δh, v̇_D ← v̇_D + k2 δh + u, u̇ = k3 δh, and k1 = 3/τ, k2 = 3/τ² + 2γ/a, k3 = 1/τ³
(three poles at −1/τ once the 2γ/a instability is cancelled).
"""

from typing import NamedTuple

import numpy as np

from navsim.earth.frames import earth_rate_n, transport_rate_n
from navsim.earth.gravity import normal_gravity
from navsim.earth.wgs84 import GAMMA_E, A, radii
from startrack import rotation as rot
from startrack.errors import InputError
from startrack.jit import njit
from startrack.rotation_jit import quat_from_rotation_vector, quat_multiply, quat_to_matrix

SIZE = 17


class Log(NamedTuple):
    """Navigation solution at the logged samples: ``lat``, ``lon`` [rad], ``h`` [m] (K,),
    ``v_n`` (K, 3) [m/s], ``q_nb`` (K, 4)."""

    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_n: np.ndarray
    q_nb: np.ndarray


def initial_state(lat, lon, h, v_n, q_nb):
    """The ``nav`` vector of a start at (L, λ, h) [rad, rad, m], NED velocity [m/s] and q_nb."""
    if not abs(lat) <= 0.5 * np.pi:
        raise InputError(f"lat: |latitude| must be <= 90 deg, got {np.degrees(lat)} deg")
    if not h >= -1000.0:
        raise InputError(f"height: must be >= -1000 m, got {h}")
    nav = np.zeros(SIZE)
    nav[0:3] = lat, lon, h
    nav[3:6] = v_n
    nav[6:10] = rot.normalize(q_nb)
    return nav


def baro_gains(time_constant):
    """(k1, k2, k3) of the third-order baro loop with three poles at −1/τ, τ = ``time_constant`` [s]."""
    if not time_constant > 0.0:
        raise InputError(f"baro_time_constant_s: must be > 0, got {time_constant!r}")
    tau = float(time_constant)
    return np.array([3.0 / tau, 3.0 / tau**2 + 2.0 * GAMMA_E / A, 1.0 / tau**3])


@njit
def _cross(a0, a1, a2, b0, b1, b2):
    """a × b of two vectors given by their components (scalar arithmetic: no allocation)."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit
def _velocity_change(lat, h, v0, v1, v2, u0, u1, u2, dt):
    """(Δv_n (3), ζ (3)) over dt with the rates at (L, h, v): Δv_n = Δv_sf^n + [g_n − (2ω_ie^n + ω_en^n)
    × v] dt, Δv_sf^n = u − ½ ζ × u (steps 3-4 for u = C_nb Δv_b), ζ = (ω_ie^n + ω_en^n) dt."""
    e0, e1, e2 = earth_rate_n(lat)
    t0, t1, t2 = transport_rate_n(lat, h, v0, v1)
    z0, z1, z2 = (e0 + t0) * dt, (e1 + t1) * dt, (e2 + t2) * dt
    r0, r1, r2 = _cross(z0, z1, z2, u0, u1, u2)
    c0, c1, c2 = _cross(2.0 * e0 + t0, 2.0 * e1 + t1, 2.0 * e2 + t2, v0, v1, v2)
    g = normal_gravity(lat, h)
    return (u0 - 0.5 * r0 - c0 * dt, u1 - 0.5 * r1 - c1 * dt, u2 - 0.5 * r2 + (g - c2) * dt), (z0, z1, z2)


@njit
def _body_increment(dtheta, dv, dtheta_prev, dv_prev):
    """(α, Δv_b): the coning-corrected rotation vector and the rotation/sculling-corrected velocity
    increment in the body frame at the start of the interval (steps 1-2)."""
    t0, t1, t2 = dtheta[0], dtheta[1], dtheta[2]
    v0, v1, v2 = dv[0], dv[1], dv[2]
    c0, c1, c2 = _cross(dtheta_prev[0], dtheta_prev[1], dtheta_prev[2], t0, t1, t2)
    alpha = np.array([t0 + c0 / 12.0, t1 + c1 / 12.0, t2 + c2 / 12.0])
    r0, r1, r2 = _cross(t0, t1, t2, v0, v1, v2)
    s0, s1, s2 = _cross(t0, t1, t2, r0, r1, r2)
    p0, p1, p2 = _cross(dtheta_prev[0], dtheta_prev[1], dtheta_prev[2], v0, v1, v2)
    q0, q1, q2 = _cross(dv_prev[0], dv_prev[1], dv_prev[2], t0, t1, t2)
    dv_b = (v0 + 0.5 * r0 + s0 / 6.0 + (p0 + q0) / 12.0,
            v1 + 0.5 * r1 + s1 / 6.0 + (p1 + q1) / 12.0,
            v2 + 0.5 * r2 + s2 / 6.0 + (p2 + q2) / 12.0)
    return alpha, dv_b


@njit
def step(nav, dtheta, dv, dt):
    """Advance ``nav`` in place by one interval of increments Δθ, Δv (3,) and length dt [s]."""
    lat, lon, h, v0, v1, v2 = nav[0], nav[1], nav[2], nav[3], nav[4], nav[5]
    alpha, dv_b = _body_increment(dtheta, dv, nav[10:13], nav[13:16])
    C = quat_to_matrix(nav[6:10])
    u0 = C[0, 0] * dv_b[0] + C[0, 1] * dv_b[1] + C[0, 2] * dv_b[2]
    u1 = C[1, 0] * dv_b[0] + C[1, 1] * dv_b[1] + C[1, 2] * dv_b[2]
    u2 = C[2, 0] * dv_b[0] + C[2, 1] * dv_b[1] + C[2, 2] * dv_b[2]
    # predictor with the rates at the start, corrector with the rates at the midpoint
    a, _ = _velocity_change(lat, h, v0, v1, v2, u0, u1, u2, dt)
    m0, m1, m2 = v0 + 0.5 * a[0], v1 + 0.5 * a[1], v2 + 0.5 * a[2]
    h_mid = h - 0.5 * dt * m2
    lat_mid = lat + 0.5 * dt * m0 / (radii(lat)[0] + h_mid)
    a, zeta = _velocity_change(lat_mid, h_mid, m0, m1, m2, u0, u1, u2, dt)
    w0, w1, w2 = v0 + a[0], v1 + a[1], v2 + a[2]
    h_new = h - 0.5 * dt * (v2 + w2)
    r_m, r_n = radii(lat)
    lat_new = lat + 0.5 * dt * (v0 / (r_m + h) + w0 / (r_m + h_new))
    lon_new = lon + 0.5 * dt * (v1 / ((r_n + h) * np.cos(lat)) + w1 / ((radii(lat_new)[1] + h_new) * np.cos(lat_new)))
    minus_zeta = np.array([-zeta[0], -zeta[1], -zeta[2]])
    q = quat_multiply(quat_from_rotation_vector(minus_zeta), quat_multiply(nav[6:10], quat_from_rotation_vector(alpha)))
    norm = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    nav[0], nav[1], nav[2], nav[3], nav[4], nav[5] = lat_new, lon_new, h_new, w0, w1, w2
    for i in range(4):
        nav[6 + i] = q[i] / norm
    for i in range(3):
        nav[10 + i] = dtheta[i]
        nav[13 + i] = dv[i]


@njit
def baro_damp(nav, baro_h, gains, dt):
    """One step of the third-order baro loop on ``nav`` (in place) with baro altitude ``baro_h`` [m]."""
    dh = nav[2] - baro_h
    nav[2] -= gains[0] * dh * dt
    nav[5] += (gains[1] * dh + nav[16]) * dt
    nav[16] += gains[2] * dh * dt


@njit
def integrate(nav, dtheta, dv, dt, baro_h, gains, every):
    """Run ``step`` over the increments (M, 3); damp with ``baro_h[k]`` where finite (NaN: none).
    Returns the solution rows nav[0:10] (1 + M // every, 10): the start, then every ``every`` steps."""
    m = dtheta.shape[0]
    out = np.empty((1 + m // every, 10))
    out[0] = nav[0:10]
    for k in range(m):
        step(nav, dtheta[k], dv[k], dt)
        if not np.isnan(baro_h[k]):
            baro_damp(nav, baro_h[k], gains, dt)
        if (k + 1) % every == 0:
            out[(k + 1) // every] = nav[0:10]
    return out


def run(nav, dtheta, dv, dt, baro_h=None, baro_time_constant=60.0, every=1):
    """Free (or baro-damped) strapdown navigation from ``nav`` (updated in place) over increments
    ``dtheta``, ``dv`` (M, 3) of interval ``dt`` [s]; ``baro_h`` (M,) [m] altitudes at the end of
    each interval (NaN or None: undamped). Returns the :class:`Log` at the start and every ``every``
    intervals."""
    dtheta = np.ascontiguousarray(dtheta, dtype=float)
    dv = np.ascontiguousarray(dv, dtype=float)
    if baro_h is None:
        baro_h = np.full(dtheta.shape[0], np.nan)
    rows = integrate(nav, dtheta, dv, float(dt), np.asarray(baro_h, dtype=float),
                     baro_gains(baro_time_constant), int(every))
    return Log(lat=rows[:, 0], lon=rows[:, 1], h=rows[:, 2], v_n=rows[:, 3:6], q_nb=rows[:, 6:10])
