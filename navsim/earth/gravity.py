"""Gravity (gravitation plus centrifugal) in the NED frame: WGS-84 normal gravity and an optional
disturbance (deflection of the vertical and anomaly).

Normal gravity on the ellipsoid is Somigliana's closed formula and above it the second-order
height expansion of NIMA TR8350.2 eq. 4-3 (also Groves, 2nd ed., eqs. 2.134 and 2.139):

    γ(L) = γ_e (1 + k sin²L) / √(1 − e² sin²L),
    γ(L, h) = γ(L) [1 − 2/a (1 + f + m − 2 f sin²L) h + 3 h²/a²],

pointing down along the ellipsoid normal: g_n = [0, 0, γ(L, h)] (the small north component of the
normal gravity above the ellipsoid, |g_N| < 1e-5 m/s² below 10 km, is neglected everywhere).

The disturbance δg_n is added to the *truth* only (the INS knows normal gravity): deflections of
the vertical ξ (north-south) and η (east-west) [rad] and anomaly Δg [m/s²] give

    δg_n = [−ξ γ, −η γ, Δg]

(ξ > 0 when the astronomic zenith lies north of the ellipsoidal one, so the plumb line points
south of the normal; Jekeli, *Inertial Navigation Systems with Geodetic Applications*, ch. 6).
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.wgs84 import E2, GAMMA_E, K_SOMIGLIANA, A, F, M
from startrack import InputError, njit


@njit
def normal_gravity(lat, h):
    """Normal gravity γ(L, h) [m/s²] at geodetic latitude ``lat`` [rad] and height ``h`` [m]
    (TR8350.2 eqs. 4-1 and 4-3)."""
    return normal_gravity_of_sine(np.sin(lat), h)


@njit
def normal_gravity_of_sine(s, h):
    """:func:`normal_gravity` at sin L = ``s`` (the wander-azimuth frame's −C_ew[2, 2])."""
    s2 = s * s
    gamma0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return gamma0 * (1.0 - 2.0 / A * (1.0 + F + M - 2.0 * F * s2) * h + 3.0 * h * h / (A * A))


@njit
def normal_gravity_height_gradient(lat, h):
    """∂γ/∂h [1/s²] of :func:`normal_gravity` (≈ −2γ/a: the vertical-channel instability)."""
    s2 = np.sin(lat) ** 2
    gamma0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return gamma0 * (-2.0 / A * (1.0 + F + M - 2.0 * F * s2) + 6.0 * h / (A * A))


@njit
def normal_gravity_latitude_gradient(lat, h):
    """∂γ/∂L [m/s²/rad] of :func:`normal_gravity` (about 0.05 sin 2L): cos L ∂γ/∂(sin L)."""
    return np.cos(lat) * normal_gravity_sine_gradient(np.sin(lat), h)


@njit
def normal_gravity_sine_gradient(s, h):
    """∂γ/∂(sin L) [m/s²] of :func:`normal_gravity` at sin L = ``s`` (finite at the poles, where the wander-azimuth
    error state takes its latitude derivative through sin L = −C_ew[2, 2])."""
    s2 = s * s
    w = 1.0 - E2 * s2
    gamma0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(w)
    d_gamma0 = GAMMA_E * 2.0 * s * (K_SOMIGLIANA / np.sqrt(w) + (1.0 + K_SOMIGLIANA * s2) * E2 / (2.0 * w**1.5))
    height = 1.0 - 2.0 / A * (1.0 + F + M - 2.0 * F * s2) * h + 3.0 * h * h / (A * A)
    return d_gamma0 * height + gamma0 * (8.0 * F * s * h / A)


@dataclass(frozen=True)
class GravityDisturbance:
    """Deflection of the vertical ξ, η [rad] and anomaly Δg [m/s²] along a track.

    ``constant``: the same (ξ, η, Δg) everywhere. ``random``: each component a first-order
    Gauss-Markov process in travelled distance s with correlation length ``correlation_length``
    [m] and steady σ ``sigma`` = (σ_ξ, σ_η, σ_Δg), the along-track form of the Kaula/Jordan
    covariance models used in inertial geodesy (Jekeli ch. 6): x(s + Δs) = ρ x(s) + σ √(1 − ρ²) w,
    ρ = exp(−Δs/D), drawn from the seeded generator. Build with :meth:`constant` or :meth:`random`.
    """

    value: tuple = (0.0, 0.0, 0.0)
    sigma: tuple = (0.0, 0.0, 0.0)
    correlation_length: float = 0.0

    @classmethod
    def constant(cls, xi, eta, anomaly):
        return cls(value=(float(xi), float(eta), float(anomaly)))

    @classmethod
    def random(cls, sigma_xi, sigma_eta, sigma_anomaly, correlation_length):
        if not correlation_length > 0.0:
            raise InputError(f"gravity.correlation_length_m: must be > 0, got {correlation_length!r}")
        sigma = (float(sigma_xi), float(sigma_eta), float(sigma_anomaly))
        if min(sigma) < 0.0:
            raise InputError(f"gravity sigma: must be >= 0, got {sigma!r}")
        return cls(sigma=sigma, correlation_length=float(correlation_length))

    def components(self, distance, rng):
        """(ξ, η, Δg) (N, 3) at the travelled distances ``distance`` (N,) [m], non-decreasing.

        The random field is drawn exactly on a grid of step D/20 from 0 to the last distance and
        interpolated linearly in between (its correlation length D spans 20 grid steps)."""
        distance = np.asarray(distance, dtype=float)
        out = np.broadcast_to(np.asarray(self.value, dtype=float), (distance.size, 3)).copy()
        if self.correlation_length > 0.0:
            step = self.correlation_length / 20.0
            grid = np.arange(int(np.ceil(distance[-1] / step)) + 2) * step
            rho = np.exp(-step / self.correlation_length)
            w = rng.standard_normal((grid.size, 3))
            w[1:] *= np.sqrt(1.0 - rho * rho)
            from scipy.signal import lfilter  # here: importing scipy.signal costs 1.3 s, and only this needs it

            field = lfilter([1.0], [1.0, -rho], w, axis=0)
            for axis in range(3):
                out[:, axis] += self.sigma[axis] * np.interp(distance, grid, field[:, axis])
        return out


def disturbance_n(components, gamma):
    """δg_n (N, 3) [m/s²] from (ξ, η, Δg) (N, 3) and the normal gravity γ (N,): [−ξγ, −ηγ, Δg]."""
    components = np.asarray(components, dtype=float)
    return np.stack([-components[:, 0] * gamma, -components[:, 1] * gamma, components[:, 2]], axis=-1)
