"""SGP4 from a two-line element set: the `sgp4` package (Vallado's C++ SGP4/SDP4, Vallado et al. 2006, *Revisiting
Spacetrack Report #3*, AIAA 2006-6753) in TEME, turned into GCRS axes with pyerfa.

TEME (the true equator, mean equinox of date) -> GCRS: TEME is turned into the pseudo-Earth-fixed frame by the
Greenwich mean sidereal time of 1982, r_PEF = R3(θ_GMST82) r_TEME (Vallado et al. 2006 eq. C-1), polar motion is
zero (as in :func:`navsim.earth.frames.c_ei`), and ITRS -> GCRS is C_ie of IAU 2006/2000A (``erfa.c2t06a``'s
product). So r_GCRS = M r_TEME with M = C_ie R3(θ_GMST82), a matrix that only precesses and nutates (its rate
~1e-11 rad/s: v_GCRS = M v_TEME within 0.1 mm/s); M is evaluated on the 60 s grid of :func:`navsim.earth.frames.slowly`.

A TLE is checked before SGP4 sees it (its two lines, their numbers, the satellite number and the checksums, since
``Satrec.twoline2rv`` takes any text), and any SGP4 error at a time of the run (eccentricity out of range, a
decayed orbit) is an InputError naming the key.
"""

from dataclasses import dataclass

import erfa
import numpy as np
from sgp4.api import WGS72, Satrec

from navsim.earth.frames import c_ei, slowly, utc_epoch, utc_offsets_extrapolated
from startrack import InputError

#: SGP4's error codes (sgp4.api.SGP4_ERRORS, Vallado's sgp4unit).
SGP4_ERRORS = {1: "the mean eccentricity is outside [0, 1)", 2: "the mean motion is below 0",
               3: "the perturbed eccentricity is outside [0, 1]", 4: "the semi-latus rectum is below 0",
               5: "the epoch elements are sub-orbital", 6: "the satellite has decayed (below the Earth's surface)"}


def checked_tle(line1, line2, key="orbit.tle"):
    """(line1, line2) of a two-line element set, stripped; an InputError naming ``key`` for anything that is not
    one (line numbers, lengths, the satellite number of both lines, the mod-10 checksums, the numeric fields)."""
    lines = [str(line).rstrip() for line in (line1, line2)]
    for k, line in enumerate(lines, start=1):
        if len(line) != 69 or line[0] != str(k) or line[1] != " ":
            raise InputError(f"{key}: line {k} must be 69 characters starting with '{k} ', got {line!r}")
        digits = sum(int(c) for c in line[:68] if c.isdigit()) + line[:68].count("-")
        if not line[68].isdigit() or digits % 10 != int(line[68]):
            raise InputError(f"{key}: line {k} fails its checksum (the digits and minus signs sum to {digits} mod 10 = "
                             f"{digits % 10}, the line ends in {line[68]!r})")
    if lines[0][2:7] != lines[1][2:7]:
        raise InputError(f"{key}: the two lines name different satellites ({lines[0][2:7]!r}, {lines[1][2:7]!r})")
    fields = {"epoch": lines[0][18:32], "inclination": lines[1][8:16], "right ascension": lines[1][17:25],
              "eccentricity": "0." + lines[1][26:33], "argument of perigee": lines[1][34:42],
              "mean anomaly": lines[1][43:51], "mean motion": lines[1][52:63]}
    for name, text in fields.items():
        try:
            float(text)
        except ValueError:
            raise InputError(f"{key}: the {name} field is not a number: {text.strip()!r}") from None
    if float(fields["mean motion"]) <= 0.0:
        raise InputError(f"{key}: the mean motion must be > 0 revolutions per day, got {fields['mean motion'].strip()}")
    return tuple(lines)


def teme_to_gcrs(epoch_utc, t):
    """M (N, 3, 3): TEME -> GCRS at times ``t`` (N,) [s] after the UTC epoch (module docstring), UT1 = UTC."""
    utc1, utc2 = utc_epoch(epoch_utc)

    def matrix(s):
        with utc_offsets_extrapolated():
            ut1, ut2 = erfa.utcut1(utc1, utc2 + np.asarray(s) / 86400.0, 0.0)
        theta = erfa.gmst82(ut1, ut2)
        c, si = np.cos(theta), np.sin(theta)
        r3 = np.zeros(np.shape(theta) + (3, 3))
        r3[..., 0, 0], r3[..., 0, 1], r3[..., 1, 0], r3[..., 1, 1], r3[..., 2, 2] = c, si, -si, c, 1.0
        return np.swapaxes(c_ei(epoch_utc, s), -1, -2) @ r3

    return slowly(matrix, np.atleast_1d(np.asarray(t, dtype=float)))


@dataclass(frozen=True, eq=False)
class SGP4Orbit:
    """The orbit of a TLE (``line1``, ``line2``) for a run whose t = 0 is ``epoch_utc`` (module docstring); WGS-72
    constants, as the element sets are fitted with them."""

    line1: str
    line2: str
    epoch_utc: str

    def __post_init__(self):
        line1, line2 = checked_tle(self.line1, self.line2)
        satrec = Satrec.twoline2rv(line1, line2, WGS72)
        jd1, jd2 = utc_epoch(self.epoch_utc)
        # minutes from the TLE's epoch to t = 0, from the two-part dates (no rounding of a whole Julian date)
        offset = ((jd1 - satrec.jdsatepoch) + (jd2 - satrec.jdsatepochF)) * 1440.0
        object.__setattr__(self, "_satrec", satrec)
        object.__setattr__(self, "offset_min", float(offset))
        self.teme(np.array([0.0]))

    def teme(self, tsince_min):
        """(r (N, 3) [km], v (N, 3) [km/s]) in TEME at ``tsince_min`` (N,) minutes after the TLE's epoch (SGP4's own
        units and frame: what its test vectors give); an SGP4 error at any of them is an InputError."""
        tsince = np.atleast_1d(np.asarray(tsince_min, dtype=float))
        jd = self._satrec.jdsatepoch + np.floor(tsince / 1440.0)
        fr = self._satrec.jdsatepochF + (tsince / 1440.0 - np.floor(tsince / 1440.0))
        error, r, v = self._satrec.sgp4_array(jd, fr)
        if np.any(error):
            k = int(np.flatnonzero(error)[0])
            raise InputError(f"orbit.tle: SGP4 fails {tsince[k]:.1f} min from the element set's epoch "
                             f"({60.0 * (tsince[k] - self.offset_min):.0f} s from the run's start): "
                             f"{SGP4_ERRORS.get(int(error[k]), f'error {int(error[k])}')}")
        return r, v

    def states(self, t):
        """(r (N, 3), v (N, 3)) [m, m/s] geocentric in GCRS axes at ``t`` (N,) [s after epoch_utc]."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        r, v = self.teme(self.offset_min + t / 60.0)
        M = teme_to_gcrs(self.epoch_utc, t)
        return 1e3 * np.einsum("nij,nj->ni", M, r), 1e3 * np.einsum("nij,nj->ni", M, v)
