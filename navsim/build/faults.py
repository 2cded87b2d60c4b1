"""The faults of a scenario's ``[faults]`` table in SI units (:mod:`navsim.sensors.faults`): gyro bias
steps, the star sensor's outages, dropped frames and false-star storms, and attitude jumps."""

import numpy as np

from navsim.sensors.faults import SensorFaults
from startrack import units


def bias_steps(faults):
    """The gyro bias steps of ``scenario['faults']`` in SI: ((time [s], step (3,) [rad/s]), ...)."""
    return tuple((s["time_s"], units.deg_per_h_to_rad_per_s(s["step_deg_per_h"])) for s in faults["gyro_bias_steps"])


def sensor_faults(faults, frame_interval):
    """The :class:`~navsim.sensors.faults.SensorFaults` of ``scenario['faults']`` on frames ``frame_interval``
    [s] apart."""
    return SensorFaults(outages=tuple((o["start_s"], o["end_s"], o["reason"]) for o in faults["outages"]),
                        dropped_s=np.asarray(faults["dropped_frames_s"], dtype=float),
                        storms=tuple((s["start_s"], s["end_s"], s["count"]) for s in faults["false_star_storms"]),
                        frame_interval=frame_interval)


def attitude_jumps(faults):
    """The attitude jumps of ``scenario['faults']`` in time order: ((time [s], angle [rad]), ...)."""
    ordered = sorted(faults["attitude_jumps"], key=lambda j: j["time_s"])
    return tuple((j["time_s"], float(units.deg_to_rad(j["angle_deg"]))) for j in ordered)
