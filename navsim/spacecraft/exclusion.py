"""What the sky from orbit takes from each head: the frames whose boresight has the Sun, the Moon or the bright
Earth limb inside its exclusion angle (``sun_exclusion_deg``, ``moon_exclusion_deg``, ``earth_exclusion_deg``;
the limb raised by ``earth_limb_height_km``).

The geometry is the truth's (the spacecraft's attitude from its dynamics, each head's true mounting) at the frame
times; the Sun and the Moon are geocentric from :func:`navsim.earth.bodies.geocentric`, seen from the orbit; the
Earth's disc is :class:`navsim.orbit.earth_disc.EarthDisc`. A body the Earth hides (the Sun in eclipse, the Moon
below the limb) blinds no head: its own exclusion does not apply (the limb's, near it, does). A frame is excluded
for the first of Sun, Moon, limb that applies; the excluded frames go to the head's
:class:`~navsim.sensors.faults.SensorFaults` (no measurement, like an outage).
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from navsim.orbit.earth_disc import EarthDisc
from startrack import angular_distance, units
from startrack import rotation as rot

#: The reasons of an excluded frame, in the order they are tested.
REASONS = ("Sun in the exclusion cone", "Moon in the exclusion cone", "Earth's limb in the exclusion cone")


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


@dataclass(frozen=True)
class HeadSky:
    """Per frame of one head: the boresight (F, 3) in GCRS, the angles [rad] of the Sun and the Moon from it, its
    angle above the bright limb (negative: on the Earth), whether the Earth hides the Sun and the Moon, and the
    reason each frame is excluded (an index of :data:`REASONS`, −1: not excluded)."""

    boresight: np.ndarray
    sun_angle: np.ndarray
    moon_angle: np.ndarray
    limb_angle: np.ndarray
    sun_hidden: np.ndarray
    moon_hidden: np.ndarray
    reason: np.ndarray

    def counts(self):
        """{reason: frames it excludes} of every reason."""
        return {text: int(np.sum(self.reason == k)) for k, text in enumerate(REASONS)}


def head_sky(head, q_IB, q_BS_true, r_I, sun, moon, pole):
    """The :class:`HeadSky` of the head table ``head`` mounted at ``q_BS_true`` on the body of attitudes ``q_IB``
    (F, 4) at the geocentric positions ``r_I`` (F, 3) [m], with the geocentric Sun and Moon (F, 3) [m] and the Earth's
    axis ``pole`` (GCRS)."""
    boresight = rot.rotate(rot.multiply(q_IB, q_BS_true), np.array([0.0, 0.0, 1.0]))
    to_sun, to_moon = _unit(sun - r_I), _unit(moon - r_I)
    solid = EarthDisc(r_I, 0.0, pole)
    limb = EarthDisc(r_I, 1e3 * head["earth_limb_height_km"], pole).limb_angle(boresight)
    sun_hidden, moon_hidden = solid.limb_angle(to_sun) < 0.0, solid.limb_angle(to_moon) < 0.0
    sun_angle, moon_angle = angular_distance(boresight, to_sun), angular_distance(boresight, to_moon)
    excluded = (~sun_hidden & (sun_angle < units.deg_to_rad(head["sun_exclusion_deg"])),
                ~moon_hidden & (moon_angle < units.deg_to_rad(head["moon_exclusion_deg"])),
                limb < units.deg_to_rad(head["earth_exclusion_deg"]))
    reason = np.full(len(q_IB), -1)
    for k in reversed(range(len(REASONS))):
        reason[excluded[k]] = k
    return HeadSky(boresight=boresight, sun_angle=sun_angle, moon_angle=moon_angle, limb_angle=limb, sun_hidden=sun_hidden,
                   moon_hidden=moon_hidden, reason=reason)


def excluding(sensor, sky, t_frames):
    """The head's sensor with the frames (times ``t_frames`` [s]) that ``sky`` excludes added to its faults."""
    hit = sky.reason >= 0
    faults = dataclasses.replace(sensor.faults, excluded_s=np.asarray(t_frames, dtype=float)[hit],
                                 excluded_reasons=tuple(REASONS[k] for k in sky.reason[hit]))
    return dataclasses.replace(sensor, faults=faults)
