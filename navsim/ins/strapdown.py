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

Optional barometric damping of the vertical channel (third-order loop, Titterton & Weston, 2nd ed.,
§10.7.2; Widnall & Sinha 1980): with δh = h − h_baro,
ḣ ← ḣ − k1 δh, v̇_D ← v̇_D + k2 δh + u, u̇ = k3 δh, and k1 = 3/τ, k2 = 3/τ² + 2γ/a, k3 = 1/τ³
(three poles at −1/τ once the 2γ/a instability is cancelled).
"""

from typing import NamedTuple

import numpy as np

from navsim.earth.frames import earth_rate_n, transport_rate_n
from navsim.earth.gravity import normal_gravity
from navsim.earth.wgs84 import A, GAMMA_E, radii
from startrack import rotation as rot
from startrack.errors import InputError
from startrack.jit import njit
from startrack.rotation_jit import quat_from_rotation_vector, quat_multiply, quat_to_matrix

SIZE = 17
POSITION, VELOCITY, ATTITUDE, PREV_DTHETA, PREV_DV, BARO_U = 0, 3, 6, 10, 13, 16


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
    nav[VELOCITY:VELOCITY + 3] = v_n
    nav[ATTITUDE:ATTITUDE + 4] = rot.normalize(q_nb)
    return nav


def baro_gains(time_constant):
    """(k1, k2, k3) of the third-order baro loop with three poles at −1/τ, τ = ``time_constant`` [s]."""
    if not time_constant > 0.0:
        raise InputError(f"baro_time_constant_s: must be > 0, got {time_constant!r}")
    tau = float(time_constant)
    return np.array([3.0 / tau, 3.0 / tau**2 + 2.0 * GAMMA_E / A, 1.0 / tau**3])


@njit
def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit
def _rates(lat, h, v):
    """(ω_ie^n, ω_en^n, g_n) at (L, h, v) as (3,) arrays."""
    w_ie = np.array(earth_rate_n(lat))
    w_en = np.array(transport_rate_n(lat, h, v[0], v[1]))
    return w_ie, w_en, np.array([0.0, 0.0, normal_gravity(lat, h)])


@njit
def _velocity_step(v, u_n, lat, h, dt):
    """(v_k, ζ) from u_n = C_nb Δv_b: steps 3-4 with the midpoint predictor-corrector."""
    w_ie, w_en, g = _rates(lat, h, v)
    zeta = (w_ie + w_en) * dt
    dv_sf = u_n - 0.5 * _cross(zeta, u_n)
    v_pred = v + dv_sf + (g - _cross(2.0 * w_ie + w_en, v)) * dt
    v_mid = 0.5 * (v + v_pred)
    h_mid = h - 0.5 * dt * v_mid[2]
    lat_mid = lat + 0.5 * dt * v_mid[0] / (radii(lat)[0] + h_mid)
    w_ie, w_en, g = _rates(lat_mid, h_mid, v_mid)
    zeta = (w_ie + w_en) * dt
    dv_sf = u_n - 0.5 * _cross(zeta, u_n)
    return v + dv_sf + (g - _cross(2.0 * w_ie + w_en, v_mid)) * dt, zeta


@njit
def step(nav, dtheta, dv, dt):
    """Advance ``nav`` in place by one interval of increments Δθ, Δv (3,) and length dt [s]."""
    lat, lon, h = nav[0], nav[1], nav[2]
    v = nav[3:6].copy()
    q = nav[6:10].copy()
    dtheta_prev, dv_prev = nav[10:13], nav[13:16]
    alpha = dtheta + _cross(dtheta_prev, dtheta) / 12.0
    rotation = _cross(dtheta, dv)
    dv_b = dv + 0.5 * rotation + _cross(dtheta, rotation) / 6.0 + (_cross(dtheta_prev, dv) + _cross(dv_prev, dtheta)) / 12.0
    u_n = quat_to_matrix(q) @ dv_b
    v_new, zeta = _velocity_step(v, u_n, lat, h, dt)
    h_new = h - 0.5 * dt * (v[2] + v_new[2])
    r_m, r_n = radii(lat)
    lat_new = lat + 0.5 * dt * (v[0] / (r_m + h) + v_new[0] / (r_m + h_new))
    r_n_new = radii(lat_new)[1]
    lon_new = lon + 0.5 * dt * (v[1] / ((r_n + h) * np.cos(lat)) + v_new[1] / ((r_n_new + h_new) * np.cos(lat_new)))
    q_new = quat_multiply(quat_from_rotation_vector(-zeta), quat_multiply(q, quat_from_rotation_vector(alpha)))
    q_new /= np.sqrt(np.sum(q_new * q_new))
    nav[0], nav[1], nav[2] = lat_new, lon_new, h_new
    nav[3:6] = v_new
    nav[6:10] = q_new
    nav[10:13] = dtheta
    nav[13:16] = dv


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
