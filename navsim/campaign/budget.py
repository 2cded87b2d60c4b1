"""The error budget of a star-aided navigation scenario (SINS/CNS): which error source leaves how many
metres of horizontal position error, from Monte Carlo campaigns with one source at a time.

    navsim budget SCENARIO.toml --out DIR [--runs N] [--workers W]

The sources (:data:`SOURCES`) are the accelerometer bias ∇, the gravity disturbance (deflections of
the vertical, anomaly), the star sensor's noise, its mounting error, the aberration of the star
directions, the rest of the inertial errors (gyro errors, IMU noise, scale factors) and the filter's
initial errors (in straight flight an initial tilt is not told from the mounting error and swings the
Schuler loop). A part is the scenario with every other source switched off by scenario overrides
(:func:`variants`): datasheet terms set to zero, the [gravity] table removed, the star σ set to
:data:`TINY_STAR_ARCSEC` (a σ cannot be zero: the filter takes it as its R), the mounting error
zero, the aberration corrected, the filter's initial σ tiny (:data:`TINY_INITIAL`). The aberration
part runs with the correction off: what skipping it would cost. The filter of each part is the one
its datasheets give, so a source switched off is also absent from the filter's model (the initial
part keeps the whole scenario's initial attitude σ, whose defaults come from the datasheets). The
baro stays in every part (its σ cannot be zero), and so does the star noise at image fidelity (it
comes from the pixels). A source the scenario does not have is listed as absent and not run.

Each part and the whole scenario (the total) is a campaign of N runs with the same seeds in
``DIR/parts/<source>/`` (resumable: a second call runs only what is missing). Per part, over the
runs: the RMS of the Schuler-mean horizontal error (the mean over the steady frames,
:mod:`navsim.ins.celestial`), of the final and of the RMS horizontal error [m], and the prediction of
eq. (1) where it gives one (∇: R·∇/g; gravity: R times the deflection; aberration: R·r_h of its
horizontal part); the total beside the root-sum-square of the parts. ``DIR/budget.json``
(``navsim.error-budget/1``) and ``DIR/budget.pdf`` hold them.
"""

from dataclasses import dataclass

import numpy as np

from navsim.output import write_json
from navsim.places import check_output, mark
from navsim.records import RunSummary
from navsim.scenario import build_navigation, resolve_scenario
from startrack import units
from startrack.errors import InputError

FORMAT = "navsim.error-budget/1"
#: The star σ of the parts without star noise [arcsec] (the filter takes it as its R: it cannot be 0).
TINY_STAR_ARCSEC = 0.1
#: The filter's initial σ of the parts without initial errors (tilt, heading, velocity, position; a σ
#: cannot be zero), and the keys every part pins to the whole scenario's P0 (their defaults follow the
#: datasheets, which the parts change).
TINY_INITIAL = {"initial_tilt_sigma_arcsec": 0.1, "initial_heading_sigma_deg": 1.0 / 3600.0,
                "initial_velocity_sigma_m_per_s": 1e-3, "initial_position_sigma_m": 0.01}
#: Runs per source by default.
DEFAULT_RUNS = 5
MAX_RUNS = 10_000

ACCEL_BIAS_KEYS = ("bias_turn_on_micro_g", "bias_instability_micro_g", "bias_rw_micro_g_per_sqrt_h")
GYRO_KEYS = ("arw_deg_per_sqrt_h", "rrw_deg_per_h_per_sqrt_h", "bias_turn_on_deg_per_h", "bias_instability_deg_per_h",
             "scale_factor_ppm", "misalignment_arcsec", "quantization_arcsec")
ACCEL_OTHER_KEYS = ("vrw_m_per_s_per_sqrt_h", "scale_factor_ppm", "misalignment_arcsec", "quantization_m_per_s")
#: The model terms of the "inertial" source (:class:`~navsim.sensors.gyro.GyroModel`, accelerometer).
GYRO_TERMS = ("arw", "rrw", "bias_turn_on_sigma", "bias_instability_sigma", "scale_factor_sigma", "misalignment_sigma",
              "quantization")
ACCEL_TERMS = ("vrw", "scale_factor_sigma", "misalignment_sigma", "quantization")
STAR_SIGMA_KEYS = ("star_sigma_arcsec", "attitude_sigma_cross_arcsec", "attitude_sigma_roll_arcsec")


@dataclass(frozen=True)
class Source:
    """An error source: its key (the part's directory), label, the overrides that switch it off, and
    where eq. (1) or the aberration's R·r_h predicts its metres in a run's ``celestial`` summary."""

    key: str
    label: str
    off: dict
    prediction: tuple | None = None


SOURCES = (
    Source("accel_bias", "accelerometer bias ∇", {f"imu.accelerometer.{k}": 0.0 for k in ACCEL_BIAS_KEYS},
           ("horizon_floor", "accel_bias_m")),
    Source("gravity", "gravity disturbance (deflection)", {"gravity": None}, ("horizon_floor", "gravity_m")),
    Source("star_noise", "star-sensor noise", {f"star_sensor.{k}": TINY_STAR_ARCSEC for k in STAR_SIGMA_KEYS}),
    Source("mounting", "star-sensor mounting error", {"star_sensor.misalignment_arcsec": [0.0, 0.0, 0.0]}),
    Source("aberration", "aberration, uncorrected", {"star_sensor.aberration_correction": True},
           ("aberration", "uncorrected_position_m")),
    Source("inertial", "gyro errors and IMU noise",
           {**{f"imu.gyro.{k}": 0.0 for k in GYRO_KEYS}, **{f"imu.accelerometer.{k}": 0.0 for k in ACCEL_OTHER_KEYS},
            "faults.gyro_bias_steps": []}),
    Source("initial", "filter's initial errors", {f"filter.{k}": v for k, v in TINY_INITIAL.items()}),
)
#: The prediction of the whole scenario: the floor of eq. (1) (∇ and gravity together).
TOTAL_PREDICTION = ("horizon_floor", "floor_m")


def check_request(scenario, runs, workers):
    """The validated star-aided navigation scenario of a budget; InputError (nothing written) otherwise."""
    if not 1 <= runs <= MAX_RUNS:
        raise InputError(f"--runs must be from 1 to {MAX_RUNS:,}, got {runs}")
    if workers is not None and workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    if scenario.is_study or not scenario.is_navigation:
        raise InputError(f"{scenario.source}: not a navigation scenario (no [trajectory] table): an error budget "
                         "needs a star-aided INS")
    if "star_sensor" not in scenario.data:
        raise InputError(f"{scenario.source}: no [star_sensor] table: an error budget needs a star-aided INS (SINS/CNS)")
    return scenario


def absent_reason(scenario, key):
    """Why source ``key`` is not run for ``scenario`` ('absent: ...', 'not isolable: ...'), or None."""
    data, sensor = scenario.data, scenario["star_sensor"]
    gyro, accel = build_navigation.imu(scenario)
    if key == "accel_bias" and not (accel.bias_turn_on_sigma or accel.bias_instability_sigma or accel.bias_rw):
        return "absent: the accelerometer has no bias"
    if key == "gravity" and not any((data.get("gravity") or {}).get(k) for k in ("xi_arcsec", "eta_arcsec", "anomaly_mgal")):
        return "absent: no gravity disturbance ([gravity])"
    if key == "star_noise" and sensor["fidelity"] == "image":
        return "not isolable: at image fidelity the star noise comes from the pixels and is in every part"
    if key == "mounting" and not any(sensor["misalignment_arcsec"]):
        return "absent: star_sensor.misalignment_arcsec is zero"
    if key == "inertial" and not (any(getattr(gyro, name) for name in GYRO_TERMS)
                                  or any(getattr(accel, name) for name in ACCEL_TERMS) or data["faults"]["gyro_bias_steps"]):
        return "absent: the gyro errors and IMU noise are zero"
    return None


def variants(scenario):
    """{source key: (the part's Scenario, or None, the reason it is not run)}: each source alone."""
    out = {}
    for source in SOURCES:
        reason = absent_reason(scenario, source.key)
        if reason is not None:
            out[source.key] = (None, reason)
            continue
        overrides = {"name": f"{scenario.name}.{source.key}", **initial_attitude_sigma(scenario)}
        for other in SOURCES:
            if other is not source:
                overrides.update(other.off)
        if source.key == "aberration":
            overrides["star_sensor.aberration_correction"] = False
        out[source.key] = (resolve_scenario(scenario, overrides), None)
    return out


def initial_attitude_sigma(scenario):
    """The filter's initial tilt and heading σ of the whole scenario (its keys, or their defaults from
    the datasheets) as the keys that fix them in every part."""
    start = scenario["trajectory"]["start"]
    lat = units.deg_to_rad(start["lat_deg"])
    P0 = build_navigation.initial_covariance(scenario, *build_navigation.imu(scenario), lat, start["height_m"])
    return {"filter.initial_tilt_sigma_arcsec": float(units.rad_to_arcsec(np.sqrt(P0[0, 0]))),
            "filter.initial_heading_sigma_deg": float(np.degrees(np.sqrt(P0[2, 2])))}


def run_budget(scenario, out, runs=DEFAULT_RUNS, workers=None, base_seed=None, overrides=(), progress=True):
    """Run (or resume) the budget of ``scenario`` into ``out``; returns the budget (also budget.json and
    budget.pdf in ``out``)."""
    from navsim.campaign.montecarlo import run_campaign
    from navsim.report.budget import budget_report

    scenario = check_request(resolve_scenario(scenario, overrides), runs, workers)
    parts = variants(scenario)
    directory = check_output(out, "budget")
    mark(directory, "budget")
    seed = scenario["seed"] if base_seed is None else int(base_seed)
    rows = []
    for source in SOURCES:
        variant, reason = parts[source.key]
        if variant is not None:
            run_campaign(variant, runs, directory / "parts" / source.key, base_seed=seed, workers=workers, progress=progress)
        rows.append(_part(directory, source.key, source.label, reason, source.prediction))
    total_scenario = resolve_scenario(scenario, {"name": f"{scenario.name}.total"})
    run_campaign(total_scenario, runs, directory / "parts" / "total", base_seed=seed, workers=workers, progress=progress)
    total = _part(directory, "total", "all sources", None, TOTAL_PREDICTION)
    budget = {"format": FORMAT, "scenario": scenario.name, "source": scenario.source, "runs": runs, "base_seed": seed,
              "aberration_corrected": bool(scenario["star_sensor"]["aberration_correction"]),
              "tiny_star_sigma_arcsec": TINY_STAR_ARCSEC, "parts": rows, "total": total,
              "root_sum_square": _root_sum_square(rows, scenario["star_sensor"]["aberration_correction"]),
              "in_every_part": "the baro (its σ cannot be zero)"
                               + (", the star noise (image fidelity)" if scenario["star_sensor"]["fidelity"] == "image" else "")}
    write_json(directory / "budget.json", budget)
    (directory / "budget.pdf").write_bytes(budget_report(budget))
    return budget


METRICS = ("schuler_mean_m", "final_m", "rms_m")


def _part(directory, key, label, reason, prediction):
    """A part's row: status, runs, the RMS over its runs of each metric and of the prediction."""
    row = {"key": key, "label": label, "status": "run" if reason is None else reason.split(":")[0], "note": reason}
    if reason is not None:
        return row
    summaries = [RunSummary.read(p) for p in sorted((directory / "parts" / key / "runs").glob("run_*/summary.json"))]
    if not summaries:
        return {**row, "status": "failed", "note": f"failed: no run finished (parts/{key}/runs/*/error.json)"}
    horizontal = [s["position_error_m"]["horizontal"] for s in summaries]
    values = {"schuler_mean_m": [s.celestial["horizon_floor"]["position_error_mean_m"] for s in summaries],
              "final_m": [h["final"] for h in horizontal], "rms_m": [h["rms"] for h in horizontal]}
    if prediction is not None:
        values["prediction_m"] = [s.celestial[prediction[0]][prediction[1]] for s in summaries]
    row.update({"runs": len(summaries), **{name: _rms(v) for name, v in values.items()}, "per_run": values})
    return row


def _rms(values):
    return float(np.sqrt(np.mean(np.square(values)))) if len(values) else None


def _root_sum_square(rows, aberration_corrected):
    """The RSS of the parts that were run, per metric; the aberration part only when the scenario itself
    leaves the aberration uncorrected (otherwise the total has it corrected)."""
    included = [r for r in rows if r["status"] == "run" and not (r["key"] == "aberration" and aberration_corrected)]
    return {"parts": [r["key"] for r in included],
            **{m: float(np.sqrt(sum(r[m] ** 2 for r in included))) for m in METRICS}}


def text(budget):
    """The budget as lines of text (the command's output)."""
    lines = [f"error budget        {budget['scenario']}: {budget['runs']} runs per source (RMS over the runs, metres)",
             f"{'source':<36} {'Schuler mean':>12} {'final':>10} {'RMS':>10} {'eq. (1)':>10}"]
    for row in [*budget["parts"], budget["total"]]:
        if row["status"] != "run":
            lines.append(f"{row['label']:<36} {row['note']}")
            continue
        predicted = f"{row['prediction_m']:10.2f}" if row.get("prediction_m") is not None else f"{'-':>10}"
        lines.append(f"{row['label']:<36} {row['schuler_mean_m']:12.2f} {row['final_m']:10.2f} {row['rms_m']:10.2f} {predicted}")
    rss = budget["root_sum_square"]
    lines.append(f"{'root-sum-square of the parts':<36} {rss['schuler_mean_m']:12.2f} {rss['final_m']:10.2f} {rss['rms_m']:10.2f}")
    lines.append(f"in every part: {budget['in_every_part']}")
    return lines
