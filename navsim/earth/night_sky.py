"""The moonless night sky as a sum of sources, each with its own geometry and its own height dependence
[mag arcsec⁻², Vega, in the bands of :data:`navsim.earth.sky_brightness.SKY_BANDS`].

Brightnesses are in S10 (one V = 10 star per square degree: μ = 27.78 − 2.5 log10 S) above the atmosphere,
in the band, then extinguished along the line of sight by the air above the observer (``air.along``); the
tropospheric part scattered into the line of sight is its own term.

- **Airglow** (a thin emitting shell at h_ag = 90 km, the O I 557.7 nm and OH layers at 87-97 km; Leinert et
  al. 1998 §6): its zenith value at mean solar activity times the solar-cycle factor 1 + 0.3 cos(2π (year −
  1992)/11) (Schaefer 1998's, 0.6 mag peak to peak as Krisciunas 1997 measured on Mauna Kea) and van Rhijn's
  factor for the shell seen from the observer's radius r = R + h,

      V(Z) = 1 / sqrt(1 − (r / (R + h_ag))² sin² Z)                                        (1)

  so a balloon's airglow is the ground's, and an observer above the shell sees it only where the line of
  sight crosses the shell (twice: 2 V(Z) below the horizontal, none upward). The V zenith at sunspot
  minimum is 2.5 times the zodiacal light at the ecliptic pole (Benn & Ellison 1998, La Palma, high
  ecliptic latitude, sunspot minimum: airglow and zodiacal light "in the ratio 2.5:1"): 150 S10, so
  150 / 0.7 at mean activity. In R and I the airglow is what is left of the dark sky of Patat's colours
  (V − R 0.74, V − I 1.90 at Paranal, Patat 2003) once the zodiacal light and starlight (the Sun's colours)
  are taken out; in J and H, the OH bands, it is the Calar Alto median moonless zenith (J 15.95, H 13.99:
  Sánchez et al. 2008) less the same two (0.2 % and 0.1 % of it).
- **Zodiacal light** (Leinert et al. 1998 Table 17, at 500 nm in 10⁻⁸ W m⁻² sr⁻¹ µm⁻¹, 1.28 of them per
  S10(V)⊙, their §8; 77 = 60 S10 = V 23.33 at the ecliptic poles): interpolated bilinearly in helioecliptic
  longitude |λ − λ⊙| (0-180°) and |β| (0-90°); the table's blanks within 15° of the Sun (the solar corona's
  vicinity, never a night sky) take the nearest filled value of the same longitude. Other bands take its
  spectrum at 90° elongation in the ecliptic (Leinert Table 19: 2.6, 2.0, 1.3, 1.2, 0.81, 0.17 × 10⁻⁶ W m⁻²
  sr⁻¹ µm⁻¹ at 0.5, 0.7, 0.9, 1.0, 1.2, 2.2 µm), interpolated in log λ, log I, against the band's
  zero-magnitude flux (:mod:`startrack.photometry.bands`): the reddened solar colour of their §8. (The paper
  itself was not readable here: Tables 17 and 19 are as public codes transcribe them alike, four and two copies.)
- **Integrated starlight and diffuse Galactic light**: 30 S10(vis) at the Galactic poles, 160-640 on the
  Galactic equator (Roach & Gordon 1973, the integrated starlight of the stars fainter than the naked eye's
  V ≈ 6, as tabulated in Schlyter's "Radiometry and photometry in astronomy"); between them the csc |b| of
  a thin plane-parallel disk, capped at 320 S10 (the geometric mean of the equator's range, reached at
  |b| = 5.4°). That pole value is V 24.1 (the issue's "~V 24"). The cut is V ≈ 6: a star sensor's catalog
  (Hipparcos, V ≲ 9) also draws the stars of 6 < V < 9 individually, so this term counts their light twice,
  an excess of a fraction of a ≤ 10 % term (Benn & Ellison: most of the starlight is in stars of
  6 < V < 16). Colours: the Sun's (the integrated light of G and K main-sequence stars at visual wavelengths,
  Leinert et al. 1998 §10), the Vega absolute magnitudes of :data:`SKY_BANDS`.
- **Tropospheric scattering** of all of them (what Schaefer's and KS91's ground-fitted night sky holds
  implicitly): single scattering of a sky of hemispheric mean radiance L̄ by the air above the observer,
  ½ L̄ [1 − 10^(−0.4 k_s X)] with k_s the scattering extinction (Rayleigh ∝ the pressure above, plus the
  aerosols: ``air.scattering``) and X KS91's eq. 3 airmass; the ½ is the part of the light a thin layer
  scatters out of downward beams that goes on downward (a fore-aft symmetric phase function). L̄ is the
  airglow's zenith times the hemispheric mean of (1), 2.5 for a layer 90 km above the ground, plus the
  zodiacal light and starlight of the line of sight. At 30 km k_s is 1 % of the ground's: a balloon sees
  almost none.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.atmosphere import EARTH_RADIUS
from startrack import band as photometric_band
from startrack import units

#: μ [mag arcsec⁻²] of 1 S10: a V = 10 star spread over a square degree.
S10_MAG = 10.0 + 2.5 * np.log10(3600.0**2)
#: The airglow shell's height [m] (Leinert et al. 1998 §6: the emitting layers at 87-97 km).
AIRGLOW_HEIGHT = 90000.0
#: Benn & Ellison 1998: airglow / zodiacal light at high ecliptic latitude, sunspot minimum.
AIRGLOW_TO_ZODIACAL_AT_MINIMUM = 2.5
#: The solar-cycle factor's amplitude and phase (Schaefer 1998: 1 + 0.3 cos(2π (year − 1992)/11)).
CYCLE_AMPLITUDE, CYCLE_MAXIMUM_YEAR, CYCLE_YEARS = 0.3, 1992.0, 11.0

#: Leinert et al. 1998 Table 17: zodiacal light at 500 nm [1e-8 W m⁻² sr⁻¹ µm⁻¹] by helioecliptic longitude
#: |λ − λ⊙| (rows) and ecliptic latitude |β| (columns); NaN: the blank cells near the Sun.
ZODIACAL_LONGITUDE_DEG = np.array([0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 60, 75, 90, 105, 120, 135, 150, 165, 180.0])
ZODIACAL_LATITUDE_DEG = np.array([0, 5, 10, 15, 20, 25, 30, 45, 60, 75, 90.0])
_ = np.nan
ZODIACAL_TABLE = np.array([
    [_, _, _, 3140, 1610, 985, 640, 275, 150, 100, 77],
    [_, _, _, 2940, 1540, 945, 625, 271, 150, 100, 77],
    [_, _, 4740, 2470, 1370, 865, 590, 264, 148, 100, 77],
    [11500, 6780, 3440, 1860, 1110, 755, 525, 251, 146, 100, 77],
    [6400, 4480, 2410, 1410, 910, 635, 454, 237, 141, 99, 77],
    [3840, 2830, 1730, 1100, 749, 545, 410, 223, 136, 97, 77],
    [2480, 1870, 1220, 845, 615, 467, 365, 207, 131, 95, 77],
    [1650, 1270, 910, 680, 510, 397, 320, 193, 125, 93, 77],
    [1180, 940, 700, 530, 416, 338, 282, 179, 120, 92, 77],
    [910, 730, 555, 442, 356, 292, 250, 166, 116, 90, 77],
    [505, 442, 352, 292, 243, 209, 183, 134, 104, 86, 77],
    [338, 317, 269, 227, 196, 172, 151, 116, 93, 82, 77],
    [259, 251, 225, 193, 166, 147, 132, 104, 86, 79, 77],
    [212, 210, 197, 170, 150, 133, 119, 96, 82, 77, 77],
    [188, 186, 177, 154, 138, 125, 113, 90, 77, 74, 77],
    [179, 178, 166, 147, 134, 122, 110, 90, 77, 73, 77],
    [179, 178, 165, 148, 137, 127, 116, 96, 79, 72, 77],
    [196, 192, 179, 165, 151, 141, 131, 104, 82, 72, 77],
    [230, 212, 195, 178, 163, 148, 134, 105, 83, 72, 77],
])
del _
#: Leinert et al. 1998 §8: 1 S10(V)⊙ = 1.28e-8 W m⁻² sr⁻¹ µm⁻¹ at 500 nm.
ZODIACAL_UNITS_PER_S10 = 1.28
#: Leinert et al. 1998 Table 19: the zodiacal light's spectrum at 90° elongation in the ecliptic [µm, W m⁻² sr⁻¹ µm⁻¹].
ZODIACAL_SPECTRUM_UM = np.array([0.5, 0.7, 0.9, 1.0, 1.2, 2.2])
ZODIACAL_SPECTRUM = np.array([2.6e-6, 2.0e-6, 1.3e-6, 1.2e-6, 8.1e-7, 1.7e-7])
#: Roach & Gordon 1973 (module docstring): the Galactic light at the pole and the cap on the equator [S10].
STARLIGHT_POLE_S10 = 30.0
STARLIGHT_EQUATOR_S10 = np.sqrt(160.0 * 640.0)


@dataclass(frozen=True)
class NightSources:
    """The night sky's sources at the observer [mag arcsec⁻², inf: none of that light]: airglow, zodiacal light,
    integrated starlight with the diffuse Galactic light, each extinguished along the line of sight, and the part
    of all three the air above the observer scatters into it."""

    airglow: np.ndarray
    zodiacal: np.ndarray
    starlight: np.ndarray
    scattered: np.ndarray

    @property
    def total(self):
        """The moonless night sky: the four summed in flux."""
        return magnitude(flux(self.airglow) + flux(self.zodiacal) + flux(self.starlight) + flux(self.scattered))


def night_sources(band_name, airglow_zenith, sun_colour, geometry, air):
    """The :class:`NightSources` in ``band_name`` for the airglow's zenith brightness above the atmosphere at mean
    solar activity ``airglow_zenith`` [mag arcsec⁻²], the Sun's colour V − band ``sun_colour`` [mag] (the
    starlight's), the line of sight and date of the :class:`~navsim.earth.sky_brightness.Sightline` ``geometry``
    (its ecliptic and Galactic coordinates) and the observer's :class:`~navsim.earth.atmosphere.Extinction` ``air``
    (module docstring)."""
    g = geometry
    airglow = airglow_flux(airglow_zenith, g.zenith, g.height, g.year)
    zodiacal = zodiacal_flux(band_name, g.helioecliptic_longitude, g.ecliptic_latitude)
    starlight = starlight_flux(sun_colour, g.galactic_latitude)
    above = airglow_flux(airglow_zenith, 0.0, g.height, g.year) * HEMISPHERE_VAN_RHIJN + zodiacal + starlight
    X = scattering_airmass(g.zenith)
    scattered = 0.5 * above * (1.0 - 10.0 ** (-0.4 * air.scattering * X))
    extinction = air.along(g.zenith)
    return NightSources(airglow=magnitude(airglow) + extinction, zodiacal=magnitude(zodiacal) + extinction,
                        starlight=magnitude(starlight) + extinction,
                        scattered=np.where(np.isfinite(extinction), magnitude(scattered), np.inf))


def solar_cycle(year):
    """Schaefer 1998's solar-cycle factor of the airglow, 1 + 0.3 cos(2π (year − 1992)/11)."""
    return 1.0 + CYCLE_AMPLITUDE * np.cos(2.0 * np.pi * (np.asarray(year, dtype=float) - CYCLE_MAXIMUM_YEAR) / CYCLE_YEARS)


def van_rhijn(zenith, height, shell_height=AIRGLOW_HEIGHT):
    """Eq. (1): the path through a thin shell at ``shell_height`` [m] of a line of sight at zenith distance ``zenith``
    [rad] from height ``height`` [m] against the zenith's; above the shell 2 V where a downward line of sight crosses
    it and 0 elsewhere."""
    z, h = np.broadcast_arrays(np.asarray(zenith, dtype=float), np.asarray(height, dtype=float))
    ratio_sin = (EARTH_RADIUS + h) / (EARTH_RADIUS + shell_height) * np.sin(z)
    crosses = ratio_sin**2 < 1.0
    factor = 1.0 / np.sqrt(np.where(crosses, 1.0 - ratio_sin**2, 1.0))
    above = h >= shell_height
    return np.where(above, np.where(crosses & (np.cos(z) < 0.0), 2.0 * factor, 0.0), factor)


def _hemisphere_mean_van_rhijn(n=2000):
    """The solid-angle mean of eq. (1) over the upper hemisphere seen from the ground (midpoint rule in cos Z)."""
    cos_z = (np.arange(n) + 0.5) / n
    return float(np.mean(van_rhijn(np.arccos(cos_z), 0.0)))


#: The hemispheric mean of eq. (1) from the ground (2.5 for the 90 km shell).
HEMISPHERE_VAN_RHIJN = _hemisphere_mean_van_rhijn()


def airglow_flux(zenith_mag, zenith, height, year):
    """The airglow above the atmosphere [flux of mag 0 per arcsec²] along a line of sight: ``zenith_mag`` (its zenith
    at mean solar activity) × the solar cycle × eq. (1)."""
    return flux(zenith_mag) * solar_cycle(year) * van_rhijn(zenith, height)


def zodiacal_s10(helioecliptic_longitude, ecliptic_latitude):
    """The zodiacal light at 500 nm [S10(V)⊙] of Leinert et al. 1998 Table 17 at helioecliptic longitude λ − λ⊙ and
    ecliptic latitude β [rad] (module docstring: bilinear, the blanks near the Sun filled along the longitude)."""
    lon = np.degrees(np.abs((np.asarray(helioecliptic_longitude, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi))
    lat = np.degrees(np.abs(np.asarray(ecliptic_latitude, dtype=float)))
    lon, lat = np.broadcast_arrays(lon, np.minimum(lat, 90.0))
    i = np.clip(np.searchsorted(ZODIACAL_LONGITUDE_DEG, lon, side="right") - 1, 0, len(ZODIACAL_LONGITUDE_DEG) - 2)
    j = np.clip(np.searchsorted(ZODIACAL_LATITUDE_DEG, lat, side="right") - 1, 0, len(ZODIACAL_LATITUDE_DEG) - 2)
    u = (lon - ZODIACAL_LONGITUDE_DEG[i]) / (ZODIACAL_LONGITUDE_DEG[i + 1] - ZODIACAL_LONGITUDE_DEG[i])
    v = (lat - ZODIACAL_LATITUDE_DEG[j]) / (ZODIACAL_LATITUDE_DEG[j + 1] - ZODIACAL_LATITUDE_DEG[j])
    t = _FILLED_TABLE
    value = ((1 - u) * (1 - v) * t[i, j] + u * (1 - v) * t[i + 1, j] + (1 - u) * v * t[i, j + 1] + u * v * t[i + 1, j + 1])
    return value / ZODIACAL_UNITS_PER_S10


def _filled_table():
    """Table 17 with each row's blanks near the Sun taken from the nearest filled cell of the same longitude."""
    table = ZODIACAL_TABLE.copy()
    for row in table:
        first = np.flatnonzero(np.isfinite(row))[0]
        row[:first] = row[first]
    return table


_FILLED_TABLE = _filled_table()


def zodiacal_flux(band_name, helioecliptic_longitude, ecliptic_latitude):
    """The zodiacal light above the atmosphere in ``band_name`` [flux of mag 0 per arcsec²] (Table 17 × Table 19's
    spectrum at the band's centre against the band's zero-magnitude flux)."""
    return zodiacal_s10(helioecliptic_longitude, ecliptic_latitude) * _ZODIACAL_PER_S10[band_name]


def _zodiacal_per_s10(name):
    """The flux [mag 0 per arcsec²] of 1 S10(V)⊙ of zodiacal light in band ``name`` (Table 19's spectrum)."""
    band = photometric_band(name)  # every band's centre lies within the table's 0.5-2.2 µm
    log_spectrum = np.interp(np.log(band.centre_um), np.log(ZODIACAL_SPECTRUM_UM), np.log(ZODIACAL_SPECTRUM))
    per_s10 = ZODIACAL_UNITS_PER_S10 * 1e-8 * np.exp(log_spectrum) / ZODIACAL_SPECTRUM[0]  # W m⁻² sr⁻¹ µm⁻¹
    return per_s10 * 1e6 * units.ARCSEC**2 / band.flux_zero  # flux_zero [W m⁻³]; per_s10 [W m⁻² sr⁻¹ µm⁻¹]


def starlight_s10(galactic_latitude):
    """The integrated starlight and diffuse Galactic light [S10(V)] at Galactic latitude b [rad]: 30 / sin |b|, at most
    320 (module docstring)."""
    sin_b = np.abs(np.sin(np.asarray(galactic_latitude, dtype=float)))
    return np.minimum(STARLIGHT_POLE_S10 / np.maximum(sin_b, 1e-12), STARLIGHT_EQUATOR_S10)


def starlight_flux(sun_colour, galactic_latitude):
    """The starlight above the atmosphere [flux of mag 0 per arcsec²] in a band where the Sun's V − band colour is
    ``sun_colour`` [mag] (the starlight takes the Sun's colours)."""
    return starlight_s10(galactic_latitude) * flux(S10_MAG - sun_colour)


def scattering_airmass(zenith):
    """KS91 eq. 3: X = (1 − 0.96 sin²Z)^(−1/2), the airmass of the scattered light's path."""
    return 1.0 / np.sqrt(1.0 - 0.96 * np.sin(zenith) ** 2)


def flux(mu):
    """10^(−0.4 μ): the flux of a surface brightness μ [mag arcsec⁻²] in magnitude-0 stars per arcsec²."""
    return 10.0 ** (-0.4 * np.asarray(mu, dtype=float))


def magnitude(f):
    """−2.5 log10 f [mag arcsec⁻²] of a flux in magnitude-0 stars per arcsec² (inf where there is none)."""
    with np.errstate(divide="ignore"):
        return -2.5 * np.log10(np.asarray(f, dtype=float))


_ZODIACAL_PER_S10 = {name: _zodiacal_per_s10(name) for name in ("V", "R", "I", "J", "H")}
