"""Shared helpers of the INS tests: navigation errors of a strapdown log against a truth trajectory."""

import numpy as np

from navsim.earth.wgs84 import radii
from navsim.truth.segments import Profile
from navsim.truth.tables import AIRCRAFT_2H
from startrack import rotation as rot


def position_errors(log, truth, every=1):
    """(north, east, down) position errors [m] (K, 3) of a log against the truth samples it logged."""
    lat, lon, h = truth.lat[::every], truth.lon[::every], truth.h[::every]
    r_m, r_n = radii(lat)
    return np.stack([(log.lat - lat) * (r_m + h), (log.lon - lon) * (r_n + h) * np.cos(lat), -(log.h - h)], axis=-1)


def attitude_errors(log, truth, every=1):
    """Attitude error rotation vectors [rad] (K, 3) of q_est against q_true (in the truth's b axes)."""
    return rot.attitude_error(truth.q_nb[::every], log.q_nb)


def aircraft_first_hour():
    """The 2 h aircraft table cut at 1 h: climb to 7 km, four turns, a speed change and the start of
    the descent."""
    segments = AIRCRAFT_2H["segments"][:9]
    head = Profile.from_table({**AIRCRAFT_2H, "segments": segments}).duration
    return Profile.from_table({**AIRCRAFT_2H, "segments": segments + [{"kind": "straight", "duration_s": 3600.0 - head}]})
