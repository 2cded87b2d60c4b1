"""Base-point grid and sub-catalog address index (eq. 1-2 and 7-8 of document 000).

The sphere is covered by ``n_d - 1`` declination circles (rings) ``L_j``,
``j = 1 .. n_d - 1`` (eq. 1), ring ``j`` carrying ``n_ra_j`` base points
equally spaced in right ascension from RA = 0 (eq. 2). Base point
``(l_d, l_ra)`` (both 1-based, as in 000) is the ``l_ra``-th point of ring
``l_d``, at RA ``2 pi (l_ra - 1) / n_ra_{l_d}``. In the flat arrays of the
navigation catalog it has the 0-based index :func:`base_index`
``= ring_offsets(n_d)[l_d - 1] + l_ra - 1``.

Eq. 7-8 map a boresight ``(alpha_b, delta_b)`` to the address of the base
point whose sub-catalog serves it. The four redundant neighbours of §4 are
the sub-catalogs of the boresights moved by ``rho_sub`` east, west, north and
south; the moves are taken along great circles (angular distance ``rho_sub``
on the sky, which is what §4's tolerance ``delta + (sqrt 2 - 1) rho_sub``
assumes), so they stay meaningful near the poles (a north move past the pole
comes down the other side, at RA + 180 deg) and wrap across RA = 0/360.
Away from the poles a north/south move is exactly ``(alpha, delta +- rho_sub)``.

All angles in radians.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from startrack.base.errors import InputError
from startrack.geometry.sphere import local_frame

#: Order of the redundant neighbours returned by :func:`redundant_neighbours`.
NEIGHBOUR_DIRECTIONS = ("east", "west", "north", "south")


def _check_n_d(n_d) -> int:
    if isinstance(n_d, bool) or int(n_d) != n_d or not 3 <= int(n_d) <= 2000:
        raise InputError(f"number of declination divisions n_d = {n_d} is not an integer between 3 and 2000.")
    return int(n_d)


@functools.lru_cache(maxsize=16)
def _rings(n_d: int):
    j = np.arange(1, n_d)
    phi = np.pi * j / n_d - np.pi / 2.0  # eq. 1
    n_ra = np.floor(0.5 + np.sqrt(3.0) * n_d * np.cos(phi)).astype(np.int64)  # eq. 2
    offsets = np.concatenate([[0], np.cumsum(n_ra)])
    for array in (phi, n_ra, offsets):
        array.flags.writeable = False
    return phi, n_ra, offsets


def ring_declinations(n_d: int) -> np.ndarray:
    """Declinations phi_j [rad] of rings j = 1 .. n_d - 1 (eq. 1 of 000): pi j / n_d - pi / 2."""
    return _rings(_check_n_d(n_d))[0]


def ring_sizes(n_d: int) -> np.ndarray:
    """Base points per ring n_ra_j = floor(1/2 + sqrt(3) n_d cos phi_j), j = 1 .. n_d - 1 (eq. 2 of 000)."""
    return _rings(_check_n_d(n_d))[1]


def ring_offsets(n_d: int) -> np.ndarray:
    """Flat index of the first base point of each ring, plus the total count at the end (length n_d)."""
    return _rings(_check_n_d(n_d))[2]


def base_point_count(n_d: int) -> int:
    """Total number of base points N = sum of n_ra_j (3100 for n_d = 53)."""
    return int(ring_offsets(n_d)[-1])


def base_points_radec(n_d: int):
    """(RA, Dec) [rad] of all base points in flat-index order (ring by ring, RA from 0 upwards)."""
    phi, n_ra, offsets = _rings(_check_n_d(n_d))
    ring = np.repeat(np.arange(n_d - 1), n_ra)
    position = np.arange(offsets[-1]) - offsets[ring]
    return 2.0 * np.pi * position / n_ra[ring], phi[ring]


def address(ra, dec, n_d: int):
    """Sub-catalog address (l_d, l_ra), 1-based int arrays, of boresights (ra, dec) [rad] (eq. 7-8 of 000).

    ``l_d = 1`` below ``(2 - n_d) pi / (2 n_d)``, ``n_d - 1`` above
    ``(n_d - 2) pi / (2 n_d)``, else ``round((delta + pi/2) n_d / pi)``;
    ``l_ra = 1`` for ``alpha > (2 n_ra - 1) pi / n_ra`` or ``alpha < pi / n_ra``,
    else ``round(alpha n_ra / (2 pi)) + 1`` with ``n_ra = n_ra_{l_d}``. Rounding is
    half up (四舍五入). RA is first wrapped into [0, 2 pi).
    """
    if np.ndim(ra) == 0 and np.ndim(dec) == 0:
        return _address_scalar(float(ra), float(dec), _check_n_d(n_d))
    phi, n_ra, _ = _rings(_check_n_d(n_d))
    ra = np.mod(np.asarray(ra, dtype=float), 2.0 * np.pi)
    dec = np.asarray(dec, dtype=float)
    if not (np.all(np.isfinite(ra)) and np.all(np.isfinite(dec))):
        raise InputError("boresight right ascension and declination must be finite numbers.")
    if np.any(np.abs(dec) > np.pi / 2.0 + 1e-12):
        raise InputError("boresight declination must lie in [-90, 90] deg.")
    low = (2 - n_d) * np.pi / (2 * n_d)
    l_d = np.floor((dec + np.pi / 2.0) * n_d / np.pi + 0.5).astype(np.int64)
    l_d = np.where(dec < low, 1, np.where(dec > -low, n_d - 1, l_d))
    l_d = np.clip(l_d, 1, n_d - 1)  # only reached by round-off at the switching declinations
    n = n_ra[l_d - 1]
    l_ra = np.floor(ra * n / (2.0 * np.pi) + 0.5).astype(np.int64) + 1
    wrap = (ra > (2 * n - 1) * np.pi / n) | (ra < np.pi / n)
    l_ra = np.where(wrap, 1, l_ra)
    l_ra = np.where(l_ra > n, 1, l_ra)  # ra rounding up to exactly 2 pi
    return l_d, l_ra


@functools.lru_cache(maxsize=16)
def _ring_lists(n_d: int):
    _, n_ra, offsets = _rings(n_d)
    return n_ra.tolist(), offsets.tolist()


def _address_scalar(ra: float, dec: float, n_d: int):
    """Eq. 7-8 for one boresight with plain floats (the per-frame hot path; same results as the array path)."""
    if not (math.isfinite(ra) and math.isfinite(dec)):
        raise InputError("boresight right ascension and declination must be finite numbers.")
    if abs(dec) > math.pi / 2.0 + 1e-12:
        raise InputError("boresight declination must lie in [-90, 90] deg.")
    ra = ra % (2.0 * math.pi)
    low = (2 - n_d) * math.pi / (2 * n_d)
    if dec < low:
        l_d = 1
    elif dec > -low:
        l_d = n_d - 1
    else:
        l_d = min(max(math.floor((dec + math.pi / 2.0) * n_d / math.pi + 0.5), 1), n_d - 1)
    n = _ring_lists(n_d)[0][l_d - 1]
    if ra > (2 * n - 1) * math.pi / n or ra < math.pi / n:
        l_ra = 1
    else:
        l_ra = math.floor(ra * n / (2.0 * math.pi) + 0.5) + 1
        if l_ra > n:
            l_ra = 1
    return l_d, l_ra


def base_index(l_d, l_ra, n_d: int):
    """0-based flat base-point (= sub-catalog) index of address (l_d, l_ra), 1-based as in 000."""
    if np.ndim(l_d) == 0 and np.ndim(l_ra) == 0:
        n_ra_list, offsets_list = _ring_lists(_check_n_d(n_d))
        l_d, l_ra = int(l_d), int(l_ra)
        if not 1 <= l_d <= n_d - 1:
            raise InputError(f"address ring l_d must lie in 1 .. {n_d - 1} for n_d = {n_d}.")
        if not 1 <= l_ra <= n_ra_list[l_d - 1]:
            raise InputError("address l_ra is outside its ring (1 .. n_ra of ring l_d).")
        return offsets_list[l_d - 1] + l_ra - 1
    _, n_ra, offsets = _rings(_check_n_d(n_d))
    l_d = np.asarray(l_d, dtype=np.int64)
    l_ra = np.asarray(l_ra, dtype=np.int64)
    if np.any((l_d < 1) | (l_d > n_d - 1)):
        raise InputError(f"address ring l_d must lie in 1 .. {n_d - 1} for n_d = {n_d}.")
    if np.any((l_ra < 1) | (l_ra > n_ra[l_d - 1])):
        raise InputError("address l_ra is outside its ring (1 .. n_ra of ring l_d).")
    return offsets[l_d - 1] + l_ra - 1


def address_of_index(index, n_d: int):
    """Inverse of :func:`base_index`: (l_d, l_ra), 1-based, of flat base-point indices."""
    _, _, offsets = _rings(_check_n_d(n_d))
    index = np.asarray(index, dtype=np.int64)
    if np.any((index < 0) | (index >= offsets[-1])):
        raise InputError(f"base-point index must lie in 0 .. {offsets[-1] - 1} for n_d = {n_d}.")
    ring = np.searchsorted(offsets, index, side="right") - 1
    return ring + 1, index - offsets[ring] + 1


def sub_catalog_index(ra, dec, n_d: int):
    """Flat sub-catalog index serving boresights (ra, dec) [rad]: eq. 7-8 then :func:`base_index`."""
    if isinstance(ra, float) and isinstance(dec, float):  # one boresight (the per-frame hot path)
        n_d = _check_n_d(n_d)
        l_d, l_ra = _address_scalar(ra, dec, n_d)
        return _ring_lists(n_d)[1][l_d - 1] + l_ra - 1
    l_d, l_ra = address(ra, dec, n_d)
    return base_index(l_d, l_ra, n_d)


def offset_directions(ra, dec, distance):
    """(RA, Dec) [rad] of the points ``distance`` [rad] east, west, north and south of (ra, dec).

    Moves along great circles: east/west along the local parallel's tangent,
    north/south along the meridian (crossing the pole if needed). Returns two
    arrays of shape (..., 4) in :data:`NEIGHBOUR_DIRECTIONS` order.
    """
    u, east, north = local_frame(ra, dec)
    directions = np.stack([east, -east, north, -north], axis=-2)  # (..., 4, 3)
    moved = np.cos(distance) * u[..., None, :] + np.sin(distance) * directions
    new_ra = np.mod(np.arctan2(moved[..., 1], moved[..., 0]), 2.0 * np.pi)
    new_dec = np.arcsin(np.clip(moved[..., 2], -1.0, 1.0))
    return new_ra, new_dec


def redundant_neighbours(ra, dec, n_d: int, rho_sub: float):
    """Addresses (l_d, l_ra) of the 4 redundant sub-catalogs of §4 of 000 for boresight (ra, dec) [rad].

    The boresights ``rho_sub`` [rad] east, west, north and south of (ra, dec)
    (:func:`offset_directions`) are addressed by eq. 7-8. Returns two int arrays
    of shape (..., 4) in :data:`NEIGHBOUR_DIRECTIONS` order.
    """
    if not np.isfinite(rho_sub) or not 0.0 < rho_sub < np.pi / 2:
        raise InputError(f"sub-catalog radius rho_sub = {rho_sub} rad is not in (0, pi/2).")
    new_ra, new_dec = offset_directions(ra, dec, rho_sub)
    return address(new_ra, new_dec, n_d)
