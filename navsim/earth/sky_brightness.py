"""The brightness of the sky in a band [mag arcsec⁻², Vega] for an observer anywhere in the atmosphere: the
night sky, the Moon's scattered light, twilight and daylight.

The model is Schaefer's (1993 §4; the program VISLIMIT.BAS of Schaefer 1998, lines 2130-2420) with the
moonlight of Krisciunas & Schaefer (1991, "KS91"), both empirical fits at ground sites, carried to other
bands and to the observer's height through the extinction components of :mod:`navsim.earth.atmosphere`:

- **night** (:mod:`navsim.earth.night_sky`): the sum of its sources, each with its own geometry -- the airglow
  (a thin shell 90 km up: van Rhijn's factor from the observer's radius, the solar cycle 1 + 0.3 cos(2π (year −
  1992)/11), V 150 S10 at sunspot minimum, 2.5 times the zodiacal light at the ecliptic pole as Benn & Ellison
  1998 measured on La Palma), the zodiacal light (Leinert et al. 1998 Table 17 by helioecliptic longitude and
  ecliptic latitude, their Table 19's colour), the integrated starlight and diffuse Galactic light (30 S10 at
  the Galactic poles, csc |b| towards the plane; Roach & Gordon 1973) -- each extinguished along the line of
  sight, plus the part of them the air above the observer scatters into it. R and I take the night sky's
  V − R = 0.74 and V − I = 1.90 measured at Paranal (Patat 2003) for the sum at the poles, J and H the median
  moonless zenith of Calar Alto, J 15.95 and H 13.99 (Sánchez et al. 2008, the OH airglow): ``night_zenith``
  is the airglow's share, its zenith above the atmosphere at mean solar activity.
- **moonlight** (KS91 eq. 15-21): B = f(ρ) I* 10^(−0.4 k X_m) [1 − 10^(−0.4 k X)] [nL] with
  f(ρ) = 10^5.36 (1.06 + cos²ρ) + 10^(6.15 − ρ/40) (ρ in degrees; 6.2e7 ρ⁻² instead of the second term
  below 10°), I* = 10^(−0.4 (m + 16.57)) the Moon's illuminance of magnitude m = −12.73 + 0.026 |α| +
  4e-9 α⁴ (α the phase angle in degrees, eq. 9), X = (1 − 0.96 sin²Z)^(−1/2) (eq. 3), and the nL to
  mag arcsec⁻² conversion of eq. 1, B = 34.08 exp(20.7233 − 0.92104 μ). No light from a Moon below the
  horizon.
- **daylight** (Schaefer 1998 lines 2310-2360): the same scattering with the Sun's magnitude and his
  constant (43.27, 0.36 mag fainter than KS91's), plus a multiply scattered term 440 000 (1 − C) that
  takes over as the Sun's transmission C = 10^(−0.4 k X_s) falls: here (below) C of the light that feeds the
  diffuse sky, k_tr = k_R + (1 − g)(k_A + k_S), and the term scaled by k_tr against KS91's site.
- **twilight** (lines 2270-2290): 10^(−0.4 (m_sun + 32.5 − h_s − Z/(360 k))) (100/ρ_s) [1 − 10^(−0.4 k X)]
  with h_s the Sun's elevation and ρ_s its angle from the line of sight [deg]; the sky takes the lesser of
  daylight and twilight (line 2380), plus the night sky and the moonlight.

**Other bands and heights.** KS91's f(ρ) was fitted in V at 2800 m on Mauna Kea with k = 0.172; its first
term is molecular (Rayleigh) scattering, its second the aerosols'. Single scattering is proportional to
each scatterer's extinction, so the model scales the two terms by the band's and the height's Rayleigh
k_R and aerosol k_A + k_S against their values at KS91's site (k_R = 0.0785 by eq. 1 of the atmosphere
module; k_M = 0.0547, the rest of 0.172 less the ozone's 0.031 and the water vapour's 0.008 that absorb
there), and the path factor [1 − 10^(−0.4 K X)] by k_KS91/K with K the band's total extinction at the
observer (eq. G):

    f(ρ) → f_R(ρ) k_R/k_R,KS91 + f_M(ρ) (k_A + k_S)/k_M,KS91,   [1 − 10^(−0.4KX)] → [1 − 10^(−0.4KX)] k_KS91/K

which is KS91 itself at KS91's site and band. The multiply scattered daylight is the light scattered out of
the Sun's beam into the diffuse sky, then into the line of sight: by van de Hulst's similarity (the transport
optical depth (1 − g) τ; Joseph, Wiscombe & Weinman 1976's δ-scaling) the aerosols' forward peak stays in the
beam (it is the aureole of f_M), absorption feeds nothing, and both steps take k_tr = k_R + (1 − g)(k_A + k_S)
with g = 0.7, the asymmetry parameter of continental aerosol at 550 nm (OPAC's continental polluted mix, 0.698:
Hess, Koepke & Schult 1998):

    440 000 (1 − C) → 440 000 (1 − 10^(−0.4 k_tr X_s)) k_tr/k_tr,KS91

(until issue 53 the term took the band's total k, water and ozone included, times the molecules' k_R: its λ⁻⁸
made the ground sky 0.5 mag too blue in R − H against Gou et al. 2023; now 0.14). The twilight term scales by
(k_R + k_S) against KS91's. So the sky darkens with height as the air above the observer thins (the daylight
sky at 12 km: a fifth of the sea level's molecular scattering and almost none of the boundary layer's
aerosol), and with wavelength as λ⁻⁴ and λ^−α (the aerosol of :class:`navsim.earth.atmosphere.Aerosol`:
Ångström exponent α, optical depth from the site's visibility). The Sun's and the Moon's band magnitudes take the Sun's colours (the Vega absolute magnitudes of
FSPS's filter table, Conroy, Gunn & White 2009: V 4.81, R_C 4.41, I_C 4.10, J 3.67, H 3.34) and, for the
Moon, Schaefer's lunar reddening against the Sun (0.24 mag at 0.70 µm, 0.36 at 0.90 µm: his CM − MS
colours) interpolated linearly in λ and extrapolated to J (0.56) and H (0.82). The twilight term's
horizon brightening Z/(360 k) takes the band's k at sea level (the term is a property of the lit layers,
not of the observer's thinning air, where it would grow without bound). :func:`spectral_radiance` turns a
sky [mag arcsec⁻², Vega] into W cm⁻² sr⁻¹ µm⁻¹ by the band's Vega zero point.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from navsim.earth import night_sky
from navsim.earth.atmosphere import extinction
from startrack import InputError, units
from startrack import band as photometric_band

#: KS91 eq. 1: B [nL] = 34.08 exp(20.7233 − 0.92104 μ), i.e. μ = NL_ZERO − 2.5 log10(B).
NL_ZERO = 20.7233 / 0.92104 + 2.5 * np.log10(34.08)
#: KS91 eq. 8: I* = 10^(−0.4 (m + MOON_ILLUMINANCE_ZERO)) foot-candles; their extinction and height.
MOON_ILLUMINANCE_ZERO = 16.57
KS91_EXTINCTION = 0.172
KS91_HEIGHT = 2800.0
#: Schaefer 1998's daylight (line 2340) and twilight (line 2280) constants [mag].
DAYLIGHT_ZERO = 43.27
TWILIGHT_ZERO = 32.5
#: Schaefer 1998's multiply scattered daylight (line 2340) [nL per foot-candle], and the aerosol's asymmetry
#: parameter g = <cos θ> of its phase function (continental aerosol at 550 nm; module docstring).
MULTIPLE_SCATTERING = 440000.0
AEROSOL_ASYMMETRY = 0.7
#: 1 W m⁻³ in W cm⁻² µm⁻¹.
W_M3_TO_W_CM2_UM = 1e-10
#: Distance modulus of 1 au [mag]: m = M + 5 log10(1 au / 10 pc).
AU_MODULUS = 5.0 * np.log10(1.495978707e11 / 3.0856775814913673e17)


@dataclass(frozen=True)
class SkyBand:
    """What the sky model needs of a band: its name, the Sun's Vega absolute magnitude in it, the Moon's
    reddening against the Sun [mag] and the airglow's zenith above the atmosphere at mean solar activity
    [mag arcsec⁻²] (the night sky's other sources: :mod:`navsim.earth.night_sky`)."""

    name: str
    sun_absolute: float
    moon_reddening: float
    night_zenith: float

    @property
    def sun_mag(self):
        """The Sun's apparent magnitude in the band at 1 au."""
        return self.sun_absolute + AU_MODULUS

    def moon_mag(self, phase_angle_deg):
        """The Moon's magnitude in the band at phase angle α [deg] (KS91 eq. 9 in V, then the colours)."""
        alpha = np.abs(np.asarray(phase_angle_deg, dtype=float))
        v = -12.73 + 0.026 * alpha + 4e-9 * alpha**4
        return v - (SKY_BANDS["V"].sun_absolute - self.sun_absolute) - self.moon_reddening


def _airglow_zeniths(bands):
    """The airglow's zenith above the atmosphere at mean solar activity [mag arcsec⁻²] of each of ``bands`` (module
    docstring): V from Benn & Ellison's 2.5 × the zodiacal light at the ecliptic pole at sunspot minimum; R, I what
    Patat's colours of the moonless sky at the ecliptic and Galactic poles leave once the zodiacal light and
    starlight are taken out; J, H the same of Calar Alto's medians."""
    pole = 0.5 * np.pi
    other = {name: night_sky.zodiacal_flux(name, np.pi, pole)
             + night_sky.starlight_flux(bands["V"].sun_absolute - b.sun_absolute, pole) for name, b in bands.items()}
    v = night_sky.AIRGLOW_TO_ZODIACAL_AT_MINIMUM * night_sky.zodiacal_flux("V", np.pi, pole) / (1.0 - night_sky.CYCLE_AMPLITUDE)
    dark_v = night_sky.magnitude(v + other["V"])
    totals = {"R": dark_v - 0.74, "I": dark_v - 1.90, "J": 15.95, "H": 13.99}
    return {"V": float(night_sky.magnitude(v)),
            **{name: float(night_sky.magnitude(night_sky.flux(mu) - other[name])) for name, mu in totals.items()}}


#: The Sun's and the Moon's colours; the airglow's zenith (its last field) from :func:`_airglow_zeniths`.
SKY_BANDS = {
    "V": SkyBand("V", 4.81, 0.0, np.nan),
    "R": SkyBand("R", 4.41, 0.146, np.nan),
    "I": SkyBand("I", 4.10, 0.299, np.nan),
    "J": SkyBand("J", 3.67, 0.561, np.nan),
    "H": SkyBand("H", 3.34, 0.817, np.nan),
}
SKY_BANDS = {name: dataclasses.replace(SKY_BANDS[name], night_zenith=mu) for name, mu in _airglow_zeniths(SKY_BANDS).items()}


def sky_band(name):
    """The :class:`SkyBand` called ``name``; InputError naming the known ones otherwise."""
    try:
        return SKY_BANDS[name]
    except (KeyError, TypeError):
        raise InputError(f"the sky model has no band {name!r}; choose from {', '.join(SKY_BANDS)}") from None


@dataclass(frozen=True)
class Sightline:
    """Where the sky is looked at, per frame (arrays broadcast together), angles in radians: the line of sight's
    zenith distance, the Sun's zenith distance and angle from it, the Moon's zenith distance, angle from it and
    phase angle; the observer's height [m] and the date as a Julian year (the solar cycle); the line of sight's
    helioecliptic longitude λ − λ⊙, ecliptic latitude and Galactic latitude (the zodiacal light and starlight; by
    default the ecliptic and Galactic poles, the darkest sky)."""

    zenith: np.ndarray
    sun_zenith: np.ndarray
    sun_angle: np.ndarray
    moon_zenith: np.ndarray
    moon_angle: np.ndarray
    moon_phase_angle: np.ndarray
    height: np.ndarray
    year: np.ndarray
    helioecliptic_longitude: np.ndarray = np.pi
    ecliptic_latitude: np.ndarray = 0.5 * np.pi
    galactic_latitude: np.ndarray = 0.5 * np.pi


@dataclass(frozen=True)
class SkyBrightness:
    """The sky's components and total [mag arcsec⁻²] (inf: none of that light); ``night`` is the sum of the night
    sky's sources, each given too (:class:`navsim.earth.night_sky.NightSources`: airglow, zodiacal light,
    starlight with the diffuse Galactic light, and the air's scattering of them)."""

    night: np.ndarray
    moon: np.ndarray
    day: np.ndarray
    twilight: np.ndarray
    airglow: np.ndarray = np.inf
    zodiacal: np.ndarray = np.inf
    starlight: np.ndarray = np.inf
    scattered: np.ndarray = np.inf

    @property
    def total(self):
        """The sky: night + the lesser of daylight and twilight + moonlight (Schaefer 1998 line 2380)."""
        sun = np.maximum(self.day, self.twilight)
        return night_sky.magnitude(night_sky.flux(self.night) + night_sky.flux(sun) + night_sky.flux(self.moon))


def sky_brightness(band_name, geometry, relative_humidity=0.4, temperature_c=15.0, air=None, aerosol=None):
    """The :class:`SkyBrightness` of ``band_name`` (a :class:`startrack.photometry.bands.Band`'s name) for the
    :class:`Sightline` ``geometry``; the ground air's humidity (0-1) and temperature [°C] set its water vapour and
    ``aerosol`` (a :class:`navsim.earth.atmosphere.Aerosol`, default the 38 km visibility's) its aerosols
    (:func:`navsim.earth.atmosphere.extinction`), or ``air`` gives the observer's
    :class:`~navsim.earth.atmosphere.Extinction` itself."""
    g, sky = geometry, sky_band(band_name)
    band = photometric_band(band_name)
    site = {"relative_humidity": relative_humidity, "temperature_c": temperature_c, "aerosol": aerosol}
    air = extinction(band, g.height, **site) if air is None else air
    ref = extinction(photometric_band("V"), KS91_HEIGHT)  # KS91's site in its own air (Schaefer's 40 %, 15 °C)
    K = air.total
    ref_rayleigh = float(ref.rayleigh)
    ref_aerosol = KS91_EXTINCTION - ref_rayleigh - float(ref.ozone + ref.water)  # the part of KS91's k that scatters
    ref_upper = ref_rayleigh + float(ref.stratospheric)
    X = night_sky.scattering_airmass(g.zenith)
    path = (1.0 - 10.0 ** (-0.4 * K * X)) * KS91_EXTINCTION / K
    upper = (air.rayleigh + air.stratospheric) / ref_upper

    def scattered(angle):
        rayleigh, mie = _scattering_function(np.degrees(angle))
        return rayleigh * air.rayleigh / ref_rayleigh + mie * (air.aerosol + air.stratospheric) / ref_aerosol

    moon_up = g.moon_zenith < 0.5 * np.pi
    t_moon, t_sun = _transmission(K, g.moon_zenith), _transmission(K, g.sun_zenith)
    moon_nl = scattered(g.moon_angle) * _illuminance(sky.moon_mag(np.degrees(g.moon_phase_angle))) * t_moon * path
    transport, ref_transport = _transport(air), ref_rayleigh + (1.0 - AEROSOL_ASYMMETRY) * ref_aerosol
    diffuse = MULTIPLE_SCATTERING * (1.0 - _transmission(transport, g.sun_zenith)) * transport / ref_transport
    day = sky.sun_mag + DAYLIGHT_ZERO - 2.5 * np.log10(path * (scattered(g.sun_angle) * t_sun + diffuse))
    sun_elevation, rho_s = 90.0 - np.degrees(g.sun_zenith), np.maximum(np.degrees(g.sun_angle), 0.25)
    k_sea = extinction(band, 0.0, **site).total
    twilight = (sky.sun_mag + TWILIGHT_ZERO - sun_elevation - np.degrees(g.zenith) / (360.0 * k_sea)
                - 2.5 * np.log10(100.0 / rho_s * path * upper))
    sources = night_sky.night_sources(band_name, sky.night_zenith, SKY_BANDS["V"].sun_absolute - sky.sun_absolute, g, air)
    night = sources.total
    moon = np.where(moon_up, NL_ZERO - 2.5 * np.log10(np.maximum(moon_nl, 1e-300)), np.inf)
    return SkyBrightness(night=np.asarray(night, dtype=float), moon=np.asarray(moon, dtype=float),
                         day=np.asarray(day, dtype=float), twilight=np.asarray(twilight, dtype=float),
                         airglow=sources.airglow, zodiacal=sources.zodiacal, starlight=sources.starlight,
                         scattered=sources.scattered)


def _transport(air):
    """k_tr = k_R + (1 − g)(k_A + k_S) [mag per airmass]: the scattering that feeds the diffuse daylight, the
    aerosols' by their transport share (module docstring)."""
    return air.rayleigh + (1.0 - AEROSOL_ASYMMETRY) * (air.aerosol + air.stratospheric)


def spectral_radiance(band_name, surface_brightness):
    """The spectral radiance L_λ [W cm⁻² sr⁻¹ µm⁻¹] of a sky of ``surface_brightness`` [mag arcsec⁻², Vega] in the
    band: L_λ = f_λ,0 10^(−0.4 μ) / Ω(1 arcsec²) with f_λ,0 the band's Vega zero point
    (:mod:`startrack.photometry.bands`) and Ω(1 arcsec²) = (π/648 000)² sr = 2.3504e-11 sr."""
    f_zero = photometric_band(band_name).flux_zero * W_M3_TO_W_CM2_UM
    return f_zero * 10.0 ** (-0.4 * np.asarray(surface_brightness, dtype=float)) / units.ARCSEC**2


def surface_brightness(band_name, radiance):
    """The inverse of :func:`spectral_radiance`: μ [mag arcsec⁻²] of a spectral radiance [W cm⁻² sr⁻¹ µm⁻¹]."""
    f_zero = photometric_band(band_name).flux_zero * W_M3_TO_W_CM2_UM
    return -2.5 * np.log10(np.asarray(radiance, dtype=float) * units.ARCSEC**2 / f_zero)


def _scattering_function(rho_deg):
    """(molecular, aerosol) terms of KS91's f(ρ) (eq. 21) [nL per foot-candle] at ρ [deg]."""
    rho = np.maximum(np.asarray(rho_deg, dtype=float), 0.25)
    molecular = 10.0**5.36 * (1.06 + np.cos(np.radians(rho)) ** 2)
    aerosol = np.where(rho < 10.0, 6.2e7 / rho**2, 10.0 ** (6.15 - rho / 40.0))
    return molecular, aerosol


def _transmission(k, zenith):
    """10^(−0.4 k X(Z)) of a source at zenith distance Z [rad] (KS91's X, eq. 3), 0 below the horizon."""
    return np.where(zenith < 0.5 * np.pi, 10.0 ** (-0.4 * k * night_sky.scattering_airmass(np.minimum(zenith, 0.5 * np.pi))), 0.0)


def _illuminance(mag):
    """KS91 eq. 8: the illuminance I* [foot-candles] of a body of magnitude ``mag``."""
    return 10.0 ** (-0.4 * (np.asarray(mag, dtype=float) + MOON_ILLUMINANCE_ZERO))
