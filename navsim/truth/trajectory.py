"""Truth navigation trajectory from a segment :class:`~navsim.truth.segments.Profile`: geodetic
position, NED velocity and attitude at the IMU sample times, and the exactly consistent IMU
increments over each interval (the inverse strapdown).

Velocity and attitude are closed-form functions of time (the segments'
:class:`~navsim.truth.segments.Channels`); position is their integral on the ellipsoid,
L̇ = v_N/(R_M + h), λ̇ = v_E/((R_N + h) cos L), ḣ = −v_D (Groves, 2nd ed., eq. 2.111), by
four-point Gauss-Legendre quadrature per interval (exact for polynomials of degree 7), iterated
to convergence in L. The body rate and specific force follow at every quadrature node from the
kinematics (Groves eqs. 5.35 and 5.53 solved for the sensed quantities):

    ω_ib^b = C_bn (ω_ie^n + ω_en^n) + ω_nb^b,
    f^b   = C_bn (v̇_n + (2 ω_ie^n + ω_en^n) × v_n − g_n),

with ω_nb^b from the Euler-angle rates and g_n the truth gravity (normal gravity plus an optional
disturbance). The increments are what an integrating IMU outputs,

    Δθ_k = ∫ ω_ib^b dt,   Δv_k = ∫ f^b dt   over [t_(k−1), t_k] in the moving body axes,

so the coning and sculling content of the motion is in them; the same quadrature gives both.

These increments under normal gravity are seed-free (:class:`Kinematics`). A gravity disturbance δg_n
(linear in time between samples) adds −∫ C_bn δg_n dt to Δv, taken by the trapezoidal rule over
each interval (:func:`with_gravity`), whose error dt³/12 |(C_bn δg_n)''| is set by the turns and the
field's roughness. Against the four-node quadrature of the same field it is at most 3e-12 m/s per
5 ms interval and 5e-10 m/s summed over the 4 h of ``sins_cns_aircraft_vector``, and 8e-11 m/s per
10 ms interval in a 4 deg/s roll-in (position: below a micrometre).
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from navsim.earth.frames import earth_rate_n, transport_rate_n
from navsim.earth.gravity import disturbance_n, normal_gravity
from navsim.earth.wgs84 import radii
from startrack import rotation as rot
from startrack import units
from startrack.errors import InputError

#: Gauss-Legendre nodes on [0, 1] and weights (sum 1).
_X, _W = np.polynomial.legendre.leggauss(4)
NODES = 0.5 * (_X + 1.0)
WEIGHTS = 0.5 * _W
#: Cubic Hermite basis at the nodes (h00, h10, h01, h11) for value/derivative interpolation.
_HERMITE = np.stack([2 * NODES**3 - 3 * NODES**2 + 1, NODES**3 - 2 * NODES**2 + NODES,
                     -2 * NODES**3 + 3 * NODES**2, NODES**3 - NODES**2])
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
    (N+1, 4), and the increments ``dtheta``, ``dv`` (N, 3) under normal gravity. A gravity disturbance
    changes only the specific force, so a random one drawn per run reuses them (:func:`with_gravity`)."""

    t: np.ndarray
    channels: object
    v_n: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    q_nb: np.ndarray
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
    at_samples = profile.channels(t)
    v_samples = _velocity(at_samples)
    v_nodes = np.concatenate([_velocity(profile.channels(_node_times(t, lo, hi))) for lo, hi in _chunks(n)])
    lat, lon, h = _position(profile.start, dt, v_samples, v_nodes)
    dtheta, dv = np.empty((n, 3)), np.empty((n, 3))
    for lo, hi in _chunks(n):
        dtheta[lo:hi], dv[lo:hi] = _increments(profile, t, lo, hi, (lat, lon, h), v_samples)
    return Kinematics(t=t, channels=at_samples, v_n=v_samples, lat=lat, lon=lon, h=h,
                      q_nb=attitude(at_samples), dtheta=dtheta, dv=dv, rate_hz=float(rate_hz))


def with_gravity(kin, disturbance=None, seed=None):
    """The :class:`Trajectory` of :class:`Kinematics` ``kin`` under the truth gravity: normal gravity
    plus the optional ``disturbance`` (a random one drawn from ``seed``): Δv gains −∫ C_bn δg_n dt by the
    trapezoidal rule (module docstring)."""
    dt = 1.0 / kin.rate_hz
    components = _disturbance_components(disturbance, seed, kin.channels, dt)
    if components is None:
        delta_g, dv = np.zeros((kin.t.size, 3)), kin.dv
    else:
        delta_g = disturbance_n(components, normal_gravity(kin.lat, kin.h))
        g_b = rot.rotate(rot.conjugate(kin.q_nb), delta_g)
        dv = kin.dv - 0.5 * dt * (g_b[:-1] + g_b[1:])
    return Trajectory(t=kin.t, lat=kin.lat, lon=kin.lon, h=kin.h, v_n=kin.v_n, q_nb=kin.q_nb, dtheta=kin.dtheta,
                      dv=dv, gravity_disturbance=delta_g, rate_hz=kin.rate_hz)


def _chunks(n):
    return [(lo, min(lo + CHUNK, n)) for lo in range(0, n, CHUNK)]


def _node_times(t, lo, hi):
    """Quadrature node times of intervals lo..hi-1, interval-major (sorted)."""
    return (t[lo:hi, None] + (t[1] - t[0]) * NODES).ravel()


def _velocity(ch):
    """v_n (..., 3) [m/s] of channels: [V cos ψ, V sin ψ, −climb]."""
    return np.stack([ch.speed * np.cos(ch.heading), ch.speed * np.sin(ch.heading), -ch.climb], axis=-1)


def _velocity_rate(ch):
    """v̇_n (..., 3) [m/s²] of channels."""
    c, s = np.cos(ch.heading), np.sin(ch.heading)
    return np.stack([ch.speed_rate * c - ch.speed * s * ch.heading_rate,
                     ch.speed_rate * s + ch.speed * c * ch.heading_rate, -ch.climb_rate], axis=-1)


def attitude(ch):
    """q_nb (..., 4) of yaw ψ, pitch θ, roll φ (ZYX): q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)."""
    zero = np.zeros_like(ch.heading)
    q_yaw = rot.from_rotation_vector(np.stack([zero, zero, ch.heading], axis=-1))
    q_pitch = rot.from_rotation_vector(np.stack([zero, ch.pitch, zero], axis=-1))
    q_roll = rot.from_rotation_vector(np.stack([ch.roll, zero, zero], axis=-1))
    return rot.multiply(rot.multiply(q_yaw, q_pitch), q_roll)


def _body_rate_from_euler(ch):
    """ω_nb^b (..., 3) [rad/s] from the ZYX Euler angles (yaw ψ, pitch θ, roll φ) and their rates
    (the inverse of the ZYX Euler-rate equations; Titterton & Weston, 2nd ed., ch. 3):
    [φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ sin φ cos θ, −θ̇ sin φ + ψ̇ cos φ cos θ]."""
    sr, cr = np.sin(ch.roll), np.cos(ch.roll)
    sp, cp = np.sin(ch.pitch), np.cos(ch.pitch)
    return np.stack([ch.roll_rate - ch.heading_rate * sp,
                     ch.pitch_rate * cr + ch.heading_rate * sr * cp,
                     -ch.pitch_rate * sr + ch.heading_rate * cr * cp], axis=-1)


def _hermite(values, rates, dt):
    """Cubic Hermite interpolation of sample ``values`` (N+1,) with derivatives ``rates`` at the
    quadrature nodes: (N, 4)."""
    h00, h10, h01, h11 = _HERMITE
    return (values[:-1, None] * h00 + dt * rates[:-1, None] * h10
            + values[1:, None] * h01 + dt * rates[1:, None] * h11)


def _cumulative(start, integrand, dt):
    """start + ∫ integrand dt at the samples, integrand (N, 4) at the nodes."""
    return start + np.concatenate([[0.0], np.cumsum(dt * integrand @ WEIGHTS)])


def _position(start, dt, v_samples, v_nodes):
    """(L, λ, h) (N+1,) at the samples by quadrature of the position rates; L iterated to
    convergence (its rate depends on L through R_M; each pass gains ~3 digits)."""
    v_nodes = v_nodes.reshape(-1, 4, 3)
    h = _cumulative(start.height_m, -v_nodes[..., 2], dt)
    h_nodes = _hermite(h, -v_samples[:, 2], dt)
    lat = np.full(h.shape, start.lat_deg * units.DEG)
    for _ in range(20):
        lat_rate = v_samples[:, 0] / (radii(lat)[0] + h)
        lat_nodes = _hermite(lat, lat_rate, dt)
        new = _cumulative(lat[0], v_nodes[..., 0] / (radii(lat_nodes)[0] + h_nodes), dt)
        change = np.max(np.abs(new - lat))
        lat = new
        if change < 1e-16:
            break
    lat_nodes = _hermite(lat, v_samples[:, 0] / (radii(lat)[0] + h), dt)
    lon = _cumulative(start.lon_deg * units.DEG, v_nodes[..., 1] / ((radii(lat_nodes)[1] + h_nodes) * np.cos(lat_nodes)), dt)
    return lat, lon, h


def _disturbance_components(disturbance, seed, at_samples, dt):
    """(ξ, η, Δg) (N+1, 3) at the samples along the travelled distance, or None."""
    if disturbance is None:
        return None
    speed = at_samples.speed
    distance = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * dt)])
    return disturbance.components(distance, np.random.default_rng(seed))


def _increments(profile, t, lo, hi, position, v_samples):
    """(Δθ, Δv) (hi−lo, 3) of intervals lo..hi−1 under normal gravity by quadrature of ω_ib^b and f^b at
    the nodes."""
    dt = t[1] - t[0]
    ch = profile.channels(_node_times(t, lo, hi))
    lat, lon, h = position
    span = slice(lo, hi + 1)
    v_part = v_samples[span]
    lat_n = _hermite(lat[span], v_part[:, 0] / (radii(lat[span])[0] + h[span]), dt).ravel()
    h_n = _hermite(h[span], -v_part[:, 2], dt).ravel()
    v_n, v_dot = _velocity(ch), _velocity_rate(ch)
    w_ie = np.stack(earth_rate_n(lat_n), axis=-1)
    w_en = np.stack(transport_rate_n(lat_n, h_n, v_n[:, 0], v_n[:, 1]), axis=-1)
    gamma = normal_gravity(lat_n, h_n)
    g_n = np.zeros_like(v_n)
    g_n[:, 2] = gamma
    C_bn = np.swapaxes(rot.to_matrix(attitude(ch)), -1, -2)
    omega = np.einsum("nij,nj->ni", C_bn, w_ie + w_en) + _body_rate_from_euler(ch)
    force = np.einsum("nij,nj->ni", C_bn, v_dot + np.cross(2.0 * w_ie + w_en, v_n) - g_n)
    weights = dt * WEIGHTS[:, None]
    return (omega.reshape(-1, 4, 3) * weights).sum(axis=1), (force.reshape(-1, 4, 3) * weights).sum(axis=1)
