"""Initial alignment of a MEMS car IMU: the IMU's axes turned into the body's, levelled from the accelerometers at
rest, the heading from the GNSS velocity once the car moves.

- mounting: f_b = C_b,imu f_imu with C_b,imu the direction-cosine matrix of the roll, pitch, yaw of the IMU's
  mounting (Groves, 2nd ed., eq. (2.22): C_β^α of the Euler angles of β from α, 3-2-1);
- levelling: the mean specific force f̄ of a span at rest gives roll φ = atan2(−f̄_y, −f̄_z) and pitch
  θ = atan(f̄_x / √(f̄_y² + f̄_z²)) (Groves, 2nd ed., eqs. (5.101)-(5.102), body axes forward-right-down); the heading
  is unknown there (a MEMS gyro cannot gyrocompass) and left 0;
- heading: at the first fix with a horizontal speed of at least ``heading_speed_m_per_s`` the heading is the course
  ψ = atan2(v_E, v_N) (a car moves along its body x axis; the sideslip and the mounting's residual yaw are the
  heading's error, its initial σ); the filter starts with the heading the gyros' yaw from the start to that fix
  turns into it (:func:`start_heading`), so that it never integrates the first metres in a wrong direction (a replay
  is post-processing: it may look seconds ahead for its alignment).
"""

import numpy as np

from navsim.earth.wander import ned_offset
from startrack import InputError
from startrack import rotation as rot


def euler_matrix(roll, pitch, yaw):
    """C (3, 3) of Groves, 2nd ed., eq. (2.22): the coordinate transformation of the frame with Euler angles
    (roll, pitch, yaw) [rad] (3-2-1) from the reference frame, i.e. C_b^n transposed for the body's attitude."""
    sr, cr, sp, cp, sy, cy = np.sin(roll), np.cos(roll), np.sin(pitch), np.cos(pitch), np.sin(yaw), np.cos(yaw)
    return np.array([[cp * cy, cp * sy, -sp],
                     [-cr * sy + sr * sp * cy, cr * cy + sr * sp * sy, sr * cp],
                     [sr * sy + cr * sp * cy, -sr * cy + cr * sp * sy, cr * cp]])


def level(specific_force):
    """(roll, pitch) [rad] of the mean body specific force ``specific_force`` (K, 3) [m/s²] of a span at rest
    (Groves eqs. (5.101)-(5.102))."""
    f = np.mean(specific_force, axis=0)
    return float(np.arctan2(-f[1], -f[2])), float(np.arctan(f[0] / np.hypot(f[1], f[2])))


def q_nb(roll, pitch, yaw):
    """q_nb of Euler angles [rad] (the body's attitude in NED)."""
    return rot.from_matrix(euler_matrix(roll, pitch, yaw).T)


def start_heading(course, q_level, gyro, dt):
    """ψ0 [rad]: the heading at the start that the gyros ``gyro`` (K, 3) [rad/s], of intervals ``dt`` [s] from the start
    to the aligning fix, turn into the GNSS ``course`` [rad] there: ψ0 = course − Σ (C_nb ω_b)_D dt, C_nb the levelled
    attitude ``q_level`` (the yaw rate about the local vertical; the Earth's rate, < 0.01 deg/min, left out)."""
    turned = float(np.sum(gyro @ rot.to_matrix(q_level)[2])) * dt
    return (course - turned + np.pi) % (2.0 * np.pi) - np.pi


def rest_span(fixes, start, seconds, max_speed):
    """The end [s] of the span of ``seconds`` after ``start`` used for levelling; an InputError when the fixes show the
    vehicle moving faster than ``max_speed`` [m/s] there (from their velocity, else their differences)."""
    inside = (fixes.t >= start) & (fixes.t <= start + seconds)
    if inside.sum() < 2:
        raise InputError(f"alignment.level_s: fewer than two fixes in the {seconds:g} s levelling span")
    speed = horizontal_speed(fixes)[inside]
    if speed.max() > max_speed:
        raise InputError(f"alignment.level_s: the vehicle moves at {speed.max():.2f} m/s in the levelling span "
                         f"(at rest means below {max_speed:g} m/s); shorten it")
    return start + seconds


def horizontal_speed(fixes):
    """(N,) [m/s] the fixes' horizontal speed: their velocity, else the differences of their positions."""
    return np.hypot(*velocity_ne(fixes).T)


def velocity_ne(fixes):
    """(N, 2) [m/s] the fixes' north and east velocity: stated, else central differences of their positions."""
    if fixes.v_n is not None:
        return fixes.v_n[:, :2]
    ned = ned_offset(fixes.lat, fixes.lon, fixes.h, fixes.lat[0], fixes.lon[0], fixes.h[0])
    return np.stack([np.gradient(ned[:, 0], fixes.t), np.gradient(ned[:, 1], fixes.t)], axis=1)
