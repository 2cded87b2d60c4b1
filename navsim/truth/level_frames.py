"""The local-level frame f in which a truth profile's heading is measured, and the position it carries
(strategy objects of :func:`navsim.truth.trajectory.kinematics`; docs/design.md, "The truth's level frame").

Every strategy gives, from the velocity in f at the samples and at the quadrature nodes (:data:`NODES`), the
:class:`Track` at the samples (L, λ, h and the angle α from north to f's x axis: C_nf = R_z(α)), and the Earth
and transport rates ω_ie^f, ω_ef^f, the latitude and height at the nodes (for the specific force and the body
rate).

- :class:`North`: f = NED (α = 0): L̇ = v_N/(R_M + h), λ̇ = v_E/((R_N + h) cos L) by quadrature (Groves,
  2nd ed., eq. 2.111), singular at the poles: segments of headings and turns.
- :class:`FreeAzimuth`: f turns about the vertical at no rate relative to the Earth (the wander-azimuth frame of
  :mod:`navsim.earth.wander`, α = 0 at the start): its position C_ef is carried by the transport rate, regular at
  the poles. A constant heading in f is a geodesic of the ellipsoid's parallel surface at constant height (the
  tangent is parallel-transported: no rotation about the normal; do Carmo 1976, §4-4): routes.
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from navsim.earth.frames import OMEGA_IE, earth_rate_n, transport_rate_n
from navsim.earth.wander import axis_of, geodetic, q_ew, transport_of_axis
from navsim.earth.wgs84 import radii
from startrack import njit, units

#: Gauss-Legendre nodes on [0, 1] and weights (sum 1).
_X, _W = np.polynomial.legendre.leggauss(4)
NODES = 0.5 * (_X + 1.0)
WEIGHTS = 0.5 * _W
#: Cubic Hermite basis at the nodes (h00, h10, h01, h11) for value/derivative interpolation.
HERMITE = np.stack([2 * NODES**3 - 3 * NODES**2 + 1, NODES**3 - 2 * NODES**2 + NODES,
                    -2 * NODES**3 + 3 * NODES**2, NODES**3 - NODES**2])


class Track(NamedTuple):
    """Position at the N + 1 samples: ``lat``, ``lon`` [rad], ``h`` [m], ``alpha`` [rad] (north to f's x axis,
    towards east; None: f is NED), and the frame's own carried state (``q_ef`` (N+1, 4), ``rate`` ω_ef^f (N+1, 3),
    or None)."""

    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    alpha: np.ndarray | None = None
    q_ef: np.ndarray | None = None
    rate: np.ndarray | None = None


def hermite(values, rates, dt):
    """Cubic Hermite interpolation of sample ``values`` (N+1,) with derivatives ``rates`` at the quadrature nodes:
    (N, 4)."""
    h00, h10, h01, h11 = HERMITE
    return (values[:-1, None] * h00 + dt * rates[:-1, None] * h10
            + values[1:, None] * h01 + dt * rates[1:, None] * h11)


def cumulative(start, integrand, dt):
    """start + ∫ integrand dt at the samples, integrand (N, 4) at the nodes."""
    return start + np.concatenate([[0.0], np.cumsum(dt * integrand @ WEIGHTS)])


def height(h0, dt, v_samples, v_nodes):
    """(h (N+1,), h at the nodes (N, 4)) [m] by quadrature of ḣ = −v_D."""
    h = cumulative(h0, -v_nodes[..., 2], dt)
    return h, hermite(h, -v_samples[:, 2], dt)


@dataclass(frozen=True)
class North:
    """f = NED: the heading is the true heading (module docstring)."""

    def track(self, start, dt, v_samples, v_nodes):
        """The :class:`Track` from ``start`` (:class:`~navsim.truth.segments.Start`) of the velocities (N+1, 3) and
        (N, 4, 3) [m/s]; L iterated to convergence (its rate depends on L through R_M; each pass gains ~3 digits)."""
        h, h_nodes = height(start.height_m, dt, v_samples, v_nodes)
        lat = np.full(h.shape, start.lat_deg * units.DEG)
        for _ in range(20):
            lat_nodes = hermite(lat, v_samples[:, 0] / (radii(lat)[0] + h), dt)
            new = cumulative(lat[0], v_nodes[..., 0] / (radii(lat_nodes)[0] + h_nodes), dt)
            change = np.max(np.abs(new - lat))
            lat = new
            if change < 1e-16:
                break
        lat_nodes = hermite(lat, v_samples[:, 0] / (radii(lat)[0] + h), dt)
        rate = v_nodes[..., 1] / ((radii(lat_nodes)[1] + h_nodes) * np.cos(lat_nodes))
        return Track(lat=lat, lon=cumulative(start.lon_deg * units.DEG, rate, dt), h=h)

    def node_rates(self, track, lo, hi, dt, v_samples, v_nodes):
        """(ω_ie^f, ω_ef^f (M, 3) [rad/s], L, h (M,)) at the M = 4 (hi − lo) nodes of intervals lo..hi−1, the
        velocities at their samples (hi − lo + 1, 3) and nodes (M, 3)."""
        span = slice(lo, hi + 1)
        lat, h = track.lat[span], track.h[span]
        lat_n = hermite(lat, v_samples[:, 0] / (radii(lat)[0] + h), dt).ravel()
        h_n = hermite(h, -v_samples[:, 2], dt).ravel()
        w_ie = np.stack(earth_rate_n(lat_n), axis=-1)
        w_en = np.stack(transport_rate_n(lat_n, h_n, v_nodes[:, 0], v_nodes[:, 1]), axis=-1)
        return w_ie, w_en, lat_n, h_n


@dataclass(frozen=True)
class FreeAzimuth:
    """f free in azimuth (α = 0 at the start, no rotation about the vertical relative to the Earth): the heading is
    measured from f's x axis and a constant one flies a geodesic (module docstring). It starts as NED at the start's
    latitude and longitude, or as the frame ``origin`` (q_ef, 4 numbers) when given (the rest of a route)."""

    origin: tuple | None = None

    def track(self, start, dt, v_samples, v_nodes):
        """The :class:`Track` from ``start`` (:class:`~navsim.truth.segments.Start`, its height; its position unless
        ``origin``) of the velocities in f (N+1, 3) and (N, 4, 3) [m/s]."""
        q0 = q_ew(start.lat_deg * units.DEG, start.lon_deg * units.DEG) if self.origin is None else self.origin
        h, h_nodes = height(start.height_m, dt, v_samples, v_nodes)
        q, rate = carry(np.asarray(q0, dtype=float), h, v_samples, h_nodes, np.ascontiguousarray(v_nodes), dt)
        lat, lon, alpha = geodetic(q)
        return Track(lat=lat, lon=lon, h=h, alpha=alpha, q_ef=q, rate=rate)

    def node_rates(self, track, lo, hi, dt, v_samples, v_nodes):
        """:meth:`North.node_rates` in f: C_ef at the nodes by Hermite interpolation of q_ef (q̇ = ½ q ⊗ ω_ef^f)."""
        span = slice(lo, hi + 1)
        h_n = hermite(track.h[span], -v_samples[:, 2], dt).ravel()
        w_ie, w_ef, sine = _node_rates(track.q_ef[span], track.rate[span], h_n, np.ascontiguousarray(v_nodes), dt)
        return w_ie, w_ef, np.arcsin(sine), h_n


@njit
def _transport(x, y, z, w, h, v0, v1):
    """ω_ef^f (x, y; z = 0) [rad/s] at q_ef = (x, y, z, w), h [m], horizontal velocity (v0, v1) [m/s]
    (:func:`navsim.earth.wander.transport_of_axis`)."""
    c0, c1, c2 = axis_of((x, y, z, w))
    return transport_of_axis(c0, c1, c2, h, v0, v1)


@njit
def _unit(x, y, z, w):
    norm = np.sqrt(x * x + y * y + z * z + w * w)
    return x / norm, y / norm, z / norm, w / norm


@njit
def _turned(x, y, z, w, t0, t1, t2):
    """q ⊗ q(θ) for q = (x, y, z, w) and θ = (t0, t1, t2) [rad], normalised."""
    angle = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    s = 0.5 - angle * angle / 48.0 if angle < 1e-8 else np.sin(0.5 * angle) / angle
    px, py, pz, pw = s * t0, s * t1, s * t2, np.cos(0.5 * angle)
    return _unit(w * px + x * pw + y * pz - z * py, w * py - x * pz + y * pw + z * px,
                 w * pz + x * py - y * px + z * pw, w * pw - x * px - y * py - z * pz)


@njit
def _at_node(q0, r0, q1, r1, i, dt):
    """q_ef (4 scalars) at node i of an interval by cubic Hermite interpolation of the end values q0, q1 (4,) and
    derivatives q̇ = ½ q ⊗ [ω, 0] (ω = (r[0], r[1], 0)), normalised."""
    a, b, c, d = HERMITE[0, i], 0.5 * dt * HERMITE[1, i], HERMITE[2, i], 0.5 * dt * HERMITE[3, i]
    return _unit(a * q0[0] + b * (q0[3] * r0[0] - q0[2] * r0[1]) + c * q1[0] + d * (q1[3] * r1[0] - q1[2] * r1[1]),
                 a * q0[1] + b * (q0[3] * r0[1] + q0[2] * r0[0]) + c * q1[1] + d * (q1[3] * r1[1] + q1[2] * r1[0]),
                 a * q0[2] + b * (q0[0] * r0[1] - q0[1] * r0[0]) + c * q1[2] + d * (q1[0] * r1[1] - q1[1] * r1[0]),
                 a * q0[3] - b * (q0[0] * r0[0] + q0[1] * r0[1]) + c * q1[3] - d * (q1[0] * r1[0] + q1[1] * r1[1]))


@njit
def _step(q, rate, k, h1, v1, h_nodes, v_nodes, dt):
    """Fill q[k + 1], rate[k + 1] (q_ef, ω_ef^f at the end of interval k) from q[k], rate[k]: the rotation vector
    ∫ ω dt by the four-node quadrature plus the commutation term (ω0 × ω1) dt²/12 (ω linear over the interval;
    Savage 1998), the nodes' q_ef by :func:`_at_node` between q[k] and the previous pass's end (three passes after
    an Euler predictor)."""
    q0, r0, q1, r1 = q[k], rate[k], q[k + 1], rate[k + 1]
    q1[0], q1[1], q1[2], q1[3] = _turned(q0[0], q0[1], q0[2], q0[3], r0[0] * dt, r0[1] * dt, 0.0)
    for _ in range(3):
        r1[0], r1[1] = _transport(q1[0], q1[1], q1[2], q1[3], h1, v1[0], v1[1])
        t0, t1 = 0.0, 0.0
        for i in range(4):
            x, y, z, w = _at_node(q0, r0, q1, r1, i, dt)
            g0, g1 = _transport(x, y, z, w, h_nodes[i], v_nodes[i, 0], v_nodes[i, 1])
            t0 += WEIGHTS[i] * g0 * dt
            t1 += WEIGHTS[i] * g1 * dt
        commutation = (r0[0] * r1[1] - r0[1] * r1[0]) * dt * dt / 12.0
        q1[0], q1[1], q1[2], q1[3] = _turned(q0[0], q0[1], q0[2], q0[3], t0, t1, commutation)
    r1[0], r1[1] = _transport(q1[0], q1[1], q1[2], q1[3], h1, v1[0], v1[1])


@njit
def carry(q0, h, v, h_nodes, v_nodes, dt):
    """(q_ef (N+1, 4), ω_ef^f (N+1, 2) [rad/s]) along the velocities in f at the samples v (N+1, 3) and nodes
    v_nodes (N, 4, 3) [m/s], heights h (N+1,) and h_nodes (N, 4) [m], from q_ef = q0 (f free in azimuth)."""
    n = v_nodes.shape[0]
    q = np.empty((n + 1, 4))
    rate = np.zeros((n + 1, 2))
    q[0, 0], q[0, 1], q[0, 2], q[0, 3] = _unit(q0[0], q0[1], q0[2], q0[3])
    rate[0, 0], rate[0, 1] = _transport(q[0, 0], q[0, 1], q[0, 2], q[0, 3], h[0], v[0, 0], v[0, 1])
    for k in range(n):
        _step(q, rate, k, h[k + 1], v[k + 1], h_nodes[k], v_nodes[k], dt)
    return q, rate


@njit
def _node_rates(q, rate, h_nodes, v_nodes, dt):
    """(ω_ie^f, ω_ef^f (M, 3), sin L (M,)) at the nodes of the intervals between the samples q (K+1, 4) with their
    transport rates (K+1, 2); heights (M,) and velocities (M, 3) at the M = 4K nodes."""
    m = h_nodes.shape[0]
    w_ie, w_ef, sine = np.empty((m, 3)), np.zeros((m, 3)), np.empty(m)
    for j in range(m):
        k, i = j // 4, j % 4
        x, y, z, w = _at_node(q[k], rate[k], q[k + 1], rate[k + 1], i, dt)
        c0, c1, c2 = axis_of((x, y, z, w))
        w_ie[j, 0], w_ie[j, 1], w_ie[j, 2] = OMEGA_IE * c0, OMEGA_IE * c1, OMEGA_IE * c2
        w_ef[j, 0], w_ef[j, 1] = _transport(x, y, z, w, h_nodes[j], v_nodes[j, 0], v_nodes[j, 1])
        sine[j] = -c2
    return w_ie, w_ef, sine
