"""The trapped-particle flux a spacecraft's detectors meet along its orbit: a parametric map of the two regions that
matter in low Earth orbit, the South Atlantic Anomaly (the inner proton belt's nearest approach, over the South
Atlantic where the geomagnetic field is weakest) and the polar horns (the outer belt's electrons reaching down along
the field lines at high geomagnetic latitude), over a galactic cosmic-ray background.

The shape follows the AP-8/AE-8 maps at 500-800 km as star-tracker engineers quote them (e.g. the SAA's >10 MeV
protons peaking at ~1e3 cm⁻² s⁻¹ near (26 S, 50 W) at 550 km over an ellipse some 50 x 30 deg; the horns at
55-75 deg of geomagnetic latitude, ~1e2; the cosmic-ray background ~2-4 cm⁻² s⁻¹): it is a configurable stand-in for
those models, not a copy of them (the scenario's ``[radiation]`` table sets every number):

    Φ = Φ_bg + Φ_SAA exp(−½ (Δφ/w_φ)² − ½ (Δλ/w_λ)²) (h/h_ref)^n + Φ_horn exp(−½ ((|φ_m| − φ_h)/w_h)²),

Δφ, Δλ the geodetic latitude and longitude from the anomaly's centre, h the height, φ_m the geomagnetic (dipole)
latitude of the IGRF-13 dipole at 2020, its north pole at (80.65 N, 72.68 W) (Alken et al. 2021).
"""

from dataclasses import dataclass

import numpy as np

#: The geomagnetic dipole's north pole (geodetic, deg) of IGRF-13 at 2020.0.
DIPOLE_POLE_DEG = (80.65, -72.68)


@dataclass(frozen=True)
class ParticleFlux:
    """The map of the module docstring: fluxes [cm⁻² s⁻¹], the anomaly's centre and widths [deg], its reference height
    [m] and height exponent, the horns' geomagnetic latitude and width [deg]."""

    background: float = 3.0
    saa_peak: float = 1000.0
    saa_lat_deg: float = -26.0
    saa_lon_deg: float = -50.0
    saa_lat_width_deg: float = 12.0
    saa_lon_width_deg: float = 25.0
    saa_height_m: float = 550e3
    saa_height_exponent: float = 2.0
    horn_peak: float = 100.0
    horn_lat_deg: float = 65.0
    horn_width_deg: float = 5.0

    def terms(self, lat, lon, h):
        """(the anomaly's, the horns') flux terms (N,) [cm⁻² s⁻¹] at geodetic (L, λ, h) (N,) [rad, rad, m]."""
        dlat = np.degrees(lat) - self.saa_lat_deg
        dlon = (np.degrees(lon) - self.saa_lon_deg + 180.0) % 360.0 - 180.0
        saa = self.saa_peak * np.exp(-0.5 * (dlat / self.saa_lat_width_deg) ** 2 - 0.5 * (dlon / self.saa_lon_width_deg) ** 2)
        saa = saa * (np.maximum(h, 0.0) / self.saa_height_m) ** self.saa_height_exponent
        magnetic = np.degrees(np.abs(geomagnetic_latitude(lat, lon)))
        return saa, self.horn_peak * np.exp(-0.5 * ((magnetic - self.horn_lat_deg) / self.horn_width_deg) ** 2)

    def flux(self, lat, lon, h):
        """Φ [cm⁻² s⁻¹] at geodetic (L, λ, h) (N,) [rad, rad, m] (module docstring)."""
        saa, horn = self.terms(lat, lon, h)
        return self.background + saa + horn


def geomagnetic_latitude(lat, lon):
    """The dipole latitude [rad] of geodetic (L, λ) [rad]: the complement of the angle from the dipole's pole."""
    pole_lat, pole_lon = np.radians(DIPOLE_POLE_DEG)
    return np.arcsin(np.clip(np.sin(lat) * np.sin(pole_lat) + np.cos(lat) * np.cos(pole_lat) * np.cos(lon - pole_lon), -1.0, 1.0))
