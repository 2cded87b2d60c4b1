"""The sky a physical star sensor of a navigation run sees at its frames (:class:`navsim.sensors.frame_sky.FrameSky`):
the sky's brightness in the sensor's band at the boresight (:mod:`navsim.earth.sky_brightness`) from the frames'
Sun, Moon and boresight geometry (:mod:`navsim.navigation.exclusion`) and the observer's height, the extinction of
the air above the observer (:mod:`navsim.earth.atmosphere`; the site's humidity, temperature and aerosol from
``star_sensor.photometry``: visibility or optical depth, Ångström exponent) and the trail of a star near the boresight
from the body rate, for the nominal trajectory (seed-free, like the exclusions). The night sky's zodiacal light and
starlight take the boresight's ecliptic coordinates of date from the Sun's (IAU 2006 precession, ``erfa.eqec06``)
and its Galactic latitude (``erfa.icrs2g``)."""

import dataclasses

import erfa
import numpy as np

from navsim.earth.atmosphere import Aerosol, extinction
from navsim.earth.frames import julian_year, tt_epoch
from navsim.earth.sky_brightness import Sightline, sky_brightness
from navsim.sensors.frame_sky import FrameSky
from startrack import rotation as rot

#: A Julian year [s].
JULIAN_YEAR_S = 365.25 * 86400.0


def sightline(scenario, geometry, path, frame_k):
    """The :class:`~navsim.earth.sky_brightness.Sightline` of the boresight at the frames (samples ``frame_k`` of the
    trajectory ``path``) with the exclusions' :class:`~navsim.navigation.exclusion.SkyGeometry` ``geometry``; the
    ecliptic and Galactic coordinates from its boresight and Sun directions (the poles where it has none)."""
    t = path.t[frame_k]
    coordinates = {}
    if geometry.boresight_I is not None and geometry.sun_I is not None:
        tt1, tt2 = tt_epoch(scenario["epoch_utc"], t)
        ra, dec = erfa.c2s(geometry.boresight_I)
        longitude, latitude = erfa.eqec06(tt1, tt2, ra, dec)
        sun_longitude, _ = erfa.eqec06(tt1, tt2, *erfa.c2s(geometry.sun_I))
        coordinates = {"helioecliptic_longitude": longitude - sun_longitude, "ecliptic_latitude": latitude,
                       "galactic_latitude": erfa.icrs2g(ra, dec)[1]}
    return Sightline(zenith=0.5 * np.pi - geometry.boresight_elevation, sun_zenith=0.5 * np.pi - geometry.sun_elevation,
                     sun_angle=geometry.sun_angle, moon_zenith=0.5 * np.pi - geometry.moon_elevation,
                     moon_angle=geometry.moon_angle, moon_phase_angle=geometry.moon_phase_angle, height=path.h[frame_k],
                     year=julian_year(scenario["epoch_utc"]) + t / JULIAN_YEAR_S, **coordinates)


def sky_sources(scenario, geometry, path, frame_k, band):
    """The :class:`~navsim.earth.sky_brightness.SkyBrightness` at the boresight of the frames in ``band`` (a
    :class:`startrack.photometry.bands.Band`): each source and the total (:func:`sightline`)."""
    site = scenario["star_sensor"]["photometry"]
    aerosol = Aerosol.of_site(site["visibility_km"], site["aerosol_optical_depth"], site["angstrom_exponent"])
    ground = {"relative_humidity": 0.01 * site["relative_humidity_percent"], "temperature_c": site["ground_temperature_c"],
              "aerosol": aerosol}
    air = extinction(band, path.h[frame_k], **ground)
    return sky_brightness(band.name, sightline(scenario, geometry, path, frame_k), **ground, air=air), air


def frame_sky(scenario, geometry, path, frame_k, photometry, q_BS_true):
    """The :class:`FrameSky` of the frames (samples ``frame_k`` of the trajectory ``path``) with the exclusions'
    :class:`~navsim.navigation.exclusion.SkyGeometry` ``geometry``, for the sensor of light budget ``photometry``
    (:class:`startrack.image.sensor_photometry.SensorPhotometry`) mounted at ``q_BS_true``."""
    sky, extinguishing = sky_sources(scenario, geometry, path, frame_k, photometry.band)
    background = sky.total
    omega_S = rot.rotate(rot.conjugate(q_BS_true), path.dtheta[frame_k - 1] * path.rate_hz)
    smear = np.hypot(omega_S[:, 0], omega_S[:, 1]) * photometry.exposure_s / photometry.pixel_scale
    return FrameSky(photometry=photometry, background_mag=background, sky_e_per_px_s=photometry.sky_e_per_px_s(background),
                    smear_px=smear, boresight_extinction=extinguishing.along(0.5 * np.pi - geometry.boresight_elevation),
                    up_I=geometry.up_I, air=extinguishing)


def seeing(star_sensor, scenario, geometry, path, frame_k):
    """The star sensor with the sky of its frames (:func:`frame_sky`) when it has a light budget, else itself."""
    budget = getattr(star_sensor, "photometry", None)
    if budget is None:
        return star_sensor
    return dataclasses.replace(star_sensor, sky=frame_sky(scenario, geometry, path, frame_k, budget, star_sensor.q_BS_true))
