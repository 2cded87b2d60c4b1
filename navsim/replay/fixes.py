"""Position (and velocity) fixes of a GNSS solution file, with their stated σ: an RTKLIB ``.pos`` solution or a CSV
with a stated column map.

RTKLIB's solution format (``rtklib_pos``; RTKLIB manual, Appendix B.3 "Solution file"): ``%`` header lines, then one
line per epoch ``YYYY/MM/DD HH:MM:SS.SSS lat lon height Q ns sdn sde sdu sdne sdeu sdun age ratio`` and, when the
solution has them, ``vn ve vu sdvn sdve sdvu ...`` [deg, deg, m, -, -, m ×6, s, -, m/s ×3, m/s ×3]; the time is GPST
(the header says ``GPST``; a ``UTC`` solution is refused), Q the quality (1 fix, 2 float, 5 single ...). A CSV
(``csv``) names its columns by :data:`CSV_COLUMNS` (``"-"`` to skip one), with the time in s on the IMU's scale.
Fixes of a quality outside ``qualities`` are dropped; none left is an :class:`InputError`.
"""

import calendar
from dataclasses import dataclass

import numpy as np

from navsim.replay import csv_table
from startrack import InputError, units

#: The columns of an RTKLIB solution line after its date and time (the velocity ones optional).
POS_COLUMNS = ("lat_deg", "lon_deg", "h_m", "quality", "satellites", "sd_n_m", "sd_e_m", "sd_u_m", "sd_ne_m",
               "sd_eu_m", "sd_un_m", "age_s", "ratio", "v_n_m_per_s", "v_e_m_per_s", "v_u_m_per_s",
               "sd_vn_m_per_s", "sd_ve_m_per_s", "sd_vu_m_per_s")
#: The names a CSV column map may use (time, position, its σ, optionally quality and NED velocity).
CSV_COLUMNS = ("time_s", "lat_deg", "lon_deg", "h_m", "sd_n_m", "sd_e_m", "sd_u_m", "quality", "v_n_m_per_s",
               "v_e_m_per_s", "v_u_m_per_s", "sd_vn_m_per_s", "sd_ve_m_per_s", "sd_vu_m_per_s")
#: The velocity's columns and their σ's: all or none.
_VELOCITY = ("v_n_m_per_s", "v_e_m_per_s", "v_u_m_per_s", "sd_vn_m_per_s", "sd_ve_m_per_s", "sd_vu_m_per_s")
_REQUIRED = ("time_s", "lat_deg", "lon_deg", "h_m", "sd_n_m", "sd_e_m", "sd_u_m")


@dataclass(frozen=True)
class Fixes:
    """Fixes in time order: ``t`` [s] (GPST since 1970 for a .pos), ``lat``, ``lon`` [rad], ``h`` [m], ``sigma`` (N, 3)
    [m] NED, ``quality`` (N,), ``v_n`` (N, 3) [m/s] NED and its σ ``v_sigma`` (N, 3) [m/s] (both None when the file
    has no velocity)."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    sigma: np.ndarray
    quality: np.ndarray
    v_n: np.ndarray | None
    v_sigma: np.ndarray | None

    def __len__(self):
        return self.t.size

    def subset(self, keep):
        """The fixes where the mask ``keep`` holds."""
        return Fixes(self.t[keep], self.lat[keep], self.lon[keep], self.h[keep], self.sigma[keep], self.quality[keep],
                     None if self.v_n is None else self.v_n[keep], None if self.v_n is None else self.v_sigma[keep])


def gpst_seconds(date, time):
    """Seconds since 1970-01-01 on the GPST scale of a ``YYYY/MM/DD`` date and ``HH:MM:SS.sss`` time (no leap
    seconds: GPST has none)."""
    year, month, day = (int(x) for x in date.split("/"))
    hour, minute, second = time.split(":")
    return calendar.timegm((year, month, day, int(hour), int(minute), 0, 0, 0, 0)) + float(second)


def read_pos(path, qualities=(1,)):
    """The :class:`Fixes` of an RTKLIB ``.pos`` solution (module docstring), those of a quality in ``qualities``."""
    path = csv_table.existing(path, "GNSS solution file")
    rows, times = [], []
    for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), start=1):
        if line.startswith("%"):
            if "UTC" in line.split("latitude")[0] and "GPST" not in line:
                raise InputError(f"{path}: a UTC solution; write it in GPST (RTKLIB: time format GPST)")
            continue
        if not line.strip():
            continue
        fields = line.split()
        try:
            times.append(gpst_seconds(fields[0], fields[1]))
            rows.append([float(x) for x in fields[2:2 + len(POS_COLUMNS)]])
        except (ValueError, IndexError):
            raise InputError(f"{path}: line {number} is not an RTKLIB solution line (date time lat lon h Q ...)") from None
        if len(rows[-1]) not in (13, len(POS_COLUMNS)):
            raise InputError(f"{path}: line {number} has {len(fields)} fields, an RTKLIB solution line 15 or more")
    if not rows:
        raise InputError(f"{path}: no solution lines")
    width = min(len(r) for r in rows)
    table = np.array([r[:width] for r in rows])
    named = {name: table[:, i] for i, name in enumerate(POS_COLUMNS[:width])}
    named["time_s"] = np.array(times)
    return _fixes(path, named, qualities)


def read_csv(path, columns, qualities=(1,)):
    """The :class:`Fixes` of a CSV with the column map ``columns`` (names of :data:`CSV_COLUMNS`, ``"-"`` to skip)."""
    path, table = csv_table.read_table(path, columns, "GNSS solution file", "gnss.columns", CSV_COLUMNS, _REQUIRED)
    named = csv_table.named(table, columns)
    named.setdefault("quality", np.ones(table.shape[0]))
    given = [c for c in _VELOCITY if c in named]
    if given and len(given) < len(_VELOCITY):
        raise InputError(f"gnss.columns: a velocity needs all of {', '.join(_VELOCITY)}; "
                         f"{next(c for c in _VELOCITY if c not in named)!r} is missing")
    return _fixes(path, named, qualities)


def _fixes(path, named, qualities):
    """The :class:`Fixes` of named columns, checked: finite, time increasing, σ > 0, some of an accepted quality."""
    keep = np.isin(named["quality"], qualities)
    if not keep.any():
        raise InputError(f"{path}: no fixes of quality {', '.join(str(q) for q in qualities)} "
                         f"(qualities present: {', '.join(str(int(q)) for q in np.unique(named['quality']))})")
    named = {name: np.asarray(column, dtype=float)[keep] for name, column in named.items()}
    for name, column in named.items():
        if not np.isfinite(column).all():
            raise InputError(f"{path}: column {name} is not finite in fix {int(np.flatnonzero(~np.isfinite(column))[0]) + 1}")
    if not (np.diff(named["time_s"]) > 0.0).all():
        raise InputError(f"{path}: time not increasing at fix {int(np.flatnonzero(np.diff(named['time_s']) <= 0)[0]) + 2}")
    sigma = np.stack([named["sd_n_m"], named["sd_e_m"], named["sd_u_m"]], axis=1)
    if not (sigma > 0.0).all():
        raise InputError(f"{path}: a stated position sigma (sdn, sde, sdu) is not > 0")
    velocity = v_sigma = None
    if "sd_vu_m_per_s" in named:  # NEU in the file, NED here
        velocity = np.stack([named["v_n_m_per_s"], named["v_e_m_per_s"], -named["v_u_m_per_s"]], axis=1)
        v_sigma = np.stack([named["sd_vn_m_per_s"], named["sd_ve_m_per_s"], named["sd_vu_m_per_s"]], axis=1)
        if not (v_sigma > 0.0).all():
            raise InputError(f"{path}: a stated velocity sigma (sdvn, sdve, sdvu) is not > 0")
    return Fixes(t=named["time_s"], lat=units.deg_to_rad(named["lat_deg"]), lon=units.deg_to_rad(named["lon_deg"]),
                 h=named["h_m"], sigma=sigma, quality=named["quality"].astype(int), v_n=velocity, v_sigma=v_sigma)
