"""The bad-input corpus of the navsim command line: every scenario key of the attitude and navigation
schemas with values it must refuse, every option of every command, broken files and unusable output places. Each case
must end with one line that names the culprit, a non-zero exit status, no traceback, and nothing
written. (The startrack command line has its corpus in tests/startrack.)"""

import json
import math
import os
import tomllib
from pathlib import Path

import pytest

from navsim import cli
from navsim.attitude.scenario import SCHEMA
from navsim.navigation import scenario as navigation
from navsim.spacecraft import scenario as spacecraft
from navsim.scenario.schema import ListOfTables, Table, Tagged, Value
from navsim.studies import schema as study_schema
from tests.support import run_cli

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"
BASES = {name: DATA / f"base_{name}.toml" for name in ("constant", "image", "segments", "rigid", "navigation",
                                                              "route", "sins_cns", "sins_cns_photometry", "spacecraft",
                                                              "spacecraft_targets", "spacecraft_tle")}
STUDY = ROOT / "scenarios" / "paper003_precision.toml"
#: Which base scenario reaches the keys below each table of the attitude and the navigation schema
#: (the first match wins; the schema's default otherwise).
NAV_BASE_OF = (("star_sensor.photometry", "sins_cns_photometry"), ("star_sensor", "sins_cns"), ("faults", "sins_cns"),
               ("trajectory.route", "route"))
#: ... and of the spacecraft schema.
SPACECRAFT_BASE_OF = (("pointing.targets", "spacecraft_targets"), ("orbit.state", "spacecraft_targets"),
                      ("orbit.tle", "spacecraft_tle"))
BASE_OF = (("truth.sinusoidal_axis", "image"), ("truth.rate_segments", "segments"), ("truth.rigid_body", "rigid"),
           ("star_sensor.image", "image"), ("faults.attitude_jumps", "image"), ("faults.false_star_storms", "image"),
           ("faults.tracking_failure_probes", "image"))


def toml(value):
    """``value`` written as a TOML value for --set."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and math.isnan(value):
        return "nan"
    if isinstance(value, float) and math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {toml(v)}" for k, v in value.items()) + "}"
    return repr(value)


def bad_values(spec):
    """(label, value) pairs a Value must refuse."""
    out = []
    limits = [("below minimum", spec.minimum, -1), ("at exclusive minimum", spec.exclusive_minimum, 0),
              ("above maximum", spec.maximum, +1)]
    if spec.kind in ("float", "int"):
        out += [("a string", "abc"), ("a boolean", True)]
        out += [("NaN", math.nan), ("infinite", math.inf)] if spec.kind == "float" else [("a fraction", 1.5)]
        for label, limit, side in limits:
            if limit is not None:
                step = max(1.0, abs(limit)) if side else 0.0
                value = limit + side * step
                out.append((label, int(value) if spec.kind == "int" else float(value)))
    elif spec.kind == "bool":
        out += [("a string", "yes"), ("a number", 1)]
    elif spec.kind == "str":
        out += [("a number", 5)] + ([("an unknown choice", "nonsense")] if spec.choices else [])
    elif spec.kind in ("vector", "quaternion"):
        size = 4 if spec.kind == "quaternion" else spec.size
        out += [("too short", [1.0] * (size - 1)), ("a string entry", ["a"] + [0.0] * (size - 1)),
                ("a NaN entry", [math.nan] + [0.0] * (size - 1)), ("a scalar", 1.0)]
        out += [("zero norm", [0.0] * 4)] if spec.kind == "quaternion" else []
        if spec.maximum is not None:
            out.append(("an entry above maximum", [spec.maximum * 2 + 1] + [0.0] * (size - 1)))
    elif spec.kind == "matrix":
        out += [("one row", [[1.0, 0.0, 0.0]]), ("a string entry", [["a", 0, 0], [0, 1, 0], [0, 0, 1]])]
    elif spec.kind in ("list", "ints"):
        out += [("a scalar", 1.0), ("a string entry", ["a"])]
        if spec.kind == "ints":
            out.append(("a fraction entry", [1.5]))
    return out


def scenario_cases(schema, base_of, default, prefix=""):
    """(case id, base, key path, --set override) for every leaf of ``schema`` and every table's unknown
    key; the base scenario of each is the first of ``base_of`` (table prefix, base) to match, else
    ``default``."""
    def base(path):
        return next((name for table, name in base_of if path.startswith(table)), default)

    cases = [(f"{prefix or '<top>'}: an unknown key", base(prefix), f"{prefix + '.' if prefix else ''}bogus_key", "1")]
    for key, spec in schema.entries.items():
        path = f"{prefix}.{key}" if prefix else key
        if isinstance(spec, Table):
            cases += scenario_cases(spec, base_of, default, path)
        elif isinstance(spec, ListOfTables):
            cases.append((f"{path}: not an array of tables", base(path), path, "5"))
            cases += list(_item_cases(spec.item, path, base(path)))
        else:
            cases += [(f"{path}: {label}", base(path), path, toml(value)) for label, value in bad_values(spec)]
    return cases


def _item_cases(item, path, base):
    """Cases for each field of a list-of-tables item: the list replaced by one item with that field bad
    (for tagged items, of each kind: its first item in the base, or an unknown kind and key)."""
    items = tomllib.loads(BASES[base].read_text())
    for part in path.split("."):
        items = items[part]
    variants = item.variants if isinstance(item, Tagged) else {"": item}
    for kind, table in variants.items():
        valid = next(dict(row) for row in items if not kind or row[item.tag] == kind)
        label = f"{path}[{kind}]" if kind else f"{path}[0]"
        for key, spec in table.entries.items():
            if not isinstance(spec, Value):  # a table inside an array's item (a head's faults): its own keys' cases
                continue                      # are those of the same table at the top (the attitude kind's faults)
            for bad, value in bad_values(spec):
                yield f"{label}.{key}: {bad}", base, path, toml([{**valid, key: value}])
        if kind:
            yield f"{label}: an unknown key", base, path, toml([{**valid, "bogus_key": 1.0}])
    if isinstance(item, Tagged):
        yield f"{path}: an unknown {item.tag}", base, path, toml([{item.tag: "fly"}])


SCENARIO_CASES = (scenario_cases(SCHEMA, BASE_OF, "constant") + scenario_cases(navigation.SCHEMA, NAV_BASE_OF, "navigation")
                  + scenario_cases(spacecraft.SCHEMA, SPACECRAFT_BASE_OF, "spacecraft"))


def assert_one_clear_line(status, err, culprit, out=None):
    assert status not in (0, None), err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(("navsim: error:", "navsim run: error:", "navsim montecarlo: error:",
                                "navsim tune: error:", "navsim report: error:")), err
    assert culprit in lines[0], (culprit, err)
    if out is not None:
        assert not Path(out).exists() or not any(Path(out).iterdir()), f"{out} was written"


@pytest.mark.parametrize("case_id, base, key, override", SCENARIO_CASES,
                         ids=[f"{c[1]}: {c[0]}" for c in SCENARIO_CASES])
def test_every_scenario_key_refuses_a_bad_value(tmp_path, capsys, case_id, base, key, override):
    out = tmp_path / "out"
    status, err = run_cli(cli.main, ["run", BASES[base], "--out", out, "--set", f"{key}={override}"], capsys)
    assert_one_clear_line(status, err, key.split(".")[-1], out)


REQUIRED = [("duration_s", "constant"), ("truth.profile", "constant"), ("gyro.rate_hz", "constant"),
            ("star_sensor.rate_hz", "constant"), ("star_sensor.fov_deg", "constant"),
            ("truth.sinusoidal_axis.amplitude_deg", "image"), ("truth.rigid_body.inertia_kg_m2", "rigid"),
            ("name", "navigation"), ("trajectory.start.lat_deg", "navigation"), ("trajectory.segments", "navigation"),
            ("imu.rate_hz", "navigation"), ("baro.rate_hz", "navigation"), ("aiding.position.sigma_ned_m", "navigation"),
            ("gravity.model", "navigation"), ("star_sensor.photometry.aperture_mm", "sins_cns_photometry"),
            ("trajectory.route.waypoints", "route"), ("epoch_utc", "spacecraft"), ("pointing.law", "spacecraft"),
            ("star_sensor.0.mounting_rotvec_deg", "spacecraft"), ("star_sensor.1.rate_hz", "spacecraft")]


@pytest.mark.parametrize("key, base", REQUIRED)
def test_a_missing_required_key_is_named(tmp_path, capsys, key, base):
    data = tomllib.loads(BASES[base].read_text())
    node = data
    *parents, last = key.split(".")
    for part in parents:
        node = node[int(part)] if isinstance(node, list) else node[part]
    del node[last]
    path = tmp_path / "missing.toml"
    path.write_text(_to_toml(data))
    status, err = run_cli(cli.main, ["run", path, "--out", tmp_path / "out"], capsys)
    assert_one_clear_line(status, err, last, tmp_path / "out")
    assert "missing" in err


def _to_toml(data, prefix=""):
    """A scenario dictionary as TOML (scalars and inline arrays/tables, then sub-tables)."""
    scalars = [f"{k} = {toml(v)}" for k, v in data.items() if not isinstance(v, dict)]
    tables = [_to_toml(v, f"{prefix}{k}.") for k, v in data.items() if isinstance(v, dict)]
    head = [f"[{prefix[:-1]}]"] if prefix else []
    return "\n".join(head + scalars) + "\n\n" + "\n".join(tables)


CROSS_KEY = [
    ("constant", "star_sensor.rate_hz=3.0", "star_sensor.rate_hz"),          # does not divide the gyro rate
    ("constant", "truth.rate_hz=15.0", "truth.rate_hz"),                     # not a multiple of the gyro rate
    ("constant", "duration_s=0.1", "duration_s"),                            # shorter than a frame
    ("constant", "settle_s=10.0", "settle_s"),                               # after the end
    ("constant", "truth.profile=\"rigid_body\"", "truth.rigid_body"),        # its table is missing
    ("image", "truth.constant_rate={rate_deg_per_s = [1.0, 0.0, 0.0]}", "truth.constant_rate"),  # another profile's
    ("image", "truth.sinusoidal_axis.axis=[0.0, 0.0, 0.0]", "axis"),        # no rotation axis
    ("image", "star_sensor.measurement=\"attitude\"", "star_sensor.measurement"),
    ("constant", "faults.attitude_jumps=[{time_s = 1.0, angle_deg = 2.0}]", "faults.attitude_jumps"),
    ("constant", "faults.outages=[{start_s = 2.0, end_s = 1.0}]", "faults.outages"),
    ("segments", "duration_s=10.0", "segments"),                             # segments do not cover the run
    ("rigid", "truth.rigid_body.inertia_kg_m2=[[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]", "inertia_kg_m2"),
    ("constant", "duration_s=1e6", "duration_s"),                            # more than one run holds
    ("constant", "gyro.rate_hz=10000.0", "gyro.rate_hz"),
    ("image", "star_sensor.image.sky_hip=[999999]", "sky_hip"),             # not in the catalog
    ("constant", "filter.estimate_scale_factor=true", "filter.estimate_scale_factor"),  # renamed
    ("constant", "filter.initial_misalignment_sigma_arcsec=10.0", "initial_misalignment_sigma_arcsec"),
    # navigation scenarios (the INS): the list, then the other cross-key rules
    ("navigation", "trajectory.start.lat_deg=91.0", "trajectory.start.lat_deg"),
    ("navigation", "trajectory.start.lat_deg=-90.5", "trajectory.start.lat_deg"),
    ("navigation", "trajectory.start.height_m=-1500.0", "trajectory.start.height_m"),
    ("navigation", 'trajectory.segments=[{kind = "hold", duration_s = 1.0}, {kind = "accelerate", speed_m_per_s = 100.0, '
                   'acceleration_m_per_s2 = 5.0}, {kind = "turn", heading_change_deg = 90.0, rate_deg_per_s = 3.0, '
                   'bank_deg = 10.0}]', "segments[2].bank_deg"),                   # a turn that cannot be flown
    ("navigation", "imu.rate_hz=0.0", "imu.rate_hz"),
    ("navigation", "imu.rate_hz=-100.0", "imu.rate_hz"),
    ("navigation", "aiding.position.rate_hz=0.0", "aiding.position.rate_hz"),
    ("navigation", "baro.rate_hz=-1.0", "baro.rate_hz"),
    ('navigation', 'trajectory.segments=[{kind = "turn", heading_change_deg = 90.0, rate_deg_per_s = 0.0}]', "rate_deg_per_s"),
    ("navigation", "aiding.position.rate_hz=50.0", "aiding.position.rate_hz"),  # faster than the IMU
    ("navigation", "baro.rate_hz=40.0", "baro.rate_hz"),                        # faster than the IMU
    ("navigation", "aiding.position.rate_hz=3.0", "aiding.position.rate_hz"),   # does not divide the IMU rate
    ("navigation", "aiding.position.rate_hz=0.75", "aiding.position.rate_hz"),  # does not divide the baro's
    ("navigation", "duration_s=100.0", "duration_s"),                           # longer than the trajectory
    ("navigation", "settle_s=40.0", "settle_s"),
    ("navigation", "trajectory.start.speed_m_per_s=10.0", "segments[0].kind"),  # a hold needs zero speed
    ("navigation", 'trajectory.segments=[{kind = "hold", duration_s = 2000000.0}]', "duration_s"),  # too many samples
    ("navigation", 'gravity.model="constant"', "gravity.correlation_length_m"),
    ("navigation", "gravity.xi_arcsec=-1.0", "xi_arcsec"),
    ("navigation", 'epoch_utc="2024-13-01T00:00:00"', "epoch_utc"),
    ("navigation", 'epoch_utc="2024-03-20T00:00:00+02:00"', "epoch_utc"),
    ("navigation", "trajectory.start={lat_deg = 45.0}", "trajectory.start.lon_deg"),
    # spacecraft (issue 51): an impossible TLE, an orbit below the surface, an unknown attitude law, and the other rules
    ("spacecraft_tle", 'orbit.tle=["1 25544U 98067A   08264.51782528 -.00002182  00000-0 -11606-4 0  2928", '
                           '"2 25544  51.6416 247.4627 0006703 130.5360 325.0288 15.72125391563537"]', "orbit.tle"),
    ("spacecraft_tle", 'orbit.tle=["1 25544U 98067A   08264.51782528 -.00002182  00000-0 -11606-4 0  2927"]', "orbit.tle"),
    ("spacecraft_tle", 'orbit.tle=["1 25544U 98067A   08264.51782528 -.00002182  00000-0 -11606-4 0  2927", '
                           '"2 25544  51.6416 247.4627 0006703 130.5360 325.0288 17.50000000563535"]', "orbit.tle"),
    ("spacecraft", "orbit.elements.height_km=50.0", "orbit.elements.height_km"),
    ("spacecraft", "orbit.elements.eccentricity=0.5", "orbit.elements.height_km"),       # the perigee inside the Earth
    ("spacecraft", "orbit.state={position_km = [6000.0, 0.0, 0.0], velocity_km_per_s = [0.0, 7.5, 0.0]}", "orbit"),
    ("spacecraft", 'orbit.elements={height_km = 500.0, inclination_deg = 97.0}', "raan_deg"),
    ("spacecraft", 'orbit.propagator="sgp4"', "orbit.propagator"),                      # sgp4 without a TLE
    ("spacecraft", 'pointing.law="sideways"', "pointing.law"),
    ("spacecraft", 'pointing.law="sun"', "pointing.offsets"),                           # nadir's offsets on another law
    ("spacecraft_tle", 'pointing.law="targets"', "pointing.targets"),                   # no targets
    ("spacecraft_targets", "pointing.targets.1.start_s=0.0", "pointing.targets[1].start_s"),    # out of time order
    ("spacecraft_targets", "pointing.targets=[{start_s = 0.0, ra_deg = 250.0, dec_deg = 0.0}, {start_s = 10.0, ra_deg = 300.0, "
                           "dec_deg = 0.0}, {start_s = 20.0, ra_deg = 250.0, dec_deg = 0.0}]", "pointing.targets[1].start_s"),
    ("spacecraft_targets", "pointing.targets.0.start_s=10.0", "pointing.targets[0].start_s"),
    ("spacecraft", "star_sensor.1.rate_hz=2.0", "star_sensor[1].rate_hz"),               # another frame clock
    ("spacecraft", 'star_sensor.1.measurement="attitude"', "star_sensor[1].measurement"),
    ("spacecraft", 'star_sensor.0.fidelity="image"', "star_sensor[0].fidelity"),
    ("spacecraft", "star_sensor.3.fov_deg=10.0", "star_sensor.3"),                       # no fourth head to change
    ("spacecraft", "star_sensor={rate_hz = 1.0, fov_deg = 20.0, mounting_rotvec_deg = [0.0, 0.0, 0.0]}", "star_sensor"),
    ("spacecraft", "gyro.rate_hz=1.5", "star_sensor[0].rate_hz"),
    ("spacecraft", "spacecraft.controller.rate_hz=3.0", "spacecraft.truth_rate_hz"),
    ("spacecraft", "spacecraft.inertia_kg_m2=[[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]", "inertia_kg_m2"),
    ("spacecraft", "spacecraft.wheels.initial_momentum_N_m_s=[0.1, 0.2]", "initial_momentum_N_m_s"),
    ("spacecraft", "orbits=2.0", "duration_s"),                                           # both
    ("spacecraft", "duration_s=1e6", "duration_s"),                                       # more than a run holds
    ("spacecraft", "settle_s=300.0", "settle_s"),
    ("spacecraft", 'epoch_utc="2025-02-30T00:00:00"', "epoch_utc"),
    # the uncertainty of a model air the processing does not correct with
    ("sins_cns", "star_sensor.refraction={correction = false, pressure_sigma_percent = 3.0}", "star_sensor.refraction"),
]


@pytest.mark.parametrize("base, override, culprit", CROSS_KEY, ids=[c[1][:40] for c in CROSS_KEY])
def test_inconsistent_keys_are_named(tmp_path, capsys, base, override, culprit):
    status, err = run_cli(cli.main, ["run", BASES[base], "--out", tmp_path / "out", "--set", override], capsys)
    assert_one_clear_line(status, err, culprit, tmp_path / "out")


def study_cases():
    """Every parameter of every static study kind, with the values it must refuse."""
    schema = study_schema()
    cases = [("study: an unknown kind", "study.kind", '"nonsense"')]
    for kind, table in schema.entries["study"].entries.items():
        if isinstance(table, Table):
            for key, spec in table.entries.items():
                if isinstance(spec, Value):
                    cases += [(f"study.{kind}.{key}: {label}", f"study.{kind}.{key}", toml(value))
                              for label, value in bad_values(spec)]
    return cases


STUDY_CASES = study_cases()


@pytest.mark.parametrize("case_id, key, override", STUDY_CASES, ids=[c[0] for c in STUDY_CASES])
def test_every_study_parameter_refuses_a_bad_value(tmp_path, capsys, case_id, key, override):
    base = ROOT / "scenarios" / ("contest_starmap.toml" if ".contest_starmap." in key else "paper003_precision.toml")
    status, err = run_cli(cli.main, ["run", base, "--out", tmp_path / "out", "--set", f"{key}={override}"], capsys)
    assert_one_clear_line(status, err, key.split(".")[-1], tmp_path / "out")


def _files(tmp_path):
    """Broken inputs on disk: (name -> path)."""
    (tmp_path / "dir.toml").mkdir()
    (tmp_path / "binary.toml").write_bytes(b"\xff\xfe\x00binary")
    (tmp_path / "invalid.toml").write_text("name = \n")
    (tmp_path / "deep.toml").write_text("name = " + "[" * 50000 + "]" * 50000 + "\n")
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "foreign").mkdir()
    (tmp_path / "foreign" / "notes.txt").write_text("mine")
    return tmp_path


def option_cases():
    """(id, argv with {tmp} and {demo} placeholders, culprit) of every command's options."""
    demo = "{demo}"
    return [
        ("run: missing scenario", ["run", "{tmp}/nope.toml", "--out", "{tmp}/o"], "nope.toml"),
        ("run: scenario is a directory", ["run", "{tmp}/dir.toml", "--out", "{tmp}/o"], "is a directory"),
        ("run: binary scenario", ["run", "{tmp}/binary.toml", "--out", "{tmp}/o"], "not a text file"),
        ("run: invalid TOML", ["run", "{tmp}/invalid.toml", "--out", "{tmp}/o"], "invalid TOML"),
        ("run: nested 50000 deep", ["run", "{tmp}/deep.toml", "--out", "{tmp}/o"], "nested too deeply"),
        ("run: --seed -1", ["run", demo, "--out", "{tmp}/o", "--seed", "-1"], "--seed"),
        ("run: --seed 2**64", ["run", demo, "--out", "{tmp}/o", "--seed", str(2**64)], "--seed"),
        ("run: --seed abc", ["run", demo, "--out", "{tmp}/o", "--seed", "abc"], "--seed"),
        ("run: no --out", ["run", demo], "--out"),
        ("run: --out is a file", ["run", demo, "--out", "{tmp}/a_file"], "a_file"),
        ("run: --out under a file", ["run", demo, "--out", "{tmp}/a_file/o"], "a_file"),
        ("run: --out in /proc", ["run", demo, "--out", "/proc/navsim-out"], "/proc"),
        ("run: --out holds foreign files", ["run", demo, "--out", "{tmp}/foreign"], "foreign"),
        ("run: --report not a PDF", ["run", demo, "--out", "{tmp}/o", "--report", "{tmp}/r.txt"], "r.txt"),
        ("run: --report a directory", ["run", demo, "--out", "{tmp}/o", "--report", "{tmp}/dir.toml"], "dir.toml"),
        ("run: --set without =", ["run", demo, "--out", "{tmp}/o", "--set", "duration_s"], "duration_s"),
        ("run: --set empty key", ["run", demo, "--out", "{tmp}/o", "--set", "=3"], "empty key"),
        ("run: --set through a value", ["run", demo, "--out", "{tmp}/o", "--set", "duration_s.x=3"], "duration_s"),
        ("run: --set deep value", ["run", demo, "--out", "{tmp}/o", "--set", "duration_s=" + "[" * 5000 + "]" * 5000],
         "duration_s"),
        ("run: unknown option", ["run", demo, "--out", "{tmp}/o", "--bogus"], "--bogus"),
        ("montecarlo: --runs 0", ["montecarlo", demo, "--runs", "0", "--out", "{tmp}/o"], "--runs"),
        ("montecarlo: --runs -1", ["montecarlo", demo, "--runs", "-1", "--out", "{tmp}/o"], "--runs"),
        ("montecarlo: --runs 1e9", ["montecarlo", demo, "--runs", "1000000000", "--out", "{tmp}/o"], "--runs"),
        ("montecarlo: --runs x", ["montecarlo", demo, "--runs", "x", "--out", "{tmp}/o"], "--runs"),
        ("montecarlo: --workers 0", ["montecarlo", demo, "--runs", "2", "--out", "{tmp}/o", "--workers", "0"], "--workers"),
        ("montecarlo: workers and scheduler", ["montecarlo", demo, "--runs", "2", "--out", "{tmp}/o", "--workers", "2",
                                               "--scheduler", "tcp://127.0.0.1:8786"], "--scheduler"),
        ("montecarlo: --scheduler notaurl", ["montecarlo", demo, "--runs", "2", "--out", "{tmp}/o",
                                             "--scheduler", "notaurl"], "notaurl"),
        ("montecarlo: no scheduler there", ["montecarlo", demo, "--runs", "2", "--out", "{tmp}/o",
                                            "--scheduler", "tcp://127.0.0.1:1"], "cannot connect"),
        ("montecarlo: --seed -5", ["montecarlo", demo, "--runs", "2", "--out", "{tmp}/o", "--seed", "-5"], "--seed"),
        ("montecarlo: --out is a file", ["montecarlo", demo, "--runs", "2", "--out", "{tmp}/a_file"], "a_file"),
        ("montecarlo: --out under a file", ["montecarlo", demo, "--runs", "2", "--out", "{tmp}/a_file/o"], "a_file"),
        ("montecarlo: --out in /proc", ["montecarlo", demo, "--runs", "2", "--out", "/proc/navsim-mc"], "/proc"),
        ("montecarlo: a study", ["montecarlo", str(STUDY), "--runs", "2", "--out", "{tmp}/o"], "static study"),
        ("tune: --runs 0", ["tune", demo, "--runs", "0"], "--runs"),
        ("tune: --evaluations 0", ["tune", demo, "--evaluations", "0"], "--evaluations"),
        ("tune: --evaluations -1", ["tune", demo, "--evaluations", "-1"], "--evaluations"),
        ("tune: --seed -1", ["tune", demo, "--seed", "-1"], "--seed"),
        ("tune: a study", ["tune", str(STUDY)], "static study"),
        ("report: missing directory", ["report", "{tmp}/nope", "-o", "{tmp}/r.pdf"], "nope"),
        ("report: a file", ["report", "{tmp}/a_file", "-o", "{tmp}/r.pdf"], "a_file"),
        ("report: not an output", ["report", "{tmp}/foreign", "-o", "{tmp}/r.pdf"], "foreign"),
        ("report: -o not a PDF", ["report", "{tmp}/foreign", "-o", "{tmp}/r.txt"], "r.txt"),
        ("report: -o under a file", ["report", "{tmp}/foreign", "-o", "{tmp}/a_file/r.pdf"], "a_file"),
        ("no command", [], "COMMAND"),
        ("unknown command", ["fly"], "fly"),
    ]


OPTION_CASES = option_cases()


@pytest.mark.parametrize("case_id, argv, culprit", OPTION_CASES, ids=[c[0] for c in OPTION_CASES])
def test_every_option_refuses_a_bad_value(tmp_path, capsys, case_id, argv, culprit):
    _files(tmp_path)
    demo = BASES["constant"]
    argv = [a.replace("{tmp}", str(tmp_path)).replace("{demo}", str(demo)) for a in argv]
    status, err = run_cli(cli.main, argv, capsys)
    assert_one_clear_line(status, err, culprit, tmp_path / "o")
    assert not Path("/proc/navsim-out").exists()


def _run_dir(tmp_path, capsys):
    out = tmp_path / "run"
    assert run_cli(cli.main, ["run", BASES["constant"], "--out", out], capsys)[0] == 0
    return out


BROKEN_OUTPUTS = [
    ("summary.json not JSON", "summary.json", b"{", "summary.json"),
    ("summary.json a list", "summary.json", b"[]", "summary.json"),
    ("summary.json another format", "summary.json", b'{"format": "other/9"}', "summary.json"),
    ("timeseries.npz not a zip", "timeseries.npz", b"not a zip", "timeseries.npz"),
    ("scenario.json not JSON", "scenario.json", b"\xff", "scenario.json"),
    ("timing.npz not a zip", "timing.npz", b"xx", "timing.npz"),
]


@pytest.mark.parametrize("case_id, name, content, culprit", BROKEN_OUTPUTS, ids=[c[0] for c in BROKEN_OUTPUTS])
def test_a_broken_run_directory_is_named_by_the_report(tmp_path, capsys, case_id, name, content, culprit):
    out = _run_dir(tmp_path, capsys)
    (out / name).write_bytes(content)
    status, err = run_cli(cli.main, ["report", out, "-o", tmp_path / "r.pdf"], capsys)
    assert_one_clear_line(status, err, culprit)
    assert not (tmp_path / "r.pdf").exists()


@pytest.mark.parametrize("content", ["[]", "{", '{"runs": "many"}'])
def test_a_broken_campaign_file_is_named(tmp_path, capsys, content):
    out = tmp_path / "mc"
    out.mkdir()
    (out / "campaign.json").write_text(content)
    status, err = run_cli(cli.main, ["montecarlo", BASES["constant"], "--runs", "2", "--out", out], capsys)
    assert_one_clear_line(status, err, "campaign.json")


def test_an_output_of_one_kind_is_not_reused_for_another(tmp_path, capsys):
    """A run directory is refused to a campaign and the other way round; a second run into the same
    directory replaces the first whole (no stale file survives)."""
    run_dir = _run_dir(tmp_path, capsys)
    status, err = run_cli(cli.main, ["montecarlo", BASES["constant"], "--runs", "2", "--out", run_dir], capsys)
    assert_one_clear_line(status, err, "a run output")
    campaign = tmp_path / "mc"
    assert run_cli(cli.main, ["montecarlo", BASES["constant"], "--runs", "1", "--out", campaign, "--workers", "1"], capsys)[0] == 0
    status, err = run_cli(cli.main, ["run", BASES["constant"], "--out", campaign], capsys)
    assert_one_clear_line(status, err, "a campaign output")
    (run_dir / "stale.npy").write_bytes(b"old")
    assert run_cli(cli.main, ["run", BASES["constant"], "--out", run_dir], capsys)[0] == 0
    assert not (run_dir / "stale.npy").exists()


def test_a_second_campaign_on_a_locked_directory_is_refused(tmp_path, capsys):
    out = tmp_path / "mc"
    assert run_cli(cli.main, ["montecarlo", BASES["constant"], "--runs", "1", "--out", out, "--workers", "1"], capsys)[0] == 0
    (out / "campaign.lock").write_text(str(os.getppid()))  # a live process holds it
    status, err = run_cli(cli.main, ["montecarlo", BASES["constant"], "--runs", "1", "--out", out, "--workers", "1"], capsys)
    assert_one_clear_line(status, err, "another campaign")
    (out / "campaign.lock").write_text("999999999")  # a stale lock is taken over
    assert run_cli(cli.main, ["montecarlo", BASES["constant"], "--runs", "1", "--out", out, "--workers", "1"], capsys)[0] == 0


def test_a_byte_order_mark_is_accepted(tmp_path, capsys):
    scenario = tmp_path / "bom.toml"
    scenario.write_bytes(b"\xef\xbb\xbf" + BASES["constant"].read_bytes())
    assert run_cli(cli.main, ["run", scenario, "--out", tmp_path / "o"], capsys)[0] == 0


def test_the_corpus_is_large():
    """The issue's floor: at least 200 bad inputs over every option and scenario key kind."""
    total = (len(SCENARIO_CASES) + len(REQUIRED) + len(CROSS_KEY) + len(STUDY_CASES) + len(OPTION_CASES)
             + len(BROKEN_OUTPUTS) + 3 + 2)
    assert total >= 200
    kinds = {spec.kind for spec in _leaves(SCHEMA)}
    assert kinds >= {"float", "int", "bool", "str", "vector", "quaternion", "matrix", "list", "ints"}


def _leaves(table):
    for spec in table.entries.values():
        if isinstance(spec, Table):
            yield from _leaves(spec)
        elif isinstance(spec, ListOfTables):
            yield from _leaves(spec.item)
        else:
            yield spec


@pytest.mark.parametrize("drop", ["error_state", "lat_true"])
def test_a_navigation_run_without_its_arrays_is_named_by_the_report(tmp_path, capsys, drop):
    from navsim.output import read_npz, write_npz

    out = tmp_path / "run"
    assert run_cli(cli.main, ["run", BASES["navigation"], "--out", out], capsys)[0] == 0
    series = read_npz(out / "timeseries.npz")
    del series[drop]
    write_npz(out / "timeseries.npz", series)
    status, err = run_cli(cli.main, ["report", out, "-o", tmp_path / "r.pdf"], capsys)
    assert_one_clear_line(status, err, drop)
    assert not (tmp_path / "r.pdf").exists()
