"""The sky's brightness (navsim.earth.sky_brightness) against published measurements and Krisciunas & Schaefer's
own model values; its scaling with height and wavelength; bad input.

Every measured number below is quoted with its source; the tolerance is the measurement's stated scatter, or
0.3 mag/arcsec² where none is stated (issue 29)."""

import numpy as np
import pytest

from navsim.earth.atmosphere import Aerosol, Extinction, extinction
from navsim.earth.sky_brightness import NL_ZERO, Sightline, sky_band, sky_brightness
from startrack.base.errors import InputError
from startrack.photometry.bands import band

BELOW = 180.0  # a Sun or Moon far below the horizon [deg]


def sight(zenith, sun_zenith=BELOW, sun_angle=BELOW, moon_zenith=BELOW, moon_angle=BELOW, moon_phase=180.0,
          height=0.0, year=2000.0):
    """A :class:`Sightline` from angles in degrees."""
    deg = np.radians
    return Sightline(zenith=deg(np.asarray(zenith, float)), sun_zenith=deg(np.asarray(sun_zenith, float)),
                     sun_angle=deg(np.asarray(sun_angle, float)), moon_zenith=deg(np.asarray(moon_zenith, float)),
                     moon_angle=deg(np.asarray(moon_angle, float)), moon_phase_angle=deg(np.asarray(moon_phase, float)),
                     height=np.asarray(height, float), year=np.asarray(year, float))


def test_dark_moonless_zenith_v():
    """Paranal (2635 m), April 2000 - September 2001 near solar maximum: V = 21.6 mag/arcsec² zenith-corrected, scatter
    "typically of the order of 0.2 mag rms" (Patat 2003, A&A 400, 1183, abstract and §5: aanda.org
    .../2003/12/aa3223/node5.html) -> within 0.2 (measured 21.51; 21.49 before the night sky was a sum of sources). La Palma (2396 m) at sunspot minimum: V = 21.9
    (Benn & Ellison 1998, La Palma Technical Note 115: ing.iac.es .../skybr.html; no scatter stated) -> within 0.3
    (measured 21.81; 21.92 before). Mauna Kea (2800 m), yearly means 1985-1996: V from 21.287 to 21.906 over the solar cycle
    (Krisciunas 1997, PASP 109, 1181: ar5iv astro-ph/9706111) -> the model's extremes over those years within 0.3
    (measured 21.39 and 21.86; 21.31 and 21.83 before)."""
    assert float(sky_brightness("V", sight(0.0, height=2635.0, year=2000.95)).total) == pytest.approx(21.6, abs=0.2)
    assert float(sky_brightness("V", sight(0.0, height=2396.0, year=1996.4)).total) == pytest.approx(21.9, abs=0.3)
    years = np.arange(1985.0, 1997.0, 0.25)
    mauna_kea = sky_brightness("V", sight(np.zeros_like(years), height=2800.0, year=years)).total
    assert mauna_kea.min() == pytest.approx(21.287, abs=0.3) and mauna_kea.max() == pytest.approx(21.906, abs=0.3)


#: Zenith V twilight at Paranal against the Sun's zenith distance [deg, mag/arcsec²]: Patat, Ugolnikov & Postylyakov
#: 2006, A&A 455, 385, Fig. 5, as digitised (WebPlotDigitizer) in lsst-sims/legacy_sims_skybrightness,
#: doc/PatatTwi/vband.dat (commit d3eaf5253b85d9cb5e042ed846c7ed06feb706a6), rounded to 0.01.
PATAT_V = [(99.06, 17.04), (100.02, 17.86), (100.93, 18.72), (101.89, 19.51), (102.84, 20.25), (103.75, 20.78),
           (104.82, 21.19), (106.78, 21.44), (108.41, 21.52), (110.89, 21.52)]


def test_twilight_against_the_suns_depression():
    """Every point of Patat et al.'s V curve within 0.3 (no scatter stated for the curve; measured: at most 0.21,
    the model a little brighter at 9-10 deg of depression and falling ~1 mag per degree as Schaefer's formula does,
    the data ~0.85)."""
    z = np.array([p[0] for p in PATAT_V])
    model = sky_brightness("V", sight(np.zeros_like(z), sun_zenith=z, sun_angle=z, height=2635.0, year=2005.0)).total
    assert np.max(np.abs(model - np.array([p[1] for p in PATAT_V]))) < 0.3


#: Krisciunas & Schaefer 1991 (PASP 103, 1033) Table 2: their model's brightening ΔV of a dark sky by the Moon
#: (k = 0.172, B_zen = 79 nL) for the phase angle α, Moon-sky angle ρ, the sky's and the Moon's zenith
#: distances [deg], as quoted in sdss/roboscheduler tests/test_scheduler.py (HEAD 8fe3997f).
KS91_TABLE_2 = [(30.0, 60.0, 0.0, 60.0, -2.22), (60.0, 60.0, 0.0, 60.0, -1.54), (90.0, 60.0, 0.0, 60.0, -0.88),
                (90.0, 30.0, 30.0, 60.0, -1.35), (120.0, 30.0, 47.7, 58.1, -0.58), (120.0, 60.0, 50.5, 58.1, -0.34)]


@pytest.mark.parametrize("alpha, rho, zenith, moon_zenith, delta_v", KS91_TABLE_2)
def test_moonlight_is_krisciunas_and_schaefers_model(alpha, rho, zenith, moon_zenith, delta_v):
    """At their site and band (Mauna Kea, V, k = 0.172: the model's molecules, ozone and water vapour there and the
    rest aerosol) the moonlight is KS91's own: their Table 2's ΔV within 0.05 mag (the table's rounding and that of its
    geometry; measured at most 0.02), the dark sky from their eq. 2, B0 = 79 nL 10^(−0.4 k (X − 1)) X. Their comparison
    with their measured moonlit skies (8-23 %) is not among the material this project can read; it is not repeated
    here. (Issue 53: the aerosol's share of k is what scatters, ozone and water absorb; before, k was all taken as
    scattering.)"""
    site = extinction(band("V"), 2800.0)
    aerosol = 0.172 - float(site.rayleigh + site.ozone + site.water)
    air = Extinction(h=np.asarray(2800.0), rayleigh=site.rayleigh, aerosol=np.asarray(aerosol),
                     stratospheric=np.asarray(0.0), ozone=site.ozone, water=site.water)
    moon = sky_brightness("V", sight(zenith, moon_zenith=moon_zenith, moon_angle=rho, moon_phase=alpha, height=2800.0),
                          air=air).moon
    b_moon = 10.0 ** (-0.4 * (float(moon) - NL_ZERO))
    X = 1.0 / np.sqrt(1.0 - 0.96 * np.sin(np.radians(zenith)) ** 2)
    b_dark = 79.0 * 10.0 ** (-0.4 * 0.172 * (X - 1.0)) * X
    assert -2.5 * np.log10((b_moon + b_dark) / b_dark) == pytest.approx(delta_v, abs=0.05)


def _coronal_sky(**air):
    """The sky brightness monitor's quantity at noon at 3200 m (the Sun 60 deg high): the V sky 4.5-7 solar radii from
    the Sun's centre in millionths of the disk's mean brightness, its annulus mean (area-weighted) per airmass."""
    sun_surface = sky_band("V").sun_mag + 2.5 * np.log10(np.pi * 959.6**2)  # mean over the disk [mag/arcsec²]
    radii = np.linspace(4.5, 7.0, 26)
    sky = sky_brightness("V", sight(np.full(radii.size, 30.0), sun_zenith=30.0, sun_angle=radii * 959.6 / 3600.0,
                                    height=3200.0), **air).total
    millionths = 1e6 * 10.0 ** (-0.4 * (sky - sun_surface))
    assert np.all(np.diff(millionths) < 0.0)  # the aureole falls away from the Sun
    return np.sum(millionths * radii) / np.sum(radii) * np.cos(np.radians(30.0))


def test_the_daytime_sky_beside_the_sun():
    """Coronagraph sites measure the sky 4.5-7 solar radii from the Sun's centre (the sky brightness monitor's annulus,
    its mean per airmass, in millionths of the disk): "usually around ten millionths" at noon at an excellent site
    (arXiv:1204.4289, the sky at Dali in the 2010 annular eclipse, which also found the aureole single scattering),
    "under 20 millionths per airmass before local noon" for most of 2011 at Lijiang (3200 m), 20 the 40 % point of
    its clear days (arXiv:1709.02053). Single scattering by the aerosol above the site: the model's excess over the
    aerosol-free sky is proportional to the aerosol's extinction k_A + k_S above 3200 m, within 5 % from 23 to 300 km
    of visibility (seen ±2 %: 870-907 millionths per mag of k). The published values have one significant figure:
    an exceptionally clear air (100 km visibility) is "ten", 5-15 (seen 10.7), the model's default air at Lijiang's
    noon "20", 15-25 (seen 21.6). (Until issue 53 the test took the two edges of the annulus within a factor 2.5 of
    ten; the aerosol's scattering share of KS91's k then brightened the edge at 4.5 radii from 24 to 39, past it: the
    monitor reports the annulus mean, not its edge.)"""
    site = extinction(band("V"), 3200.0)
    floor = _coronal_sky(air=Extinction(h=site.h, rayleigh=site.rayleigh, aerosol=np.asarray(0.0),
                                        stratospheric=np.asarray(0.0), ozone=site.ozone, water=site.water))
    slopes = []
    for visibility in (23.0, 38.0, 100.0, 300.0):
        aerosol = Aerosol.from_visibility(visibility)
        air = extinction(band("V"), 3200.0, aerosol=aerosol)
        slopes.append((_coronal_sky(aerosol=aerosol) - floor) / float(air.aerosol + air.stratospheric))
    assert max(slopes) / min(slopes) < 1.05, slopes
    assert 5.0 <= _coronal_sky(aerosol=Aerosol.from_visibility(100.0)) < 15.0
    assert 15.0 <= _coronal_sky() < 25.0


def test_the_sky_darkens_with_height_as_the_air_above_thins():
    """Single scattering (Tousey & Hulburt 1947's theory, which Packer & Lock 1951 found to agree with their B-29
    measurements from 5.5 to 11.6 km for sky points 30 deg above the horizon and 40 deg from the Sun): with the
    boundary-layer aerosol gone, the daylight sky scales with the pressure above, so from 5.5 to 11.6 km it darkens
    by the pressure ratio (1.7 mag) within 0.1 mag (the path's saturation and the stratosphere's aerosol)."""
    heights = np.array([5500.0, 11600.0])
    day = sky_brightness("V", sight(np.full(2, 30.0), sun_zenith=40.0, sun_angle=70.0, height=heights)).day
    from navsim.earth.atmosphere import temperature_pressure

    _, p = temperature_pressure(heights)
    assert day[1] - day[0] == pytest.approx(2.5 * np.log10(p[0] / p[1]), abs=0.1)


def test_the_day_sky_is_darker_in_the_infrared():
    """At 12 km with the Sun 30 deg high, 90 deg from the line of sight: each band darker than the last from V to H
    (Rayleigh λ⁻⁴, aerosol λ⁻¹·³ against the Sun's colours), H at least 2.5 mag/arcsec² darker than R."""
    s = sight(30.0, sun_zenith=60.0, sun_angle=90.0, height=12000.0)
    day = [float(sky_brightness(name, s).total) for name in ("V", "R", "I", "J", "H")]
    assert np.all(np.diff(day) > 0.0) and day[4] - day[1] > 2.5


def test_a_bright_moon_outshines_the_night_and_a_set_moon_nothing():
    """Full Moon 30 deg from the line of sight brightens the V sky by more than 2 mag; the same Moon below the
    horizon leaves the moonless sky."""
    night = float(sky_brightness("V", sight(30.0)).total)
    moonlit = float(sky_brightness("V", sight(30.0, moon_zenith=30.0, moon_angle=30.0, moon_phase=0.0)).total)
    below = float(sky_brightness("V", sight(30.0, moon_zenith=100.0, moon_angle=30.0, moon_phase=0.0)).total)
    assert night - moonlit > 2.0 and below == pytest.approx(night, abs=1e-9)


def test_an_unknown_band_is_one_clear_message():
    with pytest.raises(InputError, match="'K'.*V, R, I, J, H"):
        sky_brightness("K", sight(0.0))
