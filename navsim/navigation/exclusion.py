"""The frames the sky takes from the star sensor of a navigation run: the Sun or the Moon within its
exclusion angle of the boresight, or the boresight below the lowest elevation the sensor looks at
(``star_sensor.sun_exclusion_deg``, ``moon_exclusion_deg``, ``min_elevation_deg``; 0, 0 and −90: none).

The geometry is the truth's (the nominal trajectory, the true mounting; the random gravity field moves
no attitude) at the frame times, the Sun and the Moon from :class:`navsim.earth.bodies.SunMoon`; a frame
is excluded for the first of Sun, Moon, horizon that applies. The excluded frames go to the sensor's
:class:`~navsim.sensors.faults.SensorFaults` (no measurement, like an outage) for the runs and the
covariance analysis alike.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from navsim.earth.bodies import SunMoon
from navsim.truth.sky import inertial_attitude
from startrack import angular_distance, units
from startrack import rotation as rot

#: The reasons of an excluded frame, in the order they are tested.
REASONS = ("Sun in the exclusion cone", "Moon in the exclusion cone", "boresight below the lowest elevation")


@dataclass(frozen=True)
class SkyGeometry:
    """Per frame: the angles [rad] of the Sun and the Moon from the boresight, the boresight's elevation,
    the Sun's and the Moon's elevations [rad], the Moon's phase angle [rad] and illuminated fraction, the
    local vertical (F, 3) in ICRS axes, and the reason each frame is excluded (an index of :data:`REASONS`,
    −1: not excluded); the boresight's and the Sun's unit directions (F, 3) in ICRS axes (the zodiacal light's and
    the starlight's geometry; None: not known)."""

    sun_angle: np.ndarray
    moon_angle: np.ndarray
    boresight_elevation: np.ndarray
    sun_elevation: np.ndarray
    moon_elevation: np.ndarray
    moon_phase_angle: np.ndarray
    moon_illuminated: np.ndarray
    up_I: np.ndarray
    reason: np.ndarray
    boresight_I: np.ndarray | None = None
    sun_I: np.ndarray | None = None

    def counts(self):
        """{reason: frames it excludes} of every reason."""
        return {text: int(np.sum(self.reason == k)) for k, text in enumerate(REASONS)}


def geometry(scenario, path, orientation, frame_k, q_BS_true):
    """The :class:`SkyGeometry` of the frames (the samples ``frame_k`` of the trajectory ``path``, the Earth's
    ``orientation`` at them) for the sensor mounted at ``q_BS_true``."""
    lat, lon, h = path.lat[frame_k], path.lon[frame_k], path.h[frame_k]
    bodies = SunMoon.compute(scenario["epoch_utc"], orientation, lat, lon, h)
    q_IB = inertial_attitude(path, orientation, frame_k)
    boresight = rot.rotate(rot.multiply(q_IB, q_BS_true), np.array([0.0, 0.0, 1.0]))
    sensor = scenario["star_sensor"]
    sun, moon = angular_distance(boresight, bodies.sun_I), angular_distance(boresight, bodies.moon_I)
    elevation = bodies.elevation(boresight)
    excluded = (sun < units.deg_to_rad(sensor["sun_exclusion_deg"]), moon < units.deg_to_rad(sensor["moon_exclusion_deg"]),
                elevation < units.deg_to_rad(sensor["min_elevation_deg"]))
    reason = np.full(frame_k.size, -1)
    for k in reversed(range(len(REASONS))):
        reason[excluded[k]] = k
    return SkyGeometry(sun_angle=sun, moon_angle=moon, boresight_elevation=elevation,
                       sun_elevation=bodies.elevation(bodies.sun_I), moon_elevation=bodies.elevation(bodies.moon_I),
                       moon_phase_angle=bodies.moon_phase_angle, moon_illuminated=bodies.moon_illuminated,
                       up_I=bodies.up_I, reason=reason, boresight_I=boresight, sun_I=bodies.sun_I)


def excluding(star_sensor, sky, t_frames):
    """The star sensor with the frames (times ``t_frames`` [s]) that ``sky`` excludes added to its faults."""
    hit = sky.reason >= 0
    faults = dataclasses.replace(star_sensor.faults, excluded_s=np.asarray(t_frames, dtype=float)[hit],
                                 excluded_reasons=tuple(REASONS[k] for k in sky.reason[hit]))
    return dataclasses.replace(star_sensor, faults=faults)


def series(sky):
    """The run series of the frames' sky: the Sun's and the Moon's angles from the boresight, the boresight's and
    the Sun's elevations [rad] and each frame's exclusion (an index of :data:`REASONS`, −1: none)."""
    return {"sun_angle": sky.sun_angle, "moon_angle": sky.moon_angle, "boresight_elevation": sky.boresight_elevation,
            "sun_elevation": sky.sun_elevation, "sky_excluded": sky.reason}
