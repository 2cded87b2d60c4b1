"""Field-of-view star pre-selection by right-ascension / declination span (003 §1.3, eq. 2-5).

003 keeps the stars of a field centred on the boresight (ra0, dec0) by a declination band (eq. 2)
and a right-ascension window whose half-width grows with |dec0| (eq. 3), the whole RA circle once
the field reaches a pole (eq. 4), with the wrap-around at RA = 0 handled by case (eq. 5).  These are
exactly the RA/Dec bounds of a spherical cap: for a cap of angular radius rho around (ra0, dec0)

* eq. 2: |dec - dec0| <= rho;
* eq. 3: |ra - ra0| <= asin(sin(rho) / cos(dec0)) while sin(rho) < cos(dec0);
* eq. 4: every RA when sin(rho) >= cos(dec0) (the cap contains a pole);
* eq. 5: the RA difference is taken modulo 2 pi into [-pi, pi), which is the case split of eq. 5.

003 uses rho = A/2 for an A x A field, i.e. the circle *inscribed* in the square field; the corners of
the square (up to atan(sqrt(2) tan(A/2)) from the boresight) fall outside it and would be dropped.
Use :func:`field_radius` (the circumscribed cone of the rectangular field) for a pre-filter that never
drops a star in the field; the exact test follows on the survivors (:func:`cone_mask`, or the camera's
projection).  The pre-filter costs two comparisons per star on the catalog's RA/Dec arrays.
"""

import numpy as np

from startrack.base.errors import InputError

#: added to the cap radius in the RA/Dec tests so stars on the boundary survive rounding [rad]
_BOUNDARY_MARGIN = 1e-9


def field_radius(fov_x, fov_y=None):
    """Half-angle [rad] of the cone circumscribing a pinhole field fov_x x fov_y [rad] (square if fov_y None).

    The corner direction is (tan(fov_x/2), tan(fov_y/2), 1), so the radius is
    atan(sqrt(tan^2(fov_x/2) + tan^2(fov_y/2))).
    """
    fov_y = fov_x if fov_y is None else fov_y
    for name, value in (("fov_x", fov_x), ("fov_y", fov_y)):
        if not (np.isfinite(value) and 0.0 < value < np.pi):
            raise InputError(f"field_radius: {name} must be in (0, pi) rad; got {value!r}.")
    return float(np.arctan(np.hypot(np.tan(0.5 * fov_x), np.tan(0.5 * fov_y))))


def radec_window(ra0, dec0, radius):
    """(dec_min, dec_max, ra_half_span) [rad] of the cap of `radius` around (ra0, dec0) (003 eq. 2-4).

    ra_half_span is pi when the cap contains a pole (eq. 4).  Scalars in radians.
    """
    if not (np.isfinite(radius) and 0.0 < radius < 0.5 * np.pi):
        raise InputError(f"radec_window: radius must be in (0, pi/2) rad; got {radius!r}.")
    if not (np.isfinite(ra0) and np.isfinite(dec0) and abs(dec0) <= 0.5 * np.pi):
        raise InputError(f"radec_window: (ra0, dec0) must be finite with |dec0| <= pi/2; got ({ra0!r}, {dec0!r}).")
    dec_min = max(dec0 - radius, -0.5 * np.pi)                          # eq. 2
    dec_max = min(dec0 + radius, 0.5 * np.pi)
    sin_radius, cos_dec0 = np.sin(radius), np.cos(dec0)
    if sin_radius >= cos_dec0:                                          # eq. 4: a pole is in the cap
        return dec_min, dec_max, np.pi
    return dec_min, dec_max, float(np.arcsin(sin_radius / cos_dec0))   # eq. 3


def radec_prefilter(ra, dec, ra0, dec0, radius):
    """Boolean mask of catalog stars (ra, dec arrays [rad]) inside the RA/Dec window (003 eq. 5).

    A superset of the stars within `radius` of the boresight: no star of the cap is ever dropped.
    """
    dec_min, dec_max, half_span = radec_window(ra0, dec0, radius)
    ra = np.asarray(ra, dtype=float)
    dec = np.asarray(dec, dtype=float)
    in_dec = (dec >= dec_min - _BOUNDARY_MARGIN) & (dec <= dec_max + _BOUNDARY_MARGIN)
    if half_span >= np.pi:
        return in_dec
    delta_ra = np.mod(ra - ra0 + np.pi, 2.0 * np.pi) - np.pi            # eq. 5 without the case split
    return in_dec & (np.abs(delta_ra) <= half_span + _BOUNDARY_MARGIN)


def cone_mask(vectors, boresight, radius):
    """Exact test: unit vectors (N, 3) within `radius` [rad] of the unit boresight (3,)."""
    vectors = np.asarray(vectors, dtype=float)
    return vectors @ np.asarray(boresight, dtype=float) >= np.cos(radius)
