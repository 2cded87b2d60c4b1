"""The numerical orbit: two-body + J2 (+ an optional drag), integrated by scipy's DOP853 (the 8(5,3) Runge-Kutta
pair of Dormand & Prince; Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*, §II.10) with its
dense output, in GCRS axes.

The acceleration (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., eq. 8-30, with the pole k̂
of the Earth's figure at the epoch instead of the GCRS z axis — ~0.3 deg apart in 2025 by precession):

    a = −μ r/r³ − (3/2) J2 μ R²/r⁵ [(1 − 5 (r·k̂)²/r²) r + 2 (r·k̂) k̂] − ½ ρ(h) (C_D A/m) |v_r| v_r,

v_r = v − ω_⊕ k̂ × r the velocity relative to the co-rotating air, ρ(h) the exponential atmosphere of Vallado's
Table 8-4 (CIRA-72 to 1000 km) at the height above the ellipsoid h ≈ r − a (1 − f sin² φ') (φ' the geocentric
latitude; ~10 m off the ellipsoidal height, nothing for the density).
"""

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from navsim.earth.wgs84 import GM, OMEGA_IE
from navsim.earth.wgs84 import A as R_EARTH
from navsim.earth.wgs84 import F as FLATTENING
from navsim.orbit.elements import J2
from startrack import InputError

#: Vallado's Table 8-4: base height [km], density at it [kg/m³], scale height [km].
EXPONENTIAL_ATMOSPHERE = np.array([
    (0, 1.225, 7.249), (25, 3.899e-2, 6.349), (30, 1.774e-2, 6.682), (40, 3.972e-3, 7.554), (50, 1.057e-3, 8.382),
    (60, 3.206e-4, 7.714), (70, 8.770e-5, 6.549), (80, 1.905e-5, 5.799), (90, 3.396e-6, 5.382), (100, 5.297e-7, 5.877),
    (110, 9.661e-8, 7.263), (120, 2.438e-8, 9.473), (130, 8.484e-9, 12.636), (140, 3.845e-9, 16.149),
    (150, 2.070e-9, 22.523), (180, 5.464e-10, 29.740), (200, 2.789e-10, 37.105), (250, 7.248e-11, 45.546),
    (300, 2.418e-11, 53.628), (350, 9.518e-12, 53.298), (400, 3.725e-12, 58.515), (450, 1.585e-12, 60.828),
    (500, 6.967e-13, 63.822), (600, 1.454e-13, 71.835), (700, 3.614e-14, 88.667), (800, 1.170e-14, 124.64),
    (900, 5.245e-15, 181.05), (1000, 3.019e-15, 268.00)])
#: The integrator's tolerances: relative, and absolute [m, m/s] (a LEO orbit of 3 revolutions closes to ~1 mm).
RTOL, ATOL = 1e-12, 1e-6


def air_density(h):
    """ρ [kg/m³] of the exponential atmosphere (Table 8-4) at heights ``h`` [m] (the top layer's exponential above
    1000 km)."""
    km = np.asarray(h, dtype=float) / 1e3
    k = np.clip(np.searchsorted(EXPONENTIAL_ATMOSPHERE[:, 0], km, side="right") - 1, 0, len(EXPONENTIAL_ATMOSPHERE) - 1)
    base, rho0, scale = EXPONENTIAL_ATMOSPHERE[k].T
    return rho0 * np.exp(-(km - base) / scale)


def height(r, pole):
    """The height [m] above the ellipsoid of a geocentric position r (3,) [m] (module docstring's approximation)."""
    rn = np.linalg.norm(r)
    s = np.dot(r, pole) / rn
    return rn - R_EARTH * (1.0 - FLATTENING * s * s)


@dataclass(frozen=True)
class Forces:
    """What accelerates the spacecraft: GM ``mu`` [m³/s²], ``j2`` (0: two-body), the reference ``radius`` [m], the
    unit ``pole`` (3,) of the Earth's figure in GCRS axes, and ``ballistic`` C_D A/m [m²/kg] (0: no drag)."""

    pole: tuple = (0.0, 0.0, 1.0)
    mu: float = GM
    j2: float = J2
    radius: float = R_EARTH
    ballistic: float = 0.0

    def acceleration(self, r, v):
        """a (3,) [m/s²] at the state (r, v) (module docstring)."""
        k = np.asarray(self.pole)
        rn2 = r @ r
        rn = np.sqrt(rn2)
        z = r @ k
        a = -self.mu / (rn2 * rn) * r
        if self.j2:
            a -= 1.5 * self.j2 * self.mu * self.radius**2 / rn2**2 / rn * ((1.0 - 5.0 * z * z / rn2) * r + 2.0 * z * k)
        if self.ballistic:
            v_r = v - OMEGA_IE * np.cross(k, r)
            a -= 0.5 * air_density(height(r, k)) * self.ballistic * np.linalg.norm(v_r) * v_r
        return a


@dataclass(frozen=True, eq=False)
class NumericalOrbit:
    """The orbit from the state (r0, v0) [m, m/s] at t = 0 under ``forces`` (:class:`Forces`) over [0, ``duration``]
    [s]: integrated once when built, then :meth:`states` at any times of the span from the dense output."""

    r0: tuple
    v0: tuple
    duration: float
    forces: Forces = Forces()

    def __post_init__(self):
        def rhs(_, y):
            return np.concatenate([y[3:], self.forces.acceleration(y[:3], y[3:])])

        def hit_ground(_, y):
            return height(y[:3], np.asarray(self.forces.pole))

        hit_ground.terminal = True
        y0 = np.concatenate([self.r0, self.v0]).astype(float)
        if hit_ground(0.0, y0) <= 0.0:
            raise InputError(f"orbit: the initial position is {-hit_ground(0.0, y0) / 1e3:.1f} km below the Earth's surface")
        solution = solve_ivp(rhs, (0.0, self.duration), y0, method="DOP853", rtol=RTOL, atol=ATOL, dense_output=True,
                             events=hit_ground)
        if solution.status == 1:
            raise InputError(f"orbit: the spacecraft reaches the Earth's surface {solution.t_events[0][0]:.0f} s after the "
                             f"start, before the run's end at {self.duration:g} s")
        if solution.status != 0:
            raise InputError(f"orbit: the numerical propagation failed ({solution.message})")
        object.__setattr__(self, "_solution", solution.sol)

    def states(self, t):
        """(r (N, 3), v (N, 3)) [m, m/s] at times ``t`` (N,) [s] inside [0, duration]."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if t.size and (t.min() < -1e-9 or t.max() > self.duration + 1e-9):
            raise ValueError(f"times outside the propagated span [0, {self.duration:g}] s")
        y = self._solution(t).T
        return y[:, :3], y[:, 3:]
