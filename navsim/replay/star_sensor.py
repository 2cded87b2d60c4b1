"""A simulated star sensor in a replay (``[replay.star_sensor]``): attitude fixes drawn from a reference attitude of the
recording and applied with :meth:`navsim.estimation.nav_filter.NavFilter.update_attitude`, in the outages as well.

- **The reference** (:func:`read_reference`): a CSV of the body's attitude to NED, its columns named by a map of
  :data:`REFERENCE_COLUMNS` (``"-"`` to skip one): the time [s] in the fixes' time base (GPST since 1970) and roll,
  pitch, yaw [deg] (3-2-1 Euler angles of the body from NED, Groves, 2nd ed., eq. (2.22)); it is slerped (scipy's
  :class:`~scipy.spatial.transform.Slerp`) to the frames' times.
- **The frames**: every ``round(1 / (rate_hz dt))`` IMU intervals from the filter's start, where the reference and
  the fixes both cover (none there is an :class:`InputError`).
- **The truth of a frame** q_IB = q_ie(t) ⊗ q_en(L, λ) ⊗ q_nb,ref (:func:`navsim.truth.sky.inertial_attitude`), with
  the position (L, λ, h) and the NED velocity of the GNSS fixes (all of them, those held out included) interpolated
  linearly to the frame: the fixes are the recording's own reference, centimetres to decimetres from the truth,
  where the filter's position drifts metres to hundreds of metres in an outage (100 m of position is 3" of q_en:
  a star sensor made from the filter's position would follow the filter's error). The Earth's orientation is
  :class:`~navsim.earth.orientation.EarthOrientation` at the frames (UTC of the GPST, UT1 = UTC), the observer's
  barycentric velocity :func:`~navsim.earth.orientation.observer_velocity` of the fixes' position and velocity.
- **The measurement** is the navigation kind's vector-fidelity attitude fix
  (:meth:`navsim.sensors.star_vector.AttitudeFixSensor.observe_frames`): the aberrated q_IS ⊗ exp(ν/2),
  ν ~ N(0, diag(σ_c², σ_c², σ_r²)) in sensor axes, from a Generator of ``SeedSequence(seed)``; the filter's
  :class:`~navsim.estimation.nav_filter.StarSensorModel` knows the mounting (no mounting state), corrects the
  aberration with its own velocity and position, as the navigation kind's does. No refraction (neither in the
  sensor nor in the processing), no sky (the Sun, the day, clouds): every frame is a fix.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from navsim.earth.frames import gpst_epoch_utc
from navsim.earth.orientation import EarthOrientation, observer_velocity
from navsim.estimation.nav_filter import StarSensorModel
from navsim.replay import csv_table
from navsim.replay.alignment import q_nb, velocity_ne
from navsim.sensors.faults import SensorFaults
from navsim.sensors.star_vector import AttitudeFixSensor
from navsim.truth.sky import inertial_attitude
from startrack import InputError, units

#: The names a reference attitude's column map may use; all four are needed.
REFERENCE_COLUMNS = ("time_s", "roll_deg", "pitch_deg", "yaw_deg")


@dataclass(frozen=True)
class ReferenceAttitude:
    """The body's attitude ``q_nb`` (N, 4) at times ``t`` (N,) [s, the fixes' time base], in time order."""

    t: np.ndarray
    q_nb: np.ndarray


@dataclass(frozen=True)
class ReferenceFrames:
    """The reference at the star frames: ``lat``, ``lon`` [rad], ``h`` [m] and ``v_n`` (F, 3) [m/s] of the fixes,
    ``q_nb`` (F, 4) of the reference attitude (what :func:`navsim.truth.sky.inertial_attitude` reads)."""

    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_n: np.ndarray
    q_nb: np.ndarray


@dataclass(frozen=True)
class StarFixes:
    """The star frames of a replay: ``k`` (F,) the IMU grid index each is taken at (the filter's state after the
    intervals before it), the measured ``q_IS`` (F, 4) and their covariance ``R_S`` (3, 3) [rad², S], the reference
    ``q_nb_ref`` (F, 4) the error is measured against, the filter's ``model``
    (:class:`~navsim.estimation.nav_filter.StarSensorModel`) and ``applied`` (False: drawn and logged, not used)."""

    k: np.ndarray
    q_IS: np.ndarray
    R_S: np.ndarray
    q_nb_ref: np.ndarray
    model: StarSensorModel
    applied: bool


def read_reference(path, columns):
    """The :class:`ReferenceAttitude` of a CSV with the column map ``columns`` (module docstring); an InputError for a
    missing file, an unknown or missing column, a row of the wrong width, a non-finite row or time not increasing."""
    path, table = csv_table.read_table(path, columns, "reference attitude file", "star_sensor.columns",
                                       REFERENCE_COLUMNS, REFERENCE_COLUMNS)
    named = csv_table.named(table, columns)
    csv_table.check_rows(path, np.stack([named[c] for c in REFERENCE_COLUMNS], axis=1))
    back = np.flatnonzero(np.diff(named["time_s"]) <= 0.0)
    if back.size:
        raise InputError(f"{path}: time not increasing at row {back[0] + 2}")
    angles = units.deg_to_rad(np.stack([named["roll_deg"], named["pitch_deg"], named["yaw_deg"]], axis=1))
    return ReferenceAttitude(t=named["time_s"], q_nb=np.array([q_nb(*a) for a in angles]))


def draw(table, imu, fixes, k0):
    """The :class:`StarFixes` of a checked ``[replay.star_sensor]`` ``table`` over the recording ``imu`` (body axes)
    and its ``fixes``, the filter starting at IMU grid index ``k0`` (module docstring)."""
    reference = read_reference(table["reference_attitude"], table["columns"])
    step = max(1, round(1.0 / (table["rate_hz"] * imu.dt)))
    k = np.arange(k0 + step, imu.samples.shape[0] + 1, step)
    t = imu.t0 + k * imu.dt
    lo, hi = max(reference.t[0], fixes.t[0]), min(reference.t[-1], fixes.t[-1])
    inside = (t >= lo) & (t <= hi)
    if not inside.any():
        raise InputError(f"{table['reference_attitude']}: the reference attitude ({reference.t[0]:.3f} to "
                         f"{reference.t[-1]:.3f} s) does not cover the recording's fixes ({fixes.t[0]:.3f} to "
                         f"{fixes.t[-1]:.3f} s)")
    k, t = k[inside], t[inside]
    frames = reference_frames(reference, fixes, t)
    start = imu.t0 + k0 * imu.dt
    try:
        epoch = gpst_epoch_utc(start)
    except InputError as error:
        raise InputError(f"replay.star_sensor: the Earth's orientation needs the fixes' time in GPST: {error}") from None
    orientation = EarthOrientation.compute(epoch, (k - k0) * imu.dt)
    v_I = np.array([observer_velocity(orientation.c_ie[f], orientation.v_earth[f], frames.lat[f], frames.lon[f],
                                      frames.h[f], frames.v_n[f]) for f in range(k.size)])
    q_BS = q_nb(*units.deg_to_rad(table["mounting_rpy_deg"]))
    sensor = AttitudeFixSensor(sigma_cross=float(units.arcsec_to_rad(table["cross_boresight_arcsec"])),
                               sigma_roll=float(units.arcsec_to_rad(table["roll_arcsec"])), q_BS_true=q_BS,
                               faults=SensorFaults(outages=(), dropped_s=np.zeros(0), storms=(),
                                                   frame_interval=step * imu.dt))
    rng = np.random.default_rng(np.random.SeedSequence(table["seed"]))
    q_IS = sensor.observe_frames(inertial_attitude(frames, orientation, np.arange(k.size)), rng, v_I)
    return StarFixes(k=k, q_IS=q_IS, R_S=sensor.R_S, q_nb_ref=frames.q_nb,
                     model=StarSensorModel(q_BS=q_BS, mounting="ignore", orientation=orientation),
                     applied=table["apply"])


def reference_frames(reference, fixes, t):
    """The :class:`ReferenceFrames` at times ``t`` (F,) [s] inside both the reference and the fixes: their position
    and velocity interpolated linearly (the longitude unwrapped), the attitude slerped."""
    velocity = np.column_stack([velocity_ne(fixes), vertical_velocity(fixes)])
    q = Slerp(reference.t, Rotation.from_quat(reference.q_nb))(t).as_quat()
    return ReferenceFrames(lat=np.interp(t, fixes.t, fixes.lat), lon=np.interp(t, fixes.t, np.unwrap(fixes.lon)),
                           h=np.interp(t, fixes.t, fixes.h),
                           v_n=np.stack([np.interp(t, fixes.t, velocity[:, i]) for i in range(3)], axis=1), q_nb=q)


def vertical_velocity(fixes):
    """(N,) [m/s] the fixes' down velocity: stated, else the differences of their heights."""
    return fixes.v_n[:, 2] if fixes.v_n is not None else -np.gradient(fixes.h, fixes.t)
