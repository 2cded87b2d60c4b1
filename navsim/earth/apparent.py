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

What the processing corrects is one rule, :class:`ApparentPlace`: the filter at each frame (its own velocity and
model air) and the covariance analysis along the nominal (one row per frame) both use it.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.refraction import refract
from startrack import aberrate
from startrack import rotation as rot


def apparent(u_I, v_I, air=None):
    """Apparent unit directions (N, 3) of the catalog directions ``u_I`` (N, 3): aberrated for the observer
    velocities ``v_I`` (N, 3) or (3,) [m/s], then refracted by ``air`` (module docstring; None: no air)."""
    return ApparentPlace(v_I, air).apparent(u_I)


def fix_rotation(boresight_I, v_I, air=None):
    """q_R (..., 4): the rotation taking the boresight direction ``boresight_I`` (..., 3) to its apparent
    direction for the observer velocity ``v_I`` (..., 3) [m/s] (and the ``air``). A fix solved from apparent
    stars is q_IS,apparent = q_R⁻¹ ⊗ q_IS (the sensor believes it points at the catalog star it sees at its
    centre, displaced away from the apex and raised towards the zenith)."""
    return ApparentPlace(v_I, air).boresight_rotation(boresight_I)


def field_stars(stars_I, boresight_I, radius, v_I, air=None):
    """(index, apparent directions (N, 3)) of the stars of ``stars_I`` (M, 3) within ``radius`` [rad] of
    the boresight, seen by the observer of velocity ``v_I`` (3,) [m/s] through ``air`` (a frame's (up_I (3,),
    A, B); None: no air)."""
    index = np.flatnonzero(stars_I @ boresight_I >= np.cos(radius))
    return index, apparent(stars_I[index], v_I, air)


@dataclass(frozen=True)
class ApparentPlace:
    """The apparent-place rule of a star sensor's processing: catalog directions aberrated with the observer
    velocity ``v_I`` [m/s] ((3,) or a row per direction; None: it does not correct aberration), then refracted by
    ``air`` (up_I, A, B) (one or a row per direction; None: it does not correct refraction)."""

    v_I: object = None
    air: object = None

    def rows(self, index):
        """The rule of the rows ``index`` of per-row velocities and air (a frame's rule for each star of it)."""
        return ApparentPlace(None if self.v_I is None else self.v_I[index],
                             None if self.air is None else tuple(x[index] for x in self.air))

    def directions(self, u):
        """(aberrated, apparent) unit directions (..., 3), contiguous, of the catalog directions ``u`` (..., 3) (the
        velocity broadcast with them); their difference is the refraction the processing corrects."""
        aberrated = np.ascontiguousarray(u if self.v_I is None else aberrate(u, self.v_I))
        if self.air is None:
            return aberrated, aberrated
        return aberrated, np.ascontiguousarray(refract(np.reshape(aberrated, (-1, 3)), *self.air).reshape(aberrated.shape))

    def apparent(self, u):
        """The apparent directions (..., 3) of the catalog directions ``u`` (..., 3) (:meth:`directions`)."""
        return self.directions(u)[1]

    def refraction_rotation(self, boresight_I):
        """ρ (..., 3) [rad, ICRS axes]: the rotation vectors by which the air raises the aberrated boresights
        ``boresight_I`` (..., 3), b × refract(b) (eq. 3 of :mod:`navsim.earth.refraction`)."""
        aberrated, refracted = self.directions(boresight_I)
        return np.cross(aberrated, refracted)

    def boresight_rotation(self, boresight_I):
        """q_R (..., 4): the rotations taking the boresights ``boresight_I`` (..., 3) to their apparent directions."""
        return rot.from_two_vectors(boresight_I, self.apparent(boresight_I))

    def turn_back(self, q_IS):
        """The fixes ``q_IS`` (4,) or (N, 4) turned back by the rotation of their boresights to their apparent
        directions (:meth:`boresight_rotation`), as far as the processing corrects them."""
        if self.v_I is None and self.air is None:
            return q_IS
        boresight = rot.rotate(q_IS, np.array([0.0, 0.0, 1.0]))
        return rot.normalize(rot.multiply(self.boresight_rotation(boresight), q_IS))
