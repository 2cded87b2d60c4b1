"""A synthetic recording for the replay tests: the project's own truth (a car: 20 s at rest, away at 1 m/s², two turns)
and its exact IMU increments with known errors (constant biases, seeded white noise), written as an IMU CSV of
increments in a mounted IMU's axes and a CSV of 4 Hz position fixes with seeded noise of their stated σ."""

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from navsim.earth.wander import displaced
from navsim.replay.alignment import euler_matrix
from navsim.truth import trajectory
from navsim.truth.segments import Accelerate, Hold, Profile, Start, Straight, Turn
from startrack import units

RATE_HZ = 100.0
FIX_HZ = 4.0
GYRO_BIAS = np.array([0.02, -0.03, 0.05]) * units.DEG        # rad/s
ACCEL_BIAS = np.array([0.02, -0.015, 0.03])                   # m/s²
ARW = 0.005 * units.DEG                                       # rad/√s
VRW = 0.002                                                   # m/s/√s
FIX_SIGMA = np.array([0.02, 0.02, 0.04])                      # m, N E D
MOUNTING_RPY_DEG = [180.0, -5.0, 170.0]
T0 = 1_700_000_000.0                                          # s, the recording's clock


def car_truth():
    """The truth of a 170 s drive at 100 Hz."""
    profile = Profile(Start(40.0, -105.0, 1600.0, 0.0, heading_deg=60.0),
                      (Hold(20.0), Accelerate(10.0, 1.0), Straight(20.0), Turn(90.0, 6.0), Straight(40.0),
                       Turn(-60.0, 6.0), Straight(50.0)))
    return trajectory.generate(profile, RATE_HZ)


def stop_and_go_truth():
    """The truth of a 120 s drive at 100 Hz with two rest spans: 20 s at the start, 15 s after a stop at 1 m/s² from
    8 m/s, then away again."""
    profile = Profile(Start(40.0, -105.0, 1600.0, 0.0, heading_deg=60.0),
                      (Hold(20.0), Accelerate(8.0, 1.0), Straight(15.0), Turn(90.0, 6.0), Accelerate(0.0, 1.0),
                       Hold(15.0), Accelerate(8.0, 1.0), Straight(20.0)))
    return trajectory.generate(profile, RATE_HZ)


def moving(truth):
    """(M,) whether the vehicle moves over each IMU interval of ``truth`` (a speed above 1 mm/s at either end)."""
    speed = np.linalg.norm(truth.v_n, axis=1) > 1e-3
    return speed[1:] | speed[:-1]


def write_recording(directory, truth, seed=5, drop=(), vibration=0.0):
    """Write ``imu.csv`` (increments in the mounted IMU's axes, time [s]; the rows ``drop`` (consecutive) left out, their
    increments in the row after them, as an accumulating IMU's after lost packets: a gap) and
    ``fixes.csv`` (4 Hz, with σ) of ``truth`` into ``directory``; returns their paths. ``vibration`` [m/s²]: the RMS
    per axis of white specific force added where the vehicle moves (:func:`moving`), a road's."""
    directory = Path(directory)
    gyro_rng, accel_rng, fix_rng, road_rng = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(4))
    dt = truth.dt
    dtheta = truth.dtheta + GYRO_BIAS * dt + ARW * np.sqrt(dt) * gyro_rng.standard_normal(truth.dtheta.shape)
    dv = truth.dv + ACCEL_BIAS * dt + VRW * np.sqrt(dt) * accel_rng.standard_normal(truth.dv.shape)
    if vibration:
        dv += moving(truth)[:, None] * vibration * dt * road_rng.standard_normal(truth.dv.shape)
    C_imu_b = euler_matrix(*units.deg_to_rad(MOUNTING_RPY_DEG)).T
    rows = np.concatenate([dv @ C_imu_b.T, dtheta @ C_imu_b.T, truth.t[1:, None] + T0], axis=1)
    rows = np.concatenate([[[0.0] * 6 + [T0]], rows])  # the first row: the clock's start, its increments unused
    if len(drop):
        rows[max(drop) + 1, :6] += rows[list(drop), :6].sum(axis=0)
        rows = np.delete(rows, list(drop), axis=0)
    imu = directory / "imu.csv"
    np.savetxt(imu, rows, delimiter=",", fmt="%.12g")
    every = round(RATE_HZ / FIX_HZ)
    k = np.arange(0, truth.t.size, every)
    noise = FIX_SIGMA * fix_rng.standard_normal((k.size, 3))
    lat, lon = displaced(truth.lat[k], truth.lon[k], truth.h[k], noise[:, 0], noise[:, 1])
    fixes = directory / "fixes.csv"
    table = np.column_stack([truth.t[k] + T0, np.degrees(lat), np.degrees(lon), truth.h[k] - noise[:, 2],
                             *np.broadcast_to(FIX_SIGMA, (k.size, 3)).T])
    np.savetxt(fixes, table, delimiter=",", fmt="%.12f")
    return imu, fixes


def replay_toml(directory, imu, fixes, outages="windows = [{start_s = 110.0, duration_s = 30.0}]", extra=""):
    """Write ``replay.toml`` for the recording and return its path."""
    path = Path(directory) / "replay.toml"
    path.write_text(f"""name = "synthetic"
[replay.imu]
file = "{imu}"
columns = ["accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z", "time"]
quantity = "increments"
accel_unit = "m/s"
gyro_unit = "rad"
time_unit = "s"
mounting_rpy_deg = {MOUNTING_RPY_DEG}
[replay.gnss]
file = "{fixes}"
format = "csv"
columns = ["time_s", "lat_deg", "lon_deg", "h_m", "sd_n_m", "sd_e_m", "sd_u_m"]
[replay.alignment]
level_s = 15.0
[replay.filter]
gyro_arw_deg_per_sqrt_s = 0.005
accel_vrw_m_per_s_per_sqrt_s = 0.002
gyro_bias_rw_deg_per_s_per_sqrt_s = 1e-5
accel_bias_rw_m_per_s2_per_sqrt_s = 1e-5
initial_gyro_bias_sigma_deg_per_s = 0.1
initial_accel_bias_sigma_m_per_s2 = 0.1
[replay.outages]
{outages}
{extra}
""")
    return path


def write_reference(directory, truth, every=10):
    """Write ``reference.csv``: the truth's attitude every ``every`` samples as time [s, the fixes' clock], roll,
    pitch, yaw [deg] (scipy's intrinsic ZYX angles of q_nb: independent of the replay's Euler conversion); returns
    its path."""
    k = np.arange(0, truth.t.size, every)
    yaw, pitch, roll = Rotation.from_quat(truth.q_nb[k]).as_euler("ZYX", degrees=True).T
    path = Path(directory) / "reference.csv"
    np.savetxt(path, np.column_stack([truth.t[k] + T0, roll, pitch, yaw]), delimiter=",", fmt="%.12f")
    return path


def star_table(reference, **keys):
    """A ``[replay.star_sensor]`` table for :func:`replay_toml`'s ``extra``."""
    lines = [f'reference_attitude = "{reference}"', *(f"{k} = {str(v).lower() if isinstance(v, bool) else v}"
                                                      for k, v in keys.items())]
    return "[replay.star_sensor]\n" + "\n".join(lines)
