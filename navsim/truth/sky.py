"""What the star sensor of a navigation run sees at its frames: the true inertial attitude of the body,
q_IB = q_ie ⊗ q_en(L, λ) ⊗ q_nb (C_ib = C_ie C_en C_nb), the mean body rate ω_ib^b of the IMU
interval the frame closes, the observer's barycentric velocity in ICRS axes that aberrates the
stars (:func:`navsim.earth.orientation.observer_velocity`) and, inside the air, the local vertical and the
refraction coefficients of the real air at the vehicle (:mod:`navsim.earth.refraction`)."""

from dataclasses import dataclass

import numpy as np

from navsim.earth.frames import local_up, q_en
from navsim.earth.orientation import observer_velocity
from navsim.truth.profiles import FrameTruth
from startrack import rotation as rot


def inertial_attitude(trajectory, orientation, frame_k):
    """q_IB (F, 4) = q_ie ⊗ q_en(L, λ) ⊗ q_nb of the ``trajectory``'s samples ``frame_k`` (F,) for the Earth's
    ``orientation`` at them."""
    lat, lon = trajectory.lat[frame_k], trajectory.lon[frame_k]
    return rot.multiply(rot.multiply(orientation.q_ie, np.stack(q_en(lat, lon), axis=-1)), trajectory.q_nb[frame_k])


@dataclass(frozen=True)
class SkyTruth:
    """Per frame f (closing IMU interval k = (f + 1)·``ratio``): ``q_IB`` (F, 4), ``omega_B`` (F, 3)
    [rad/s], ``v_I`` (F, 3) [m/s], the local vertical ``up_I`` (F, 3) in ICRS axes and the refraction
    coefficients ``refraction`` (F, 2) [rad] of the real air (eq. 1 of :mod:`navsim.earth.refraction`;
    zero without air); ``at(k)`` is the :class:`~navsim.truth.profiles.FrameTruth` the closed loop hands
    the star sensor."""

    q_IB: np.ndarray
    omega_B: np.ndarray
    v_I: np.ndarray
    up_I: np.ndarray
    refraction: np.ndarray
    ratio: int

    @classmethod
    def of(cls, trajectory, orientation, frame_k, air=None):
        """The sky truth of a :class:`~navsim.truth.trajectory.Trajectory` at the frames' IMU samples
        ``frame_k`` (F,) for the :class:`~navsim.earth.orientation.EarthOrientation` at those frames, seen
        through the real ``air`` (a :class:`navsim.earth.refraction.Air`; None: none)."""
        lat, lon, h = trajectory.lat[frame_k], trajectory.lon[frame_k], trajectory.h[frame_k]
        q_IB = inertial_attitude(trajectory, orientation, frame_k)
        v_n = trajectory.v_n[frame_k]
        v_I = np.array([observer_velocity(orientation.c_ie[f], orientation.v_earth[f], lat[f], lon[f], h[f], v_n[f])
                        for f in range(frame_k.size)])
        refraction = np.zeros((frame_k.size, 2)) if air is None else np.stack(air.coefficients(h), axis=-1)
        ratio = int(frame_k[0])
        return cls(q_IB=q_IB, omega_B=trajectory.dtheta[frame_k - 1] / trajectory.dt, v_I=v_I,
                   up_I=local_up(orientation.c_ie, lat, lon), refraction=refraction, ratio=ratio)

    def air(self, frame):
        """(up_I (N, 3), A (N,), B (N,)) of the frames ``frame`` (N,): the ``air`` of
        :func:`navsim.earth.apparent.apparent`."""
        return self.up_I[frame], self.refraction[frame, 0], self.refraction[frame, 1]

    def at(self, k):
        f = k // self.ratio - 1
        return FrameTruth(q_IB=self.q_IB[f], omega_B=self.omega_B[f], v_I=self.v_I[f], air=self.air(f))
