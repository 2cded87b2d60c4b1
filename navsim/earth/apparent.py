"""Apparent star directions seen from a moving observer, and what the star sensor's processing does
with them.

A star of catalog (ICRS, natural) direction u is seen at a(u) = ``startrack.aberration.aberrate(u,
v_I)`` by an observer of barycentric velocity v_I (the Earth's orbit, its rotation and the vehicle:
:func:`navsim.earth.orientation.observer_velocity`), up to 20.5" + v/c. Across a star sensor's field
the displacement is a rotation (about b × v for the boresight b) plus a differential part of at most
(v/c)·θ for a field of half-angle θ (1.7" at 10 deg): an attitude solved from apparent stars against
the catalog is turned by the rotation that takes b to a(b), :func:`fix_rotation`. The processing of
a real CNS removes it: it aberrates the catalog directions with the INS's own velocity and the
ephemeris before fusing stars, or turns a fix back by :func:`fix_rotation` of its own boresight.
"""

import numpy as np

from startrack import rotation as rot
from startrack.aberration import aberrate


def fix_rotation(boresight_I, v_I):
    """q_R (..., 4): the rotation taking the boresight direction ``boresight_I`` (..., 3) to its apparent
    direction for the observer velocity ``v_I`` (..., 3) [m/s]. A fix solved from apparent stars is
    q_IS,apparent = q_R⁻¹ ⊗ q_IS (the sensor believes it points at the catalog star it sees at its
    centre, displaced away from the apex)."""
    return rot.from_two_vectors(boresight_I, aberrate(boresight_I, v_I))


def field_stars(stars_I, boresight_I, radius, v_I):
    """(index, apparent directions (N, 3)) of the stars of ``stars_I`` (M, 3) within ``radius`` [rad] of
    the boresight, aberrated for the observer velocity ``v_I`` (3,) [m/s]."""
    index = np.flatnonzero(stars_I @ boresight_I >= np.cos(radius))
    return index, aberrate(stars_I[index], v_I)
