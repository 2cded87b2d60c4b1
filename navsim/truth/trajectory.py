"""Truth navigation trajectory from a segment :class:`~navsim.truth.segments.Profile`: geodetic
position, NED velocity and attitude at the IMU sample times, and the exactly consistent IMU
increments over each interval (the inverse strapdown).

Velocity and attitude are closed-form functions of time (the segments'
:class:`~navsim.truth.segments.Channels`) in the profile's local-level frame f (its ``frame``, a
strategy of :mod:`navsim.truth.level_frames`: NED, or free in azimuth for routes); position is their
integral on the ellipsoid by four-point Gauss-Legendre quadrature per interval (exact for polynomials
of degree 7). The body rate and specific force follow at every quadrature node from the kinematics
(Groves eqs. 5.35 and 5.53 solved for the sensed quantities, f for n):

    ω_ib^b = C_bf (ω_ie^f + ω_ef^f) + ω_fb^b,
    f^b   = C_bf (v̇_f + (2 ω_ie^f + ω_ef^f) × v_f − g_f),

with ω_fb^b from the Euler-angle rates and g_f the truth gravity (normal gravity plus an optional
disturbance). The increments are what an integrating IMU outputs,

    Δθ_k = ∫ ω_ib^b dt,   Δv_k = ∫ f^b dt   over [t_(k−1), t_k] in the moving body axes,

so the coning and sculling content of the motion is in them; the same quadrature gives both.

These increments under normal gravity are seed-free (:class:`Kinematics`). A gravity disturbance δg_f
(its deflections along f's axes; linear in time between samples) adds −∫ C_bf δg_f dt to Δv, taken by
the trapezoidal rule over each interval (:func:`with_gravity`), whose error dt³/12 |(C_bf δg_f)''| is
set by the turns and the field's roughness. Against the four-node quadrature of the same field it is at
most 3e-12 m/s per 5 ms interval and 5e-10 m/s summed over the 4 h of ``sins_cns_aircraft_vector``,
and 8e-11 m/s per 10 ms interval in a 4 deg/s roll-in (position: below a micrometre).
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from navsim.earth.gravity import disturbance_n, normal_gravity
from navsim.truth.level_frames import NODES, WEIGHTS
from startrack import InputError
from startrack import rotation as rot

CHUNK = 50_000


class State(NamedTuple):
    """The truth at one sample: ``lat``, ``lon`` [rad], ``h`` [m], ``v_n`` (3,) [m/s], ``q_nb`` (4,)."""

    lat: float
    lon: float
    h: float
    v_n: np.ndarray
    q_nb: np.ndarray


@dataclass(frozen=True)
class Trajectory:
    """Truth at the N + 1 sample times ``t`` [s] (uniform, 1/rate_hz apart): ``lat``, ``lon`` [rad],
    ``h`` [m], ``v_n`` (N+1, 3) [m/s], ``q_nb`` (N+1, 4) (C_nb), ``gravity_disturbance`` δg_n
    (N+1, 3) [m/s²]; and the increments ``dtheta`` (N, 3) [rad], ``dv`` (N, 3) [m/s] over the
    N intervals."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_n: np.ndarray
    q_nb: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    gravity_disturbance: np.ndarray
    rate_hz: float

    @property
    def dt(self):
        return 1.0 / self.rate_hz

    def at(self, k):
        """The :class:`State` at sample k (the end of interval k)."""
        return State(lat=self.lat[k], lon=self.lon[k], h=self.h[k], v_n=self.v_n[k], q_nb=self.q_nb[k])


@dataclass(frozen=True)
class Kinematics:
    """The seed-free part of a truth trajectory: the N + 1 sample times ``t`` [s], the segments'
    ``channels`` there, ``v_n`` (N+1, 3) [m/s], ``lat``, ``lon`` [rad], ``h`` [m], ``q_nb``
    (N+1, 4), the attitude ``q_fb`` in the profile's level frame f and its angle ``alpha`` [rad] from
    north (None: f = NED), and the increments ``dtheta``, ``dv`` (N, 3) under normal gravity. A gravity
    disturbance changes only the specific force, so a random one drawn per run reuses them
    (:func:`with_gravity`)."""

    t: np.ndarray
    channels: object
    v_n: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    q_nb: np.ndarray
    q_fb: np.ndarray
    alpha: np.ndarray | None
    dtheta: np.ndarray
    dv: np.ndarray
    rate_hz: float


def generate(profile, rate_hz, disturbance=None, seed=None, duration=None):
    """The truth :class:`Trajectory` of ``profile`` sampled at ``rate_hz`` [Hz] over its whole
    duration, or its first ``duration`` [s] (the last partial interval dropped). ``disturbance`` is an
    optional :class:`~navsim.earth.gravity.GravityDisturbance`; a random one draws from ``seed``."""
    return with_gravity(kinematics(profile, rate_hz, duration), disturbance, seed)


def kinematics(profile, rate_hz, duration=None):
    """The :class:`Kinematics` of ``profile`` at ``rate_hz`` [Hz] over its duration or its first
    ``duration`` [s]: velocity and attitude in closed form, position by quadrature (module docstring)."""
    if not (isinstance(rate_hz, (int, float)) and rate_hz > 0.0 and np.isfinite(rate_hz)):
        raise InputError(f"imu.rate_hz: must be > 0, got {rate_hz!r}")
    dt = 1.0 / rate_hz
    span = profile.duration if duration is None else min(duration, profile.duration)
    n = int(np.floor(span * rate_hz + 1e-9))
    if n < 1:
        raise InputError(f"imu.rate_hz: {rate_hz} Hz gives no sample interval in {span} s")
    t = np.arange(n + 1) * dt
    at_samples, v_samples, track = _flown(profile, t)
    dtheta, dv = np.empty((n, 3)), np.empty((n, 3))
    for lo, hi in _chunks(n):
        dtheta[lo:hi], dv[lo:hi] = _increments(profile, t, lo, hi, track, v_samples[lo:hi + 1])
    q_fb = attitude(at_samples)
    return Kinematics(t=t, channels=at_samples, v_n=ned_of(track.alpha, v_samples), lat=track.lat, lon=track.lon,
                      h=track.h, q_nb=_attitude_ned(track.alpha, q_fb), q_fb=q_fb, alpha=track.alpha, dtheta=dtheta,
                      dv=dv, rate_hz=float(rate_hz))


def track(profile, rate_hz):
    """The :class:`~navsim.truth.level_frames.Track` (position only) of ``profile`` at ``rate_hz`` [Hz] over its
    whole duration (the last partial interval dropped)."""
    n = int(np.floor(profile.duration * rate_hz + 1e-9))
    return _flown(profile, np.arange(n + 1) / rate_hz)[2]


def _flown(profile, t):
    """(channels, v_f (N+1, 3) [m/s], Track) at the sample times ``t`` (uniform)."""
    at_samples = profile.channels(t)
    v_samples = _velocity(at_samples)
    v_nodes = np.concatenate([_velocity(profile.channels(_node_times(t, lo, hi))) for lo, hi in _chunks(t.size - 1)])
    return at_samples, v_samples, profile.frame.track(profile.start, t[1] - t[0], v_samples, v_nodes.reshape(-1, 4, 3))


def with_gravity(kin, disturbance=None, seed=None):
    """The :class:`Trajectory` of :class:`Kinematics` ``kin`` under the truth gravity: normal gravity
    plus the optional ``disturbance`` (a random one drawn from ``seed``) along f: Δv gains −∫ C_bf δg_f dt
    by the trapezoidal rule (module docstring); δg_n = C_nf δg_f."""
    dt = 1.0 / kin.rate_hz
    components = _disturbance_components(disturbance, seed, kin.channels, dt)
    if components is None:
        delta_g, dv = np.zeros((kin.t.size, 3)), kin.dv
    else:
        delta_f = disturbance_n(components, normal_gravity(kin.lat, kin.h))
        g_b = rot.rotate(rot.conjugate(kin.q_fb), delta_f)
        dv = kin.dv - 0.5 * dt * (g_b[:-1] + g_b[1:])
        delta_g = ned_of(kin.alpha, delta_f)
    return Trajectory(t=kin.t, lat=kin.lat, lon=kin.lon, h=kin.h, v_n=kin.v_n, q_nb=kin.q_nb, dtheta=kin.dtheta,
                      dv=dv, gravity_disturbance=delta_g, rate_hz=kin.rate_hz)


def ned_of(alpha, vectors):
    """C_nf ``vectors`` (N+1, 3): turned about the vertical by the angle ``alpha`` (N+1,) [rad] of f from north
    (None: f = NED, unchanged)."""
    return vectors if alpha is None else rot.rotate(_q_nf(alpha), vectors)


def _attitude_ned(alpha, q_fb):
    """q_nb = q_nf ⊗ q_fb (:func:`ned_of`)."""
    return q_fb if alpha is None else rot.multiply(_q_nf(alpha), q_fb)


def _q_nf(alpha):
    zero = np.zeros_like(alpha)
    return rot.from_rotation_vector(np.stack([zero, zero, alpha], axis=-1))


def _chunks(n):
    return [(lo, min(lo + CHUNK, n)) for lo in range(0, n, CHUNK)]


def _node_times(t, lo, hi):
    """Quadrature node times of intervals lo..hi-1, interval-major (sorted)."""
    return (t[lo:hi, None] + (t[1] - t[0]) * NODES).ravel()


def _velocity(ch):
    """v_f (..., 3) [m/s] of channels: [V cos ψ, V sin ψ, −climb]."""
    return np.stack([ch.speed * np.cos(ch.heading), ch.speed * np.sin(ch.heading), -ch.climb], axis=-1)


def _velocity_rate(ch):
    """v̇_f (..., 3) [m/s²] of channels."""
    c, s = np.cos(ch.heading), np.sin(ch.heading)
    return np.stack([ch.speed_rate * c - ch.speed * s * ch.heading_rate,
                     ch.speed_rate * s + ch.speed * c * ch.heading_rate, -ch.climb_rate], axis=-1)


def attitude(ch):
    """q_fb (..., 4) of yaw ψ, pitch θ, roll φ (ZYX) in the level frame f: q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)."""
    zero = np.zeros_like(ch.heading)
    q_yaw = rot.from_rotation_vector(np.stack([zero, zero, ch.heading], axis=-1))
    q_pitch = rot.from_rotation_vector(np.stack([zero, ch.pitch, zero], axis=-1))
    q_roll = rot.from_rotation_vector(np.stack([ch.roll, zero, zero], axis=-1))
    return rot.multiply(rot.multiply(q_yaw, q_pitch), q_roll)


def _body_rate_from_euler(ch):
    """ω_fb^b (..., 3) [rad/s] from the ZYX Euler angles (yaw ψ, pitch θ, roll φ) and their rates
    (the inverse of the ZYX Euler-rate equations; Titterton & Weston, 2nd ed., ch. 3):
    [φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ sin φ cos θ, −θ̇ sin φ + ψ̇ cos φ cos θ]."""
    sr, cr = np.sin(ch.roll), np.cos(ch.roll)
    sp, cp = np.sin(ch.pitch), np.cos(ch.pitch)
    return np.stack([ch.roll_rate - ch.heading_rate * sp,
                     ch.pitch_rate * cr + ch.heading_rate * sr * cp,
                     -ch.pitch_rate * sr + ch.heading_rate * cr * cp], axis=-1)


def _disturbance_components(disturbance, seed, at_samples, dt):
    """(ξ, η, Δg) (N+1, 3) at the samples along the travelled distance, or None."""
    if disturbance is None:
        return None
    speed = at_samples.speed
    distance = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * dt)])
    return disturbance.components(distance, np.random.default_rng(seed))


def _increments(profile, t, lo, hi, track, v_part):
    """(Δθ, Δv) (hi−lo, 3) of intervals lo..hi−1 under normal gravity by quadrature of ω_ib^b and f^b at
    the nodes; ``v_part`` the velocities in f at samples lo..hi."""
    dt = t[1] - t[0]
    ch = profile.channels(_node_times(t, lo, hi))
    v_f, v_dot = _velocity(ch), _velocity_rate(ch)
    w_ie, w_ef, lat_n, h_n = profile.frame.node_rates(track, lo, hi, dt, v_part, v_f)
    gamma = normal_gravity(lat_n, h_n)
    g_f = np.zeros_like(v_f)
    g_f[:, 2] = gamma
    C_bf = np.swapaxes(rot.to_matrix(attitude(ch)), -1, -2)
    omega = np.einsum("nij,nj->ni", C_bf, w_ie + w_ef) + _body_rate_from_euler(ch)
    force = np.einsum("nij,nj->ni", C_bf, v_dot + np.cross(2.0 * w_ie + w_ef, v_f) - g_f)
    weights = dt * WEIGHTS[:, None]
    return (omega.reshape(-1, 4, 3) * weights).sum(axis=1), (force.reshape(-1, 4, 3) * weights).sum(axis=1)
