"""The Earth's stray light in a spacecraft's star sensor (issue 51): the sunlit Earth's light that the baffle lets
reach the detector when the bright limb is near the field, a background level in every pixel of each frame.

A baffle is specified by its point-source transmittance PST(θ), the focal-plane irradiance over the irradiance at the
entrance from a source θ off the axis (Breault 1995); a power law through the value at one angle,
PST(θ) = PST(θ_ref) (θ/θ_ref)^(−k), is the usual reading of a vendor's curve between the exclusion angle and ~90 deg.
With the Earth's irradiance E_⊕ at the spacecraft (:meth:`navsim.orbit.earth_disc.EarthDisc.albedo_irradiance`,
photons from the Sun's magnitude in the band: m_V = −26.76 of Willmer 2018 with the solar colours V − R_C = 0.36,
V − I_C = 0.70 of Ramírez et al. 2012 and V − J = 1.20, V − H = 1.48 of Casagrande et al. 2012) and θ the limb's angle from the boresight,

    e⁻ px⁻¹ s⁻¹ = PST(θ) E_⊕ p² QE     (p the pixel pitch),

the frame's sky level at image fidelity (:class:`navsim.sensors.star_image.ImageStarSensor`'s ``sky``). In space
nothing extinguishes the stars.
"""

from dataclasses import dataclass

import numpy as np

#: The Sun's apparent magnitude in each band (Vega system; module docstring).
SUN_MAGNITUDE = {"V": -26.76, "R": -27.12, "I": -27.46, "J": -27.96, "H": -28.24}
#: The least limb angle [rad] the power law is taken to: nearer, the frame is excluded anyway.
MIN_ANGLE = np.radians(1.0)


@dataclass(frozen=True)
class Baffle:
    """A baffle's PST(θ) (module docstring): ``pst_ref`` at ``angle_ref`` [rad], falling as θ^(−``slope``)."""

    pst_ref: float = 1e-7
    angle_ref: float = np.radians(20.0)
    slope: float = 3.0

    def pst(self, angle):
        return self.pst_ref * (np.maximum(angle, MIN_ANGLE) / self.angle_ref) ** (-self.slope)


@dataclass(frozen=True)
class StrayLight:
    """A head's stray-light level ``sky_e_per_px_s`` (F,) [e⁻ px⁻¹ s⁻¹] at each frame, read as its frames' sky."""

    sky_e_per_px_s: np.ndarray

    @classmethod
    def of_earth(cls, limb_angle, earth_ratio, band, baffle, pixel_um, qe):
        """The level of the Earth at ``earth_ratio`` (F,) of the Sun's irradiance whose limb is ``limb_angle`` (F,)
        [rad] from the boresight, in the :class:`startrack.photometry.bands.Band` ``band`` (module docstring)."""
        sun = band.photons_zero * 10.0 ** (-0.4 * SUN_MAGNITUDE[band.name])
        return cls(sky_e_per_px_s=baffle.pst(limb_angle) * earth_ratio * sun * (1e-6 * pixel_um) ** 2 * qe)

    def extinguished(self, frame, mags, directions):
        """The stars' magnitudes as seen: in space, the catalog's."""
        return mags
