"""Trajectory segments in geodetic terms: hold, straight, accelerate, coordinated turn, climb or
descent, and a ship's roll/pitch/heave — and the tables (TOML-ready dicts) that list them.

Each segment is an immutable object with ``duration_from(entry)`` [s] and ``channels(tau, entry)``: the
motion at local times ``tau`` [s] as :class:`Channels` (ground speed, heading, climb rate, roll and
pitch, each with its time derivative), given the speed and heading it enters with. Every change is
shaped by the smooth window of :func:`window` (C² at both ends), so rates and specific forces are
continuous and the IMU increments have no steps. Yaw is the heading (no sideslip); a coordinated
turn banks by atan(V ψ̇ / g0); a climb pitches by the flight-path angle atan(climb / V).

Keys carry their units (``rate_deg_per_s``); every problem raises one
:class:`~startrack.base.errors.InputError` naming the key.
"""

import math
from dataclasses import MISSING, dataclass, fields
from typing import NamedTuple

import numpy as np

from navsim.truth.level_frames import North
from startrack import InputError, units

#: The g of the coordinated-turn bank relation tan φ = V ψ̇ / g [m/s²].
BANK_GRAVITY = units.STANDARD_GRAVITY


class Channels(NamedTuple):
    """Motion at a set of times (arrays): ground speed [m/s] and its rate, heading [rad] and
    rate, climb (up) rate [m/s] and its rate, roll and pitch [rad] and their rates."""

    speed: np.ndarray
    speed_rate: np.ndarray
    heading: np.ndarray
    heading_rate: np.ndarray
    climb: np.ndarray
    climb_rate: np.ndarray
    roll: np.ndarray
    roll_rate: np.ndarray
    pitch: np.ndarray
    pitch_rate: np.ndarray


class Entry(NamedTuple):
    """What a segment starts from: ground speed [m/s] and heading [rad]."""

    speed: float
    heading: float


def window(tau, duration, ramp):
    """Smooth trapezoid e(τ) on [0, T]: rises over ``ramp`` as s(x) = x − sin(2πx)/(2π), stays at 1,
    falls symmetrically. Returns (E, e, ė, ë) with E = ∫₀^τ e (E(T) = T − ramp)."""
    tau = np.asarray(tau, dtype=float)
    rising = tau < ramp
    falling = tau > duration - ramp
    x = np.where(rising, tau / ramp, np.where(falling, (duration - tau) / ramp, 1.0))
    two_pi_x = 2.0 * np.pi * x
    s = x - np.sin(two_pi_x) / (2.0 * np.pi)
    s1 = (1.0 - np.cos(two_pi_x)) / ramp
    s2 = 2.0 * np.pi * np.sin(two_pi_x) / ramp**2
    integral_s = ramp * (0.5 * x * x + (np.cos(two_pi_x) - 1.0) / (4.0 * np.pi**2))
    e = np.where(rising | falling, s, 1.0)
    de = np.where(rising, s1, np.where(falling, -s1, 0.0))
    dde = np.where(rising | falling, s2, 0.0)
    big = np.where(rising, integral_s, np.where(falling, duration - ramp - integral_s, tau - 0.5 * ramp))
    return big, e, de, dde


def _positive(key, value):
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
        raise InputError(f"{key}: must be a number > 0, got {value!r}")


def _finite(key, value):
    if isinstance(value, bool) or not (isinstance(value, (int, float)) and math.isfinite(value)):
        raise InputError(f"{key}: must be a finite number, got {value!r}")


def _steady(tau, entry):
    """Channels of constant speed and heading, wings level."""
    zero = np.zeros_like(tau)
    return Channels(zero + entry.speed, zero, zero + entry.heading, zero, zero, zero, zero, zero, zero, zero)


@dataclass(frozen=True)
class Straight:
    """Straight and level at the entry speed and heading for ``duration_s``."""

    duration_s: float

    def __post_init__(self):
        _positive("duration_s", self.duration_s)

    def duration_from(self, entry):
        return float(self.duration_s)

    def check_entry(self, entry):
        pass

    def channels(self, tau, entry):
        return _steady(tau, entry)

    def exit(self, entry):
        return entry


@dataclass(frozen=True)
class Hold(Straight):
    """Stationary (zero ground speed) for ``duration_s``."""

    def check_entry(self, entry):
        if abs(entry.speed) > 1e-9:
            raise InputError(f"kind: a hold needs zero speed, entered at {entry.speed} m/s (decelerate first)")


@dataclass(frozen=True)
class Accelerate:
    """Change ground speed to ``speed_m_per_s`` at ``acceleration_m_per_s2`` (> 0), the acceleration
    ramped in and out over ``ramp_s``: duration |ΔV|/a + ramp."""

    speed_m_per_s: float
    acceleration_m_per_s2: float
    ramp_s: float = 2.0

    def __post_init__(self):
        _finite("speed_m_per_s", self.speed_m_per_s)
        if self.speed_m_per_s < 0.0:
            raise InputError(f"speed_m_per_s: must be >= 0, got {self.speed_m_per_s!r}")
        _positive("acceleration_m_per_s2", self.acceleration_m_per_s2)
        _positive("ramp_s", self.ramp_s)

    def _change(self, entry):
        return self.speed_m_per_s - entry.speed

    def check_entry(self, entry):
        if abs(self._change(entry)) / self.acceleration_m_per_s2 < self.ramp_s:
            raise InputError(f"acceleration_m_per_s2: {entry.speed} -> {self.speed_m_per_s} m/s at "
                             f"{self.acceleration_m_per_s2} m/s² is shorter than its ramp_s = {self.ramp_s} s")

    def duration_from(self, entry):
        return abs(self._change(entry)) / self.acceleration_m_per_s2 + self.ramp_s

    def channels(self, tau, entry):
        a = math.copysign(self.acceleration_m_per_s2, self._change(entry))
        big, e, _, _ = window(tau, self.duration_from(entry), self.ramp_s)
        steady = _steady(tau, entry)
        return steady._replace(speed=entry.speed + a * big, speed_rate=a * e)

    def exit(self, entry):
        return Entry(float(self.speed_m_per_s), entry.heading)


@dataclass(frozen=True)
class Turn:
    """Coordinated turn by ``heading_change_deg`` (positive to the right) at ``rate_deg_per_s``,
    rolled in and out over ``roll_in_s``; bank atan(V ψ̇/g0). ``bank_deg``, if given, must agree
    with the rate and the entry speed (within 1 %), else the turn cannot be flown."""

    heading_change_deg: float
    rate_deg_per_s: float
    roll_in_s: float = 3.0
    bank_deg: float | None = None

    def __post_init__(self):
        _finite("heading_change_deg", self.heading_change_deg)
        if self.heading_change_deg == 0.0:
            raise InputError("heading_change_deg: must not be 0")
        _positive("rate_deg_per_s", self.rate_deg_per_s)
        _positive("roll_in_s", self.roll_in_s)
        if self.bank_deg is not None:
            _finite("bank_deg", self.bank_deg)

    def _rate(self):
        return math.copysign(self.rate_deg_per_s * units.DEG, self.heading_change_deg)

    def check_entry(self, entry):
        if abs(self.heading_change_deg) / self.rate_deg_per_s < self.roll_in_s:
            raise InputError(f"rate_deg_per_s: a {self.heading_change_deg} deg turn at {self.rate_deg_per_s} deg/s "
                             f"is shorter than its roll_in_s = {self.roll_in_s} s")
        if self.bank_deg is not None:
            needed = math.degrees(math.atan(entry.speed * abs(self._rate()) / BANK_GRAVITY))
            if abs(abs(self.bank_deg) - needed) > 0.01 * max(needed, 1e-9):
                raise InputError(f"bank_deg: a coordinated turn at {self.rate_deg_per_s} deg/s and {entry.speed} m/s "
                                 f"banks {needed:.2f} deg, got {self.bank_deg} (cannot be flown)")

    def duration_from(self, entry):
        return abs(self.heading_change_deg) / self.rate_deg_per_s + self.roll_in_s

    def channels(self, tau, entry):
        rate = self._rate()
        big, e, de, _ = window(tau, self.duration_from(entry), self.roll_in_s)
        k = entry.speed * rate / BANK_GRAVITY
        steady = _steady(tau, entry)
        return steady._replace(heading=entry.heading + rate * big, heading_rate=rate * e,
                               roll=np.arctan(k * e), roll_rate=k * de / (1.0 + (k * e) ** 2))

    def exit(self, entry):
        return Entry(entry.speed, entry.heading + self.heading_change_deg * units.DEG)


@dataclass(frozen=True)
class Climb:
    """Climb (positive) or descend by ``height_change_m`` at ``rate_m_per_s`` (> 0), pitched by the
    flight-path angle, with the climb rate ramped over ``transition_s``; needs a forward speed."""

    height_change_m: float
    rate_m_per_s: float
    transition_s: float = 5.0

    def __post_init__(self):
        _finite("height_change_m", self.height_change_m)
        if self.height_change_m == 0.0:
            raise InputError("height_change_m: must not be 0")
        _positive("rate_m_per_s", self.rate_m_per_s)
        _positive("transition_s", self.transition_s)

    def check_entry(self, entry):
        if entry.speed <= 0.0:
            raise InputError("kind: a climb needs a forward speed > 0 (accelerate first)")
        if abs(self.height_change_m) / self.rate_m_per_s < self.transition_s:
            raise InputError(f"rate_m_per_s: {self.height_change_m} m at {self.rate_m_per_s} m/s "
                             f"is shorter than its transition_s = {self.transition_s} s")

    def duration_from(self, entry):
        return abs(self.height_change_m) / self.rate_m_per_s + self.transition_s

    def channels(self, tau, entry):
        rate = math.copysign(self.rate_m_per_s, self.height_change_m)
        _, e, de, _ = window(tau, self.duration_from(entry), self.transition_s)
        ratio = rate * e / entry.speed
        steady = _steady(tau, entry)
        return steady._replace(climb=rate * e, climb_rate=rate * de, pitch=np.arctan(ratio),
                               pitch_rate=rate * de / entry.speed / (1.0 + ratio * ratio))

    def exit(self, entry):
        return entry


@dataclass(frozen=True)
class ShipMotion:
    """A ship's roll, pitch and heave (sinusoids of given amplitude and period) at the entry speed and
    heading for ``duration_s``, faded in and out over ``ramp_s`` (the motion starts and ends at rest)."""

    duration_s: float
    roll_amplitude_deg: float = 5.0
    roll_period_s: float = 10.0
    pitch_amplitude_deg: float = 2.0
    pitch_period_s: float = 7.0
    heave_amplitude_m: float = 1.0
    heave_period_s: float = 9.0
    ramp_s: float = 30.0

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            (_finite if "amplitude" in f.name else _positive)(f.name, value)
        if self.duration_s < 2.0 * self.ramp_s:
            raise InputError(f"duration_s: must be at least 2 ramp_s = {2.0 * self.ramp_s} s, got {self.duration_s}")

    def duration_from(self, entry):
        return float(self.duration_s)

    def check_entry(self, entry):
        pass

    def channels(self, tau, entry):
        _, e, de, dde = window(tau, self.duration_s, self.ramp_s)
        roll, roll_rate = _faded_sine(tau, e, de, self.roll_amplitude_deg * units.DEG, self.roll_period_s)
        pitch, pitch_rate = _faded_sine(tau, e, de, self.pitch_amplitude_deg * units.DEG, self.pitch_period_s)
        w = 2.0 * np.pi / self.heave_period_s
        s, c = np.sin(w * tau), np.cos(w * tau)
        climb = self.heave_amplitude_m * (de * s + e * w * c)
        climb_rate = self.heave_amplitude_m * (dde * s + 2.0 * de * w * c - e * w * w * s)
        steady = _steady(tau, entry)
        return steady._replace(climb=climb, climb_rate=climb_rate, roll=roll, roll_rate=roll_rate,
                               pitch=pitch, pitch_rate=pitch_rate)

    def exit(self, entry):
        return entry


def _faded_sine(tau, e, de, amplitude, period):
    """A e(τ) sin(2πτ/P) and its rate."""
    w = 2.0 * np.pi / period
    return amplitude * e * np.sin(w * tau), amplitude * (de * np.sin(w * tau) + e * w * np.cos(w * tau))


KINDS = {"hold": Hold, "straight": Straight, "accelerate": Accelerate, "turn": Turn, "climb": Climb,
         "ship": ShipMotion}


@dataclass(frozen=True)
class Start:
    """Where and how the trajectory starts: geodetic position, ground speed and heading."""

    lat_deg: float
    lon_deg: float
    height_m: float = 0.0
    speed_m_per_s: float = 0.0
    heading_deg: float = 0.0

    def __post_init__(self):
        for f in fields(self):
            _finite(f.name, getattr(self, f.name))
        if abs(self.lat_deg) > 90.0:
            raise InputError(f"lat_deg: |latitude| must be <= 90, got {self.lat_deg}")
        if self.height_m < -1000.0:
            raise InputError(f"height_m: must be >= -1000 m (1 km below the ellipsoid), got {self.height_m}")
        if self.speed_m_per_s < 0.0:
            raise InputError(f"speed_m_per_s: must be >= 0, got {self.speed_m_per_s}")

    @property
    def entry(self):
        return Entry(float(self.speed_m_per_s), self.heading_deg * units.DEG)


@dataclass(frozen=True)
class Profile:
    """A start and its segments, checked in sequence (each segment against the speed it enters with), their
    headings measured in the level frame ``frame`` (:mod:`navsim.truth.level_frames`: north by default).

    ``starts`` [s] and ``entries`` hold each segment's start time and entry state; ``duration`` is the total."""

    start: Start
    segments: tuple
    frame: object = North()

    def __post_init__(self):
        entry, t, starts, entries = self.start.entry, 0.0, [], []
        for index, segment in enumerate(self.segments):
            try:
                segment.check_entry(entry)
            except InputError as error:
                raise InputError(f"segments[{index}].{error}") from None
            starts.append(t)
            entries.append(entry)
            t += segment.duration_from(entry)
            entry = segment.exit(entry)
        if not self.segments:
            raise InputError("segments: at least one segment is needed")
        object.__setattr__(self, "starts", np.array(starts))
        object.__setattr__(self, "entries", tuple(entries))
        object.__setattr__(self, "duration", t)

    @classmethod
    def from_table(cls, table, where="trajectory"):
        """A profile from a TOML-ready dict ``{"start": {...}, "segments": [{"kind": ..., ...}, ...]}``;
        problems are named as ``where.start.lat_deg`` or ``where.segments[2].rate_deg_per_s``."""
        if not isinstance(table, dict) or set(table) != {"start", "segments"}:
            raise InputError(f"{where}: must be a table with exactly the keys start and segments")
        start = _build(Start, table["start"], f"{where}.start")
        if not isinstance(table["segments"], list):
            raise InputError(f"{where}.segments: must be a list of tables")
        segments = []
        for index, row in enumerate(table["segments"]):
            key = f"{where}.segments[{index}]"
            if not isinstance(row, dict) or row.get("kind") not in KINDS:
                raise InputError(f"{key}.kind: must be one of {', '.join(KINDS)}")
            segments.append(_build(KINDS[row["kind"]], {k: v for k, v in row.items() if k != "kind"}, key))
        try:
            return cls(start, tuple(segments))
        except InputError as error:
            raise InputError(f"{where}.{error}") from None

    def channels(self, t):
        """:class:`Channels` at the sorted times ``t`` [s] (0 <= t <= duration)."""
        t = np.asarray(t, dtype=float)
        index = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.segments) - 1)
        bounds = np.searchsorted(index, np.arange(len(self.segments) + 1))
        parts = [seg.channels(t[lo:hi] - t0, entry) for seg, t0, entry, lo, hi in
                 zip(self.segments, self.starts, self.entries, bounds[:-1], bounds[1:]) if hi > lo]
        return Channels(*(np.concatenate(arrays) for arrays in zip(*parts)))


def _build(kind, row, where):
    """``kind(**row)`` with unknown or missing keys and bad values named at ``where``."""
    if not isinstance(row, dict):
        raise InputError(f"{where}: must be a table")
    names = {f.name for f in fields(kind)}
    unknown = sorted(set(row) - names)
    if unknown:
        raise InputError(f"{where}.{unknown[0]}: unknown key (expected one of {', '.join(sorted(names))})")
    try:
        return kind(**row)
    except InputError as error:
        raise InputError(f"{where}.{error}") from None
    except TypeError:
        missing = [f.name for f in fields(kind) if f.name not in row and f.default is MISSING]
        raise InputError(f"{where}.{missing[0]}: missing") from None
