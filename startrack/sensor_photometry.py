"""A star sensor's light budget: which stars it detects against a sky, and how well it places them.

The sensor collects its band (:mod:`startrack.bands`) through an aperture of area A and optics of
transmission τ onto a detector (:mod:`startrack.detectors`) of quantum efficiency QE at the band's centre,
read noise σ_r, dark current D and full well W, in exposures of t_exp, with pixels of Ω_px on the sky. A star
of magnitude m (already extinguished by the air) gives N = Z 10^(−0.4 m) t_exp photoelectrons (Z of
:func:`startrack.bands.zero_point`); a sky of rate S [e⁻ s⁻¹ px⁻¹] (:func:`startrack.bands.sky_rate`) leaves
a pixel without a star the variance v = (S + D) t_exp + σ_r² [e⁻²]. Then, as the image chain does it:

- **detection** (eq. 1 and 4 of 004): the star's brightest pixel N f_peak (:func:`startrack.photometry.peak_fraction`,
  for its trail of L px) reaches a √v above the background: N f_peak ≥ a √v; none while the sky and dark
  charge alone fill the well;
- **saturation**: a star whose centred peak N f_0 + (S + D) t_exp exceeds W is placed as well as a star
  just at the well (the fit leaves its saturated pixels out): its N taken as (W − (S + D) t_exp)/f_0;
- **position**: the Cramér-Rao bound on its centroid (:func:`startrack.psf_fit.centroid_variance`), σ [rad]
  = √(σ²_px) Ω_px^(1/2) — one σ per tangent axis.
"""

from dataclasses import dataclass

import numpy as np

from startrack.bands import Band, sky_rate, zero_point
from startrack.detectors import Detector
from startrack.errors import InputError
from startrack.photometry import peak_fraction, pixel_fraction, trail_peak_fraction
from startrack.psf_fit import centroid_variance
from startrack.units import ARCSEC


@dataclass(frozen=True)
class SensorPhotometry:
    """The light budget of a star sensor: ``band``, ``detector``, aperture area [m²], optics transmission,
    exposure [s], PSF radius [px], pixel scale [rad px⁻¹] and the detection threshold a (in σ of a pixel)."""

    band: Band
    detector: Detector
    aperture_area: float
    transmission: float
    exposure_s: float
    psf_sigma_px: float
    pixel_scale: float
    detection_sigmas: float

    def __post_init__(self):
        if self.qe <= 0.0:
            raise InputError(f"the {self.detector.name} detector has no quantum efficiency in the {self.band.name} band "
                             f"({self.band.centre_um:.3f} µm)")

    @property
    def qe(self):
        return self.detector.qe(self.band.centre)

    @property
    def zero_point_e_per_s(self):
        """Z [e⁻ s⁻¹] of a magnitude-0 star."""
        return zero_point(self.band, self.aperture_area, self.transmission, self.qe)

    @property
    def pixel_solid_angle_arcsec2(self):
        return (self.pixel_scale / ARCSEC) ** 2

    def star_electrons(self, mag):
        """N [e⁻] per exposure of stars of (extinguished) magnitude ``mag`` in the band."""
        return self.zero_point_e_per_s * self.exposure_s * 10.0 ** (-0.4 * np.asarray(mag, dtype=float))

    def sky_e_per_px_s(self, surface_brightness):
        """S [e⁻ s⁻¹ px⁻¹] of a sky of ``surface_brightness`` [mag arcsec⁻²] in the band."""
        return sky_rate(self.band, surface_brightness, self.aperture_area, self.transmission, self.qe,
                        self.pixel_solid_angle_arcsec2)

    def background_e(self, sky_e_per_px_s):
        """(S + D) t_exp [e⁻]: the charge of a pixel without a star."""
        return (np.asarray(sky_e_per_px_s, dtype=float) + self.detector.dark_e_per_px_s) * self.exposure_s

    def pixel_variance(self, sky_e_per_px_s):
        """v = (S + D) t_exp + σ_r² [e⁻²]."""
        return self.background_e(sky_e_per_px_s) + self.detector.read_noise_e**2

    def measure(self, mag, sky_e_per_px_s, smear_px=0.0):
        """(detected (N,) bool, σ (N,) [rad] per tangent axis, saturated (N,) bool) of stars of magnitude ``mag``
        on a sky of ``sky_e_per_px_s`` with trails of ``smear_px`` [px] (module docstring)."""
        n = self.star_electrons(mag)
        background = self.background_e(sky_e_per_px_s)
        v = self.pixel_variance(sky_e_per_px_s)
        well = self.detector.full_well_e
        detected = (n * peak_fraction(self.psf_sigma_px, smear_px) >= self.detection_sigmas * np.sqrt(v)) & (background < well)
        top = _centred_peak(self.psf_sigma_px, smear_px)
        saturated = n * top + background > well
        placed = np.where(saturated, np.maximum(well - background, 1.0) / top, n)
        sigma = np.sqrt(centroid_variance(placed, v, self.psf_sigma_px, smear_px)) * self.pixel_scale
        return detected, sigma, detected & saturated

    def limiting_magnitude(self, sky_e_per_px_s, smear_px=0.0):
        """The faintest (extinguished) magnitude detected on a sky of ``sky_e_per_px_s`` [mag] (inf: none)."""
        v = self.pixel_variance(sky_e_per_px_s)
        n = self.detection_sigmas * np.sqrt(v) / peak_fraction(self.psf_sigma_px, smear_px)
        mag = -2.5 * np.log10(n / (self.zero_point_e_per_s * self.exposure_s))
        return np.where(self.background_e(sky_e_per_px_s) < self.detector.full_well_e, mag, -np.inf)


def _centred_peak(sigma_px, smear_px):
    """The fraction of a star's light in its brightest pixel when it is centred on it (the highest the peak gets):
    the centred fraction, lowered by the trail as the phase-averaged peak is."""
    return pixel_fraction(0.0, 0.0, sigma_px) * trail_peak_fraction(sigma_px, smear_px) / trail_peak_fraction(sigma_px, 0.0)
