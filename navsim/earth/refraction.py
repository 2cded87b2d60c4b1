"""Atmospheric refraction for an observer inside the air: a star seen higher than it is.

Below ~30 km the air bends every star towards the zenith by (Green 1987, eq. 4.31; ERFA ``eraRefco``)

    ΔZ = A tan Z + B tan³ Z,                                                                         (1)

Z the observed zenith distance, A ≈ 58" and B ≈ −0.07" at sea level, a fifth of that at 12 km. A and B come
from ``erfa.refco`` for the pressure, temperature and humidity at the observer and the band's wavelength (the
refractivity of Gill 1982 / Crane 1976 / Hohenkerk & Sinclair 1985 in its Note 5; within 62 mas worst and
8 mas RMS of ray tracing through model atmospheres for Z <= 75°, its Note 2). The air at the observer is
the U.S. Standard Atmosphere 1976 at its height (:func:`navsim.earth.atmosphere.temperature_pressure`),
dry: at the heights of aircraft the water vapour is negligible, and on the ground a relative humidity of
50 % changes (1) by 0.2 % at 0.55 µm, far below a forecast's pressure error.

A direction u is refracted about the observer's local vertical as ``eraAtioq`` does: with the vacuum
zenith distance Z_v, (1) inverted by one Newton step, ΔZ = (A + B tan² Z_v) tan Z_v / (1 + (A + 3B tan² Z_v)
/ cos² Z_v) (2), and u turned by ΔZ towards the zenith; below 2.9° of elevation the tangent is held at its
value there (``eraAtioq``'s SELMIN = 0.05), where (1) has lost its accuracy anyway (3' of error near the
horizon). A star sensor's ``min_elevation_deg`` keeps it above that.

A vehicle's truth sees the stars refracted by the real air, its processing corrects them with the model air
at the height its INS gives: the difference -- a pressure error ε_p and a temperature error δT of the real
air against the model -- is left in every star (:class:`Air`). To first order it is the correction scaled by the
real air's fractional excess ε = A_real/A_model − 1 (:meth:`Air.fraction`):

    u_real − u_model = ε (u_model − u),                                                              (3)

u the aberrated direction and u_model its refraction by the model air: one number for all the stars of a frame,
which the navigation filter carries as a consider state of σ :meth:`Air.fraction_sigma`. Exact for a pressure error
(A and B are both ∝ p); a temperature error changes B unlike A, which leaves 1.3 % of its residual at 15° of
elevation, 0.3 % at 30° (3 K at 11 km: 0.011" of 0.88" at 15°).
"""

from dataclasses import dataclass

import erfa
import numpy as np

from navsim.earth.atmosphere import temperature_pressure

#: ``eraAtioq``'s floors of the cosine and sine of the elevation in (2).
CELMIN = 1e-6
SELMIN = 0.05


@dataclass(frozen=True)
class Air:
    """The air at an observer as the refraction sees it: the band's ``wavelength_um`` [µm] and the real air's
    departure from the standard atmosphere, ``pressure_error`` (a fraction: p = p_76 (1 + ε_p)) and
    ``temperature_error`` [K] (T = T_76 + δT)."""

    wavelength_um: float
    pressure_error: float = 0.0
    temperature_error: float = 0.0

    def coefficients(self, h):
        """(A, B) [rad] of eq. (1) at heights h (...,) [m]."""
        T, p = temperature_pressure(h)
        p_hpa = np.maximum(p * (1.0 + self.pressure_error), 0.0) / 100.0
        return erfa.refco(p_hpa, T + self.temperature_error - 273.15, 0.0, self.wavelength_um)

    def modelled(self):
        """This air as the processing models it: the standard atmosphere, no error."""
        return Air(self.wavelength_um)

    def fraction(self, h):
        """ε (...,) at heights h [m]: this air's refraction as a fraction of the model air's, A/A_76 − 1 of eq. (1). A
        processing that corrects with the model air leaves ε times its correction in every star (eq. 3)."""
        return self.coefficients(h)[0] / self.modelled().coefficients(h)[0] - 1.0

    def fraction_sigma(self, h, pressure_sigma, temperature_sigma):
        """σ_ε (...,) at heights h [m] of an air whose pressure (a fraction) and temperature [K] are uncertain by
        those σ about this one: the sensitivities of ε by central differences of :meth:`fraction`, in
        root-sum-square (the two independent)."""
        dp, dT = 1e-3, 0.1
        slope_p = (self._shifted(dp, 0.0).fraction(h) - self._shifted(-dp, 0.0).fraction(h)) / (2.0 * dp)
        slope_T = (self._shifted(0.0, dT).fraction(h) - self._shifted(0.0, -dT).fraction(h)) / (2.0 * dT)
        return np.hypot(slope_p * pressure_sigma, slope_T * temperature_sigma)

    def _shifted(self, pressure, temperature):
        return Air(self.wavelength_um, self.pressure_error + pressure, self.temperature_error + temperature)


def refract(u, up, a, b):
    """Observed directions (N, 3) of the vacuum unit directions ``u`` (N, 3) for the local vertical ``up``
    (N, 3) and the coefficients ``a``, ``b`` (N,) [rad] of eq. (1), or one of each for all: each turned towards the
    zenith by eq. (2)."""
    u, up = np.atleast_2d(u), np.atleast_2d(up)
    s = np.sum(u * up, axis=-1)
    horizontal = u - s[:, None] * up
    r = np.maximum(np.linalg.norm(horizontal, axis=-1), CELMIN)
    z = np.maximum(s, SELMIN)
    tz = r / z
    w = b * tz * tz
    delta = (a + w) * tz / (1.0 + (a + 3.0 * w) / (z * z))
    cos_delta = 1.0 - 0.5 * delta * delta
    f = cos_delta - delta * z / r
    return horizontal * f[:, None] + (cos_delta * s + delta * r)[:, None] * up


def refraction_angle(u, up, a, b):
    """ΔZ [rad] (N,): how far :func:`refract` raises each direction."""
    seen = refract(u, up, a, b)
    return np.arcsin(np.clip(np.sum(seen * up, axis=-1), -1.0, 1.0)) - np.arcsin(np.clip(np.sum(np.atleast_2d(u) * up, axis=-1), -1.0, 1.0))
