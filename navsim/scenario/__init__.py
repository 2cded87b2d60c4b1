"""Scenario files: strict TOML with the unit in every key name.

``load_scenario(path, overrides)`` reads a file, applies ``--set key=value`` overrides
(dotted keys, TOML values), validates everything against :data:`SCHEMA` (an attitude simulation),
:data:`navsim.scenario.navigation.SCHEMA` (a navigation simulation: a file with a ``[trajectory]``
table) or :func:`study_schema` (a static study: a file with a ``[study]`` table, see
:mod:`navsim.studies`) and returns a :class:`Scenario` (the validated plain dictionary plus the name of its file). Every
problem ends in one :class:`InputError` naming the file, the key and what is wrong.
"""

import copy
import functools
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from navsim.estimation.attitude_filter import TREATMENTS
from navsim.scenario import navigation
from navsim.scenario.inertial_fields import GYRO_ERRORS, MAX_ARCSEC, MAX_ARW, MAX_BIAS, MAX_RATE, MAX_RRW
from navsim.scenario.schema import ListOfTables, Table, Value, is_multiple
from navsim.scenario.star_sensor_fields import FAULTS, STAR_SENSOR, check_faults, check_star_sensor
from navsim.studies import STUDIES
from startrack.errors import InputError

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
        "faults": Table(
            {
                **FAULTS,
                "tracking_failure_probes": Table(
                    {"count": Value("int", minimum=1, maximum=100000),
                     "angle_3sigma_deg": Value("float", exclusive_minimum=0.0, maximum=90.0)},
                    optional=True,
                    doc="000 §5: at `count` random frames the prior is disturbed (Rayleigh angle of "
                        "3σ = angle_3sigma_deg) and the predicted sub-catalog and full-sky methods are both "
                        "run on that frame's centroids; the filter is not disturbed",
                ),
            }
        ),
        "filter": Table(
            {
                "initial_attitude_sigma_deg": Value("float", default=0.1, exclusive_minimum=0.0, maximum=180.0),
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


@functools.cache
def study_schema():
    """The schema of a static study: its kind and the kind's own parameters (built when first needed,
    so a simulation scenario does not import the studies)."""
    return Table(
        {
            "name": Value("str"),
            "description": Value("str", default=""),
            "seed": Value("int", default=0, minimum=0),
            "study": Table({"kind": Value("str", choices=tuple(STUDIES))}
                           | {kind: Table(module.PARAMETERS.entries, optional=True)
                              for kind, module in STUDIES.items()}),
        }
    )


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: ``data`` is the checked dictionary (units in key names)."""

    data: dict
    source: str = "<scenario>"

    @property
    def name(self):
        return self.data["name"]

    @property
    def is_study(self):
        """True for a static study (a ``[study]`` table), False for a simulation."""
        return "study" in self.data

    @property
    def is_navigation(self):
        """True for a navigation simulation (a ``[trajectory]`` table: the INS), False otherwise."""
        return "trajectory" in self.data

    def require_simulation(self, action):
        """Raise an InputError when this is a static study, which ``action`` cannot take."""
        if self.is_study:
            raise InputError(f"{self.source}: a static study (study.kind = {self.data['study']['kind']!r}) cannot be "
                             f"used for {action}: it has no trajectory; run it with `navsim run` "
                             "(Python: navsim.run_study)")

    @property
    def catalog_epoch(self):
        """The star catalog's epoch [Julian year]: ``epoch_jyear``, or a navigation scenario's ``epoch_utc``."""
        if self.is_navigation:
            from navsim.earth.frames import julian_year

            return julian_year(self.data["epoch_utc"])
        return self.data["epoch_jyear"]

    @property
    def study_parameters(self):
        """The parameters of a static study's kind."""
        return self.data["study"][self.data["study"]["kind"]]

    def __getitem__(self, key):
        return self.data[key]


def parse_override(text):
    """``'gyro.rate_hz=200'`` -> (['gyro', 'rate_hz'], 200.0); the value is read as TOML,
    a bare word as a string."""
    if "=" not in text:
        raise InputError(f"--set {text!r}: expected KEY=VALUE, e.g. --set gyro.rate_hz=200")
    key, raw = text.split("=", 1)
    path = [part.strip() for part in key.strip().split(".")]
    if not all(path):
        raise InputError(f"--set {text!r}: empty key")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    except RecursionError:
        raise InputError(f"--set {key.strip()}: the value is nested too deeply") from None
    return path, value


def apply_overrides(data, overrides, source):
    """Return a copy of ``data`` with overrides applied; ``overrides`` is a dict {dotted: value}
    (a value of None removes the key) or a list of 'key=value' strings."""
    data = copy.deepcopy(data)
    items = overrides.items() if isinstance(overrides, dict) else (parse_override(o) for o in overrides)
    for key, value in items:
        path = key.split(".") if isinstance(key, str) else list(key)
        node = data
        for part in path[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise InputError(f"{source}: {'.'.join(path)}: {part} is not a table")
        if value is None:  # the Python API's way to remove an optional key or table
            node.pop(path[-1], None)
        else:
            node[path[-1]] = value
    return data


#: Keys of earlier versions -> what replaced them.
RENAMED = {
    ("filter", "estimate_scale_factor"): 'filter.scale_factor = "estimate" (or "consider", "ignore")',
    ("filter", "estimate_misalignment"): 'filter.mounting = "estimate" (the star-sensor mounting; the gyro\'s own axis '
                                         'misalignment is filter.gyro_misalignment)',
    ("filter", "initial_misalignment_sigma_arcsec"): "filter.initial_mounting_sigma_arcsec",
}


def validate(data, source="<scenario>"):
    """Check a raw dictionary against the schema and the cross-key rules."""
    if isinstance(data, dict) and "study" in data:
        return _validate_study(data, source)
    if isinstance(data, dict) and "trajectory" in data:
        return Scenario(data=navigation.validate(_checked(navigation.SCHEMA, data, source), source), source=source)
    for (table, key), replacement in RENAMED.items():
        if isinstance(data, dict) and isinstance(data.get(table), dict) and key in data[table]:
            raise InputError(f"{source}: {table}.{key}: renamed; use {replacement}")
    checked = _checked(SCHEMA, data, source)
    truth = checked["truth"]
    profile = truth["profile"]
    if profile not in truth:
        raise InputError(f"{source}: truth.{profile}: missing table for truth.profile = {profile!r}")
    _only_chosen(truth, "truth", "profile", PROFILES, source)
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
    if checked["faults"].get("tracking_failure_probes") and sensor["fidelity"] != "image":
        raise InputError(f"{source}: faults.tracking_failure_probes: needs star_sensor.fidelity = 'image' (it acts on frames)")
    check_faults(checked["faults"], sensor["fidelity"], source)
    if checked["settle_s"] is None:
        checked["settle_s"] = 0.1 * checked["duration_s"]
    if checked["settle_s"] >= checked["duration_s"]:
        raise InputError(f"{source}: settle_s: must be shorter than duration_s")
    if profile == "rigid_body":
        J = np.array(truth["rigid_body"]["inertia_kg_m2"])
        if not np.allclose(J, J.T) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) <= 0.0):
            raise InputError(f"{source}: truth.rigid_body.inertia_kg_m2: must be symmetric positive definite")
    return Scenario(data=checked, source=source)


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


def _checked(schema, data, source):
    try:
        return schema.check("", data)
    except InputError as error:
        raise InputError(f"{source}: {error}") from None


def _only_chosen(table, where, selector, options, source):
    """No table of an option other than the one ``table[selector]`` chose."""
    for other in options:
        if other != table[selector] and other in table:
            raise InputError(f"{source}: {where}.{other}: given, but {where}.{selector} is {table[selector]!r}")


def _validate_study(data, source):
    """A static study: the kind's own table (all defaults when absent), no other kind's table."""
    checked = _checked(study_schema(), data, source)
    study = checked["study"]
    kind = study["kind"]
    _only_chosen(study, "study", "kind", STUDIES, source)
    if kind not in study:
        study[kind] = STUDIES[kind].PARAMETERS.check(f"study.{kind}", {})
    return Scenario(data=checked, source=source)


def resolve_scenario(scenario, overrides=()):
    """A :class:`Scenario` from a path, a dictionary or a Scenario, with overrides applied."""
    if isinstance(scenario, Scenario):
        if overrides:
            return scenario_from_dict(scenario.data, overrides, source=scenario.source)
        return scenario
    if isinstance(scenario, dict):
        return scenario_from_dict(scenario, overrides)
    return load_scenario(Path(scenario), overrides)


def load_scenario(path, overrides=()):
    """Read, override and validate a scenario TOML file."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: scenario file not found")
    if path.is_dir():
        raise InputError(f"{path}: is a directory, expected a scenario .toml file")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a byte-order mark is not an error
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text file (not UTF-8)") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(f"{path}: invalid TOML: {error}") from None
    except RecursionError:
        raise InputError(f"{path}: invalid TOML: arrays or tables nested too deeply") from None
    data = apply_overrides(data, overrides, str(path))
    image = data.get("star_sensor", {}).get("image", {}) if isinstance(data.get("star_sensor"), dict) else {}
    if isinstance(image, dict) and isinstance(image.get("camera_file"), str):  # relative to the scenario file
        image["camera_file"] = str(path.parent / image["camera_file"])
    return validate(data, source=path.name)


def scenario_from_dict(data, overrides=(), source="<dict>"):
    """Validate a scenario given as a dictionary (the Python API's entry point)."""
    return validate(apply_overrides(data, overrides, source), source=source)
