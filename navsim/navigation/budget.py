"""The error budget of a star-aided navigation scenario (SINS/CNS): which error source leaves how many
metres of horizontal position error, from Monte Carlo campaigns with one source at a time
(``navsim budget``; the campaigns are run by :mod:`navsim.campaign.budget`, the PDF is
:mod:`navsim.report.budget`'s).

The sources (:data:`SOURCES`) are the accelerometer bias ∇, the gravity disturbance (deflections of
the vertical, anomaly), the star sensor's noise, its mounting error, the rest of the inertial errors
(gyro errors, IMU noise, scale factors), the filter's initial errors (in straight flight an initial
tilt is not told from the mounting error and swings the Schuler loop) and the baro's and position
fixes' errors (with ``filter.baro_states = "all"`` the baro reaches the horizontal channels). A part
is the scenario's own filter (the same P0, Q, R, consider states, gains) on a truth with every other
source switched off (``truth_off``, :data:`navsim.navigation.run.TRUTH_SOURCES`), so the navigation
errors are one linear system driven by the sources one at a time: per run the parts' Schuler-mean
error vectors add up to the total's (the superposition residual in budget.json) and, over the runs,
the parts add up in root-sum-square (their ratio to the total is given) up to the runs' cross terms:
sampling noise for a source drawn per run, but a source the scenario fixes (a constant deflection,
the given mounting error) is the same vector in every run and two of them add linearly. Every run
draws each source from the same seeded sub-stream whatever is switched off, so the parts share the
other sources' draws exactly.

The aberration and the refraction's correction are another thing: the truth's stars are always apparent
and refracted, and such a part is what skipping the correction costs — the filter without the correction
on a truth without any other source. When the scenario corrects (the default) that part is left out of the
root-sum-square and the superposition; when it does not, the other parts run with the correction (their
filter otherwise the scenario's) and the part is one of the sources. The refraction's residual — the real
air's pressure and temperature against the model the processing corrects with — is a source like the
others (``truth_off`` "refraction": the truth's air is the model's). At image fidelity the star noise
comes from the pixels: it is not isolable and stays in every part. A source the scenario does not
have is listed as absent and not run.

Each part and the whole scenario (the total) is a campaign of N runs with the same seeds in
``DIR/parts/<source>/`` (resumable: a second call runs only what is missing; its campaign.json
records what the truth leaves out). Per part, over the runs: the RMS of the Schuler-mean horizontal
error (the mean over the steady frames, :mod:`navsim.navigation.celestial`), of the final and of the RMS
horizontal error [m], and the prediction of eq. (1) where it gives one (∇: R·∇/g; gravity: R times the
deflection; aberration: R·r_h of its horizontal part); the total beside the root-sum-square of the
parts and their ratio: :func:`summarize_budget`, the content of ``DIR/budget.json`` (``navsim.error-budget/2``).
"""

from dataclasses import dataclass

import numpy as np

from navsim.navigation import build
from navsim.navigation.records import RunSummary
from navsim.navigation.run import TRUTH_SOURCES
from navsim.navigation.scenario import validate
from navsim.scenario import Scenario, apply_overrides
from startrack import InputError

FORMAT = "navsim.error-budget/2"

#: The model terms of the "inertial" source (:class:`~navsim.sensors.gyro.GyroModel`, accelerometer).
GYRO_TERMS = ("arw", "rrw", "bias_turn_on_sigma", "bias_instability_sigma", "scale_factor_sigma", "misalignment_sigma",
              "quantization")
ACCEL_TERMS = ("vrw", "scale_factor_sigma", "misalignment_sigma", "quantization")


@dataclass(frozen=True)
class Source:
    """An error source: its key (the part's directory and, but for a correction's cost, its name in
    ``truth_off``), label, where eq. (1) or R·r_h predicts its metres in a run's ``celestial`` summary, and
    for the cost of skipping a correction the scenario key that switches it (``correction``, dotted); ``covariance``
    the covariance analysis' source that is this part (default: the key)."""

    key: str
    label: str
    prediction: tuple | None = None
    correction: str | None = None
    covariance: str | None = None

    def corrected(self, scenario):
        """Whether ``scenario`` applies this source's correction (None: not a correction)."""
        if self.correction is None:
            return None
        value = scenario.data
        for name in self.correction.split("."):
            value = value[name]
        return bool(value)


SOURCES = (
    Source("accel_bias", "accelerometer bias ∇", ("horizon_floor", "accel_bias_m")),
    Source("gravity", "gravity disturbance (deflection)", ("horizon_floor", "gravity_m")),
    Source("star_noise", "star-sensor noise"),
    Source("mounting", "star-sensor mounting error"),
    Source("aberration", "aberration, cost of not correcting", ("aberration", "uncorrected_position_m"),
           "star_sensor.aberration_correction"),
    Source("refraction", "refraction residual (real air vs model)", ("refraction", "residual_position_m")),
    Source("refraction_correction", "refraction, cost of not correcting", ("refraction", "uncorrected_position_m"),
           "star_sensor.refraction.correction", "refraction"),
    Source("inertial", "gyro errors and IMU noise"),
    Source("initial", "filter's initial errors"),
    Source("aiding", "baro and position-fix errors"),
)
CORRECTIONS = tuple(s for s in SOURCES if s.correction is not None)
#: The prediction of the whole scenario: the floor of eq. (1) (∇ and gravity together).
TOTAL_PREDICTION = ("horizon_floor", "floor_m")


@dataclass(frozen=True)
class Part:
    """A part of the budget: its key (its campaign's directory ``parts/<key>``), label, the scenario it
    runs and the truth sources it switches off (None when it is not run, and ``reason`` says why),
    where eq. (1) or the aberration's R·r_h predicts its metres in a run's ``celestial`` summary, and the
    covariance analysis' source it is (``covariance``)."""

    key: str
    label: str
    scenario: Scenario | None
    truth_off: tuple | None
    reason: str | None
    prediction: tuple | None
    covariance: str | None = None

    def __post_init__(self):
        if self.covariance is None:
            object.__setattr__(self, "covariance", self.key)


def absent_reason(scenario, key):
    """Why source ``key`` is not run for ``scenario`` ('absent: ...', 'not isolable: ...'), or None."""
    data, sensor = scenario.data, scenario["star_sensor"]
    gyro, accel = build.imu(scenario)
    if key == "accel_bias" and not (accel.bias_turn_on_sigma or accel.bias_instability_sigma or accel.bias_rw):
        return "absent: the accelerometer has no bias"
    if key == "gravity" and not any((data.get("gravity") or {}).get(k) for k in ("xi_arcsec", "eta_arcsec", "anomaly_mgal")):
        return "absent: no gravity disturbance ([gravity])"
    if key == "star_noise" and sensor["fidelity"] == "image":
        return "not isolable: at image fidelity the star noise comes from the pixels and is in every part"
    if key == "mounting" and not any(sensor["misalignment_arcsec"]):
        return "absent: star_sensor.misalignment_arcsec is zero"
    air = sensor["refraction"]
    if key == "refraction" and not (air["pressure_error_percent"] or air["temperature_error_k"] or air["drawn"]):
        return "absent: the real air is the model's (star_sensor.refraction's errors are zero, none drawn)"
    if key == "aiding" and not (data.get("baro") or data["aiding"].get("position")):
        return "absent: neither a baro nor position fixes"
    if key == "inertial" and not (any(getattr(gyro, name) for name in GYRO_TERMS)
                                  or any(getattr(accel, name) for name in ACCEL_TERMS) or data["faults"]["gyro_bias_steps"]):
        return "absent: the gyro errors and IMU noise are zero"
    return None


def budget_parts(scenario):
    """The parts of the budget of ``scenario``: each source alone under the scenario's own filter, then the
    total (every source); a part the scenario does not have is not run and says why (its ``reason``).
    An InputError when the scenario has no star sensor."""
    if "star_sensor" not in scenario.data:
        raise InputError(f"{scenario.source}: no [star_sensor] table: an error budget needs a star-aided INS (SINS/CNS)")
    sensor = scenario["star_sensor"]
    switchable = set(TRUTH_SOURCES) - ({"star_noise"} if sensor["fidelity"] == "image" else set())
    parts = []
    for source in SOURCES:
        reason = absent_reason(scenario, source.key)
        if reason is not None:
            parts.append(Part(source.key, source.label, None, None, reason, source.prediction, source.covariance))
            continue
        overrides = {"name": f"{scenario.name}.{source.key}"}
        for correction in CORRECTIONS:
            if correction is source or not correction.corrected(scenario):
                overrides[correction.correction] = correction is not source
        parts.append(Part(source.key, source.label, _variant(scenario, overrides), tuple(sorted(switchable - {source.key})),
                          None, source.prediction, source.covariance))
    parts.append(Part("total", "all sources", _variant(scenario, {"name": f"{scenario.name}.total"}), (), None,
                      TOTAL_PREDICTION))
    return tuple(parts)


def _variant(scenario, overrides):
    """``scenario`` with ``overrides`` applied, validated again."""
    return Scenario(data=validate(apply_overrides(scenario.data, overrides, scenario.source), scenario.source),
                    source=scenario.source, kind=scenario.kind)


def summarize_budget(scenario, directory, parts, runs, seed):
    """The budget (the content of budget.json) of ``scenario`` from its parts' campaigns in
    ``directory/parts/<key>/`` (:func:`budget_parts`, ``runs`` runs each with base seed ``seed``)."""
    rows = [{**_part(directory, p.key, p.label, p.reason, p.prediction),
             "truth_off": None if p.scenario is None else list(p.truth_off)} for p in parts if p.key != "total"]
    total = _part(directory, "total", "all sources", None, TOTAL_PREDICTION)
    corrected = {c.key: c.corrected(scenario) for c in CORRECTIONS}
    rss = _root_sum_square(rows, corrected, total)
    return {"format": FORMAT, "scenario": scenario.name, "source": scenario.source, "runs": runs, "base_seed": seed,
            "aberration_corrected": corrected["aberration"], "corrected": corrected, "parts": rows, "total": total,
            "root_sum_square": rss,
            "superposition": _superposition(rows, total, rss["parts"]), "in_every_part": _in_every_part(scenario)}


METRICS = ("schuler_mean_m", "final_m", "rms_m")


def _part(directory, key, label, reason, prediction):
    """A part's row: status, runs, the RMS over its runs of each metric and of the prediction."""
    row = {"key": key, "label": label, "status": "run" if reason is None else reason.split(":")[0], "note": reason}
    if reason is not None:
        return row
    paths = sorted((directory / "parts" / key / "runs").glob("run_*/summary.json"))
    summaries = [RunSummary.read(p) for p in paths]
    if not summaries:
        return {**row, "status": "failed", "note": f"failed: no run finished (parts/{key}/runs/*/error.json)"}
    horizontal = [s["position_error_m"]["horizontal"] for s in summaries]
    values = {"schuler_mean_m": [s.celestial["horizon_floor"]["position_error_mean_m"] for s in summaries],
              "final_m": [h["final"] for h in horizontal], "rms_m": [h["rms"] for h in horizontal]}
    vectors = [s.celestial["horizon_floor"]["position_error_mean_ne_m"] for s in summaries]
    if prediction is not None:
        values["prediction_m"] = [s.celestial[prediction[0]][prediction[1]] for s in summaries]
    row.update({"runs": len(summaries), **{name: _rms(v) for name, v in values.items()},
                "per_run": {"run": [int(p.parent.name.split("_")[1]) for p in paths], **values,
                            "schuler_mean_ne_m": vectors}})
    return row


def _rms(values):
    return float(np.sqrt(np.mean(np.square(values)))) if len(values) else None


def _in_every_part(scenario):
    """What no part switches off in the truth."""
    if scenario["star_sensor"]["fidelity"] == "image":
        return "the star noise (image fidelity: it comes from the pixels)"
    return "nothing"


def _root_sum_square(rows, corrected, total):
    """The RSS of the parts that were run, per metric, and its ratio to the total; a correction's part
    only when the scenario itself does not correct (``corrected``: {key: bool}; otherwise the total has it
    corrected and that part is the cost of not correcting)."""
    included = [r for r in rows if r["status"] == "run" and not corrected.get(r["key"], False)]
    rss = {m: float(np.sqrt(sum(r[m] ** 2 for r in included))) for m in METRICS}
    ratio = {m: rss[m] / total[m] if total.get(m) else None for m in METRICS}
    return {"parts": [r["key"] for r in included], **rss, "ratio_to_total": ratio}


def _superposition(rows, total, keys):
    """Per run, the total's Schuler-mean error vector (north, east) against the sum of the parts'
    (the same filter, the same draws: a linear system adds them up): the RMS over the runs of the
    total's and of the difference [m], and their ratio; None unless every part finished the same runs."""
    included = [r for r in rows if r["key"] in keys]
    runs = total.get("per_run", {}).get("run")
    if not runs or any(r["per_run"]["run"] != runs for r in included):
        return None
    parts_sum = np.sum([r["per_run"]["schuler_mean_ne_m"] for r in included], axis=0)
    whole = np.asarray(total["per_run"]["schuler_mean_ne_m"])
    residual = _rms(np.linalg.norm(whole - parts_sum, axis=1))
    size = _rms(np.linalg.norm(whole, axis=1))
    return {"total_m": size, "residual_m": residual, "relative": residual / size if size else None}


def budget_text(budget):
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
    ratio = rss["ratio_to_total"]
    lines.append(f"{'  its ratio to the total':<36} " + " ".join(f"{'-' if ratio[m] is None else f'{ratio[m]:.3f}':>{w}}"
                                                            for m, w in zip(METRICS, (12, 10, 10))))
    sup = budget["superposition"]
    if sup is not None:
        lines.append(f"superposition: per run, total minus the sum of the parts' Schuler-mean error vectors: RMS "
                     f"{sup['residual_m']:.2f} m against {sup['total_m']:.2f} m")
    lines.append(f"in every part: {budget['in_every_part']}")
    return lines
