"""Strapdown mechanization in the wander-azimuth frame w (:mod:`navsim.earth.wander`), compiled (numba), one IMU
interval per step: regular everywhere, the poles included (issue 31).

State vector ``nav`` (float64, :data:`SIZE`): [q_ew (4, scalar-last) | h | v_w (3) | q_wb (4) | previous Δθ (3) |
previous Δv (3) | baro-loop acceleration correction u]; the position is C_ew and the height, v_w the ground velocity
in w. Each step takes the increments Δθ, Δv [rad, m/s] of one interval of length dt [s] and updates, in this order
(Savage 1998, Parts 1 and 2; Groves, 2nd ed., §5.4-5.5 with w for n; Titterton & Weston, 2nd ed., §3.7.1):

1. coning: α = Δθ + (1/12) Δθ_prev × Δθ (two-sample, previous-interval form; Savage Part 1,
   Ignagni 1990 algorithm with one previous sample);
2. velocity in the body frame at t_(k−1): Δv_b = Δv + ½ Δθ × Δv + ⅙ Δθ × (Δθ × Δv) (rotation, to
   second order) + (1/12)(Δθ_prev × Δv + Δv_prev × Δθ) (sculling; Savage Part 2);
3. specific-force increment in w: Δv_sf^w = C_wb Δv_b − ½ ζ × C_wb Δv_b, ζ = ω_iw^w dt
   (the rotation of the w frame over the interval);
4. velocity: v_k = v_(k−1) + Δv_sf^w + [g_w − (2 ω_ie^w + ω_ew^w) × v] dt (Groves eq. 5.54), the
   bracket at the interval midpoint by one predictor-corrector pass;
5. position: h by the trapezoid rule, C_ew,k = C_ew,(k−1) exp([ω_ew^w dt ×]), the transport rate at the
   interval's midpoint (the mean velocity, the midpoint height and position);
6. attitude: q_wb,k = q(−ζ) ⊗ q_wb,(k−1) ⊗ q(α), q(·) the quaternion of a rotation vector.

Latitude, longitude, NED velocity and q_nb are outputs (:func:`navsim.earth.wander.to_ned`); a start from
(L, λ, h, v_n, q_nb) takes the wander angle 0 (w = NED there).

Optional barometric damping of the vertical channel (the third-order loop of Widnall & Sinha 1980):
with δh = h − h_baro,
ḣ ← ḣ − k1 δh, v̇_z ← v̇_z + k2 δh + u, u̇ = k3 δh, and k1 = 3/τ, k2 = 3/τ² + 2γ/a, k3 = 1/τ³
(three poles at −1/τ once the 2γ/a instability is cancelled).
"""

from typing import NamedTuple

import numpy as np

from navsim.earth.gravity import normal_gravity_of_sine
from navsim.earth.wander import axis_of, geodetic, q_ew, to_ned, transport_of_axis
from navsim.earth.wgs84 import GAMMA_E, OMEGA_IE, A
from startrack import InputError, njit
from startrack import rotation as rot

SIZE = 19
#: Length of a solution row (q_ew, h, v_w, q_wb): what a log keeps of ``nav``.
ROW = 12
#: The parts of a solution row in ``nav``: q_ew, h, v_w, q_wb.
Q_EW, HEIGHT, V_W, Q_WB = slice(0, 4), 4, slice(5, 8), slice(8, 12)


class Log(NamedTuple):
    """Navigation solution at the logged samples: ``lat``, ``lon`` [rad], ``h`` [m] (K,),
    ``v_n`` (K, 3) [m/s], ``q_nb`` (K, 4), and the wander-azimuth solution itself ``q_ew`` (K, 4), ``v_w`` (K, 3),
    ``q_wb`` (K, 4)."""

    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_n: np.ndarray
    q_nb: np.ndarray
    q_ew: np.ndarray
    v_w: np.ndarray
    q_wb: np.ndarray


def log_of(rows):
    """The :class:`Log` of solution rows (K, :data:`ROW`)."""
    q, v_w, q_wb = rows[:, 0:4], rows[:, 5:8], rows[:, 8:12]
    lat, lon, v_n, q_nb = to_ned(q, v_w, q_wb)
    return Log(lat=lat, lon=lon, h=rows[:, 4].copy(), v_n=v_n, q_nb=q_nb, q_ew=q.copy(), v_w=v_w.copy(), q_wb=q_wb.copy())


def initial_state(lat, lon, h, v_n, q_nb):
    """The ``nav`` vector of a start at (L, λ, h) [rad, rad, m], NED velocity [m/s] and q_nb, wander angle 0
    (at a pole, NED is the limit along the meridian λ)."""
    if not abs(lat) <= 0.5 * np.pi:
        raise InputError(f"lat: |latitude| must be <= 90 deg, got {np.degrees(lat)} deg")
    if not h >= -1000.0:
        raise InputError(f"height: must be >= -1000 m, got {h}")
    nav = np.zeros(SIZE)
    nav[0:4] = q_ew(lat, lon)
    nav[4] = h
    nav[5:8] = v_n
    nav[8:12] = rot.normalize(q_nb)
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
def _exp(t0, t1, t2):
    """exp(θ/2), the quaternion of the rotation vector θ = (t0, t1, t2) [rad] as a scalar-last 4-tuple (the series
    below 1e-4 rad of :func:`startrack.geometry.rotation_kernels.quat_from_rotation_vector`; no allocation)."""
    angle = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    k = 0.5 - angle * angle / 48.0 if angle < 1e-4 else np.sin(0.5 * angle) / angle
    return k * t0, k * t1, k * t2, np.cos(0.5 * angle)


@njit
def _product(p, q):
    """Hamilton product p ⊗ q of scalar-last 4-tuples (:func:`startrack.geometry.rotation_kernels.quat_multiply`; no
    allocation)."""
    return (p[3] * q[0] + p[0] * q[3] + p[1] * q[2] - p[2] * q[1],
            p[3] * q[1] - p[0] * q[2] + p[1] * q[3] + p[2] * q[0],
            p[3] * q[2] + p[0] * q[1] - p[1] * q[0] + p[2] * q[3],
            p[3] * q[3] - p[0] * q[0] - p[1] * q[1] - p[2] * q[2])


@njit
def _unit(q):
    """The 4-tuple q divided by its norm."""
    norm = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm


@njit
def _rotated(q, a0, a1, a2):
    """R(q) a for the unit 4-tuple q = (u, w) and a by its components: a + w t + u × t, t = 2 u × a
    (:func:`startrack.geometry.rotation.rotate`; no allocation)."""
    t0, t1, t2 = _cross(q[0], q[1], q[2], 2.0 * a0, 2.0 * a1, 2.0 * a2)
    s0, s1, s2 = _cross(q[0], q[1], q[2], t0, t1, t2)
    return a0 + q[3] * t0 + s0, a1 + q[3] * t1 + s1, a2 + q[3] * t2 + s2


@njit
def _velocity_change(c, h, v0, v1, v2, u0, u1, u2, dt):
    """(Δv_w (3), ζ (3)) over dt with the rates at the position of axis c = C_ew[2, :]
    (:func:`navsim.earth.wander.axis_of`), h and v: Δv_w = Δv_sf^w + [g_w − (2ω_ie^w + ω_ew^w) × v] dt,
    Δv_sf^w = u − ½ ζ × u (steps 3-4 for u = C_wb Δv_b), ζ = (ω_ie^w + ω_ew^w) dt, ω_ie^w = ω_ie c (eq. 1 of
    :mod:`navsim.earth.wander`)."""
    e0, e1, e2 = OMEGA_IE * c[0], OMEGA_IE * c[1], OMEGA_IE * c[2]
    t0, t1 = transport_of_axis(c[0], c[1], c[2], h, v0, v1)
    z0, z1, z2 = (e0 + t0) * dt, (e1 + t1) * dt, e2 * dt
    r0, r1, r2 = _cross(z0, z1, z2, u0, u1, u2)
    k0, k1, k2 = _cross(2.0 * e0 + t0, 2.0 * e1 + t1, 2.0 * e2, v0, v1, v2)
    g = normal_gravity_of_sine(-c[2], h)
    return (u0 - 0.5 * r0 - k0 * dt, u1 - 0.5 * r1 - k1 * dt, u2 - 0.5 * r2 + (g - k2) * dt), (z0, z1, z2)


@njit
def _body_increment(dtheta, dv, dtheta_prev, dv_prev):
    """(α, Δv_b) (3-tuples): the coning-corrected rotation vector and the rotation/sculling-corrected velocity
    increment in the body frame at the start of the interval (steps 1-2)."""
    t0, t1, t2 = dtheta[0], dtheta[1], dtheta[2]
    v0, v1, v2 = dv[0], dv[1], dv[2]
    c0, c1, c2 = _cross(dtheta_prev[0], dtheta_prev[1], dtheta_prev[2], t0, t1, t2)
    alpha = (t0 + c0 / 12.0, t1 + c1 / 12.0, t2 + c2 / 12.0)
    r0, r1, r2 = _cross(t0, t1, t2, v0, v1, v2)
    s0, s1, s2 = _cross(t0, t1, t2, r0, r1, r2)
    p0, p1, p2 = _cross(dtheta_prev[0], dtheta_prev[1], dtheta_prev[2], v0, v1, v2)
    q0, q1, q2 = _cross(dv_prev[0], dv_prev[1], dv_prev[2], t0, t1, t2)
    dv_b = (v0 + 0.5 * r0 + s0 / 6.0 + (p0 + q0) / 12.0,
            v1 + 0.5 * r1 + s1 / 6.0 + (p1 + q1) / 12.0,
            v2 + 0.5 * r2 + s2 / 6.0 + (p2 + q2) / 12.0)
    return alpha, dv_b


@njit
def _moved(q, c, h, v0, v1, span):
    """q_ew (4-tuple) turned by the transport rate at (c, h, v) over ``span`` [s]: q ⊗ q(ω_ew^w span), normalised;
    c the axis (:func:`navsim.earth.wander.axis_of`) where the rate is taken, (v0, v1) the horizontal velocity."""
    r0, r1 = transport_of_axis(c[0], c[1], c[2], h, v0, v1)
    return _unit(_product(q, _exp(r0 * span, r1 * span, 0.0)))


@njit
def step(nav, dtheta, dv, dt):
    """Advance ``nav`` in place by one interval of increments Δθ, Δv (3,) and length dt [s] (no allocation)."""
    q, h, v0, v1, v2 = (nav[0], nav[1], nav[2], nav[3]), nav[4], nav[5], nav[6], nav[7]
    c = axis_of(q)
    alpha, dv_b = _body_increment(dtheta, dv, nav[12:15], nav[15:18])
    q_wb = (nav[8], nav[9], nav[10], nav[11])
    u0, u1, u2 = _rotated(q_wb, dv_b[0], dv_b[1], dv_b[2])
    # predictor with the rates at the start, corrector with the rates at the midpoint
    a, _ = _velocity_change(c, h, v0, v1, v2, u0, u1, u2, dt)
    m0, m1, m2 = v0 + 0.5 * a[0], v1 + 0.5 * a[1], v2 + 0.5 * a[2]
    h_mid = h - 0.5 * dt * m2
    c_mid = axis_of(_moved(q, c, h_mid, m0, m1, 0.5 * dt))
    a, zeta = _velocity_change(c_mid, h_mid, m0, m1, m2, u0, u1, u2, dt)
    w0, w1, w2 = v0 + a[0], v1 + a[1], v2 + a[2]
    h_new = h - 0.5 * dt * (v2 + w2)
    mean0, mean1, h_mean = 0.5 * (v0 + w0), 0.5 * (v1 + w1), 0.5 * (h + h_new)
    c_half = axis_of(_moved(q, c, h_mean, mean0, mean1, 0.5 * dt))
    q_new = _moved(q, c_half, h_mean, mean0, mean1, dt)
    p = _unit(_product(_exp(-zeta[0], -zeta[1], -zeta[2]), _product(q_wb, _exp(alpha[0], alpha[1], alpha[2]))))
    for i in range(4):
        nav[i] = q_new[i]
        nav[8 + i] = p[i]
    nav[4], nav[5], nav[6], nav[7] = h_new, w0, w1, w2
    for i in range(3):
        nav[12 + i] = dtheta[i]
        nav[15 + i] = dv[i]


@njit
def baro_damp(nav, baro_h, gains, dt):
    """One step of the third-order baro loop on ``nav`` (in place) with baro altitude ``baro_h`` [m]."""
    dh = nav[4] - baro_h
    nav[4] -= gains[0] * dh * dt
    nav[7] += (gains[1] * dh + nav[18]) * dt
    nav[18] += gains[2] * dh * dt


@njit
def integrate(nav, dtheta, dv, dt, baro_h, gains, every):
    """Run ``step`` over the increments (M, 3); damp with ``baro_h[k]`` where finite (NaN: none).
    Returns the solution rows nav[0:ROW] (1 + M // every, ROW): the start, then every ``every`` steps."""
    m = dtheta.shape[0]
    out = np.empty((1 + m // every, ROW))
    out[0] = nav[0:ROW]
    for k in range(m):
        step(nav, dtheta[k], dv[k], dt)
        if not np.isnan(baro_h[k]):
            baro_damp(nav, baro_h[k], gains, dt)
        if (k + 1) % every == 0:
            out[(k + 1) // every] = nav[0:ROW]
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
    return log_of(rows)


def wander_rows(truth):
    """The solution rows (N+1, :data:`ROW`) of a truth trajectory (``lat``, ``lon``, ``h``, ``v_n``, ``q_nb`` at N + 1
    samples, increments ``dtheta``, ``dv``, interval ``dt``) in the wander-azimuth frame this mechanization would
    carry along it: the wander angle α of the truth's own increments integrated from 0 (the vertical channel held on
    the true height), the position, velocity and attitude the truth's: q_ew(L, λ, α), v_w = C_wn v_n,
    q_wb = q_z(−α) ⊗ q_nb."""
    nav = initial_state(truth.lat[0], truth.lon[0], truth.h[0], truth.v_n[0], truth.q_nb[0])
    alpha = geodetic(run(nav, truth.dtheta, truth.dv, truth.dt, baro_h=truth.h[1:]).q_ew)[2]
    zero = np.zeros_like(alpha)
    q_wn = rot.from_rotation_vector(np.stack([zero, zero, -alpha], axis=-1))
    return np.concatenate([q_ew(truth.lat, truth.lon, alpha), truth.h[:, None], rot.rotate(q_wn, truth.v_n),
                           rot.multiply(q_wn, truth.q_nb)], axis=1)
