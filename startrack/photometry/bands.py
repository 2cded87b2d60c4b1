"""Photometric bands: where a star sensor's light is collected, and the photon zero point a band implies.

A band is a rectangle of centre λ_c and width Δλ [m] (the equivalent width of the filter) in the Vega
system: a star of magnitude 0 in the band delivers, above the atmosphere,

    Φ_0 = f_λ,0 Δλ λ_c / (h c)            [photons s⁻¹ m⁻²]                         (1)

with f_λ,0 the flux density of a zero-magnitude star at λ_c (Bessell, Castelli & Plez 1998, Table A2, for
V, R_C, I_C; Cohen, Wheaton & Megeath 2003, Table 2, for the 2MASS J and H the catalogue's J and H are
in). A sensor of aperture area A, optics transmission τ and detector quantum efficiency QE(λ_c) then has
the zero point Z = Φ_0 A τ QE [e⁻ s⁻¹ for magnitude 0] (:func:`zero_point`), and a sky of surface
brightness μ [mag arcsec⁻²] puts Φ_0 10^(−0.4 μ) A τ QE Ω_px [e⁻ s⁻¹] into a pixel of Ω_px arcsec²
(:func:`sky_rate`).

Widths: V, R_C, I_C from Binney & Merrifield (1998) Table 2.1 (88, 138, 149 nm); J and H are 2MASS's
(162, 251 nm). The centres are the zero points' effective wavelengths.
"""

from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError

#: Planck constant [J s] and speed of light [m/s] (CODATA 2018, exact).
PLANCK = 6.62607015e-34
LIGHT_SPEED = 299792458.0
#: 1 erg s⁻¹ cm⁻² Å⁻¹ in W m⁻² m⁻¹.
_ERG_PER_S_CM2_A = 1e7


@dataclass(frozen=True)
class Band:
    """A photometric band: ``name``, centre and width [m], flux density of a zero-magnitude star [W m⁻³]."""

    name: str
    centre: float
    width: float
    flux_zero: float

    @property
    def photons_zero(self):
        """Φ_0 of eq. (1): photons s⁻¹ m⁻² of a magnitude-0 star through the band above the atmosphere."""
        return self.flux_zero * self.width * self.centre / (PLANCK * LIGHT_SPEED)

    @property
    def centre_um(self):
        return self.centre * 1e6


#: The bands of the product (Vega system).
BANDS = {
    "V": Band("V", 0.545e-6, 0.088e-6, 363.1e-11 * _ERG_PER_S_CM2_A),
    "R": Band("R", 0.641e-6, 0.138e-6, 217.7e-11 * _ERG_PER_S_CM2_A),
    "I": Band("I", 0.798e-6, 0.149e-6, 112.6e-11 * _ERG_PER_S_CM2_A),
    "J": Band("J", 1.235e-6, 0.162e-6, 3.129e-10 * _ERG_PER_S_CM2_A),
    "H": Band("H", 1.662e-6, 0.251e-6, 1.133e-10 * _ERG_PER_S_CM2_A),
}


def band(name):
    """The :class:`Band` called ``name``; InputError naming the known ones otherwise."""
    try:
        return BANDS[name]
    except (KeyError, TypeError):
        raise InputError(f"unknown band {name!r}; choose from {', '.join(BANDS)}") from None


def zero_point(band_, aperture_area, transmission, qe):
    """Z = Φ_0 A τ QE [e⁻ s⁻¹] of a magnitude-0 star for an aperture of ``aperture_area`` [m²] (eq. 1)."""
    return band_.photons_zero * aperture_area * transmission * qe


def sky_rate(band_, surface_brightness, aperture_area, transmission, qe, pixel_solid_angle_arcsec2):
    """Sky photoelectrons per second in one pixel [e⁻ s⁻¹] of a sky of ``surface_brightness`` [mag arcsec⁻²]."""
    mu = np.asarray(surface_brightness, dtype=float)
    return zero_point(band_, aperture_area, transmission, qe) * pixel_solid_angle_arcsec2 * 10.0 ** (-0.4 * mu)
