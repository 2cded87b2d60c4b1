"""The navigation scenario kind: a scenario file with a ``[trajectory]`` table (docs/design.md, "The
navigation scenario").

Its own strict schema (:data:`SCHEMA`: units in the key names, every value bounded) and cross-key
rules (:func:`validate`): the trajectory's segments of :mod:`navsim.truth.segments` (a
segment that cannot be flown is named), the IMU (a gyro and an accelerometer, each a preset and/or
datasheet fields), an optional baro, position aiding (none: a free INS), an optional star sensor
(SINS/CNS: the attitude kind's star-sensor keys and its faults), an optional gravity disturbance and
the filter, whose noise and initial σ come from the datasheets unless given.
Every problem is one :class:`~startrack.base.errors.InputError` naming the file, the key and what is wrong.
"""

import dataclasses

import numpy as np

from navsim.earth.frames import julian_year, utc_epoch
from navsim.estimation.treatments import TREATMENTS
from navsim.scenario import checked_table
from navsim.scenario.inertial_fields import ACCELEROMETER_ERRORS, GYRO_ERRORS, MAX_ARCSEC
from navsim.scenario.schema import REQUIRED, ListOfTables, Table, Tagged, Value, is_multiple
from navsim.scenario.star_sensor_fields import (
    FAULTS,
    IDENTIFICATION,
    PHOTOMETRY,
    REFRACTION,
    STAR_SENSOR,
    check_faults,
    check_star_sensor,
    mounting,
)
from navsim.scenario.star_sensor_presets import PRESETS, with_preset
from navsim.truth import route, segments, trajectory
from startrack import InputError
from startrack import rotation as rot

#: Bounds: speed [m/s] (below orbital speed), height [m] (the ellipsoid +/- ), a segments start's latitude [deg]
#: (headings from north are singular at the poles: routes go there), a segment's duration [s].
MAX_SPEED, MAX_HEIGHT, MAX_LATITUDE, MAX_DURATION = 7500.0, 1e5, 90.0, 2.6e6
#: Samples of the flight on which the star sensor's boresight elevation is checked.
ELEVATION_SAMPLES = 2000
#: ... and of each segment, its ends included (a turn's bank, however short against the flight).
SEGMENT_SAMPLES = 9
#: What one run holds in memory: IMU samples (the truth trajectory and both sensors) and frames (each
#: with the filter's covariance).
MAX_IMU_SAMPLES, MAX_FRAMES = 1e7, 1e5
#: A free vertical channel diverges (e-folding time √(a/2g) ≈ 570 s): longer runs need a baro.
MAX_FREE_VERTICAL_S = 3600.0
#: Frames per second of a run without aiding sensors (the run log's rate).
FREE_FRAME_RATE_HZ = 1.0


def _default(kind, name):
    """The default of field ``name`` of segment class ``kind`` (one set of defaults: the dataclass's)."""
    return next(f.default for f in dataclasses.fields(kind) if f.name == name)


def _seconds(kind=None, name=None, maximum=1e4):
    """A positive time [s]: required, or with the default of segment class ``kind``'s field ``name``."""
    default = _default(kind, name) if kind is not None else REQUIRED
    return Value("float", default=default, exclusive_minimum=0.0, maximum=maximum)


def _ship():
    ship = segments.ShipMotion
    return Table({
        "duration_s": _seconds(maximum=MAX_DURATION),
        "roll_amplitude_deg": Value("float", default=_default(ship, "roll_amplitude_deg"), minimum=-45.0, maximum=45.0),
        "roll_period_s": _seconds(ship, "roll_period_s"),
        "pitch_amplitude_deg": Value("float", default=_default(ship, "pitch_amplitude_deg"), minimum=-30.0, maximum=30.0),
        "pitch_period_s": _seconds(ship, "pitch_period_s"),
        "heave_amplitude_m": Value("float", default=_default(ship, "heave_amplitude_m"), minimum=-100.0, maximum=100.0),
        "heave_period_s": _seconds(ship, "heave_period_s"),
        "ramp_s": _seconds(ship, "ramp_s"),
    })


#: One trajectory segment: its ``kind`` and that kind's keys (:mod:`navsim.truth.segments`).
SEGMENT = Tagged("kind", {
    "hold": Table({"duration_s": _seconds(maximum=MAX_DURATION)}),
    "straight": Table({"duration_s": _seconds(maximum=MAX_DURATION)}),
    "accelerate": Table({
        "speed_m_per_s": Value("float", minimum=0.0, maximum=MAX_SPEED),
        "acceleration_m_per_s2": Value("float", exclusive_minimum=0.0, maximum=100.0),
        "ramp_s": _seconds(segments.Accelerate, "ramp_s"),
    }),
    "turn": Table({
        "heading_change_deg": Value("float", minimum=-36000.0, maximum=36000.0),
        "rate_deg_per_s": Value("float", exclusive_minimum=0.0, maximum=100.0),
        "roll_in_s": _seconds(segments.Turn, "roll_in_s"),
        "bank_deg": Value("float", default=None, minimum=-89.0, maximum=89.0,
                          doc="checked against tan φ = V ψ̇ / g0 (within 1 %): a turn that cannot be flown is refused"),
    }),
    "climb": Table({
        "height_change_m": Value("float", minimum=-MAX_HEIGHT, maximum=MAX_HEIGHT),
        "rate_m_per_s": Value("float", exclusive_minimum=0.0, maximum=1000.0),
        "transition_s": _seconds(segments.Climb, "transition_s"),
    }),
    "ship": _ship(),
})

#: A route of waypoints flown over along geodesics (:mod:`navsim.truth.route`), instead of start and segments.
ROUTE = Table({
    "bank_deg": Value("float", default=_default(route.Route, "bank_deg"), exclusive_minimum=0.0,
                      maximum=route.MAX_BANK_DEG, doc="of the coordinated turns between legs"),
    "roll_in_s": _seconds(route.Route, "roll_in_s"),
    "acceleration_m_per_s2": Value("float", default=_default(route.Route, "acceleration_m_per_s2"),
                                   exclusive_minimum=0.0, maximum=100.0, doc="of the speed changes at a leg's start"),
    "climb_rate_m_per_s": Value("float", default=_default(route.Route, "climb_rate_m_per_s"), exclusive_minimum=0.0,
                                maximum=1000.0, doc="of the height changes at a leg's start"),
    "waypoints": ListOfTables(Table({
        "lat_deg": Value("float", minimum=-90.0, maximum=90.0),
        "lon_deg": Value("float", minimum=-360.0, maximum=360.0),
        "height_m": Value("float", default=0.0, minimum=-1000.0, maximum=MAX_HEIGHT),
        "speed_m_per_s": Value("float", exclusive_minimum=0.0, maximum=MAX_SPEED),
    }), required=True, doc="flown over in order (at least two), each at its height and speed"),
}, optional=True, doc="waypoints flown over along geodesics, the poles and the antimeridian included")

SCHEMA = Table(
    {
        "name": Value("str"),
        "description": Value("str", default=""),
        "seed": Value("int", default=0, minimum=0, maximum=2**63 - 1),
        "epoch_utc": Value("str", default="2000-01-01T12:00:00",
                           doc="UTC calendar epoch of t = 0 (C_ei of pyerfa; the star sensor's sky)"),
        "duration_s": Value("float", default=None, exclusive_minimum=0.0, maximum=MAX_DURATION,
                            doc="default: the whole trajectory; shorter runs stop early"),
        "settle_s": Value("float", default=None, minimum=0.0,
                          doc="errors are summarised after this time (default: 10 % of the run)"),
        "trajectory": Table({
            "start": Table({
                "lat_deg": Value("float", minimum=-MAX_LATITUDE, maximum=MAX_LATITUDE),
                "lon_deg": Value("float", minimum=-360.0, maximum=360.0),
                "height_m": Value("float", default=0.0, minimum=-1000.0, maximum=MAX_HEIGHT,
                                  doc="above the WGS-84 ellipsoid; at most 1 km below it"),
                "speed_m_per_s": Value("float", default=0.0, minimum=0.0, maximum=MAX_SPEED),
                "heading_deg": Value("float", default=0.0, minimum=-360.0, maximum=360.0),
            }, optional=True, doc="where the segments start (not with a route)"),
            "segments": ListOfTables(SEGMENT, doc="headings and turns from the start, at least one (not with a route)"),
            "route": ROUTE,
        }),
        "imu": Table({
            "rate_hz": Value("float", exclusive_minimum=0.0, maximum=1e4),
            "gyro": Table(dict(GYRO_ERRORS)),
            "accelerometer": Table(dict(ACCELEROMETER_ERRORS)),
        }),
        "baro": Table({
            "rate_hz": Value("float", exclusive_minimum=0.0, maximum=1e3),
            "noise_sigma_m": Value("float", default=1.0, exclusive_minimum=0.0, maximum=1e4),
            "bias_sigma_m": Value("float", default=0.0, minimum=0.0, maximum=1e4),
            "bias_rw_m_per_sqrt_h": Value("float", default=0.0, minimum=0.0, maximum=1e4),
            "lag_s": Value("float", default=0.0, minimum=0.0, maximum=1e4),
        }, optional=True, doc="a barometric altimeter: a height measurement of the filter at its rate"),
        "aiding": Table({
            "position": Table({
                "rate_hz": Value("float", exclusive_minimum=0.0, maximum=1e3),
                "sigma_ned_m": Value("vector", exclusive_minimum=0.0, maximum=1e6,
                                     doc="1σ of the fix's north, east and down errors"),
            }, optional=True, doc="position fixes (GNSS-like): the truth plus white NED noise"),
        }, doc="no table: a free INS"),
        "star_sensor": Table({
            "preset": Value("str", default=None, choices=tuple(PRESETS),
                            doc="a named sensor (navsim.scenario.star_sensor_presets) filling the keys the table "
                                "leaves unset: field, band, catalog depth, image size, exposure, aperture, detector"),
            **STAR_SENSOR,
            "aberration_correction": Value("bool", default=True,
                                           doc="the processing aberrates the catalog stars with the INS's velocity and "
                                               "the ephemeris (the truth always sees apparent stars)"),
            "sun_exclusion_deg": Value("float", default=0.0, minimum=0.0, maximum=180.0,
                                       doc="no frame while the Sun is within this angle of the boresight (0: none)"),
            "moon_exclusion_deg": Value("float", default=0.0, minimum=0.0, maximum=180.0,
                                        doc="no frame while the Moon is within this angle of the boresight (0: none)"),
            "min_elevation_deg": Value("float", default=-90.0, minimum=-90.0, maximum=90.0,
                                       doc="no frame while the boresight is lower above the local horizon (-90: none)"),
            "photometry": PHOTOMETRY,
            "refraction": REFRACTION,
            "identification": IDENTIFICATION,
        }, optional=True, doc="a star sensor aiding the INS (SINS/CNS) at its rate, vector or image fidelity"),
        "faults": Table(dict(FAULTS), doc="outages, dropped frames, false-star storms and attitude jumps of the star "
                                          "sensor; gyro bias steps"),
        "gravity": Table({
            "model": Value("str", choices=("constant", "random")),
            "xi_arcsec": Value("float", default=0.0, minimum=-3600.0, maximum=3600.0,
                               doc="north-south deflection of the vertical (constant) or its σ (random)"),
            "eta_arcsec": Value("float", default=0.0, minimum=-3600.0, maximum=3600.0,
                                doc="east-west deflection of the vertical (constant) or its σ (random)"),
            "anomaly_mgal": Value("float", default=0.0, minimum=-1e4, maximum=1e4, doc="anomaly (constant) or its σ"),
            "correlation_length_m": Value("float", default=None, exclusive_minimum=0.0, maximum=1e8,
                                          doc="random: the correlation length along the track"),
        }, optional=True, doc="a gravity disturbance of the truth, unknown to the INS"),
        "filter": Table({
            "initial_tilt_sigma_arcsec": Value("float", default=None, exclusive_minimum=0.0, maximum=36000.0,
                                               doc="default: levelling's limit, accelerometer bias σ / g"),
            "initial_heading_sigma_deg": Value("float", default=None, exclusive_minimum=0.0, maximum=30.0,
                                               doc="default: gyrocompassing's limit, gyro bias σ / (ω_ie cos L), "
                                                   "at most 10 deg"),
            "initial_velocity_sigma_m_per_s": Value("float", default=0.1, exclusive_minimum=0.0, maximum=1e3),
            "initial_position_sigma_m": Value("float", default=5.0, exclusive_minimum=0.0, maximum=1e5),
            "initial_attitude_error_arcsec": Value("vector", default=None, minimum=-36000.0, maximum=36000.0,
                                                   doc="the filter's initial attitude error φ (NED: the tilts and −heading "
                                                       "error), fixed instead of drawn from its σ (PSINS avperrset's "
                                                       "phi, in arcsec)"),
            "initial_velocity_error_m_per_s": Value("vector", default=None, minimum=-1e3, maximum=1e3,
                                                    doc="the filter's initial velocity error (NED), fixed instead of drawn"),
            "initial_position_error_m": Value("vector", default=None, minimum=-1e5, maximum=1e5,
                                              doc="the filter's initial position error (NED), fixed instead of drawn"),
            "scale_factors": Value("str", default=None, choices=("estimate", "ignore"),
                                   doc="six scale-factor states (gyro and accelerometer); default: estimate when "
                                       "either sensor has a scale-factor error"),
            "covariance_interval": Value("int", default=20, minimum=1, maximum=100000,
                                         doc="IMU intervals per covariance propagation"),
            "gate_probability": Value("float", default=0.9999, exclusive_minimum=0.0, maximum=0.999999999),
            "process_noise_scale": Value("float", default=1.0, exclusive_minimum=0.0, maximum=1e6),
            "measurement_noise_scale": Value("float", default=1.0, exclusive_minimum=0.0, maximum=1e6),
            "baro_states": Value("str", default="vertical", choices=("vertical", "all"),
                                 doc="the states a baro height updates: the vertical channel (δv_D, δh, the body-z "
                                     "accelerometer bias), or all (a white-noise height reference: its Coriolis and "
                                     "manoeuvre couplings then inform the horizontal channels, as in PSINS)"),
            "mounting": Value("str", default="estimate", choices=TREATMENTS,
                              doc="the star-sensor mounting error μ (star_sensor.misalignment_arcsec is its truth): "
                                  "three states estimated, consider states (Schmidt) or ignored"),
            "initial_mounting_sigma_arcsec": Value("float", default=60.0, exclusive_minimum=0.0, maximum=MAX_ARCSEC),
            "gravity": Value("str", default="consider", choices=("consider", "ignore"),
                             doc="the gravity disturbance as three consider states (Schmidt) when the filter has a "
                                 "gravity model (its σ below, default from [gravity]), or ignored"),
            "deflection_sigma_arcsec": Value("float", default=None, exclusive_minimum=0.0, maximum=3600.0,
                                             doc="σ of each deflection of the vertical the filter assumes (default: "
                                                 "[gravity]'s σ, or the magnitude of a constant one)"),
            "anomaly_sigma_mgal": Value("float", default=None, exclusive_minimum=0.0, maximum=1e4,
                                        doc="σ of the gravity anomaly the filter assumes (default from [gravity])"),
            "gravity_correlation_length_m": Value("float", default=None, exclusive_minimum=0.0, maximum=1e8,
                                                  doc="correlation length the filter assumes (default: [gravity]'s; "
                                                      "a constant disturbance: infinite)"),
        }),
    }
)


#: The years [Julian year] the star sensor's ephemerides serve (erfa.epv00: 1900-2100).
EPHEMERIS_YEARS = (1900, 2100)


def validate(data, source):
    """The checked dictionary of a navigation scenario: :data:`SCHEMA` and the cross-key rules (derived
    defaults filled: ``duration_s``, ``settle_s``); one InputError naming the key otherwise."""
    if isinstance(data, dict) and "star_sensor" in data:
        data = {**data, "star_sensor": with_preset(data["star_sensor"], source)}
    checked = checked_table(SCHEMA, data, source)
    try:
        utc_epoch(checked["epoch_utc"])
        flown = route.profile_of(checked["trajectory"]).duration
    except InputError as error:
        raise InputError(f"{source}: {error}") from None
    imu_hz = checked["imu"]["rate_hz"]
    if checked["duration_s"] is None:
        checked["duration_s"] = route.flight_time(checked["trajectory"])
    if checked["duration_s"] > flown + 1e-9:
        raise InputError(f"{source}: duration_s: {checked['duration_s']:g} s is longer than the trajectory "
                         f"({flown:g} s)")
    if checked["duration_s"] * imu_hz < 1.0:
        raise InputError(f"{source}: imu.rate_hz: {imu_hz:g} Hz gives no IMU interval in {checked['duration_s']:g} s")
    frame_hz = frame_rate(checked, source)
    _check_run_size(checked, frame_hz, source)
    if "position" not in checked["aiding"] and "baro" not in checked and checked["duration_s"] > MAX_FREE_VERTICAL_S:
        raise InputError(f"{source}: baro: a free INS of {checked['duration_s']:g} s needs a [baro] table (the free "
                             f"vertical channel diverges, e-folding time 570 s; at most {MAX_FREE_VERTICAL_S:g} s without)")
    _check_gravity(checked.get("gravity"), source)
    _check_star_sensor(checked, source)
    _check_ephemeris(checked, source)
    _check_baro_states(checked, source)
    if checked["settle_s"] is None:
        checked["settle_s"] = 0.1 * checked["duration_s"]
    if checked["settle_s"] >= checked["duration_s"]:
        raise InputError(f"{source}: settle_s: must be shorter than duration_s")
    return checked


def check_tuning(scenario):
    """Filter tuning judges the NIS: an InputError for a free INS without [baro] (no measurement at all)."""
    if not aiding_rates(scenario.data):
        raise InputError(f"{scenario.source}: filter tuning needs measurements to judge the NIS by; a free INS without "
                         "[baro] has none (add [aiding.position] or [baro])")


def aiding_rates(checked):
    """{key: rate [Hz]} of the aiding sensors a navigation scenario has (star sensor, position fix, baro)."""
    rates = {}
    if "star_sensor" in checked:
        rates["star_sensor.rate_hz"] = checked["star_sensor"]["rate_hz"]
    if "position" in checked["aiding"]:
        rates["aiding.position.rate_hz"] = checked["aiding"]["position"]["rate_hz"]
    if "baro" in checked:
        rates["baro.rate_hz"] = checked["baro"]["rate_hz"]
    return rates


def frame_rate(checked, source="<scenario>"):
    """The rate of the run's frames [Hz]: the star sensor's, else the fastest aiding sensor's (1 Hz
    without one, or the IMU's when slower). Every aiding rate must divide it and it must divide the
    IMU rate: an aiding sensor faster than the IMU is refused."""
    imu_hz = checked["imu"]["rate_hz"]
    rates = aiding_rates(checked)
    for key, rate in rates.items():
        if rate > imu_hz * (1.0 + 1e-9):
            raise InputError(f"{source}: {key}: {rate:g} Hz is faster than the IMU (imu.rate_hz = {imu_hz:g} Hz)")
        if not is_multiple(imu_hz, rate):
            raise InputError(f"{source}: {key}: {rate:g} Hz must divide imu.rate_hz = {imu_hz:g} Hz")
    star_hz = rates.get("star_sensor.rate_hz")
    frame_hz = star_hz or (max(rates.values()) if rates else min(FREE_FRAME_RATE_HZ, imu_hz))
    for key, rate in rates.items():
        if not is_multiple(frame_hz, rate):
            what = "the star sensor's rate (the run's frames)" if star_hz else "the fastest aiding rate"
            raise InputError(f"{source}: {key}: {rate:g} Hz must divide {what}, {frame_hz:g} Hz")
    if not is_multiple(imu_hz, frame_hz):
        raise InputError(f"{source}: imu.rate_hz: {imu_hz:g} Hz must be a multiple of the frame rate {frame_hz:g} Hz")
    return frame_hz


def _check_run_size(checked, frame_hz, source):
    duration = checked["duration_s"]
    samples, frames = duration * checked["imu"]["rate_hz"], duration * frame_hz
    if samples > MAX_IMU_SAMPLES:
        raise InputError(f"{source}: duration_s: {duration:g} s at imu.rate_hz = {checked['imu']['rate_hz']:g} Hz is "
                         f"{samples:.3g} IMU samples, more than the {MAX_IMU_SAMPLES:.0e} one run holds in memory; "
                         "lower the IMU rate or shorten the run")
    if frames > MAX_FRAMES:
        raise InputError(f"{source}: duration_s: {duration:g} s at {frame_hz:g} frames per second is {frames:.3g} frames, "
                         f"more than the {MAX_FRAMES:.0e} one run logs; lower the aiding rate or shorten the run")


def _check_baro_states(checked, source):
    """``filter.baro_states = "all"`` needs a white-noise baro: a bias, its random walk or a lag would be
    taken for horizontal information (the baro's σ holds its bias as if it were white)."""
    baro = checked.get("baro")
    if checked["filter"]["baro_states"] != "all" or baro is None:
        return
    coloured = [key for key in ("bias_sigma_m", "bias_rw_m_per_sqrt_h", "lag_s") if baro[key] > 0.0]
    if coloured:
        raise InputError(f"{source}: filter.baro_states: \"all\" needs a white-noise baro (baro.{coloured[0]} = "
                         f"{baro[coloured[0]]:g}): a bias or lag would pass for horizontal information")


def _check_star_sensor(checked, source):
    """The star sensor's and the faults' rules: those of the attitude kind, faults only with a star sensor
    (but gyro bias steps), an outage no longer than the flight, a boresight above the horizon at some
    time of the flight, and no shadow attitude filter (``compare_without_stacking``)."""
    sensor = checked.get("star_sensor")
    faults = checked["faults"]
    if sensor is None:
        for kind, value in faults.items():
            if value and kind != "gyro_bias_steps":
                raise InputError(f"{source}: faults.{kind}: needs a [star_sensor] (it acts on the star sensor)")
        return
    check_star_sensor(sensor, source)
    if sensor["identification"]["method"] == "prior" and (sensor["fidelity"] != "vector" or "photometry" not in sensor):
        raise InputError(f"{source}: star_sensor.identification.method: 'prior' identifies the detections of a "
                         "vector-fidelity sensor with a light budget ([star_sensor.photometry]: their magnitudes)")
    refraction = sensor["refraction"]
    if (refraction["pressure_sigma_percent"] or refraction["temperature_sigma_k"]) and not refraction["correction"]:
        raise InputError(f"{source}: star_sensor.refraction: pressure_sigma_percent and temperature_sigma_k are the "
                         "uncertainty of the air the processing corrects with; without the correction there is none "
                         "(set correction = true or the σ to 0)")
    if refraction["drawn"] and not (refraction["pressure_sigma_percent"] or refraction["temperature_sigma_k"]):
        raise InputError(f"{source}: star_sensor.refraction.drawn: each run's air is drawn from pressure_sigma_percent "
                         "and temperature_sigma_k, which are both 0 (give the σ the processing states)")
    if sensor.get("image", {}).get("compare_without_stacking"):
        raise InputError(f"{source}: star_sensor.image.compare_without_stacking: the shadow filter of 004 §3 is the "
                         "attitude filter's; a navigation run compares the attitude solvers of the stacked frames only "
                         "(set it false)")
    check_faults(faults, sensor["fidelity"], source)
    duration = checked["duration_s"]
    for k, outage in enumerate(faults["outages"]):
        length = min(outage["end_s"], duration) - max(outage["start_s"], 0.0)
        if outage["end_s"] - outage["start_s"] > duration or length >= duration:
            raise InputError(f"{source}: faults.outages[{k}]: the outage ({outage['start_s']:g}-{outage['end_s']:g} s) is "
                             f"longer than the flight (duration_s = {duration:g} s): the star sensor would never see a star")
    if faults["outages"] and _covered_until(faults["outages"]) >= duration:
        raise InputError(f"{source}: faults.outages: together they cover the whole flight (0-{duration:g} s): the star "
                         "sensor would never see a star")
    highest = boresight_elevation(checked).max()
    if highest < 0.0:
        raise InputError(f"{source}: star_sensor.mounting_rotvec_deg: the boresight points below the horizon for the whole "
                         f"flight (highest elevation {np.degrees(highest):.1f} deg): the star sensor would see the ground")


def _check_ephemeris(checked, source):
    """A star sensor's sky (the Sun, the Moon, the Earth's motion: erfa.epv00, moon98) is computed from 1900 to 2100
    only: the run must lie in it."""
    if "star_sensor" not in checked:
        return
    first = julian_year(checked["epoch_utc"])
    last = first + checked["duration_s"] / (365.25 * 86400.0)
    if not (EPHEMERIS_YEARS[0] <= first and last < EPHEMERIS_YEARS[1]):
        raise InputError(f"{source}: epoch_utc: {checked['epoch_utc']} (to {last:.2f}) is outside the ephemeris' validity "
                         f"({EPHEMERIS_YEARS[0]}-{EPHEMERIS_YEARS[1]}: the Sun and the Earth's motion of erfa.epv00)")


def _covered_until(outages):
    """The end [s] of the span from t = 0 the ``outages`` cover without a gap (0 if the first starts later)."""
    end = 0.0
    for outage in sorted(outages, key=lambda o: o["start_s"]):
        if outage["start_s"] > end:
            break
        end = max(end, outage["end_s"])
    return end


def boresight_elevation(checked, samples=ELEVATION_SAMPLES):
    """The star sensor's boresight elevation above the local horizon [rad] at ``samples`` times of the
    flight and at SEGMENT_SAMPLES times of each segment (a short bank in a long flight is not missed):
    asin(−b_D) of b_n = C_nb R_BS e_z (nominal mounting and misalignment)."""
    profile = route.profile_of(checked["trajectory"])
    duration = checked["duration_s"]
    ends = np.append(profile.starts[1:], profile.duration)
    per_segment = np.linspace(profile.starts, ends, SEGMENT_SAMPLES).ravel()
    times = np.union1d(np.linspace(0.0, duration, samples), per_segment[per_segment <= duration])
    q_nb = trajectory.attitude(profile.channels(times))
    _, q_BS_true = mounting(checked["star_sensor"])
    boresight = rot.rotate(rot.multiply(q_nb, q_BS_true), np.array([0.0, 0.0, 1.0]))
    return np.arcsin(np.clip(-boresight[:, 2], -1.0, 1.0))


def _check_gravity(gravity, source):
    if gravity is None:
        return
    if gravity["model"] == "random" and gravity["correlation_length_m"] is None:
        raise InputError(f"{source}: gravity.correlation_length_m: a random disturbance needs its correlation length")
    if gravity["model"] == "constant" and gravity["correlation_length_m"] is not None:
        raise InputError(f"{source}: gravity.correlation_length_m: only for model = \"random\" (the constant model "
                         "has none)")
    if gravity["model"] == "random" and min(gravity["xi_arcsec"], gravity["eta_arcsec"], gravity["anomaly_mgal"]) < 0.0:
        raise InputError(f"{source}: gravity: a random disturbance takes σ >= 0 for xi_arcsec, eta_arcsec and anomaly_mgal")
