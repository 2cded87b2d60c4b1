"""WGS-84 ellipsoid: defining and derived constants, radii of curvature, geodetic <-> ECEF.

The four defining parameters (a, 1/f, GM, ω_ie) are those of NIMA TR8350.2 (3rd ed., 2000),
Table 3.1; every other constant is derived from them here, including the normal gravity at the
equator and the pole (the closed formulas of the level ellipsoid, Moritz 1980, *Geodetic Reference
System 1980*; Hofmann-Wellenhof & Moritz, *Physical Geodesy*, 2nd ed., §2.7-2.8), so the published
values of TR8350.2 (Table 3.4: γ_e = 9.7803253359, γ_p = 9.8321849378 m/s²) test this module rather
than feed it.

The functions are compiled (numba) and take scalars or arrays alike; functions of vectors return
their components as a tuple (north, east, down) or (x, y, z), so the same code serves the compiled
strapdown kernels and vectorised Python callers (``np.stack(..., axis=-1)`` makes an array).
"""

import math

import numpy as np

from startrack import njit

#: Semi-major axis a [m].
A = 6378137.0
#: Flattening f = 1/298.257223563.
F = 1.0 / 298.257223563
#: Earth's gravitational constant GM (atmosphere included) [m³/s²].
GM = 3.986004418e14
#: Earth rotation rate ω_ie [rad/s] (the nominal mean rate, TR8350.2 Table 3.1).
OMEGA_IE = 7.292115e-5

#: Semi-minor axis b = a (1 − f) [m].
B = A * (1.0 - F)
#: First eccentricity squared e² = f (2 − f).
E2 = F * (2.0 - F)
#: m = ω² a² b / GM (TR8350.2 §4).
M = OMEGA_IE**2 * A**2 * B / GM


def _normal_gravity_at_equator_and_pole():
    """(γ_e, γ_p) [m/s²] of the level ellipsoid from (a, b, GM, ω) (Moritz 1980):
    γ_e = GM/(ab) (1 − m − m e' q0'/(6 q0)), γ_p = GM/a² (1 + m e' q0'/(3 q0)),
    with e' the second eccentricity, q0 = ½[(1 + 3/e'²) atan e' − 3/e'] and
    q0' = 3 (1 + 1/e'²)(1 − atan(e')/e') − 1."""
    ep = math.sqrt(A * A - B * B) / B
    q0 = 0.5 * ((1.0 + 3.0 / ep**2) * math.atan(ep) - 3.0 / ep)
    q0p = 3.0 * (1.0 + 1.0 / ep**2) * (1.0 - math.atan(ep) / ep) - 1.0
    ratio = M * ep * q0p / q0
    return GM / (A * B) * (1.0 - M - ratio / 6.0), GM / A**2 * (1.0 + ratio / 3.0)


#: Normal gravity on the ellipsoid at the equator and at the poles [m/s²].
GAMMA_E, GAMMA_P = _normal_gravity_at_equator_and_pole()
#: Somigliana's constant k = b γ_p / (a γ_e) − 1.
K_SOMIGLIANA = B * GAMMA_P / (A * GAMMA_E) - 1.0


@njit
def radii(lat):
    """Radii of curvature (R_M meridian, R_N prime vertical) [m] at geodetic latitude ``lat`` [rad]:
    R_N = a / √(1 − e² sin²L), R_M = a (1 − e²) / (1 − e² sin²L)^(3/2)
    (Groves, 2nd ed., eqs. 2.105-2.106, where they are called R_N and R_E)."""
    s = np.sin(lat)
    w = 1.0 - E2 * s * s
    r_n = A / np.sqrt(w)
    return r_n * (1.0 - E2) / w, r_n


@njit
def geodetic_to_ecef(lat, lon, h):
    """ECEF coordinates (x, y, z) [m] of geodetic (L, λ, h) [rad, rad, m] (Groves eq. 2.112)."""
    _, r_n = radii(lat)
    c = np.cos(lat)
    return (r_n + h) * c * np.cos(lon), (r_n + h) * c * np.sin(lon), (r_n * (1.0 - E2) + h) * np.sin(lat)


@njit
def ecef_to_geodetic(x, y, z):
    """Geodetic (L, λ, h) [rad, rad, m] of ECEF (x, y, z) [m]: Bowring's iteration on the parametric
    latitude, five passes (sub-micrometre, sub-nanoradian everywhere above the Earth's centre
    region; Bowring 1976, Survey Review 23(181))."""
    p = np.sqrt(x * x + y * y)
    ep2 = E2 / (1.0 - E2)
    beta = np.arctan2(z, (1.0 - F) * p)
    for _ in range(5):
        lat = np.arctan2(z + ep2 * B * np.sin(beta) ** 3, p - E2 * A * np.cos(beta) ** 3)
        beta = np.arctan2((1.0 - F) * np.sin(lat), np.cos(lat))
    _, r_n = radii(lat)
    s, c = np.sin(lat), np.cos(lat)
    # h along the normal, well conditioned at every latitude (Groves eq. C.29 form).
    h = p * c + z * s - A * A / r_n
    return lat, np.arctan2(y, x), h
