"""The frames of the INS (docs/design.md): n (NED at the vehicle), e (ITRS/ECEF, WGS-84) and
i (the star catalog's ICRS), their rotations and rates.

C_ab rotates b-frame vectors into a (v_a = C_ab v_b); ω_ab^c is the rate of frame b relative to a
in c axes. Compiled functions of vectors return component tuples (see :mod:`navsim.earth.wgs84`).
"""

import contextlib
import warnings
from datetime import datetime, timedelta

import erfa
import numpy as np

from navsim.earth.wgs84 import OMEGA_IE, radii
from startrack import InputError, njit


def c_en(lat, lon):
    """C_en (..., 3, 3): NED axes at (L, λ) [rad] into ECEF; its columns are the north, east and down
    unit vectors in e (the transpose of Groves' C_e^n, 2nd ed. eq. 2.150)."""
    lat = np.asarray(lat, dtype=float)
    lon = np.asarray(lon, dtype=float)
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    zero = np.zeros_like(sl)
    north = np.stack([-sl * co, -sl * so, cl], axis=-1)
    east = np.stack([-so, co, zero], axis=-1)
    down = np.stack([-cl * co, -cl * so, -sl], axis=-1)
    return np.stack([north, east, down], axis=-1)


def local_up(c_ie, lat, lon):
    """The local vertical (..., 3) in ICRS axes at geodetic (L, λ) (...,) [rad] for C_ie (..., 3, 3): C_ie C_en
    [0, 0, −1] (the ellipsoid's normal, up)."""
    return np.einsum("...ij,...j->...i", c_ie, -c_en(lat, lon)[..., 2])


@njit
def q_en(lat, lon):
    """The quaternion of :func:`c_en` as components (x, y, z, w) (scalars or arrays alike; compiled):
    C_en = R_z(λ) R_y(−L − π/2), so q_en = q_z(λ) ⊗ q_y(−L − π/2)."""
    sz, cz = np.sin(0.5 * lon), np.cos(0.5 * lon)
    half = -0.5 * lat - 0.25 * np.pi
    sy, cy = np.sin(half), np.cos(half)
    return -sz * sy, cz * sy, sz * cy, cz * cy


@njit
def earth_rate_n(lat):
    """ω_ie^n = ω_ie [cos L, 0, −sin L] [rad/s] as (north, east, down) (Groves eq. 2.123)."""
    return OMEGA_IE * np.cos(lat), 0.0 * lat, -OMEGA_IE * np.sin(lat)


@njit
def transport_rate_n(lat, h, v_north, v_east):
    """Transport rate ω_en^n = [v_E/(R_N+h), −v_N/(R_M+h), −v_E tan L/(R_N+h)] [rad/s] as
    (north, east, down) (Groves eq. 5.44, R_M meridian, R_N prime vertical)."""
    r_m, r_n = radii(lat)
    return v_east / (r_n + h), -v_north / (r_m + h), -v_east * np.tan(lat) / (r_n + h)


#: Step [s] of the grid of :func:`slowly`: the fastest terms of the precession-nutation (13.7 d) and of the
#: geocentre's velocity (the Moon's pull, 27.3 d; the year) leave < 1e-14 rad and < 1e-6 m/s between its points.
SLOW_STEP_S = 60.0


def utc_epoch(text):
    """Two-part Julian date (jd1, jd2) of a UTC calendar epoch 'YYYY-MM-DDTHH:MM:SS[.ffffff]'."""
    try:
        when = datetime.fromisoformat(text)
    except (TypeError, ValueError):
        raise InputError(f"epoch_utc: expected 'YYYY-MM-DDTHH:MM:SS', got {text!r}") from None
    if when.utcoffset() not in (None, timedelta(0)):
        raise InputError(f"epoch_utc: must be UTC (no offset or Z), got {text!r}")
    seconds = when.second + when.microsecond * 1e-6
    with utc_offsets_extrapolated():
        return erfa.dtf2d("UTC", when.year, when.month, when.day, when.hour, when.minute, seconds)


#: TAI − GPST [s]: GPS time is TAI less the 19 leap seconds of its 1980 epoch (IS-GPS-200, §3.3.4).
TAI_MINUS_GPST_S = 19.0


def gpst_epoch_utc(gpst_s):
    """The UTC calendar epoch 'YYYY-MM-DDTHH:MM:SS.ffffff' of ``gpst_s`` [s GPST since 1970-01-01, GPST counted
    without leap seconds]: UTC = GPST + 19 s − (TAI − UTC), the leap seconds of erfa's table (``erfa.dat``) at
    that date (18 s from 2017); an InputError for a time before GPS time began (1980-01-06) or after 2100."""
    if not 315964800.0 <= gpst_s <= 4102444800.0:
        raise InputError(f"GNSS time {gpst_s!r} s is not GPST seconds since 1970 between 1980-01-06 and 2100")
    when = datetime(1970, 1, 1) + timedelta(seconds=float(gpst_s))
    with utc_offsets_extrapolated():
        tai_utc = erfa.dat(when.year, when.month, when.day, 0.0)
    return (when + timedelta(seconds=TAI_MINUS_GPST_S - float(tai_utc))).isoformat(timespec="microseconds")


@contextlib.contextmanager
def utc_offsets_extrapolated():
    """A context in which erfa's "dubious year" (a UTC before 1960 or years past its leap-second table: it takes the
    table's nearest UTC − TAI, within seconds) is no warning on the user's terminal: a sky needs the epoch to
    seconds, and a star sensor's epoch is checked against the ephemerides' span instead."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*dubious year.*", category=erfa.ErfaWarning)
        yield


def _utc(epoch_utc, t):
    """Two-part UTC Julian date of ``t`` [s] after the UTC epoch (uniform seconds, no leap inserted)."""
    utc1, utc2 = utc_epoch(epoch_utc)
    return utc1, utc2 + np.asarray(t, dtype=float) / 86400.0


def tt_epoch(epoch_utc, t=0.0):
    """Two-part TT Julian date (tt1, tt2) of ``t`` [s] after the UTC epoch ``epoch_utc`` (TT is TDB
    within 2 ms: what :func:`startrack.catalog.apparent_place.earth_barycentric_velocity` takes)."""
    with utc_offsets_extrapolated():
        return erfa.taitt(*erfa.utctai(*_utc(epoch_utc, t)))


def julian_year(epoch_utc):
    """The Julian epoch [Julian year] (TT) of a UTC calendar epoch: the star catalog's epoch of a run."""
    return float(erfa.epj(*tt_epoch(epoch_utc)))


def c_ei(epoch_utc, t=0.0, dut1=0.0):
    """C_ei (..., 3, 3): ICRS (GCRS axes) into ITRS at ``t`` [s] (scalar or array) after the UTC
    epoch ``epoch_utc``, with UT1 − UTC = ``dut1`` [s] and zero polar motion.

    The IAU 2006/2000A celestial-to-terrestrial matrix of pyerfa, ``erfa.c2t06a``'s product (CIO
    based: the Earth rotation angle ERA(UT1) between the CIP/CIO precession-nutation-bias matrix and
    polar motion; IERS Conventions 2010, eq. 5.1), its slow precession-nutation ``erfa.c2i06a`` on the
    grid of :func:`slowly` and ERA at every time (within 1e-14 rad of ``c2t06a``). ``t`` is added to
    UTC as uniform seconds (a leap second inside the span is not inserted).
    """
    utc1, utc2 = _utc(epoch_utc, t)
    with utc_offsets_extrapolated():
        tt1, tt2 = erfa.taitt(*erfa.utctai(utc1, utc2))
        ut11, ut12 = erfa.utcut1(utc1, utc2, dut1)
    c2i = slowly(lambda s: erfa.c2i06a(*tt_epoch(epoch_utc, s)), t)
    return erfa.c2tcio(c2i, erfa.era00(ut11, ut12), erfa.pom00(0.0, 0.0, erfa.sp00(tt1, tt2)))


def slowly(values_at, t):
    """``values_at(t)`` (..., ...) of a function of time that varies slowly, at times ``t`` [s] (scalar or
    array): evaluated on a grid of :data:`SLOW_STEP_S` spanning ``t`` and interpolated linearly (directly
    when ``t`` has no more elements than the grid)."""
    t = np.asarray(t, dtype=float)
    flat = t.ravel()
    start = flat.min() if flat.size else 0.0
    n = int(np.ceil((flat.max() - start) / SLOW_STEP_S)) + 1 if flat.size else 0
    if flat.size <= n + 1:
        return values_at(t)
    grid = values_at(start + np.arange(n + 1) * SLOW_STEP_S)
    k = np.minimum(((flat - start) // SLOW_STEP_S).astype(np.int64), n - 1)
    w = ((flat - start) / SLOW_STEP_S - k).reshape((-1,) + (1,) * (grid.ndim - 1))
    return (grid[k] * (1.0 - w) + grid[k + 1] * w).reshape(t.shape + grid.shape[1:])
