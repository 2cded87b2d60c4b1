"""The sky a physical star sensor of a navigation run sees at its frames (:class:`navsim.sensors.frame_sky.FrameSky`):
the sky's brightness in the sensor's band at the boresight (:mod:`navsim.earth.sky_brightness`) from the frames'
Sun, Moon and boresight geometry (:mod:`navsim.navigation.exclusion`) and the observer's height, the extinction of
the air above the observer (:mod:`navsim.earth.atmosphere`; the site's humidity, temperature and aerosol from
``star_sensor.photometry``: visibility or optical depth, Ångström exponent) and the trail of a star near the boresight from the
body rate, for the nominal trajectory (seed-free, like the exclusions)."""

import dataclasses

import numpy as np

from navsim.earth.atmosphere import Aerosol, extinction
from navsim.earth.frames import julian_year
from navsim.earth.sky_brightness import Sightline, sky_brightness
from navsim.sensors.frame_sky import FrameSky
from startrack import rotation as rot

#: A Julian year [s].
JULIAN_YEAR_S = 365.25 * 86400.0


def frame_sky(scenario, geometry, path, frame_k, photometry, q_BS_true):
    """The :class:`FrameSky` of the frames (samples ``frame_k`` of the trajectory ``path``) with the exclusions'
    :class:`~navsim.navigation.exclusion.SkyGeometry` ``geometry``, for the sensor of light budget ``photometry``
    (:class:`startrack.image.sensor_photometry.SensorPhotometry`) mounted at ``q_BS_true``."""
    site = scenario["star_sensor"]["photometry"]
    h = path.h[frame_k]
    sight = Sightline(zenith=0.5 * np.pi - geometry.boresight_elevation, sun_zenith=0.5 * np.pi - geometry.sun_elevation,
                      sun_angle=geometry.sun_angle, moon_zenith=0.5 * np.pi - geometry.moon_elevation,
                      moon_angle=geometry.moon_angle, moon_phase_angle=geometry.moon_phase_angle, height=h,
                      year=julian_year(scenario["epoch_utc"]) + path.t[frame_k] / JULIAN_YEAR_S)
    aerosol = Aerosol.of_site(site["visibility_km"], site["aerosol_optical_depth"], site["angstrom_exponent"])
    ground = {"relative_humidity": 0.01 * site["relative_humidity_percent"], "temperature_c": site["ground_temperature_c"],
              "aerosol": aerosol}
    extinguishing = extinction(photometry.band, h, **ground)
    background = sky_brightness(photometry.band.name, sight, **ground, air=extinguishing).total
    omega_S = rot.rotate(rot.conjugate(q_BS_true), path.dtheta[frame_k - 1] * path.rate_hz)
    smear = np.hypot(omega_S[:, 0], omega_S[:, 1]) * photometry.exposure_s / photometry.pixel_scale
    return FrameSky(photometry=photometry, background_mag=background, sky_e_per_px_s=photometry.sky_e_per_px_s(background),
                    smear_px=smear, boresight_extinction=extinguishing.along(sight.zenith), up_I=geometry.up_I,
                    air=extinguishing)


def seeing(star_sensor, scenario, geometry, path, frame_k):
    """The star sensor with the sky of its frames (:func:`frame_sky`) when it has a light budget, else itself."""
    budget = getattr(star_sensor, "photometry", None)
    if budget is None:
        return star_sensor
    return dataclasses.replace(star_sensor, sky=frame_sky(scenario, geometry, path, frame_k, budget, star_sensor.q_BS_true))
