"""The Earth's orientation and the observer's velocity at the frames of a run.

C_ie (ICRS axes from ITRS axes) is :func:`navsim.earth.frames.c_ei` (pyerfa's ``c2t06a``) and the
barycentric velocity of the geocentre comes from the ephemeris of :mod:`startrack.catalog.apparent_place`
(``erfa.epv00``, on the grid of :func:`navsim.earth.frames.slowly`); both depend on time only, so a scenario computes them once for its frame times
(:class:`EarthOrientation`), for the truth and the filter alike. The observer's velocity relative
to the solar-system barycentre, which sets the aberration of the stars it sees, is (ICRS axes)

    v_I = v_⊕ + C_ie (ω_ie × r_e + C_en v_n)

(the Earth's orbital velocity, the Earth's rotation at the observer and the vehicle's ground
velocity; Groves, 2nd ed., eq. 2.145 for the rotating-frame term).
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.frames import c_ei, q_en, slowly, tt_epoch
from navsim.earth.wgs84 import OMEGA_IE, geodetic_to_ecef
from startrack import earth_barycentric_velocity, njit
from startrack import rotation as rot
from startrack import rotation_kernels as rk

#: Tolerance [s] of :meth:`EarthOrientation.index` (frame times are multiples of the IMU interval).
TIME_TOLERANCE = 1e-6


@dataclass(frozen=True)
class EarthOrientation:
    """At the frame times ``t`` (F,) [s after the epoch]: ``q_ie`` (F, 4) and ``c_ie`` (F, 3, 3) (ICRS
    from ITRS) and the geocentre's barycentric velocity ``v_earth`` (F, 3) [m/s] in ICRS axes."""

    t: np.ndarray
    q_ie: np.ndarray
    c_ie: np.ndarray
    v_earth: np.ndarray

    @classmethod
    def compute(cls, epoch_utc, t, dut1=0.0):
        """The orientation at times ``t`` (F,) [s] after the UTC epoch ``epoch_utc``, UT1 − UTC =
        ``dut1`` [s] (TDB taken as TT for the ephemeris: they differ by < 2 ms)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        c_ie = np.swapaxes(c_ei(epoch_utc, t, dut1), -1, -2)
        v_earth = slowly(lambda s: earth_barycentric_velocity(*tt_epoch(epoch_utc, s)), t)
        return cls(t=t, q_ie=rot.from_matrix(c_ie), c_ie=c_ie, v_earth=v_earth)

    def index(self, t):
        """The frame index of time ``t`` [s]; a time that is not a frame time raises ValueError."""
        j = int(np.searchsorted(self.t, t - TIME_TOLERANCE))
        if j >= self.t.size or abs(self.t[j] - t) > TIME_TOLERANCE:
            raise ValueError(f"t = {t} s is not a frame time of this Earth orientation")
        return j


@njit
def observer_velocity(c_ie, v_earth, lat, lon, h, v_n):
    """v_I (3,) [m/s]: the observer's velocity relative to the barycentre in ICRS axes at (L, λ, h)
    [rad, rad, m] with NED ground velocity v_n (3,), for C_ie (3, 3) and the geocentre's v_earth (3,)
    (module docstring)."""
    x, y, _ = geodetic_to_ecef(lat, lon, h)
    v_e = rk.quat_to_matrix(np.array(q_en(lat, lon))) @ v_n + np.array([-OMEGA_IE * y, OMEGA_IE * x, 0.0])
    return v_earth + c_ie @ v_e
