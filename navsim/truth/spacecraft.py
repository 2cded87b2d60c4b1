"""A spacecraft's attitude from its dynamics: the rigid body with reaction wheels, a quaternion-feedback controller
that follows an attitude law (:mod:`navsim.truth.pointing`), the gravity-gradient torque of its orbit and the wheels'
friction; so the truth's rates and jitter (the controller's sampling, the wheels' torque and momentum limits and
friction, the disturbance) come from dynamics.

Equations (Markley & Crassidis 2014, eqs. 3.147 and 7.x; B body axes, wheel spin axes the columns of G (3, n)):

    q̇_IB = ½ q_IB ⊗ [ω, 0],
    J ω̇ = τ_gg − G ḣ_w − ω × (J ω + G h_w),          ḣ_w = τ_m − c_v Ω − τ_c tanh(Ω/Ω_s),   Ω = h_w / I_w,
    τ_gg = 3 μ/|r|⁵ (r_B × J r_B)                      (the gravity gradient; Markley & Crassidis eq. 3.155),

h_w the wheels' momenta about their axes relative to the body [N m s], τ_m the motors' torques [N m] (clipped to
±τ_max, and to 0 when a wheel at its momentum limit would go further), the friction viscous and Coulomb (smoothed
over Ω_s = 0.1 rad/s). The controller runs at its own rate with the truth's state (ideal knowledge: what the sensors
make of it is the estimation's business) and holds its command (Wie, Weiss & Arapostathis 1989, with feedforward):

    δq = q_IR⁻¹ ⊗ q_IB (δq₄ ≥ 0),  ω_r = C_BR ω_R,  δω = ω − ω_r,
    u = −K_p δq_v − K_i ∫δq_v dt − K_d δω + ω × (J ω + G h_w) + J (C_BR ω̇_R − δω × ω_r),

with the gains that place the small-angle response (δθ = 2 δq_v) at a pair of natural frequency ω_n and damping ζ and
a real pole at ω_n/4 (the integral action that takes out a steady torque: the wheels' friction, the gravity
gradient): (s² + 2ζω_n s + ω_n²)(s + p) = s³ + (K_d/J) s² + (K_p/2J) s + K_i/2J, so K_d = (2ζω_n + p) J,
K_p = 2(ω_n² + 2ζω_n p) J, K_i = 2 ω_n² p J; the integral runs only while the error is below 0.5 deg and the last
command was within the wheels' limits (conditional integration, the anti-windup of a slew). τ_m = −G⁺ u, the least-norm wheel torques (G⁺ = Gᵀ(G Gᵀ)⁻¹).

The integration is RK4 on (q, ω, h_w) at the truth's step, the command held over each control interval (a control
interval is a whole number of steps).
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.wgs84 import GM
from startrack import InputError, njit
from startrack import rotation_kernels as rk

#: The speed [rad/s] over which the wheels' Coulomb friction changes sign (tanh).
COULOMB_SMOOTHING = 0.1
#: The integral pole over the natural frequency, and the pointing error [rad] below which the integral runs (module
#: docstring).
INTEGRAL_POLE, INTEGRAL_ZONE = 0.25, np.radians(0.5)


@dataclass(frozen=True)
class Wheels:
    """Reaction wheels: spin ``axes`` (n, 3) in body axes (unit), each of spin inertia ``inertia`` [kg m²], motor
    torque limit ``max_torque`` [N m], momentum limit ``max_momentum`` [N m s], viscous friction ``viscous``
    [N m s/rad] and Coulomb friction ``coulomb`` [N m]."""

    axes: tuple
    inertia: float = 0.01
    max_torque: float = 0.1
    max_momentum: float = 4.0
    viscous: float = 0.0
    coulomb: float = 0.0

    @property
    def G(self):
        """(3, n): the spin axes as columns."""
        return np.ascontiguousarray(np.asarray(self.axes, dtype=float).T)

    def check(self):
        G = self.G
        if np.linalg.matrix_rank(G) < 3:
            raise InputError("spacecraft.wheels.axes: the wheels' axes must span the three body axes (rank 3)")
        return self


@dataclass(frozen=True)
class Controller:
    """The attitude controller (module docstring): natural frequency ``bandwidth`` ω_n [rad/s], damping ``damping``
    ζ, and its ``rate_hz`` [Hz]."""

    bandwidth: float = 0.1
    damping: float = 0.9
    rate_hz: float = 10.0


@dataclass(frozen=True)
class AttitudeMotion:
    """The spacecraft's attitude on the truth's grid: t (N+1,) [s], q_IB (N+1, 4), ω_B (N+1, 3) [rad/s]; per control
    interval (K,): the wheels' momenta ``wheel_momentum`` (K, n) [N m s] at its start, the motors' torques
    ``wheel_torque`` (K, n) [N m], ``saturated`` (K,) True when a wheel's torque or momentum limit cut the command,
    and the ``pointing_error`` (K,) [rad] of the body from the reference at the interval's start."""

    t: np.ndarray
    q_IB: np.ndarray
    omega_B: np.ndarray
    wheel_momentum: np.ndarray
    wheel_torque: np.ndarray
    saturated: np.ndarray
    pointing_error: np.ndarray


@dataclass(frozen=True)
class Spacecraft:
    """The rigid body: ``inertia`` (3, 3) [kg m²], its ``wheels`` (:class:`Wheels`), ``controller``
    (:class:`Controller`) and whether the orbit's ``gravity_gradient`` torques it."""

    inertia: tuple
    wheels: Wheels
    controller: Controller = Controller()
    gravity_gradient: bool = True

    def simulate(self, dt, steps_per_control, q_ref, omega_ref, domega_ref, r_I, initial_momentum=None):
        """The :class:`AttitudeMotion` over K control intervals of ``steps_per_control`` truth steps of ``dt`` [s]:
        the reference q_IR (K, 4), ω_R (K, 3) and ω̇_R (K, 3) at the intervals' starts, the geocentric position r_I
        (K, 3) [m] for the gravity gradient; the body starts on the reference at its rate, the wheels at
        ``initial_momentum`` (n,) [N m s] (default 0)."""
        J = np.asarray(self.inertia, dtype=float)
        w = self.wheels
        h0 = np.zeros(len(w.axes)) if initial_momentum is None else np.asarray(initial_momentum, dtype=float)
        c = self.controller
        p = INTEGRAL_POLE * c.bandwidth
        gains = np.array([2.0 * (c.bandwidth**2 + 2.0 * c.damping * c.bandwidth * p), 2.0 * c.damping * c.bandwidth + p,
                          2.0 * c.bandwidth**2 * p])
        limits = np.array([w.inertia, w.max_torque, w.max_momentum, w.viscous, w.coulomb, GM if self.gravity_gradient else 0.0])
        q, omega, h, torque, saturated, error = _simulate(J, w.G, limits, gains, float(dt), int(steps_per_control),
                                                          np.ascontiguousarray(q_ref), np.ascontiguousarray(omega_ref),
                                                          np.ascontiguousarray(domega_ref), np.ascontiguousarray(r_I), h0)
        t = np.arange(len(q)) * dt
        return AttitudeMotion(t=t, q_IB=q, omega_B=omega, wheel_momentum=h, wheel_torque=torque, saturated=saturated,
                              pointing_error=error)


@njit
def _derivatives(y, tau_m, J, J_inv, G, limits, r_I, out):
    """ẏ of y = (q (4), ω (3), h_w (n)) by the module docstring's equations, written into ``out``."""
    inertia_w, _, _, viscous, coulomb, mu = limits
    n = G.shape[1]
    w0, w1, w2 = y[4], y[5], y[6]
    H = np.empty(3)
    torque = np.zeros(3)
    for i in range(3):
        H[i] = J[i, 0] * w0 + J[i, 1] * w1 + J[i, 2] * w2
    for k in range(n):
        speed = y[7 + k] / inertia_w
        h_dot = tau_m[k] - viscous * speed - coulomb * np.tanh(speed / COULOMB_SMOOTHING)
        out[7 + k] = h_dot
        for i in range(3):
            H[i] += G[i, k] * y[7 + k]
            torque[i] -= G[i, k] * h_dot
    torque[0] -= w1 * H[2] - w2 * H[1]
    torque[1] -= w2 * H[0] - w0 * H[2]
    torque[2] -= w0 * H[1] - w1 * H[0]
    if mu > 0.0:
        C = rk.quat_to_matrix(y[0:4])
        r_B = C.T @ r_I
        rn2 = r_B[0] ** 2 + r_B[1] ** 2 + r_B[2] ** 2
        scale = 3.0 * mu / (rn2 * rn2 * np.sqrt(rn2))
        Jr = J @ r_B
        torque[0] += scale * (r_B[1] * Jr[2] - r_B[2] * Jr[1])
        torque[1] += scale * (r_B[2] * Jr[0] - r_B[0] * Jr[2])
        torque[2] += scale * (r_B[0] * Jr[1] - r_B[1] * Jr[0])
    x, yq, z, w = y[0], y[1], y[2], y[3]
    out[0] = 0.5 * (w * w0 + yq * w2 - z * w1)
    out[1] = 0.5 * (w * w1 - x * w2 + z * w0)
    out[2] = 0.5 * (w * w2 + x * w1 - yq * w0)
    out[3] = -0.5 * (x * w0 + yq * w1 + z * w2)
    for i in range(3):
        out[4 + i] = J_inv[i, 0] * torque[0] + J_inv[i, 1] * torque[1] + J_inv[i, 2] * torque[2]


@njit
def _command(q, omega, h, q_ref, omega_R, domega_R, J, G, G_pinv, gains, integral, control_dt, integrate):
    """The motors' commanded torques τ_m = −G⁺ u (module docstring) and the pointing error angle [rad]; ``integral``
    (3,) ∫δq_v dt is advanced by the interval ``control_dt`` [s] in place when ``integrate`` and the error is inside
    :data:`INTEGRAL_ZONE`."""
    conj = np.array([-q_ref[0], -q_ref[1], -q_ref[2], q_ref[3]])
    dq = rk.quat_multiply(conj, q)
    if dq[3] < 0.0:
        dq = -dq
    C_BR = rk.quat_to_matrix(dq).T
    omega_r = C_BR @ omega_R
    domega = omega - omega_r
    error = 2.0 * np.arctan2(np.sqrt(np.sum(dq[0:3] * dq[0:3])), dq[3])
    if integrate and error < INTEGRAL_ZONE:
        integral += dq[0:3] * control_dt
    u = -gains[0] * (J @ dq[0:3]) - gains[2] * (J @ integral) - gains[1] * (J @ domega) + np.cross(omega, J @ omega + G @ h)
    u += J @ (C_BR @ domega_R - np.cross(domega, omega_r))
    return -(G_pinv @ u), error


@njit
def _limited(tau, h, limits):
    """The motors' torques within their limits (module docstring) and whether a limit cut them."""
    out = tau.copy()
    cut = False
    for i in range(tau.shape[0]):
        if abs(out[i]) > limits[1]:
            out[i] = np.sign(out[i]) * limits[1]
            cut = True
        if abs(h[i]) >= limits[2] and out[i] * h[i] > 0.0:
            out[i] = 0.0
            cut = True
    return out, cut


@njit
def _simulate(J, G, limits, gains, dt, steps, q_ref, omega_ref, domega_ref, r_I, h0):
    K = q_ref.shape[0]
    n = G.shape[1]
    J_inv = np.linalg.inv(J)
    G_pinv = G.T @ np.linalg.inv(G @ G.T)
    q_out = np.empty((K * steps + 1, 4))
    w_out = np.empty((K * steps + 1, 3))
    h_log = np.empty((K, n))
    tau_log = np.empty((K, n))
    cut_log = np.zeros(K, dtype=np.bool_)
    error_log = np.empty(K)
    y = np.empty(7 + n)
    y[0:4] = q_ref[0]
    y[4:7] = omega_ref[0]  # the body starts on the reference: C_BR = I
    y[7:] = h0
    integral = np.zeros(3)
    q_out[0] = y[0:4]
    w_out[0] = y[4:7]
    k1, k2, k3, k4, stage = np.empty(7 + n), np.empty(7 + n), np.empty(7 + n), np.empty(7 + n), np.empty(7 + n)
    for k in range(K):
        command, error_log[k] = _command(y[0:4], y[4:7], y[7:], q_ref[k], omega_ref[k], domega_ref[k], J, G, G_pinv, gains,
                                         integral, dt * steps, k == 0 or not cut_log[k - 1])
        tau, cut_log[k] = _limited(command, y[7:], limits)
        h_log[k] = y[7:]
        tau_log[k] = tau
        r = r_I[k]
        for s in range(steps):
            _derivatives(y, tau, J, J_inv, G, limits, r, k1)
            for i in range(7 + n):
                stage[i] = y[i] + 0.5 * dt * k1[i]
            _derivatives(stage, tau, J, J_inv, G, limits, r, k2)
            for i in range(7 + n):
                stage[i] = y[i] + 0.5 * dt * k2[i]
            _derivatives(stage, tau, J, J_inv, G, limits, r, k3)
            for i in range(7 + n):
                stage[i] = y[i] + dt * k3[i]
            _derivatives(stage, tau, J, J_inv, G, limits, r, k4)
            for i in range(7 + n):
                y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            norm = np.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2 + y[3] ** 2)
            for i in range(4):
                y[i] /= norm
            q_out[k * steps + s + 1] = y[0:4]
            w_out[k * steps + s + 1] = y[4:7]
    return q_out, w_out, h_log, tau_log, cut_log, error_log
