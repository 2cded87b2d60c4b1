"""Stars for the apparent-place tests of both packages: random directions, skyfield's synthetic
stars of them and back, and the Sun's light deflection that skyfield applies and ours leaves out."""

import erfa
import numpy as np

from startrack.base import units
from startrack.geometry import sphere


def random_directions(n, seed=0):
    """``n`` unit vectors (n, 3) uniform on the sphere."""
    u = np.random.default_rng(seed).normal(size=(n, 3))
    return u / np.linalg.norm(u, axis=-1, keepdims=True)


def skyfield_stars(u):
    """skyfield's ``Star`` of catalog directions u (n, 3): no parallax (skyfield puts them at 1 Gpc),
    no proper motion."""
    from skyfield.api import Star

    ra, dec = sphere.vector_to_radec(u)
    return Star(ra_hours=ra / (15.0 * units.DEG), dec_degrees=dec / units.DEG)


def skyfield_vectors(position):
    """Unit vectors (n, 3) of a skyfield position's ICRS RA/Dec (GCRS axes for an Earth observer)."""
    ra, dec, _ = position.radec()
    return sphere.radec_to_vector(ra.radians, dec.radians)


def deflected_by_the_sun(u, jd1, jd2):
    """erfa.ldsun for the geocentre at the TDB date: the Sun's light deflection of directions u,
    which skyfield's apparent() applies and ours leaves out (<= 4 mas at 90 deg from the Sun,
    0.47" at 1 deg)."""
    heliocentric = erfa.epv00(jd1, jd2)[0]["p"]
    distance = np.linalg.norm(heliocentric)
    return erfa.ldsun(u, heliocentric / distance, distance)
