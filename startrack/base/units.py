"""Units at the edges, SI inside: the one set of angle, time and sensor-datasheet conversions of
both packages (``navsim`` imports it from here; ``startrack`` never imports ``navsim``).

Constants multiply a value given in the named unit to get SI: ``5 * ARCSEC`` is 5" in radians.
"""

import numpy as np

DEG = np.pi / 180.0
ARCMIN = DEG / 60.0
ARCSEC = DEG / 3600.0
MILLIARCSEC = ARCSEC / 1000.0
HOUR = 3600.0
PPM = 1e-6


def deg_to_rad(x):
    return np.asarray(x, dtype=float) * DEG


def arcsec_to_rad(x):
    return np.asarray(x, dtype=float) * ARCSEC


def rad_to_arcsec(x):
    return np.asarray(x, dtype=float) / ARCSEC


def deg_per_h_to_rad_per_s(x):
    """Gyro bias [deg/h] -> [rad/s]."""
    return np.asarray(x, dtype=float) * DEG / HOUR


def rad_per_s_to_deg_per_h(x):
    return np.asarray(x, dtype=float) * HOUR / DEG


def arw_to_si(x):
    """Angle random walk [deg/√h] -> σ_v [rad/√s]."""
    return np.asarray(x, dtype=float) * DEG / np.sqrt(HOUR)


def rrw_to_si(x):
    """Rate random walk [deg/h/√h] -> σ_u [rad/s^(3/2)]."""
    return np.asarray(x, dtype=float) * DEG / HOUR / np.sqrt(HOUR)

#: Standard gravity g0 [m/s²] (the datasheet unit of accelerometer errors; not the local gravity).
STANDARD_GRAVITY = 9.80665
#: International nautical mile [m].
NAUTICAL_MILE = 1852.0
#: The gravity-anomaly unit milligal [m/s²] (1 Gal = 1 cm/s²).
MILLIGAL = 1e-5


def micro_g_to_si(x):
    """Accelerometer bias [µg] -> [m/s²] (1 µg = 1e-6 g0)."""
    return np.asarray(x, dtype=float) * 1e-6 * STANDARD_GRAVITY


def vrw_to_si(x):
    """Velocity random walk [m/s/√h] -> σ [m/s/√s] = [m/s^(3/2)]."""
    return np.asarray(x, dtype=float) / np.sqrt(HOUR)


def micro_g_per_sqrt_h_to_si(x):
    """Accelerometer bias random walk [µg/√h] -> σ [m/s²/√s] = [m/s^(5/2)]."""
    return np.asarray(x, dtype=float) * 1e-6 * STANDARD_GRAVITY / np.sqrt(HOUR)


def _sexagesimal(value, decimals):
    """(whole, minutes, seconds) of a non-negative ``value`` rounded to ``decimals`` of a second (no 60 s)."""
    step = 10**decimals
    units = round(value * 3600.0 * step)
    whole, rest = divmod(units, 3600 * step)
    minutes, seconds = divmod(rest, 60 * step)
    return whole, minutes, seconds / step


def ra_hms(ra_deg, decimals=3):
    """Right ascension [deg] as "HH:MM:SS.sss" (hours, astrometry.net's form), within [0, 24 h)."""
    hours, minutes, seconds = _sexagesimal(float(ra_deg) % 360.0 / 15.0, decimals)
    return f"{hours % 24:02d}:{minutes:02d}:{seconds:0{3 + decimals}.{decimals}f}"


def dec_dms(dec_deg, decimals=2):
    """Declination [deg] as "+DD:MM:SS.ss" (sign always, astrometry.net's form)."""
    degrees, minutes, seconds = _sexagesimal(abs(float(dec_deg)), decimals)
    return f"{'-' if dec_deg < 0 else '+'}{degrees:02d}:{minutes:02d}:{seconds:0{3 + decimals}.{decimals}f}"
