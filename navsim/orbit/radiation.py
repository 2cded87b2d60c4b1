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
latitude: the complement of the angle between the geocentric position and the centred dipole's axis, the axis
−(g11, h11, g10)/|…| (ECEF) of IGRF-13's first-degree Gauss coefficients at 2020.0 (Alken et al. 2021): the north
geomagnetic pole at 80.59 N (geocentric; 80.65 N geodetic where the axis meets the ellipsoid), 72.68 W.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.wgs84 import geodetic_to_ecef

#: IGRF-13's first-degree Gauss coefficients (g10, g11, h11) [nT] at 2020.0 (Alken et al. 2021).
IGRF13_DIPOLE_NT = (-29404.8, -1450.9, 4652.5)
#: The unit ECEF vector of the north geomagnetic pole: −(g11, h11, g10)/|…|.
DIPOLE_AXIS = -np.array(IGRF13_DIPOLE_NT)[[1, 2, 0]] / np.linalg.norm(IGRF13_DIPOLE_NT)


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
        magnetic = np.degrees(np.abs(geomagnetic_latitude(lat, lon, h)))
        return saa, self.horn_peak * np.exp(-0.5 * ((magnetic - self.horn_lat_deg) / self.horn_width_deg) ** 2)

    def flux(self, lat, lon, h):
        """Φ [cm⁻² s⁻¹] at geodetic (L, λ, h) (N,) [rad, rad, m] (module docstring)."""
        saa, horn = self.terms(lat, lon, h)
        return self.background + saa + horn


def geomagnetic_latitude(lat, lon, h):
    """The dipole latitude [rad] of geodetic (L, λ, h) (N,) [rad, rad, m]: the complement of the angle between the
    geocentric position and :data:`DIPOLE_AXIS`."""
    r = np.stack(geodetic_to_ecef(*(np.asarray(x, dtype=float) for x in (lat, lon, h))), axis=-1)
    return np.arcsin(np.clip(r @ DIPOLE_AXIS / np.linalg.norm(r, axis=-1), -1.0, 1.0))
