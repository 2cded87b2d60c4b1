"""Shared helpers of the INS tests: navigation errors of a strapdown log against a truth trajectory, and
the trajectories of the shipped navigation scenarios."""

from pathlib import Path

import numpy as np

from navsim.earth.wander import ned_offset
from navsim.kinds import load_scenario
from navsim.truth.segments import Profile
from startrack.geometry import rotation as rot

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def position_errors(log, truth, every=1):
    """(north, east, down) position errors [m] (K, 3) of a log against the truth samples it logged."""
    return ned_offset(log.lat, log.lon, log.h, truth.lat[::every], truth.lon[::every], truth.h[::every])


def attitude_errors(log, truth, every=1):
    """Attitude error rotation vectors [rad] (K, 3) of q_est against q_true (in the truth's b axes)."""
    return rot.attitude_error(truth.q_nb[::every], log.q_nb)


def trajectory_table(name):
    """The validated [trajectory] table of scenarios/NAME.toml."""
    return load_scenario(SCENARIOS / f"{name}.toml")["trajectory"]


def aircraft_first_hour():
    """The 2 h aircraft flight of the shipped scenarios cut at 1 h: climb to 7 km, four turns, a speed
    change and the start of the descent."""
    table = trajectory_table("free_ins_navigation_aircraft")
    segments = table["segments"][:9]
    head = Profile.from_table({**table, "segments": segments}).duration
    return Profile.from_table({**table, "segments": segments + [{"kind": "straight", "duration_s": 3600.0 - head}]})
