"""What the sky lets a physical star sensor see at each frame: the sky's brightness at the boresight in the
sensor's band, the air between the sensor and each star, and the trail a star leaves in the exposure.

Built once per scenario before the runs (seed-free: the nominal truth's geometry,
:func:`navsim.navigation.sky_background.frame_sky`); a star sensor with a light budget
(:class:`startrack.image.sensor_photometry.SensorPhotometry`) takes it to decide which stars of a frame it detects
and how well it places them, at vector fidelity (:mod:`navsim.sensors.star_vector`) and at image fidelity
(:mod:`navsim.sensors.star_image`: the frame's sky level and the stars' extinguished magnitudes drawn). The
sky is one level across the field (its gradient over a star sensor's field is a few tenths of a magnitude
by day and is left out); each star's extinction is its own, along its own line of sight; a line of sight
that meets the ground shows no star.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FrameSky:
    """Per frame F: the sky's surface brightness at the boresight ``background_mag`` [mag arcsec⁻²] and its
    photoelectrons ``sky_e_per_px_s`` [e⁻ s⁻¹ px⁻¹], the trail of a star near the boresight ``smear_px`` [px],
    the extinction along the boresight ``boresight_extinction`` [mag], the observer's local vertical ``up_I``
    (F, 3) in ICRS axes and the air's extinction ``air`` (a :class:`navsim.earth.atmosphere.Extinction` of (F,)
    arrays)."""

    photometry: object
    background_mag: np.ndarray
    sky_e_per_px_s: np.ndarray
    smear_px: np.ndarray
    boresight_extinction: np.ndarray
    up_I: np.ndarray
    air: object

    def extinguished(self, frames, mag, directions_I):
        """The magnitudes [mag] of stars of band magnitude ``mag`` (M,) seen along ``directions_I`` (M, 3) at the
        frames ``frames`` (M,): plus their extinction (inf where the line of sight meets the ground)."""
        mag = np.asarray(mag, dtype=float)
        cos_z = np.clip(np.einsum("mi,mi->m", directions_I, self.up_I[frames]), -1.0, 1.0)
        return mag + self.air.at(frames).along(np.arccos(cos_z))

    def measure(self, frames, seen):
        """(detected (M,), σ (M,) [rad], saturated (M,)) of stars of magnitudes ``seen`` through the air
        (:meth:`extinguished`) at the frames ``frames`` (:meth:`startrack.image.sensor_photometry.SensorPhotometry.measure`)."""
        with np.errstate(over="ignore"):
            detected, sigma, saturated = self.photometry.measure(seen, self.sky_e_per_px_s[frames], self.smear_px[frames])
        return detected & np.isfinite(seen), sigma, saturated

    def magnitude_sigma(self, frames, seen):
        """σ_m (M,) [mag] of the measured magnitudes of stars of magnitudes ``seen`` through the air at the frames
        ``frames`` (:meth:`startrack.image.sensor_photometry.SensorPhotometry.magnitude_sigma`)."""
        with np.errstate(over="ignore"):
            return self.photometry.magnitude_sigma(seen, self.sky_e_per_px_s[frames])

    def limiting_magnitude(self):
        """(F,) [mag]: the faintest catalog magnitude detected at the boresight, its extinction included (−inf:
        the sky fills the well)."""
        return self.photometry.limiting_magnitude(self.sky_e_per_px_s, self.smear_px) - self.boresight_extinction

    def series(self):
        """The run series of the frames' sky: its brightness at the boresight [mag arcsec⁻²] and the limiting
        magnitude there [mag]."""
        return {"sky_background_mag": np.asarray(self.background_mag, dtype=float),
                "limiting_mag": np.asarray(self.limiting_magnitude(), dtype=float)}
