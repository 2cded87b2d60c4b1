"""Routes by waypoints on the ellipsoid: the profile that flies over each waypoint in turn along geodesics, and the
one entry point from a scenario's ``[trajectory]`` table to a :class:`~navsim.truth.segments.Profile` (segments or
a route; docs/design.md, "Routes").

A route's profile is made of ordinary segments in the free-azimuth level frame
(:class:`~navsim.truth.level_frames.FreeAzimuth`), where a constant heading flies a geodesic of the parallel surface
at the flight's height (do Carmo 1976, §4-4): the legs are straight, so the poles and the antimeridian are ordinary
points. Leg k (to waypoint k) is: a coordinated turn by Δ at the route's bank (rate g tan φ / V; a turn smaller than
2 ψ̇ ``roll_in_s`` is flown slower, over 3 ``roll_in_s``), a speed change and a climb to the waypoint's speed and
height when they differ, then straight for a time T. The first leg starts at waypoint 0 on an initial course
instead of a turn. (Δ or the course, T) are solved by Newton's method on the miss distance at the leg's end, the
position carried at :data:`STEP` (the truth at the IMU rate flies over each waypoint within millimetres).

Between two waypoints at height h the track is the geodesic of the parallel surface, which projects on the
ellipsoid's geodesic to within h/R of its length and about an arcsecond of its azimuth (tested against Karney 2013).
"""

import dataclasses
import functools
import json
import math
from dataclasses import dataclass

import numpy as np

from navsim.earth.wander import normal, q_ew
from navsim.earth.wgs84 import A
from navsim.truth import segments, trajectory
from navsim.truth.level_frames import FreeAzimuth
from startrack import InputError, units
from startrack import rotation_kernels as rk

#: Steepest bank a route may ask for [deg] (a load factor of 2 g).
MAX_BANK_DEG = 60.0
#: Miss distance at which a leg is solved [m]; the step [s] of the legs' position while solving; Newton's iterations.
MISS, STEP, ITERATIONS = 1e-3, 1.0, 30
#: Consecutive waypoints closer than this [rad of arc] coincide; farther apart than this [deg] are (nearly)
#: antipodal, where the geodesic is not unique.
COINCIDENT, ANTIPODAL_DEG = 1e-7, 179.0
#: Shortest straight part of a leg [s].
MIN_STRAIGHT_S = 1.0
#: Latitude [deg] from which a trajectory of segments is carried in the free-azimuth frame (the North frame's
#: λ̇ = v_E/((R_N + h) cos L) is singular at the poles); the least meridian radius of curvature a(1 − e²) [m].
POLAR_CAP_DEG, LEAST_MERIDIAN_RADIUS = 89.0, 6335439.327


@dataclass(frozen=True)
class Waypoint:
    """A point the route flies over: geodetic ``lat_deg``, ``lon_deg`` [deg], ``height_m`` [m] above the ellipsoid
    and the ground speed ``speed_m_per_s`` [m/s] there (each leg changes speed and height at its start)."""

    lat_deg: float
    lon_deg: float
    height_m: float
    speed_m_per_s: float

    @property
    def up(self):
        """The ellipsoid's normal (3,) in e."""
        return normal(self.lat_deg * units.DEG, self.lon_deg * units.DEG)


@dataclass(frozen=True)
class Route:
    """Waypoints (at least two) flown in order with coordinated turns at ``bank_deg`` rolled in over ``roll_in_s``,
    speed changes at ``acceleration_m_per_s2`` and climbs at ``climb_rate_m_per_s``."""

    waypoints: tuple
    bank_deg: float = 25.0
    roll_in_s: float = 5.0
    acceleration_m_per_s2: float = 1.0
    climb_rate_m_per_s: float = 10.0

    def check(self, where):
        """One InputError naming ``where``'s key for a bank out of (0, 60] deg, fewer than two waypoints, or two
        consecutive ones coincident or (nearly) antipodal."""
        if not 0.0 < self.bank_deg <= MAX_BANK_DEG:
            raise InputError(f"{where}.bank_deg: a coordinated turn banks more than 0 and at most {MAX_BANK_DEG:g} deg "
                             f"(2 g), got {self.bank_deg:g}")
        if len(self.waypoints) < 2:
            raise InputError(f"{where}.waypoints: a route needs at least two waypoints, got {len(self.waypoints)}")
        for k in range(1, len(self.waypoints)):
            a, b = self.waypoints[k - 1].up, self.waypoints[k].up
            arc = math.atan2(np.linalg.norm(np.cross(a, b)), float(a @ b))
            if arc < COINCIDENT:
                raise InputError(f"{where}.waypoints[{k}]: coincides with waypoints[{k - 1}] (a leg needs two places)")
            if math.degrees(arc) > ANTIPODAL_DEG:
                raise InputError(f"{where}.waypoints[{k}]: {math.degrees(arc):.2f} deg from waypoints[{k - 1}], (nearly) "
                                 f"antipodal: the geodesic between them is not unique; add a waypoint between them")

    def turn_rate(self, speed):
        """ψ̇ [rad/s] of a coordinated turn at the route's bank and ``speed`` [m/s]: g tan φ / V."""
        return segments.BANK_GRAVITY * math.tan(self.bank_deg * units.DEG) / speed

    def profile(self, where="trajectory.route"):
        """The :class:`~navsim.truth.segments.Profile` that flies over every waypoint (module docstring)."""
        return self.solve(where)[0]

    def solve(self, where="trajectory.route"):
        """(:meth:`profile`, the times [s] it flies over waypoints 1, 2, ...); problems named at ``where``."""
        self.check(where)
        first = self.waypoints[0]
        course, legs, ends, q, h = 0.0, [], [], None, first.height_m
        entry = segments.Entry(first.speed_m_per_s, 0.0)
        for k in range(1, len(self.waypoints)):
            leg, x = self._solve(k, q, h, entry, where)
            if k == 1:
                course, entry = x, segments.Entry(entry.speed, x)
            legs.extend(leg)
            ends.append(len(legs))
            q, h, entry = _fly(q, h, entry, leg, first)
        start = segments.Start(first.lat_deg, first.lon_deg, first.height_m, first.speed_m_per_s, math.degrees(course))
        profile = segments.Profile(start, tuple(legs), FreeAzimuth())
        return profile, np.append(profile.starts, profile.duration)[ends]

    def _leg(self, k, entry, h, x):
        """The segments of leg k entered at ``entry`` and height ``h`` [m] for the unknowns x = (Δ or the initial
        course [rad], T [s])."""
        target = self.waypoints[k]
        leg = [] if k == 1 else [self._turn(entry.speed, x[0])]
        change = target.speed_m_per_s - entry.speed
        if abs(change) > 1e-9:
            ramp = min(2.0, abs(change) / self.acceleration_m_per_s2)
            leg.append(segments.Accelerate(target.speed_m_per_s, self.acceleration_m_per_s2, ramp))
        climb = target.height_m - h
        if abs(climb) > 1e-6:
            leg.append(segments.Climb(climb, self.climb_rate_m_per_s, min(5.0, abs(climb) / self.climb_rate_m_per_s)))
        return leg + [segments.Straight(float(x[1]))]

    def _turn(self, speed, change):
        """A coordinated turn by ``change`` [rad] at the route's rate, slower when short (module docstring)."""
        if abs(change) < 1e-12:
            return segments.Straight(3.0 * self.roll_in_s)
        rate = min(self.turn_rate(speed), abs(change) / (2.0 * self.roll_in_s))
        return segments.Turn(math.degrees(change), math.degrees(rate), self.roll_in_s)

    def _solve(self, k, q, h, entry, where):
        """(segments, x) of leg k from the frame q_ef = ``q`` (None: NED at waypoint 0), height ``h``, ``entry``:
        Newton's method on the miss at the leg's end, its Jacobian by finite differences."""
        first, target = self.waypoints[0], self.waypoints[k]
        x = _initial_guess(q, h, entry, first, target, k == 1)

        def miss(y):
            start = entry if k > 1 else entry._replace(heading=y[0])
            end, height, _ = _fly(q, h, start, self._leg(k, entry, h, y), first)
            return _miss(end, height, target.up)

        for _ in range(ITERATIONS):
            m = miss(x)
            if np.hypot(*m) < MISS:
                return self._leg(k, entry, h, x), x[0]
            J = np.column_stack([(miss(x + [1e-6, 0.0]) - m) / 1e-6, miss(x + [0.0, 1.0]) - m])
            x = x - np.linalg.solve(J, m)
            if x[1] < MIN_STRAIGHT_S or abs(x[0]) > 2.0 * np.pi:
                break
        radius = entry.speed / self.turn_rate(entry.speed)
        raise InputError(f"{where}.waypoints[{k}]: cannot be flown over from waypoints[{k - 1}] at "
                         f"{entry.speed:g} m/s with a bank of {self.bank_deg:g} deg (turn radius {radius / 1000:.2f} km):"
                         f" too close after the turn; move it farther, lower the speed or bank more")


def _fly(q, h, entry, leg, first):
    """(q_ef, h [m], exit Entry) at the end of the segments ``leg`` from the frame ``q`` (None: NED at ``first``)
    at height ``h`` entered at ``entry``, the position carried at about :data:`STEP`."""
    start = segments.Start(first.lat_deg, first.lon_deg, h, entry.speed, math.degrees(entry.heading))
    profile = segments.Profile(start, tuple(leg), FreeAzimuth(None if q is None else tuple(q)))
    track = trajectory.track(profile, math.ceil(profile.duration / STEP) / profile.duration)
    return track.q_ef[-1], track.h[-1], leg[-1].exit(profile.entries[-1])


def _miss(q, h, up):
    """The target's horizontal offset (2,) [m] in f from the position q_ef at height ``h`` [m]: (R + h) times the
    horizontal components of its normal ``up`` (e) in f."""
    d = rk.quat_to_matrix(q).T @ up
    return (A + h) * d[:2]


def _initial_guess(q, h, entry, first, target, initial):
    """x = (Δ or the course [rad], T [s]) of the great circle to ``target``: its course in f and the arc length at the
    target's speed."""
    if q is None:
        q = q_ew(first.lat_deg * units.DEG, first.lon_deg * units.DEG)
    d = rk.quat_to_matrix(q).T @ target.up
    course = math.atan2(d[1], d[0])
    arc = math.atan2(math.hypot(d[0], d[1]), -d[2])
    turn = course if initial else (course - entry.heading + np.pi) % (2.0 * np.pi) - np.pi
    return np.array([turn, max((A + h) * arc / target.speed_m_per_s, 10.0 * MIN_STRAIGHT_S)])


def profile_of(table, where="trajectory"):
    """The :class:`~navsim.truth.segments.Profile` of a checked ``[trajectory]`` table: ``start`` and ``segments``, or
    a ``route`` (solved once per table and process)."""
    return _profile(json.dumps(table, sort_keys=True), where)


def flight_time(table, where="trajectory"):
    """The default run length [s] of a checked ``[trajectory]`` table: a profile's sum of segments, a route's
    flown time to the millisecond below (1 ns above one counts as it) -- its Newton solve's last digits are
    the machine's and the code's, and a campaign's scenario must compare equal when it resumes."""
    flown = profile_of(table, where).duration
    return math.floor(flown * 1000.0 + 1e-6) / 1000.0 if "route" in table else flown


@functools.lru_cache(maxsize=16)
def _profile(text, where):
    table = json.loads(text)
    if "route" in table:
        if table.get("segments") or "start" in table:
            raise InputError(f"{where}: a route or a start with segments, not both")
        return _route(table["route"]).profile(f"{where}.route")
    if "start" not in table:
        raise InputError(f"{where}.start: missing required key (or a [{where}.route])")
    if not table.get("segments"):
        raise InputError(f"{where}.segments: missing required key (at least one segment, or a [{where}.route])")
    profile = segments.Profile.from_table({"start": table["start"], "segments": table["segments"]}, where)
    return profile if _clear_of_poles(profile) else dataclasses.replace(profile, frame=FreeAzimuth())


def _clear_of_poles(profile):
    """Whether a profile of segments in the North frame stays below :data:`POLAR_CAP_DEG` of latitude: at once when its
    start lies farther from the cap than it can fly (the sum of each segment's duration times its greater speed),
    else along its North track at :data:`STEP` (L̇ = v_N/(R_M + h) is regular at the poles; λ's value is not used)."""
    lat0 = abs(profile.start.lat_deg)
    ends = [seg.exit(entry).speed for seg, entry in zip(profile.segments, profile.entries)]
    spans = np.diff(np.append(profile.starts, profile.duration))
    reach = sum(t * max(entry.speed, end) for t, entry, end in zip(spans, profile.entries, ends))
    if lat0 + math.degrees(reach / LEAST_MERIDIAN_RADIUS) < POLAR_CAP_DEG:
        return True
    if lat0 >= POLAR_CAP_DEG:
        return False
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        lat = trajectory.track(profile, math.ceil(profile.duration / STEP) / profile.duration).lat
    return bool(np.all(np.abs(np.degrees(lat)) < POLAR_CAP_DEG))


def _route(table):
    points = tuple(Waypoint(**point) for point in table["waypoints"])
    return Route(points, **{key: value for key, value in table.items() if key != "waypoints"})
