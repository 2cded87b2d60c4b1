"""The spacecraft kind's scenario (docs/design.md, "The spacecraft"): a scenario file with an ``[orbit]`` table — the
orbit, the attitude law, the rigid body with its wheels and controller, the gyro, one to three star-sensor heads
(``[[star_sensor]]``, each with its mounting, field, exclusions and faults) and the attitude filter.

Its strict schema (:data:`SCHEMA`: units in the key names, every value bounded) and cross-key rules
(:func:`validate`); every problem is one :class:`~startrack.base.errors.InputError` naming the file, the key and what is
wrong: an impossible TLE, an orbit below the surface, an unknown attitude law, a head without its mounting.
"""

import numpy as np

from navsim.attitude.scenario import SCHEMA as ATTITUDE_SCHEMA
from navsim.earth.frames import julian_year
from navsim.earth.wgs84 import GM
from navsim.earth.wgs84 import A as R_EARTH
from navsim.orbit.sgp4_orbit import checked_tle
from navsim.scenario import checked_table
from navsim.scenario.inertial_fields import GYRO_ERRORS, MAX_RATE
from navsim.scenario.schema import ListOfTables, Table, Value, is_multiple
from navsim.scenario.star_sensor_fields import FAULTS, STAR_SENSOR, check_faults, check_star_sensor
from startrack import InputError

#: The attitude laws (navsim.truth.pointing) and the orbit propagators (navsim.orbit).
LAWS, PROPAGATORS = ("nadir", "sun", "targets"), ("sgp4", "numerical")
#: The lowest perigee [m] an orbit may have: below it the air brings a spacecraft down within days.
MIN_PERIGEE_HEIGHT = 100e3
#: What one run holds in memory: truth samples (the dynamics' grid) and frames (each with the filter's covariance).
MAX_TRUTH_SAMPLES, MAX_FRAMES = 2e7, 2e5
#: The most heads one spacecraft carries.
MAX_HEADS = 4

ELEMENTS = Table({
    "height_km": Value("float", default=None, minimum=-7000.0, maximum=4e5,
                       doc="of a circular or elliptic orbit's semi-major axis above the equatorial radius (instead of "
                           "semi_major_axis_km)"),
    "semi_major_axis_km": Value("float", default=None, exclusive_minimum=0.0, maximum=4e5),
    "eccentricity": Value("float", default=0.0, minimum=0.0, maximum=0.95),
    "inclination_deg": Value("float", default=None, minimum=0.0, maximum=180.0,
                             doc="default: sun-synchronous (sun_synchronous = true)"),
    "sun_synchronous": Value("bool", default=False, doc="the inclination whose J2 node rate follows the mean Sun"),
    "raan_deg": Value("float", default=None, minimum=-360.0, maximum=360.0),
    "ltan_h": Value("float", default=None, minimum=0.0, maximum=24.0,
                    doc="local time of the ascending node (instead of raan_deg): the node's right ascension is the "
                        "mean Sun's plus 15 deg per hour after noon"),
    "argp_deg": Value("float", default=0.0, minimum=-360.0, maximum=360.0),
    "true_anomaly_deg": Value("float", default=0.0, minimum=-360.0, maximum=360.0),
}, optional=True, doc="osculating Keplerian elements at t = 0 (GCRS axes)")

ORBIT = Table({
    "propagator": Value("str", default=None, choices=PROPAGATORS,
                        doc="sgp4 (the default with a TLE) or numerical (two-body + J2 + drag; the default otherwise)"),
    "tle": Value("strs", default=None, doc="the two lines of a two-line element set"),
    "elements": ELEMENTS,
    "state": Table({"position_km": Value("vector", minimum=-1e6, maximum=1e6),
                    "velocity_km_per_s": Value("vector", minimum=-20.0, maximum=20.0)}, optional=True,
                   doc="the geocentric state at t = 0 in GCRS axes"),
    "j2": Value("bool", default=True, doc="the Earth's oblateness in the numerical propagator"),
    "ballistic_m2_per_kg": Value("float", default=0.0, minimum=0.0, maximum=10.0,
                                 doc="C_D A / m of the drag (0: none; the numerical propagator)"),
})

POINTING = Table({
    "law": Value("str", choices=LAWS, doc="nadir (LVLH), sun (an axis on the Sun) or targets (inertial, with slews)"),
    "yaw_deg": Value("float", default=0.0, minimum=-360.0, maximum=360.0, doc="nadir: the yaw about +z_B"),
    "sun_axis": Value("vector", default=[0.0, 0.0, 1.0], minimum=-1.0, maximum=1.0, doc="sun: the body axis on the Sun"),
    "secondary_axis": Value("vector", default=[1.0, 0.0, 0.0], minimum=-1.0, maximum=1.0,
                            doc="sun: the body axis towards celestial north (or nadir with yaw_steering)"),
    "yaw_steering": Value("bool", default=False, doc="sun: the secondary axis towards nadir"),
    "max_rate_deg_per_s": Value("float", default=1.0, exclusive_minimum=0.0, maximum=MAX_RATE),
    "max_acceleration_deg_per_s2": Value("float", default=0.02, exclusive_minimum=0.0, maximum=MAX_RATE),
    "offsets": ListOfTables(Table({"start_s": Value("float", minimum=0.0, maximum=2.6e6),
                                   "roll_deg": Value("float", default=0.0, minimum=-90.0, maximum=90.0),
                                   "pitch_deg": Value("float", default=0.0, minimum=-90.0, maximum=90.0)}),
                            doc="nadir: off-nadir looks, a roll about +x_B then a pitch about +y_B from the LVLH "
                                "frame, held from start_s on (slews under the rate limits; nadir before the first)"),
    "targets": ListOfTables(Table({"start_s": Value("float", minimum=0.0, maximum=2.6e6),
                                   "ra_deg": Value("float", minimum=-360.0, maximum=360.0),
                                   "dec_deg": Value("float", minimum=-90.0, maximum=90.0),
                                   "roll_deg": Value("float", default=0.0, minimum=-360.0, maximum=360.0)}),
                            doc="targets: the body's +z at (RA, Dec) with its roll, held from start_s on"),
})

SPACECRAFT = Table({
    "inertia_kg_m2": Value("matrix", default=[[300.0, 0.0, 0.0], [0.0, 350.0, 0.0], [0.0, 0.0, 250.0]], minimum=-1e9, maximum=1e9),
    "truth_rate_hz": Value("float", default=None, exclusive_minimum=0.0, maximum=1e4,
                           doc="the dynamics' integration rate (default 4x the gyro's), a multiple of the gyro's and the "
                               "controller's rates"),
    "gravity_gradient": Value("bool", default=True),
    "wheels": Table({
        "layout": Value("str", default="pyramid", choices=("pyramid", "triad"),
                        doc="four wheels in a pyramid about +z at 54.74 deg of elevation, or three on the body axes"),
        "inertia_kg_m2": Value("float", default=0.02, exclusive_minimum=0.0, maximum=100.0, doc="each wheel's spin inertia"),
        "max_torque_N_m": Value("float", default=0.1, exclusive_minimum=0.0, maximum=100.0),
        "max_momentum_N_m_s": Value("float", default=4.0, exclusive_minimum=0.0, maximum=1e4),
        "viscous_N_m_s_per_rad": Value("float", default=2e-6, minimum=0.0, maximum=1.0),
        "coulomb_N_m": Value("float", default=1e-3, minimum=0.0, maximum=10.0),
        "initial_momentum_N_m_s": Value("list", default=None, minimum=-1e4, maximum=1e4,
                                        doc="per wheel (default: 0.5 N m s on each, away from zero speed)"),
    }),
    "controller": Table({
        "bandwidth_rad_per_s": Value("float", default=0.2, exclusive_minimum=0.0, maximum=100.0),
        "damping": Value("float", default=0.9, exclusive_minimum=0.0, maximum=10.0),
        "rate_hz": Value("float", default=10.0, exclusive_minimum=0.0, maximum=1e3),
    }),
})

#: A head: the star sensor's keys with its mounting required, its exclusions and its own faults.
HEAD = Table({
    **STAR_SENSOR,
    "name": Value("str", default=None, doc="default: head 1, head 2, ..."),
    "mounting_rotvec_deg": Value("vector", minimum=-360.0, maximum=360.0,
                                 doc="nominal R_BS (sensor to body) as a rotation vector: every head needs its mounting"),
    "sun_exclusion_deg": Value("float", default=30.0, minimum=0.0, maximum=180.0),
    "moon_exclusion_deg": Value("float", default=10.0, minimum=0.0, maximum=180.0),
    "earth_exclusion_deg": Value("float", default=20.0, minimum=-90.0, maximum=180.0,
                                 doc="the least angle of the boresight above the bright Earth limb"),
    "earth_limb_height_km": Value("float", default=100.0, minimum=0.0, maximum=1000.0,
                                  doc="the atmosphere counted as the bright limb (and hiding the stars behind it)"),
    "misalignment_sigma_arcsec": Value("float", default=0.0, minimum=0.0, maximum=36000.0,
                                       doc="the σ of a mounting error drawn per run (per axis) on top of "
                                           "misalignment_arcsec; with it the filter's initial σ of this head's mounting "
                                           "(default) is this σ"),
    "filter_mounting": Value("str", default=None, choices=("estimate", "consider", "ignore"),
                             doc="the filter's treatment of this head's mounting error (default: filter.mounting); a "
                                 "reference head is usually 'consider': the body frame is defined by it"),
    "aberration_correction": Value("bool", default=True,
                                   doc="the processing corrects the stars' aberration with the orbit's velocity"),
    "faults": Table(dict(FAULTS)),
    "stray_light": Table({
        "pst": Value("float", default=1e-7, minimum=0.0, maximum=1.0,
                     doc="the baffle's point-source transmittance at angle_deg (image fidelity)"),
        "angle_deg": Value("float", default=20.0, exclusive_minimum=0.0, maximum=180.0),
        "slope": Value("float", default=3.0, minimum=0.0, maximum=20.0, doc="PST falls as the angle to this power"),
        "pixel_um": Value("float", default=5.5, exclusive_minimum=0.0, maximum=100.0),
        "qe": Value("float", default=0.6, exclusive_minimum=0.0, maximum=1.0),
        "earth_albedo": Value("float", default=0.3, minimum=0.0, maximum=1.0, doc="the Earth's Bond albedo"),
    }, doc="the sunlit Earth's light through the baffle (navsim.sensors.stray_light), image fidelity"),
})

#: The particle flux of the orbit and what a hit leaves in a detector (navsim.orbit.radiation,
#: navsim.sensors.radiation_hits): image fidelity.
RADIATION = Table({
    "background_per_cm2_s": Value("float", default=3.0, minimum=0.0, maximum=1e7),
    "saa_peak_per_cm2_s": Value("float", default=1000.0, minimum=0.0, maximum=1e7),
    "saa_lat_deg": Value("float", default=-26.0, minimum=-90.0, maximum=90.0),
    "saa_lon_deg": Value("float", default=-50.0, minimum=-360.0, maximum=360.0),
    "saa_lat_width_deg": Value("float", default=12.0, exclusive_minimum=0.0, maximum=90.0),
    "saa_lon_width_deg": Value("float", default=25.0, exclusive_minimum=0.0, maximum=180.0),
    "saa_height_km": Value("float", default=550.0, exclusive_minimum=0.0, maximum=1e5),
    "saa_height_exponent": Value("float", default=2.0, minimum=-10.0, maximum=10.0),
    "horn_peak_per_cm2_s": Value("float", default=100.0, minimum=0.0, maximum=1e7),
    "horn_lat_deg": Value("float", default=65.0, minimum=0.0, maximum=90.0),
    "horn_width_deg": Value("float", default=5.0, exclusive_minimum=0.0, maximum=90.0),
    "thickness_um": Value("float", default=10.0, exclusive_minimum=0.0, maximum=1000.0,
                          doc="the detector's sensitive layer"),
    "electrons_per_um": Value("float", default=300.0, exclusive_minimum=0.0, maximum=1e6),
    "spread": Value("float", default=0.5, minimum=0.0, maximum=3.0, doc="σ of the log-normal charge spread"),
}, optional=True, doc="particle hits in the heads' frames (image fidelity)")

SCHEMA = Table({
    "name": Value("str"),
    "description": Value("str", default=""),
    "seed": Value("int", default=0, minimum=0, maximum=2**63 - 1),
    "epoch_utc": Value("str", doc="UTC of t = 0, 'YYYY-MM-DDTHH:MM:SS'"),
    "duration_s": Value("float", default=None, exclusive_minimum=0.0, maximum=2.6e6),
    "orbits": Value("float", default=None, exclusive_minimum=0.0, maximum=1000.0,
                    doc="the run's length in orbital periods (instead of duration_s)"),
    "settle_s": Value("float", default=None, minimum=0.0, doc="errors are summarised after this time (default 10 %)"),
    "orbit": ORBIT,
    "pointing": POINTING,
    "spacecraft": SPACECRAFT,
    "gyro": Table({"preset": GYRO_ERRORS["preset"], "rate_hz": Value("float", exclusive_minimum=0.0, maximum=1e4), **GYRO_ERRORS}),
    "star_sensor": ListOfTables(HEAD, required=True, min_length=1, doc="the heads, [[star_sensor]] each"),
    "filter": ATTITUDE_SCHEMA.entries["filter"],
    "radiation": RADIATION,
})


def validate(data, source="<scenario>"):
    """The checked dictionary of a spacecraft scenario: :data:`SCHEMA` and the cross-key rules (derived defaults
    filled: the propagator, ``duration_s`` from ``orbits``, the truth rate, ``settle_s``, ``epoch_jyear``, the heads'
    names); one InputError naming the key otherwise."""
    if isinstance(data, dict) and isinstance(data.get("star_sensor"), dict):
        raise InputError(f"{source}: star_sensor: a spacecraft's heads are an array of tables, [[star_sensor]] each")
    checked = checked_table(SCHEMA, data, source)
    _check_orbit(checked["orbit"], source)
    _check_duration(checked, source)
    _check_pointing(checked["pointing"], checked["duration_s"], source)
    _check_heads(checked, source)
    _check_rates(checked, source)
    if checked.get("radiation") is not None and checked["star_sensor"][0]["fidelity"] != "image":
        raise InputError(f"{source}: radiation: particle hits act on frames: the heads need fidelity = 'image'")
    checked["epoch_jyear"] = julian_year(checked["epoch_utc"])
    if checked["settle_s"] is None:
        checked["settle_s"] = 0.1 * checked["duration_s"]
    if checked["settle_s"] >= checked["duration_s"]:
        raise InputError(f"{source}: settle_s: must be shorter than the run ({checked['duration_s']:g} s)")
    J = np.array(checked["spacecraft"]["inertia_kg_m2"])
    if not np.allclose(J, J.T) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) <= 0.0):
        raise InputError(f"{source}: spacecraft.inertia_kg_m2: must be symmetric positive definite")
    wheels = checked["spacecraft"]["wheels"]
    n_wheels = 4 if wheels["layout"] == "pyramid" else 3
    if wheels["initial_momentum_N_m_s"] is not None and len(wheels["initial_momentum_N_m_s"]) != n_wheels:
        raise InputError(f"{source}: spacecraft.wheels.initial_momentum_N_m_s: one value per wheel ({n_wheels} for the "
                         f"{wheels['layout']}), got {len(wheels['initial_momentum_N_m_s'])}")
    return checked


def _check_orbit(orbit, source):
    """One of a TLE, elements or a state; the propagator that can take it; the orbit above the surface."""
    given = [key for key in ("tle", "elements", "state") if orbit.get(key) is not None]
    if len(given) != 1:
        raise InputError(f"{source}: orbit: give one of tle, elements or state (got {', '.join(given) or 'none'})")
    if orbit["propagator"] is None:
        orbit["propagator"] = "sgp4" if given[0] == "tle" else "numerical"
    if orbit["propagator"] == "sgp4" and given[0] != "tle":
        raise InputError(f"{source}: orbit.propagator: sgp4 needs orbit.tle (its mean elements), got orbit.{given[0]}")
    if given[0] == "tle":
        if len(orbit["tle"]) != 2:
            raise InputError(f"{source}: orbit.tle: the two lines of a two-line element set, got {len(orbit['tle'])}")
        try:
            orbit["tle"] = list(checked_tle(*orbit["tle"]))
        except InputError as error:
            raise InputError(f"{source}: {error}") from None
    if given[0] == "elements":
        _check_elements(orbit["elements"], source)
    if given[0] == "state":
        r = np.array(orbit["state"]["position_km"]) * 1e3
        if np.linalg.norm(r) < R_EARTH + MIN_PERIGEE_HEIGHT:
            raise InputError(f"{source}: orbit.state.position_km: {np.linalg.norm(r) / 1e3 - R_EARTH / 1e3:.0f} km above the "
                             f"equator's radius, below the lowest {MIN_PERIGEE_HEIGHT / 1e3:.0f} km an orbit keeps")


def _check_elements(elements, source):
    """The semi-major axis (one of height_km, semi_major_axis_km), the perigee above the surface, the inclination
    (or sun-synchronous), the node (raan_deg or ltan_h)."""
    sizes = [key for key in ("height_km", "semi_major_axis_km") if elements[key] is not None]
    if len(sizes) != 1:
        raise InputError(f"{source}: orbit.elements: give one of height_km or semi_major_axis_km")
    a = (R_EARTH + 1e3 * elements["height_km"]) if sizes[0] == "height_km" else 1e3 * elements["semi_major_axis_km"]
    perigee = a * (1.0 - elements["eccentricity"]) - R_EARTH
    if perigee < MIN_PERIGEE_HEIGHT:
        raise InputError(f"{source}: orbit.elements.{sizes[0]}: the perigee is {perigee / 1e3:.0f} km above the equator's "
                         f"radius, below the lowest {MIN_PERIGEE_HEIGHT / 1e3:.0f} km an orbit keeps")
    elements["semi_major_axis_km"] = a / 1e3
    if (elements["inclination_deg"] is None) == (not elements["sun_synchronous"]):
        raise InputError(f"{source}: orbit.elements: give inclination_deg or sun_synchronous = true (one of them)")
    if (elements["raan_deg"] is None) == (elements["ltan_h"] is None):
        raise InputError(f"{source}: orbit.elements: give raan_deg or ltan_h (one of them)")


def _check_duration(checked, source):
    """``duration_s`` or ``orbits`` (one of them; ``duration_s`` then ``orbits`` periods, to the millisecond below)."""
    if (checked["duration_s"] is None) == (checked["orbits"] is None):
        raise InputError(f"{source}: duration_s: give duration_s or orbits (one of them)")
    if checked["orbits"] is not None:
        try:
            orbital_period = period(checked["orbit"])
        except InputError as error:
            raise InputError(f"{source}: {error}") from None
        checked["duration_s"] = float(np.floor(1e3 * checked["orbits"] * orbital_period) / 1e3)


def period(orbit):
    """The orbital period [s] of a checked ``orbit`` table: of the TLE's mean motion, the elements' semi-major axis or
    the state's energy."""
    if orbit.get("tle") is not None:
        return 86400.0 / float(orbit["tle"][1][52:63])
    if orbit.get("elements") is not None:
        a = 1e3 * orbit["elements"]["semi_major_axis_km"]
    else:
        r, v = (1e3 * np.linalg.norm(orbit["state"][key]) for key in ("position_km", "velocity_km_per_s"))
        energy = 0.5 * v * v - GM / r
        if energy >= 0.0:
            raise InputError("orbit.state: the state is not bound (it escapes the Earth)")
        a = -GM / (2.0 * energy)
    return float(2.0 * np.pi * np.sqrt(a**3 / GM))


def _check_pointing(pointing, duration, source):
    """The targets law has targets, the first from t = 0, in time order; the other laws none."""
    targets = pointing["targets"]
    if pointing["offsets"] and pointing["law"] != "nadir":
        raise InputError(f"{source}: pointing.offsets: given, but pointing.law is {pointing['law']!r} (offsets are nadir's)")
    for k in range(1, len(pointing["offsets"])):
        if pointing["offsets"][k]["start_s"] <= pointing["offsets"][k - 1]["start_s"]:
            raise InputError(f"{source}: pointing.offsets[{k}].start_s: the offsets must be in time order")
    if pointing["law"] != "targets":
        if targets:
            raise InputError(f"{source}: pointing.targets: given, but pointing.law is {pointing['law']!r}")
        return
    if not targets:
        raise InputError(f"{source}: pointing.targets: the targets law needs at least one target")
    if targets[0]["start_s"] != 0.0:
        raise InputError(f"{source}: pointing.targets[0].start_s: the first target is held from t = 0, got "
                         f"{targets[0]['start_s']:g}")
    for k in range(1, len(targets)):
        if targets[k]["start_s"] <= targets[k - 1]["start_s"]:
            raise InputError(f"{source}: pointing.targets[{k}].start_s: the targets must be in time order")
    for axis in ("sun_axis", "secondary_axis"):
        if not any(pointing[axis]):
            raise InputError(f"{source}: pointing.{axis}: must not be the zero vector")


def _check_heads(checked, source):
    """Every head of one measurement kind and frame clock, the star sensor's own rules, names."""
    heads = checked["star_sensor"]
    if len(heads) > MAX_HEADS:
        raise InputError(f"{source}: star_sensor: at most {MAX_HEADS} heads, got {len(heads)}")
    for k, head in enumerate(heads):
        where = f"star_sensor[{k}]"
        try:
            check_star_sensor(head, source)
            check_faults(head["faults"], head["fidelity"], source)
        except InputError as error:
            raise InputError(str(error).replace("star_sensor.", f"{where}.").replace("faults.", f"{where}.faults.")) from None
        for kind in ("gyro_bias_steps", "attitude_jumps", "tracking_failure_probes"):
            if head["faults"].get(kind):
                raise InputError(f"{source}: {where}.faults.{kind}: not a head's fault (a head takes outages, dropped "
                                 "frames and false-star storms)")
        for key in ("fidelity", "measurement", "rate_hz"):
            if head[key] != heads[0][key]:
                raise InputError(f"{source}: {where}.{key}: {head[key]!r}, but star_sensor[0].{key} is {heads[0][key]!r}: "
                                 "the heads share one fidelity, one kind of measurement and one frame clock")
        head["name"] = head["name"] or f"head {k + 1}"
    names = [head["name"] for head in heads]
    if len(set(names)) != len(names):
        raise InputError(f"{source}: star_sensor: the heads' names must differ, got {names}")


def _check_rates(checked, source):
    """The gyro's rate a multiple of the frames', the truth's of the gyro's and the controller's; the run's size."""
    gyro_hz, frame_hz = checked["gyro"]["rate_hz"], checked["star_sensor"][0]["rate_hz"]
    spacecraft = checked["spacecraft"]
    control_hz = spacecraft["controller"]["rate_hz"]
    if not is_multiple(gyro_hz, frame_hz):
        raise InputError(f"{source}: star_sensor[0].rate_hz: {frame_hz:g} Hz must divide gyro.rate_hz = {gyro_hz:g} Hz")
    truth_hz = spacecraft["truth_rate_hz"] or 4.0 * max(gyro_hz, control_hz)
    for key, rate in (("gyro.rate_hz", gyro_hz), ("spacecraft.controller.rate_hz", control_hz)):
        if not is_multiple(truth_hz, rate):
            raise InputError(f"{source}: spacecraft.truth_rate_hz: {truth_hz:g} Hz must be a multiple of {key} = {rate:g} Hz")
    spacecraft["truth_rate_hz"] = truth_hz
    duration = checked["duration_s"]
    for what, count, limit in (("truth samples", duration * truth_hz, MAX_TRUTH_SAMPLES),
                               ("star-sensor frames", duration * frame_hz, MAX_FRAMES)):
        if count > limit:
            raise InputError(f"{source}: duration_s: {duration:g} s is {count:.3g} {what}, more than the {limit:.0e} one run "
                             "holds in memory; shorten the run or lower the rate")
    if duration * frame_hz < 1.0:
        raise InputError(f"{source}: duration_s: shorter than one star-sensor frame")


def check_tuning(scenario):
    """Filter tuning judges the NIS of the heads' updates, which every spacecraft scenario has."""
