"""The attitude kind's scenario (docs/design.md, "The attitude scenario"): a star sensor and a gyro on a
truth attitude profile, no trajectory. Its strict schema (:data:`SCHEMA`: units in the key names, every
value bounded) and cross-key rules (:func:`validate`); every problem is one
:class:`~startrack.base.errors.InputError` naming the file, the key and what is wrong.
"""

import numpy as np

from navsim.estimation.treatments import TREATMENTS
from navsim.scenario import checked_table, only_chosen
from navsim.scenario.inertial_fields import GYRO_ERRORS, MAX_ARCSEC, MAX_ARW, MAX_BIAS, MAX_RATE, MAX_RRW
from navsim.scenario.schema import ListOfTables, Table, Value, is_multiple
from navsim.scenario.star_sensor_fields import FAULTS, STAR_SENSOR, check_faults, check_star_sensor
from startrack import InputError

PROFILES = ("constant_rate", "sinusoidal_axis", "rate_segments", "rigid_body")
#: What one run holds in memory: gyro samples, truth samples (the finer grid) and star-sensor frames.
MAX_GYRO_SAMPLES, MAX_TRUTH_SAMPLES, MAX_FRAMES = 1e7, 4e7, 2e5

SCHEMA = Table(
    {
        "name": Value("str"),
        "description": Value("str", default=""),
        "duration_s": Value("float", exclusive_minimum=0.0, maximum=2.6e6),
        "seed": Value("int", default=0, minimum=0, maximum=2**63 - 1),
        "epoch_jyear": Value("float", default=2000.0, minimum=1900.0, maximum=2100.0),
        "settle_s": Value("float", default=None, minimum=0.0,
                          doc="errors are summarised after this time (default: 10 % of the run)"),
        "truth": Table(
            {
                "profile": Value("str", choices=PROFILES),
                "rate_hz": Value("float", default=None, exclusive_minimum=0.0, maximum=1e5,
                                 doc="truth integration rate, an integer multiple of the gyro rate"),
                "initial_q_IB": Value("quaternion", default=[0.0, 0.0, 0.0, 1.0]),
                "initial_radec_roll_deg": Value("vector", default=None,
                                                doc="initial boresight RA, Dec and roll (003 §1.1) instead of "
                                                    "initial_q_IB; with the nominal mounting"),
                "constant_rate": Table({"rate_deg_per_s": Value("vector", minimum=-MAX_RATE, maximum=MAX_RATE)}, optional=True),
                "sinusoidal_axis": Table(
                    {
                        "axis": Value("vector", minimum=-1e6, maximum=1e6),
                        "theta0_deg": Value("float", default=0.0, minimum=-1e6, maximum=1e6),
                        "amplitude_deg": Value("float", minimum=-1e6, maximum=1e6),
                        "angular_frequency_rad_per_s": Value("float", minimum=0.0, maximum=1e4),
                        "phase_deg": Value("float", default=0.0, minimum=-1e6, maximum=1e6),
                    },
                    optional=True,
                ),
                "rate_segments": Table(
                    {
                        "segments": ListOfTables(
                            Table({"duration_s": Value("float", exclusive_minimum=0.0, maximum=2.6e6),
                                   "rate_deg_per_s": Value("vector", minimum=-MAX_RATE, maximum=MAX_RATE)}),
                            required=True,
                            min_length=1,
                        )
                    },
                    optional=True,
                ),
                "rigid_body": Table(
                    {
                        "inertia_kg_m2": Value("matrix", minimum=-1e12, maximum=1e12),
                        "initial_rate_deg_per_s": Value("vector", minimum=-MAX_RATE, maximum=MAX_RATE),
                        "torque_segments": ListOfTables(
                            Table({"duration_s": Value("float", exclusive_minimum=0.0, maximum=2.6e6),
                                   "torque_N_m": Value("vector", minimum=-1e9, maximum=1e9)})
                        ),
                    },
                    optional=True,
                ),
            }
        ),
        "gyro": Table({"preset": GYRO_ERRORS["preset"], "rate_hz": Value("float", exclusive_minimum=0.0, maximum=1e5),
                       **GYRO_ERRORS}),
        "star_sensor": Table(dict(STAR_SENSOR)),
        "faults": Table(dict(FAULTS)),
        "filter": Table(
            {
                "initial_attitude_sigma_deg": Value("float", default=0.1, exclusive_minimum=0.0, maximum=180.0),
                "initial_attitude_error_arcsec": Value("vector", default=None, minimum=-36000.0, maximum=36000.0,
                                                       doc="the filter's initial attitude error δθ (body axes: q_true = "
                                                           "q_est ⊗ δq(δθ)), fixed instead of drawn from its σ"),
                "initial_bias_sigma_deg_per_h": Value("float", default=None, exclusive_minimum=0.0, maximum=MAX_BIAS),
                "arw_deg_per_sqrt_h": Value("float", default=None, minimum=0.0, maximum=MAX_ARW,
                                            doc="ARW the filter assumes (default: the gyro's)"),
                "rrw_deg_per_h_per_sqrt_h": Value("float", default=None, minimum=0.0, maximum=MAX_RRW,
                                                  doc="RRW the filter assumes (default: the gyro's; plus the "
                                                      "Gauss-Markov drive when bias_instability is ignored)"),
                "bias_instability": Value("str", default=None, choices=TREATMENTS,
                                          doc="the gyro's Gauss-Markov bias (σ_g, τ of the gyro) as three states: "
                                              "estimate, consider or ignore (an equivalent random walk); default: "
                                              "estimate when the gyro has one"),
                "scale_factor": Value("str", default=None, choices=TREATMENTS,
                                      doc="the gyro's three scale-factor errors: estimate, consider (kept in P, "
                                          "not estimated: Schmidt) or ignore; default: estimate when the gyro has one"),
                "gyro_misalignment": Value("str", default=None, choices=TREATMENTS,
                                           doc="the gyro's six misalignment (non-orthogonality) terms; default: "
                                               "estimate when the gyro has them"),
                "mounting": Value("str", default="ignore", choices=TREATMENTS,
                                  doc="the star-sensor mounting error δm (star_sensor.misalignment_arcsec is its truth)"),
                "initial_scale_factor_sigma_ppm": Value("float", default=None, exclusive_minimum=0.0, maximum=1e6,
                                                        doc="default: the gyro's scale-factor σ"),
                "initial_gyro_misalignment_sigma_arcsec": Value("float", default=None, exclusive_minimum=0.0, maximum=MAX_ARCSEC,
                                                                doc="default: the gyro's misalignment σ"),
                "initial_mounting_sigma_arcsec": Value("float", default=60.0, exclusive_minimum=0.0, maximum=MAX_ARCSEC),
                "gate_probability": Value("float", default=0.9999, exclusive_minimum=0.0, maximum=0.999999999),
                "process_noise_scale": Value("float", default=1.0, exclusive_minimum=0.0, maximum=1e6),
                "measurement_noise_scale": Value("float", default=1.0, exclusive_minimum=0.0, maximum=1e6),
            }
        ),
    }
)


#: Keys of earlier versions -> what replaced them.
RENAMED = {
    ("filter", "estimate_scale_factor"): 'filter.scale_factor = "estimate" (or "consider", "ignore")',
    ("filter", "estimate_misalignment"): 'filter.mounting = "estimate" (the star-sensor mounting; the gyro\'s own axis '
                                         'misalignment is filter.gyro_misalignment)',
    ("filter", "initial_misalignment_sigma_arcsec"): "filter.initial_mounting_sigma_arcsec",
}


def validate(data, source="<scenario>"):
    """The checked dictionary of an attitude scenario: :data:`SCHEMA` and the cross-key rules (derived
    defaults filled: ``truth.rate_hz``, ``settle_s``); one InputError naming the key otherwise."""
    for (table, key), replacement in RENAMED.items():
        if isinstance(data, dict) and isinstance(data.get(table), dict) and key in data[table]:
            raise InputError(f"{source}: {table}.{key}: renamed; use {replacement}")
    checked = checked_table(SCHEMA, data, source)
    truth = checked["truth"]
    profile = truth["profile"]
    if profile not in truth:
        raise InputError(f"{source}: truth.{profile}: missing table for truth.profile = {profile!r}")
    only_chosen(truth, "truth", "profile", PROFILES, source)
    gyro_hz = checked["gyro"]["rate_hz"]
    sensor_hz = checked["star_sensor"]["rate_hz"]
    if not is_multiple(gyro_hz, sensor_hz):
        raise InputError(
            f"{source}: star_sensor.rate_hz: {sensor_hz:g} Hz must divide gyro.rate_hz = {gyro_hz:g} Hz"
        )
    truth_hz = truth.get("rate_hz") or 4.0 * gyro_hz
    if not is_multiple(truth_hz, gyro_hz):
        raise InputError(
            f"{source}: truth.rate_hz: {truth_hz:g} Hz must be an integer multiple of gyro.rate_hz"
        )
    truth["rate_hz"] = truth_hz
    if checked["duration_s"] * sensor_hz < 1.0:
        raise InputError(f"{source}: duration_s: shorter than one star-sensor frame")
    _check_run_size(checked, source)
    if profile == "sinusoidal_axis" and not any(truth["sinusoidal_axis"]["axis"]):
        raise InputError(f"{source}: truth.sinusoidal_axis.axis: must not be the zero vector (it is the rotation axis)")
    if profile == "rate_segments":
        covered = sum(s["duration_s"] for s in truth["rate_segments"]["segments"])
        if covered + 1e-9 < checked["duration_s"]:
            raise InputError(
                f"{source}: truth.rate_segments.segments: cover {covered:g} s, "
                f"less than duration_s = {checked['duration_s']:g} s"
            )
    sensor = checked["star_sensor"]
    check_star_sensor(sensor, source)
    check_faults(checked["faults"], sensor["fidelity"], source)
    if checked["settle_s"] is None:
        checked["settle_s"] = 0.1 * checked["duration_s"]
    if checked["settle_s"] >= checked["duration_s"]:
        raise InputError(f"{source}: settle_s: must be shorter than duration_s")
    if profile == "rigid_body":
        J = np.array(truth["rigid_body"]["inertia_kg_m2"])
        if not np.allclose(J, J.T) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) <= 0.0):
            raise InputError(f"{source}: truth.rigid_body.inertia_kg_m2: must be symmetric positive definite")
    return checked


def _check_run_size(checked, source):
    """One run must fit in memory: bounds on its gyro samples, truth samples and frames."""
    duration = checked["duration_s"]
    sizes = (("gyro.rate_hz", duration * checked["gyro"]["rate_hz"], MAX_GYRO_SAMPLES, "gyro samples"),
             ("truth.rate_hz", duration * checked["truth"]["rate_hz"], MAX_TRUTH_SAMPLES, "truth samples"),
             ("star_sensor.rate_hz", duration * checked["star_sensor"]["rate_hz"], MAX_FRAMES, "star-sensor frames"))
    for key, count, limit, what in sizes:
        if count > limit:
            raise InputError(f"{source}: duration_s: {duration:g} s at {key} = {checked[key.split('.')[0]]['rate_hz']:g} Hz "
                             f"is {count:.3g} {what}, more than the {limit:.0e} one run holds in memory; shorten the "
                             "run (a campaign of shorter runs covers more) or lower the rate")


def check_tuning(scenario):
    """Filter tuning judges the NIS of the star sensor's updates, which every attitude scenario has."""
