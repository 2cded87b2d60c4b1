"""The replay file (``navsim replay REPLAY.toml``): a ``[replay]`` table naming the recording, its IMU's mounting, the
GNSS fixes, the alignment, the filter and the outages. Paths are relative to the file. Checked by the scenario
schema (:mod:`navsim.scenario.schema`): every problem one :class:`InputError` naming the file and the key.

    name = "car"
    [replay.imu]       file, columns, quantity, accel_unit, gyro_unit, time_unit, time_tag_file, time_offset_s,
                       mounting_rpy_deg (the IMU's axes to the body's, Groves eq. 2.22), duration_s (replay only
                       the first seconds of the log)
    [replay.gnss]      file, format ("rtklib_pos" | "csv"), columns (csv), qualities, sigma_floor_m (a floor under
                       the stated position σ), use_velocity (update with the fixes' velocity and its σ too)
    [replay.alignment] level_s, rest_speed_m_per_s, heading_speed_m_per_s
    [replay.filter]    initial σ, the IMU noise the filter assumes, covariance_interval, gate_probability
    [replay.constraints] zupt (zero-velocity updates at rest, :mod:`navsim.replay.stationarity`), zupt_sigma_m_per_s,
                       zupt_window_s, zupt_probability (the detector's), nhc (the non-holonomic constraint while
                       moving), nhc_sigma_m_per_s; both off by default
    [replay.outages]   windows = [{start_s, duration_s}, ...] and/or schedule = {first_s, lengths_s, spacing_s}
                       [s after the replay's start]; free_ins = true holds out every fix after the alignment
    [replay.star_sensor] (optional) reference_attitude (a CSV: time [s, the fixes' GPST], roll, pitch, yaw [deg]),
                       columns (its map), rate_hz, cross_boresight_arcsec, roll_arcsec, mounting_rpy_deg (S to B;
                       the default [180, 0, 0] looks up), seed, apply (false: the frames drawn and logged, not used)
                       (:mod:`navsim.replay.star_sensor`)
"""

from pathlib import Path

from navsim.replay import fixes, recording, star_sensor
from navsim.scenario import checked_table, read_scenario_file
from navsim.scenario.schema import ListOfTables, Table, Value
from startrack import InputError


def _positive(default, maximum=None):
    return Value("float", default=default, exclusive_minimum=0.0, maximum=maximum)


SCHEMA = Table({
    "name": Value("str"),
    "replay": Table({
        "imu": Table({
            "file": Value("str"),
            "columns": Value("strs", choices=(*recording.CHANNELS, "-"), min_length=7),
            "quantity": Value("str", default="rates", choices=tuple(recording.QUANTITY_UNITS)),
            "accel_unit": Value("str"),
            "gyro_unit": Value("str"),
            "time_unit": Value("str", default="s"),
            "time_tag_file": Value("str", default=""),
            "time_offset_s": Value("float", default=0.0, minimum=-10.0, maximum=10.0),
            "mounting_rpy_deg": Value("vector", default=[0.0, 0.0, 0.0], minimum=-360.0, maximum=360.0),
            "duration_s": Value("float", default=None, exclusive_minimum=0.0),
        }),
        "gnss": Table({
            "file": Value("str"),
            "format": Value("str", default="rtklib_pos", choices=("rtklib_pos", "csv")),
            "columns": Value("strs", default=[], choices=(*fixes.CSV_COLUMNS, "-")),
            "qualities": Value("ints", default=[1], min_length=1, minimum=0),
            "sigma_floor_m": Value("float", default=0.0, minimum=0.0, maximum=100.0),
            "use_velocity": Value("bool", default=False),
        }),
        "alignment": Table({
            "level_s": _positive(10.0, maximum=600.0),
            "rest_speed_m_per_s": _positive(0.2),
            "heading_speed_m_per_s": _positive(1.0),
        }),
        "filter": Table({
            "initial_tilt_sigma_deg": _positive(2.0, maximum=30.0),
            "initial_heading_sigma_deg": _positive(5.0, maximum=30.0),
            "initial_velocity_sigma_m_per_s": _positive(0.05),
            "initial_gyro_bias_sigma_deg_per_s": _positive(0.2),
            "initial_accel_bias_sigma_m_per_s2": _positive(0.2),
            "gyro_arw_deg_per_sqrt_s": _positive(0.038),
            "accel_vrw_m_per_s_per_sqrt_s": _positive(0.0137),
            "gyro_bias_rw_deg_per_s_per_sqrt_s": Value("float", default=7.6e-4, minimum=0.0),
            "accel_bias_rw_m_per_s2_per_sqrt_s": Value("float", default=2.75e-3, minimum=0.0),
            "covariance_interval": Value("int", default=5, minimum=1, maximum=1000),
            "gate_probability": Value("float", default=0.9999, exclusive_minimum=0.0, maximum=0.999999999),
        }),
        "constraints": Table({
            "zupt": Value("bool", default=False),
            "zupt_sigma_m_per_s": _positive(0.02, maximum=1.0),
            "zupt_window_s": _positive(1.0, maximum=10.0),
            "zupt_probability": Value("float", default=0.99, exclusive_minimum=0.0, maximum=0.999999999),
            "nhc": Value("bool", default=False),
            "nhc_sigma_m_per_s": _positive(0.1, maximum=5.0),
        }),
        "outages": Table({
            "windows": ListOfTables(Table({"start_s": Value("float", minimum=0.0),
                                           "duration_s": Value("float", exclusive_minimum=0.0)})),
            "schedule": Table({"first_s": Value("float", minimum=0.0),
                               "lengths_s": Value("list", min_length=1, exclusive_minimum=0.0),
                               "spacing_s": Value("float", minimum=0.0)}, optional=True),
            "free_ins": Value("bool", default=False),
        }),
        "star_sensor": Table({
            "reference_attitude": Value("str"),
            "columns": Value("strs", default=list(star_sensor.REFERENCE_COLUMNS),
                             choices=(*star_sensor.REFERENCE_COLUMNS, "-")),
            "rate_hz": _positive(1.0, maximum=100.0),
            "cross_boresight_arcsec": _positive(5.0, maximum=3600.0),
            "roll_arcsec": _positive(40.0, maximum=3600.0),
            "mounting_rpy_deg": Value("vector", default=[180.0, 0.0, 0.0], minimum=-360.0, maximum=360.0),
            "seed": Value("int", default=0, minimum=0),
            "apply": Value("bool", default=True),
        }, optional=True),
    }),
})


def load(path, overrides=()):
    """The checked replay dictionary of the TOML file ``path`` (``overrides``: ``--set`` strings), its file names made
    absolute relative to it."""
    path = Path(path)
    data = checked_table(SCHEMA, read_scenario_file(path, overrides), path.name)
    replay = data["replay"]
    if "time" not in replay["imu"]["columns"]:
        raise InputError(f"{path.name}: replay.imu.columns: needs a 'time' column")
    missing = [c for c in recording.CHANNELS if c not in replay["imu"]["columns"]]
    if missing:
        raise InputError(f"{path.name}: replay.imu.columns: needs a {missing[0]!r} column")
    if replay["gnss"]["format"] == "csv" and not replay["gnss"]["columns"]:
        raise InputError(f"{path.name}: replay.gnss.columns: a csv solution needs its column map")
    files = [(replay["imu"], "file"), (replay["imu"], "time_tag_file"), (replay["gnss"], "file")]
    if "star_sensor" in replay:
        files.append((replay["star_sensor"], "reference_attitude"))
    for table, key in files:
        if table[key]:
            table[key] = str((path.parent / table[key]).resolve())
    return data
