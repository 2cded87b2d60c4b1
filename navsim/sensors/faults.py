"""Faults a scenario can switch on (``[faults]``), applied to the truth and the sensor stream.

Gyro bias steps change the true bias (and so the gyro output) from their time on; outages and
dropped frames remove star-sensor frames. Attitude jumps and false-star storms act inside the
image-fidelity closed loop (:mod:`navsim.closed_loop`).
"""

import numpy as np

from startrack import units


def apply_bias_steps(omega, bias, t_samples, steps):
    """Gyro output and true bias with each step (deg/h, at ``time_s``) added from its time on.

    ``t_samples`` (M,) are the sample times [s] (end of each gyro interval)."""
    if not steps:
        return omega, bias
    omega, bias = omega.copy(), bias.copy()
    for step in steps:
        after = t_samples > step["time_s"]
        delta = units.deg_per_h_to_rad_per_s(step["step_deg_per_h"])
        omega[after] += delta
        bias[after] += delta
    return omega, bias


def frames_available(t_frames, faults, frame_interval):
    """False for frames inside an outage or dropped (within half a frame interval of a listed time)."""
    available = np.ones(len(t_frames), dtype=bool)
    for outage in faults["outages"]:
        available &= ~((t_frames >= outage["start_s"]) & (t_frames < outage["end_s"]))
    for t in faults["dropped_frames_s"]:
        available &= np.abs(t_frames - t) >= 0.5 * frame_interval
    return available
