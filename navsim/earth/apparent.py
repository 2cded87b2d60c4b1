"""Apparent star directions seen from a moving observer, and what the star sensor's processing does
with them.

A star of catalog (ICRS, natural) direction u is seen at a(u) = ``startrack.catalog.apparent_place.aberrate(u,
v_I)`` by an observer of barycentric velocity v_I (the Earth's orbit, its rotation and the vehicle:
:func:`navsim.earth.orientation.observer_velocity`), up to 20.5" + v/c. Across a star sensor's field
the displacement is a rotation (about b × v for the boresight b) plus a differential part of at most
(v/c)·θ for a field of half-angle θ (1.7" at 10 deg): an attitude solved from apparent stars against
the catalog is turned by the rotation that takes b to a(b), :func:`fix_rotation`. The processing of
a real CNS removes it: it aberrates the catalog directions with the INS's own velocity and the
ephemeris before fusing stars, or turns a fix back by :func:`fix_rotation` of its own boresight.

Inside the air the stars are also refracted (:mod:`navsim.earth.refraction`): ``air`` = (up_I, A, B), the
local vertical in ICRS axes and the coefficients of its eq. (1) for each direction (None: no air). The
refraction acts on the aberrated direction (the light's direction at the observer, which the air bends).
"""

import numpy as np

from navsim.earth.refraction import refract
from startrack import aberrate
from startrack import rotation as rot


def apparent(u_I, v_I, air=None):
    """Apparent unit directions (N, 3) of the catalog directions ``u_I`` (N, 3): aberrated for the observer
    velocities ``v_I`` (N, 3) or (3,) [m/s], then refracted by ``air`` (module docstring; None: no air)."""
    seen = aberrate(u_I, v_I)
    return seen if air is None else refract(seen, *air)


def fix_rotation(boresight_I, v_I, air=None):
    """q_R (..., 4): the rotation taking the boresight direction ``boresight_I`` (..., 3) to its apparent
    direction for the observer velocity ``v_I`` (..., 3) [m/s] (and the ``air``). A fix solved from apparent
    stars is q_IS,apparent = q_R⁻¹ ⊗ q_IS (the sensor believes it points at the catalog star it sees at its
    centre, displaced away from the apex and raised towards the zenith)."""
    seen = aberrate(boresight_I, v_I)
    if air is not None:
        seen = refract(np.reshape(seen, (-1, 3)), *air).reshape(np.shape(seen))
    return rot.from_two_vectors(boresight_I, seen)


def field_stars(stars_I, boresight_I, radius, v_I, air=None):
    """(index, apparent directions (N, 3)) of the stars of ``stars_I`` (M, 3) within ``radius`` [rad] of
    the boresight, seen by the observer of velocity ``v_I`` (3,) [m/s] through ``air`` (a frame's (up_I (3,),
    A, B); None: no air)."""
    index = np.flatnonzero(stars_I @ boresight_I >= np.cos(radius))
    return index, apparent(stars_I[index], v_I, air)
