"""The night sky as a sum of sources (navsim.earth.night_sky, issue 53 item 1): the zodiacal light against Leinert et
al. 1998, the airglow's geometry and its share at a balloon against SuperBIT (Gill et al. 2020), the moonlit sky
against Patat 2003 §7, the air's scattering with height, the boresight's ecliptic and Galactic coordinates, and
``navsim sky``'s sources.

Every measured number is quoted with its source; the tolerance is 0.25 mag/arcsec² unless the measurement's own
scatter is larger (then stated). Comparisons the model does not meet hold its miss to the recorded one within
:data:`MISS_TOLERANCE`: a worse miss fails, and so does a better one until the record is updated."""

import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from navsim.earth import night_sky
from navsim.earth.atmosphere import extinction
from navsim.earth.sky_brightness import SKY_BANDS, Sightline, sky_brightness
from navsim.kinds import scenario_from_dict
from navsim.navigation import sky_background
from navsim.navigation.availability import SOURCES, star_availability
from startrack.photometry.bands import band

BELOW = 180.0  # a Sun or Moon far below the horizon [deg]
DATA = Path(__file__).parent / "data"


def sight(zenith, sun_zenith=BELOW, sun_angle=BELOW, moon_zenith=BELOW, moon_angle=BELOW, moon_phase=180.0,
          height=0.0, year=2000.0, **coordinates_deg):
    """A :class:`Sightline` from angles in degrees (ecliptic and Galactic coordinates optional: the poles)."""
    deg = np.radians
    extra = {name: deg(np.asarray(value, float)) for name, value in coordinates_deg.items()}
    return Sightline(zenith=deg(np.asarray(zenith, float)), sun_zenith=deg(np.asarray(sun_zenith, float)),
                     sun_angle=deg(np.asarray(sun_angle, float)), moon_zenith=deg(np.asarray(moon_zenith, float)),
                     moon_angle=deg(np.asarray(moon_angle, float)), moon_phase_angle=deg(np.asarray(moon_phase, float)),
                     height=np.asarray(height, float), year=np.asarray(year, float), **extra)


#: Leinert et al. 1998 Table 16 in S10(V)⊙ at (λ − λ⊙, β) [deg], as quoted beside their Table 17 in the cross-check of
#: TuSKan/astrogo skybrightness/zodiacal.go (an independent transcription: 1.28 × Table 16 = Table 17 within 1.2 %).
LEINERT_TABLE_16 = [(90.0, 90.0, 60.0), (180.0, 0.0, 180.0), (90.0, 0.0, 202.0), (60.0, 0.0, 395.0), (30.0, 0.0, 1940.0)]


@pytest.mark.parametrize("longitude, latitude, s10", LEINERT_TABLE_16)
def test_zodiacal_light_is_leinerts(longitude, latitude, s10):
    """Table 17 through the 1.28e-8 W m⁻² sr⁻¹ µm⁻¹ per S10 of their §8 gives Table 16 within its rounding (1.2 %)."""
    model = night_sky.zodiacal_s10(np.radians(longitude), np.radians(latitude))
    assert float(model) == pytest.approx(s10, rel=0.012)


def test_zodiacal_light_at_the_ecliptic_pole_and_between_the_table():
    """At the ecliptic pole V 23.3 mag/arcsec² (60 S10: the issue, Leinert et al.) within 0.05 at any longitude and in
    either hemisphere; between the table's nodes the interpolation stays between its neighbours; its colour is redder
    than the Sun's (Leinert et al. §8: the zodiacal spectrum reddened against the solar one) in R, I, J, H."""
    lon = np.radians([0.0, 75.0, 180.0, 270.0])
    pole = night_sky.magnitude(night_sky.zodiacal_flux("V", lon, np.radians(-90.0)))
    assert np.all(np.abs(pole - 23.3) < 0.05)
    mid = float(night_sky.zodiacal_s10(np.radians(97.5), np.radians(37.5)))
    assert 96.0 / 1.28 < mid < 132.0 / 1.28  # Table 17's (90, 30) and (105, 45) bracket it
    v = night_sky.magnitude(night_sky.zodiacal_flux("V", np.pi, 0.5 * np.pi))
    for name in "RIJH":
        colour = v - night_sky.magnitude(night_sky.zodiacal_flux(name, np.pi, 0.5 * np.pi))
        assert colour > SKY_BANDS["V"].sun_absolute - SKY_BANDS[name].sun_absolute


def test_starlight_by_galactic_latitude():
    """At the Galactic poles V 24.1 mag/arcsec² (Roach & Gordon 1973's 30 S10: 10 + 2.5 log10(3600²) − 2.5 log10 30 =
    24.09, the issue's "~V 24") within 0.05; towards the plane a thin plane-parallel disk's, the pole's times csc |b|
    (the path through the slab) within 1e-9 from 90 to 6 deg (a csc² or a cos law fails); on the equator inside Roach &
    Gordon's 160-640 S10, which spans the longitudes the model does not resolve."""
    assert float(night_sky.magnitude(night_sky.starlight_flux(0.0, 0.5 * np.pi))) == pytest.approx(24.1, abs=0.05)
    b = np.radians(np.arange(6.0, 91.0, 4.0))
    pole = night_sky.starlight_s10(np.radians(90.0))
    np.testing.assert_allclose(night_sky.starlight_s10(b) * np.sin(b), pole, rtol=1e-9)
    assert 160.0 <= float(night_sky.starlight_s10(0.0)) <= 640.0


def test_airglow_is_above_every_vehicle_below_its_shell():
    """Van Rhijn's factor (eq. 1): from the ground 1/sqrt(1 − (R/(R + 90 km))²) = 6.0 at the horizon; a balloon at 30 km
    sees the ground's factor within 2 % (0.02 mag) up to 60 deg from the zenith (measured 1.3 %); above the shell nothing upward and twice the
    slant path where a line of sight crosses it downward."""
    R, h = night_sky.EARTH_RADIUS, night_sky.AIRGLOW_HEIGHT
    assert float(night_sky.van_rhijn(0.5 * np.pi, 0.0)) == pytest.approx(1.0 / np.sqrt(1.0 - (R / (R + h)) ** 2), rel=1e-12)
    z = np.radians(np.arange(0.0, 61.0, 5.0))
    assert np.allclose(night_sky.van_rhijn(z, 30000.0), night_sky.van_rhijn(z, 0.0), rtol=0.02)
    assert float(night_sky.van_rhijn(0.0, 400000.0)) == 0.0
    down = np.radians(110.0)
    ratio = (R + 400000.0) / (R + h) * np.sin(down)
    assert float(night_sky.van_rhijn(down, 400000.0)) == pytest.approx(2.0 / np.sqrt(1.0 - ratio**2))


def test_the_airs_scattering_scales_with_the_air_above():
    """The scattered part of the night sky is single scattering by the air above the observer: from 12 to 30 km (the
    boundary layer's aerosol gone) its flux falls as the scattering extinction k_s (Rayleigh ∝ the pressure above,
    plus the stratosphere's aerosol) within 2 % (the path's saturation: 1 − 10^(−0.4 k_s X) falls short of 0.92 k_s X by
    0.46 k_s, 1.5 % at 12 km), and at 30 km it is under 1 % of the night sky."""
    heights = np.array([12000.0, 30000.0])
    s = sky_brightness("V", sight(np.zeros(2), height=heights))
    k_s = extinction(band("V"), heights).scattering
    scattered = night_sky.flux(s.scattered)
    assert scattered[1] / scattered[0] == pytest.approx(k_s[1] / k_s[0], rel=0.02)
    assert scattered[1] < 0.01 * night_sky.flux(s.night[1])


def test_the_sources_sum_to_the_night_sky_and_each_has_its_geometry():
    """The night term is the flux sum of its four sources; the zodiacal light brightens towards the Sun and the
    ecliptic, the starlight towards the Galactic plane, and neither depends on the solar cycle."""
    s = sky_brightness("V", sight(30.0, height=2635.0, helioecliptic_longitude=120.0, ecliptic_latitude=20.0,
                                  galactic_latitude=15.0))
    summed = sum(night_sky.flux(getattr(s, name)) for name in ("airglow", "zodiacal", "starlight", "scattered"))
    assert float(night_sky.magnitude(summed)) == pytest.approx(float(s.night), abs=1e-12)
    zl = sky_brightness("V", sight(np.zeros(3), helioecliptic_longitude=[60.0, 120.0, 120.0],
                                   ecliptic_latitude=[10.0, 10.0, 60.0])).zodiacal
    assert zl[0] < zl[1] < zl[2]
    years = sky_brightness("V", sight(np.zeros(2), year=[1992.0, 1997.5], galactic_latitude=10.0))
    assert years.starlight[0] == pytest.approx(years.starlight[1]) and years.zodiacal[0] == pytest.approx(years.zodiacal[1])
    assert years.airglow[1] - years.airglow[0] == pytest.approx(2.5 * np.log10(1.3 / 0.7), abs=1e-9)


def test_the_dark_paranal_sky_in_r_and_i():
    """Paranal April 2000 - September 2001 (near solar maximum), zenith-corrected dark sky R 20.9, I 19.7 mag/arcsec²,
    scatter of the order of 0.2 mag rms (Patat 2003, abstract) -> within 0.2 (measured 20.75, 19.56). Not independent
    of the model's R and I airglow, which take Patat's V − R and V − I of the moonless sky: this checks that the sum of
    the sources, carried through the air of a 2635 m site and the solar cycle, still gives his sky."""
    for name, measured in (("R", 20.9), ("I", 19.7)):
        assert float(sky_brightness(name, sight(0.0, height=2635.0, year=2000.95)).total) == pytest.approx(measured, abs=0.2)


#: Gill et al. 2020 (AJ 160:266), abstract: SuperBIT's zodiacal-light- and DGL-subtracted sky, its airglow projected
#: to the zenith, at 28-34 km, against "the darkest ground-based measurements" (zenith, moonless, high Galactic and
#: ecliptic latitude): darker by (flight year, band, mag); 2019's I 0.1 brighter. Their table of the values themselves
#: was not in the material this project could read.
SUPERBIT = {(2016, "V"): 1.0, (2016, "R"): 1.1, (2016, "I"): 0.6, (2018, "V"): 1.0, (2018, "R"): 1.3,
            (2019, "V"): 0.6, (2019, "I"): -0.1}
#: The flights' own spread in each band (max − min of the above) where it exceeds 0.25: V 0.4, I 0.7.
SUPERBIT_TOLERANCE = {"V": 0.4, "R": 0.25, "I": 0.7}
#: What the model misses the flights it does not meet by: its difference less SuperBIT's [mag] (measured 2026-12, the
#: same since).
SUPERBIT_MISSES = {(2016, "V"): -0.90, (2016, "R"): -1.12, (2016, "I"): -0.79, (2018, "V"): -0.53, (2018, "R"): -0.96}
#: How far a recorded miss may move [mag]: the records' rounding, and well under any change of the model worth noting.
MISS_TOLERANCE = 0.05


def superbit_difference(year, name):
    """The model's airglow alone at the zenith of a 30 km balloon in the middle of ``year`` less its darkest ground sky:
    La Palma (2396 m) at sunspot minimum (1996.4) at the ecliptic and Galactic poles, the sky Benn & Ellison measured
    V 21.9 (the model 21.81, tests/navsim/test_sky_brightness.py)."""
    balloon = sky_brightness(name, sight(0.0, height=30000.0, year=year + 0.5)).airglow
    ground = sky_brightness(name, sight(0.0, height=2396.0, year=1996.4)).total
    return float(balloon - ground)


@pytest.mark.parametrize("year, name", list(SUPERBIT), ids=[f"{year}-{name}" for year, name in SUPERBIT])
def test_airglow_alone_against_superbit(year, name):
    """Gill et al.'s difference between the balloon's airglow and the darkest ground sky, with the flights' own spread
    as the tolerance in V (0.4) and I (0.7), 0.25 in R. Met in 2019 (V 0.54 for 0.6, I 0.24 for −0.1); not met in 2016
    and 2018, where the model's airglow at the balloon is 0.5-1.1 mag brighter than SuperBIT's (:data:`SUPERBIT_MISSES`,
    each held to :data:`MISS_TOLERANCE`): with the airglow above both, the zodiacal light, starlight and the air's
    scattering at the ground make only 0.35-0.55 mag of the difference near sunspot minimum, and the solar-cycle
    sinusoid puts mid-2016 at 1.12 of the mean activity."""
    miss = superbit_difference(year, name) - SUPERBIT[(year, name)]
    if (year, name) in SUPERBIT_MISSES:
        assert miss == pytest.approx(SUPERBIT_MISSES[(year, name)], abs=MISS_TOLERANCE), \
            f"the known miss of {year} {name} moved: {miss:+.2f} mag, recorded {SUPERBIT_MISSES[(year, name)]:+.2f}"
    else:
        assert abs(miss) <= SUPERBIT_TOLERANCE[name], miss


def moonlit_brightening(name, days):
    """The largest brightening [mag] of the Paranal sky (2635 m, solar maximum) by the Moon ``days`` after new (phase
    angle 180° − 360° days / 29.53) over the sky FORS1 could see: the field 0-60° from the zenith, the Moon 20-80° from
    the zenith and 30-90° from the field."""
    alpha = 180.0 - 360.0 * days / 29.53
    grid = np.array(np.meshgrid([20.0, 40.0, 60.0, 80.0], [0.0, 30.0, 60.0], [30.0, 60.0, 90.0])).reshape(3, -1)
    s = sky_brightness(name, sight(grid[1], moon_zenith=grid[0], moon_angle=grid[2], moon_phase=alpha, height=2635.0,
                                   year=2000.95))
    return float(np.max(s.night - s.total))


#: The model's miss of Patat's moonlit I at 10 days [mag]: its brightening less his.
PATAT_I_MISS = -0.47


@pytest.mark.parametrize("name, days, measured", [("V", 6.0, 1.0), ("I", 10.0, 1.2)])
def test_the_moonlit_sky_against_patat(name, days, measured):
    """Patat 2003 §7 (Paranal, Fig. 12, moonlight's brightening over his dark-time Table 4): "already at 6 days past new
    moon the observed V data show maximum deviations of the order of 1 mag"; in I "at roughly the same moon age"
    (10 days) "this deviation just reaches ~1.2 mag". The model's largest brightening over FORS1's sky within 0.25:
    V 0.96 at 6 days (met); I 0.73 at 10 days (not met: KS91's moonlight carried to I by the λ⁻⁴ and λ⁻¹·³ scattering
    is too faint against the I sky; its miss :data:`PATAT_I_MISS` held to :data:`MISS_TOLERANCE`). (Measured V 0.89,
    I 0.62 when the test was written; issue 53's aerosol, scattering by its scattering share of KS91's k, brightened
    the moonlight's aureole.) His comparison of the data with KS91 itself (Fig. 12, upper panel) was not in the material
    this project could read."""
    miss = moonlit_brightening(name, days) - measured
    if name == "I":
        assert miss == pytest.approx(PATAT_I_MISS, abs=MISS_TOLERANCE), f"the known miss in I moved: {miss:+.2f} mag"
    else:
        assert abs(miss) <= 0.25, miss


def test_the_boresights_ecliptic_and_galactic_coordinates():
    """A boresight at the north ecliptic pole (RA 18 h, Dec 66.56°) has ecliptic latitude 90° within 0.2° (J2000 against
    the ecliptic of 2024); one at the north Galactic pole (RA 192.859°, Dec 27.128°) Galactic latitude 90° within
    0.01°; one at the Sun's own direction helioecliptic longitude 0."""
    def unit(ra_deg, dec_deg):
        ra, dec = np.radians(ra_deg), np.radians(dec_deg)
        return np.array([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])

    sun = unit(300.0, -20.0)
    boresight = np.stack([unit(270.0, 66.56), unit(192.859, 27.128), sun])
    geometry = SimpleNamespace(boresight_elevation=np.full(3, 0.5), sun_elevation=np.full(3, -1.0), sun_angle=np.ones(3),
                               moon_elevation=np.full(3, -1.0), moon_angle=np.ones(3), moon_phase_angle=np.ones(3),
                               boresight_I=boresight, sun_I=np.tile(sun, (3, 1)))
    path = SimpleNamespace(t=np.zeros(3), h=np.zeros(3))
    s = sky_background.sightline({"epoch_utc": "2024-01-15T20:00:00"}, geometry, path, np.arange(3))
    assert np.degrees(s.ecliptic_latitude[0]) == pytest.approx(90.0, abs=0.2)
    assert np.degrees(s.galactic_latitude[1]) == pytest.approx(90.0, abs=0.01)
    assert np.degrees(s.helioecliptic_longitude[2]) == pytest.approx(0.0, abs=1e-9)


def test_navsim_sky_gives_the_sources_at_the_boresight():
    """``navsim sky`` of a light-budget scenario (the corpus' 20 s at 11 km, a V sensor at night): the summary and the
    printed line carry each source's median; frame by frame the sources' fluxes sum to the sky's brightness."""
    data = tomllib.loads((DATA / "base_sins_cns_photometry.toml").read_text())
    data["epoch_utc"] = "2024-01-15T20:00:00"
    data["star_sensor"] |= {"band": "V", "photometry": {"aperture_mm": 25.0}, "max_stars": 50}
    availability = star_availability(scenario_from_dict(data, source="sky.toml"))
    series, sources = availability.series, availability.summary["sky_sources"]
    assert set(sources) == {name for _, name, _ in SOURCES} | {"total"}
    summed = sum(night_sky.flux(series[key]) for key, _, _ in SOURCES)
    assert np.allclose(night_sky.magnitude(summed), series["sky_background_mag"], atol=1e-9)
    line = next(text for text in availability.lines() if text.startswith("sky sources"))
    assert "airglow" in line and "zodiacal" in line and "starlight/DGL" in line and "total" in line
