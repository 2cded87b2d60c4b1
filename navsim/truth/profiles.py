"""Truth attitude motion: prescribed profiles and rigid-body dynamics.

Every profile is an immutable strategy object with one method,
``simulate(t, q0) -> (q_IB (N, 4), omega_B (N, 3))`` on a uniform time grid
``t`` [s] starting at 0, with body rates [rad/s] in body axes
(``q̇_IB = ½ q_IB ⊗ [ω_B, 0]``, docs/design.md).
"""

from dataclasses import dataclass

import numpy as np

from navsim.kinematics_jit import quat_derivative
from startrack import njit
from startrack import rotation as rot


def _uniform_step(t):
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError("time grid must be a 1-D array of at least two samples")
    dt = t[1] - t[0]
    if not np.allclose(np.diff(t), dt, rtol=1e-9, atol=1e-12):
        raise ValueError("time grid must be uniform")
    return t, dt


@dataclass(frozen=True)
class ConstantRate:
    """Constant body rate ω [rad/s]: q(t) = q0 ⊗ exp(ω t / 2) (exact)."""

    rate: tuple

    def simulate(self, t, q0):
        t, _ = _uniform_step(t)
        omega = np.asarray(self.rate, dtype=float)
        q = rot.multiply(q0, rot.from_rotation_vector(t[:, None] * omega))
        return rot.normalize(q), np.broadcast_to(omega, (t.size, 3)).copy()


@dataclass(frozen=True)
class SinusoidalAxis:
    """Rotation about a fixed axis l by θ(t) = θ0 + A sin(Ω t + φ) (the experiment of 000 §3-§5).

    q_IB(t) = q0 ⊗ exp(l θ(t) / 2) and ω_B = θ̇ l, exact. 000 uses l = [√2/2, 1/2, 1/2],
    θ0 = π/3 (the quaternion of its Table 2 at t = 0), A = π/6, Ω = 1 rad/s: peak rate 30 deg/s.
    """

    axis: tuple
    theta0: float
    amplitude: float
    angular_frequency: float
    phase: float = 0.0

    def simulate(self, t, q0):
        t, _ = _uniform_step(t)
        axis = np.asarray(self.axis, dtype=float)
        axis = axis / np.linalg.norm(axis)
        arg = self.angular_frequency * t + self.phase
        theta = self.theta0 + self.amplitude * np.sin(arg)
        theta_dot = self.amplitude * self.angular_frequency * np.cos(arg)
        q = rot.multiply(q0, rot.from_rotation_vector(theta[:, None] * axis))
        return rot.normalize(q), theta_dot[:, None] * axis


@dataclass(frozen=True)
class RateSegments:
    """Piecewise-constant body rates: ``segments`` of (duration [s], rate (3,) [rad/s]), exact.

    The segments must cover the whole time grid.
    """

    segments: tuple

    def simulate(self, t, q0):
        t, _ = _uniform_step(t)
        ends = np.cumsum([duration for duration, _ in self.segments])
        if t[-1] > ends[-1] + 1e-9:
            raise ValueError(f"rate segments cover {ends[-1]:g} s but the run lasts {t[-1]:g} s")
        starts = np.concatenate([[0.0], ends[:-1]])
        table = np.array([rate for _, rate in self.segments], dtype=float)
        # Attitude at each segment start, then exact exponentials inside each segment.
        seg = np.minimum(np.searchsorted(ends, t, side="right"), len(self.segments) - 1)
        q_start = np.empty((len(self.segments), 4))
        q = np.asarray(q0, dtype=float)
        for k, (duration, _) in enumerate(self.segments):
            q_start[k] = q
            q = rot.multiply(q, rot.from_rotation_vector(table[k] * duration))
        phi = table[seg] * (t - starts[seg])[:, None]
        q_t = rot.multiply(q_start[seg], rot.from_rotation_vector(phi))
        return rot.normalize(q_t), table[seg]


@dataclass(frozen=True)
class RigidBody:
    """Rigid body under Euler's equations I ω̇ = τ − ω × I ω, integrated by RK4 on (q, ω).

    ``inertia`` (3x3) [kg m²], ``initial_rate`` (3,) [rad/s] in body axes, ``torque_segments``
    of (duration [s], torque (3,) [N m]) in body axes; no segments means torque-free.
    The integration step is the grid step (choose a truth rate well above the motion's bandwidth);
    the torque is held over each step at its mid-step value, so segment boundaries on the grid are exact.
    """

    inertia: tuple
    initial_rate: tuple
    torque_segments: tuple = ()

    def torques(self, t_mid):
        """Body torque (N, 3) [N m] at times t_mid (zero after the last segment)."""
        if not self.torque_segments:
            return np.zeros((len(t_mid), 3))
        ends = np.cumsum([duration for duration, _ in self.torque_segments])
        table = np.vstack([np.array([torque for _, torque in self.torque_segments], dtype=float), np.zeros(3)])
        return table[np.searchsorted(ends, t_mid, side="right")]

    def simulate(self, t, q0):
        t, dt = _uniform_step(t)
        return rigid_body_rk4(
            np.asarray(q0, dtype=float),
            np.asarray(self.initial_rate, dtype=float),
            np.asarray(self.inertia, dtype=float),
            self.torques(t[:-1] + 0.5 * dt),
            dt,
        )


@dataclass(frozen=True)
class FrameTruth:
    """The truth at one star-sensor frame: attitude q_IB (4,), the mean body rate over the last
    gyro interval omega_B (3,) [rad/s] and, for a sensor on a vehicle near the Earth, the observer's
    barycentric velocity v_I (3,) [m/s] that aberrates the stars (None: no aberration) and the air that
    refracts them, (up_I (3,), A, B) (:func:`navsim.earth.apparent.apparent`; None: none)."""

    q_IB: np.ndarray
    omega_B: np.ndarray
    v_I: np.ndarray | None = None
    air: tuple | None = None


@dataclass(frozen=True)
class TruthRecord:
    """The truth on the gyro grid: times t (M+1,) [s], attitude q_IB (M+1, 4) and the mean body rate
    of each gyro interval omega_mean (M, 3) [rad/s] (what an ideal rate-integrating gyro reports); for a
    spacecraft, the barycentric velocity ``v_I`` (F, 3) [m/s] at its frames, one every ``frame_ratio`` samples."""

    t: np.ndarray
    q_IB: np.ndarray
    omega_mean: np.ndarray
    v_I: np.ndarray | None = None
    frame_ratio: int = 1

    def at(self, k):
        """The :class:`FrameTruth` of the frame that closes gyro interval k (sample k)."""
        v_I = None if self.v_I is None else self.v_I[k // self.frame_ratio - 1]
        return FrameTruth(q_IB=self.q_IB[k], omega_B=self.omega_mean[k - 1], v_I=v_I)


def sample_truth(profile, q0, n_gyro, gyro_hz, factor):
    """Simulate ``profile`` from q0 on a grid ``factor`` times denser than the gyro's (``n_gyro``
    intervals at ``gyro_hz``) and return the :class:`TruthRecord` on the gyro grid."""
    dt = 1.0 / gyro_hz
    q_fine, _ = profile.simulate(np.arange(n_gyro * factor + 1) / (gyro_hz * factor), q0)
    return TruthRecord(t=np.arange(n_gyro + 1) * dt, q_IB=q_fine[::factor],
                       omega_mean=interval_mean_rates(q_fine, factor, dt))


def interval_mean_rates(q_fine, factor, dt_gyro):
    """Mean body rate over each gyro interval [t_k, t_(k+1)] of length dt_gyro [s].

    ``q_fine`` (factor*M + 1, 4) is the truth attitude on a grid ``factor`` times denser. Each
    truth step contributes the rotation vector of q_iᵀ ⊗ q_(i+1) (its delta angle, exact for a
    rate held over the step, O(h³) coning otherwise); the gyro sample is their sum over the
    interval divided by dt_gyro — an ideal rate-integrating gyro, exact at rate steps on the grid.
    """
    q_fine = np.asarray(q_fine, dtype=float)
    n_intervals = (q_fine.shape[0] - 1) // factor
    q = q_fine[: n_intervals * factor + 1]
    delta = rot.to_rotation_vector(rot.multiply(rot.conjugate(q[:-1]), q[1:]))
    return delta.reshape(n_intervals, factor, 3).sum(axis=1) / dt_gyro


@njit
def rigid_body_rk4(q0, omega0, J, torques, dt):
    """Integrate q̇ = ½ q ⊗ [ω, 0] and J ω̇ = τ − ω × J ω (Euler) jointly by RK4.

    ``torques`` (m, 3) body torque [N m] held over each of the m steps of dt [s];
    returns q (m+1, 4) and ω (m+1, 3)."""
    m = torques.shape[0]
    J_inv = np.linalg.inv(J)
    q = np.empty((m + 1, 4))
    w = np.empty((m + 1, 3))
    q[0] = q0 / np.sqrt(np.sum(q0 * q0))
    w[0] = omega0
    for k in range(m):
        tau = torques[k]
        qk = q[k]
        wk = w[k]
        k1q = quat_derivative(qk, wk)
        k1w = J_inv @ (tau - np.cross(wk, J @ wk))
        w2 = wk + 0.5 * dt * k1w
        k2q = quat_derivative(qk + 0.5 * dt * k1q, w2)
        k2w = J_inv @ (tau - np.cross(w2, J @ w2))
        w3 = wk + 0.5 * dt * k2w
        k3q = quat_derivative(qk + 0.5 * dt * k2q, w3)
        k3w = J_inv @ (tau - np.cross(w3, J @ w3))
        w4 = wk + dt * k3w
        k4q = quat_derivative(qk + dt * k3q, w4)
        k4w = J_inv @ (tau - np.cross(w4, J @ w4))
        q_next = qk + dt / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q)
        q[k + 1] = q_next / np.sqrt(np.sum(q_next * q_next))
        w[k + 1] = wk + dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w)
    return q, w
