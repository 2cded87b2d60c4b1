"""Attitude laws of a spacecraft: the attitude its controller is told to follow (the reference R, the body frame B
it wants), as immutable strategy objects with one method, ``attitude(t, r, v, sun) -> q_IR (N, 4)``, from the
orbit's geocentric position r and velocity v (N, 3) [m, m/s] and the geocentric Sun (N, 3) [m] at the times t (N,)
[s] (GCRS axes throughout); :func:`reference_rates` gives the rate and acceleration the controller feeds forward.

- :class:`Nadir`: the local-vertical, local-horizontal frame (LVLH): +z_B to nadir (−r̂), +y_B against the orbit's
  angular momentum (−(r × v)/|r × v|), +x_B = y_B × z_B, about the velocity; turned by a fixed yaw about +z_B and by
  ``offsets`` held from given times with slews between them (an Earth-observation spacecraft's off-nadir looks).
- :class:`SunPointing`: a body axis on the Sun and a second body axis as near as it goes to celestial north, or
  with ``yaw_steering`` to nadir (the rotation about the Sun line then follows the orbit, keeping the Earth on one
  side of the spacecraft).
- :class:`Targets`: inertial attitudes held from given times, with eigenaxis slews between them under a rate and an
  acceleration limit (bang-coast-bang in the slew angle: Markley & Crassidis 2014 §7.6; one target: inertial hold).

Two body axes on two inertial directions is TRIAD's construction (Black 1964; :func:`aligned`).
"""

from dataclasses import dataclass

import numpy as np

from startrack import InputError
from startrack import rotation as rot


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _triad(a, b):
    """(N, 3, 3) orthonormal frames [a, a × b / |a × b|, a × (a × b)/|…|] as columns, of unit a (N, 3) and b (N, 3)."""
    t2 = _unit(np.cross(a, b))
    return np.stack([a, t2, np.cross(a, t2)], axis=-1)


def aligned(primary_B, primary_I, secondary_B, secondary_I):
    """q_IR (N, 4): the attitude that puts the body axis ``primary_B`` (3,) exactly on ``primary_I`` (N, 3) and
    ``secondary_B`` (3,) as near as it goes to ``secondary_I`` (N, 3) (TRIAD: C_IR = T_I T_Bᵀ); an InputError when the
    two directions coincide somewhere (the rotation about the primary is undefined)."""
    primary_I, secondary_I = _unit(np.atleast_2d(primary_I)), _unit(np.atleast_2d(secondary_I))
    if np.any(np.linalg.norm(np.cross(primary_I, secondary_I), axis=-1) < 1e-9):
        raise InputError("pointing: the primary and secondary directions coincide: the rotation about the primary "
                         "axis is undefined")
    T_B = _triad(_unit(np.asarray(primary_B, dtype=float))[None], _unit(np.asarray(secondary_B, dtype=float))[None])
    return rot.from_matrix(_triad(primary_I, secondary_I) @ np.swapaxes(T_B, -1, -2))


@dataclass(frozen=True)
class Nadir:
    """LVLH pointing (module docstring), turned by ``yaw`` [rad] about +z_B, then by the body-axes offsets of
    ``offsets`` (a :class:`Targets` of rotations from the yawed LVLH frame, with its slews; None: none)."""

    yaw: float = 0.0
    offsets: object = None

    def attitude(self, t, r, v, sun):
        q = aligned([0.0, 0.0, 1.0], -r, [0.0, 1.0, 0.0], -np.cross(r, v))
        q = rot.multiply(q, rot.from_rotation_vector(np.array([0.0, 0.0, self.yaw])))
        return q if self.offsets is None else rot.normalize(rot.multiply(q, self.offsets.attitude(t, r, v, sun)))


@dataclass(frozen=True)
class SunPointing:
    """The body axis ``axis`` (3,) on the Sun; ``secondary`` (3,) towards celestial north, or to nadir with
    ``yaw_steering`` (module docstring)."""

    axis: tuple = (0.0, 0.0, 1.0)
    secondary: tuple = (1.0, 0.0, 0.0)
    yaw_steering: bool = False

    def attitude(self, t, r, v, sun):
        toward = -r if self.yaw_steering else np.broadcast_to([0.0, 0.0, 1.0], np.shape(r))
        return aligned(self.axis, sun - r, self.secondary, toward)


def slew_angle(t, angle, max_rate, max_acceleration):
    """θ(t) [rad] of a rest-to-rest slew through ``angle`` [rad] started at t = 0 under the rate and acceleration
    limits (bang-coast-bang; a triangle when the rate limit is not reached): t (N,) [s], the angle reached at and
    after the slew's end. Also returns the slew's duration [s]."""
    t_ramp = min(max_rate / max_acceleration, np.sqrt(angle / max_acceleration))
    rate = max_acceleration * t_ramp
    coast = (angle - rate * t_ramp) / rate if rate > 0.0 else 0.0
    end = 2.0 * t_ramp + coast
    t = np.clip(np.asarray(t, dtype=float), 0.0, end)
    ramp_up = 0.5 * max_acceleration * np.minimum(t, t_ramp) ** 2
    coasting = rate * np.clip(t - t_ramp, 0.0, coast)
    down = np.clip(t - t_ramp - coast, 0.0, t_ramp)
    return ramp_up + coasting + rate * down - 0.5 * max_acceleration * down**2, end


@dataclass(frozen=True)
class Targets:
    """Inertial attitudes ``targets`` = ((start [s], q_IR (4,)), ...) in time order, the first held from t = 0; at each
    later start an eigenaxis slew from the previous target under ``max_rate`` [rad/s] and ``max_acceleration`` [rad/s²]
    (:func:`slew_angle`). A slew must end before the next target's start."""

    targets: tuple
    max_rate: float = np.radians(1.0)
    max_acceleration: float = np.radians(0.01)

    def slews(self):
        """[(start [s], q_from (4,), rotation axis (3,) in the from-frame, angle [rad], duration [s]), ...]."""
        out = []
        for (_, q_from), (start, q_to) in zip(self.targets[:-1], self.targets[1:]):
            phi = rot.to_rotation_vector(rot.multiply(rot.conjugate(q_from), q_to))
            angle = float(np.linalg.norm(phi))
            duration = slew_angle(0.0, angle, self.max_rate, self.max_acceleration)[1] if angle > 0.0 else 0.0
            out.append((start, np.asarray(q_from, dtype=float), phi / angle if angle > 0.0 else np.zeros(3), angle, duration))
        return out

    def late(self):
        """The index of the first target whose slew has not ended at the next target's start, or None."""
        slews = self.slews()
        for k, (start, _, _, _, duration) in enumerate(slews[:-1]):
            if start + duration > slews[k + 1][0]:
                return k + 1
        return None

    def attitude(self, t, r, v, sun):
        t = np.asarray(t, dtype=float)
        q = np.broadcast_to(np.asarray(self.targets[0][1], dtype=float), (t.size, 4)).copy()
        for start, q_from, axis, angle, _ in self.slews():
            after = t >= start
            if angle > 0.0:
                theta, _ = slew_angle(t[after] - start, angle, self.max_rate, self.max_acceleration)
                q[after] = rot.multiply(q_from, rot.from_rotation_vector(theta[:, None] * axis))
            else:
                q[after] = q_from
        return rot.normalize(q)


def reference_rates(q_IR, dt):
    """(ω_R (N, 3) [rad/s], ω̇_R (N, 3) [rad/s²]): the rate of the reference relative to inertial space in its own axes
    (q̇ = ½ q ⊗ [ω, 0]) and its derivative, by central differences of ``q_IR`` (N, 4) sampled every ``dt`` [s]
    (one-sided at the ends): ω_k = rotvec(q_(k−1)⁻¹ ⊗ q_(k+1)) / 2Δt, second order in Δt."""
    n = len(q_IR)
    before = np.concatenate([[0], np.arange(n - 1)])
    after = np.concatenate([np.arange(1, n), [n - 1]])
    span = (after - before) * dt
    omega = rot.to_rotation_vector(rot.multiply(rot.conjugate(q_IR[before]), q_IR[after])) / span[:, None]
    return omega, (omega[after] - omega[before]) / span[:, None]
