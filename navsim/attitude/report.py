"""The report of an attitude run or campaign: key results, the attitude and gyro-bias errors with the
filter's ±3σ, the gyro calibration states, consistency, the image-fidelity star sensor's sections and,
across a campaign, error envelopes, NEES over the runs, final errors and identification success.

Built with :mod:`navsim.typeset`; key numbers are written as plain text ("cross-boresight RMS 1.99
arcsec") so they can be extracted from the PDF.
"""

import tempfile
from pathlib import Path

import matplotlib

from navsim.attitude import figures as attitude_figures
from navsim.attitude.report_statistics import ATTITUDE, RUN_METRICS, envelopes
from navsim.typeset import figures
from navsim.typeset import statistics as stats
from navsim.typeset.document import Document, markup, number, scenario_name, table, xyz
from navsim.typeset.sections import (
    address_section,
    campaign_headline,
    campaign_summary_section,
    campaign_tables,
    comparison_section,
    frame_section,
    nees_sentence,
    notes_section,
    scenario_section,
    sensor_section,
)
from startrack import units

#: Arrays every attitude run must have, and those a campaign report reads from each run.
REQUIRED_SERIES = ("t", "attitude_error")
CAMPAIGN_SERIES = ("t", "attitude_error", "P_diag", "nees", "mode", "n_identified", "n_stacked", "n_accepted")


def run_report(run, kind_sections=None) -> bytes:
    """The PDF (bytes) of one run directory's report; ``kind_sections(doc, run)`` adds a kind's own sections after the
    key results (the spacecraft's orbit and heads)."""
    summary, s = run.summary, run.series
    name = scenario_name(summary, run.scenario, run.directory)
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim run report: {name}", f"navsim run · {name}")
        description = (run.scenario or {}).get("description", "")
        doc.title(f"Simulation run report: {name}", description or str(run.directory))
        doc.paragraph(markup(
            f"Run directory {run.directory}; seed {summary.get('seed', 'n/a')}; "
            f"{run.frames} star-sensor frames over {number(float(s['t'][-1]), 1)} s; fidelity "
            f"{summary.get('fidelity', 'n/a')}, measurement {summary.get('measurement', 'n/a')}."))
        _key_results(doc, run)
        if kind_sections is not None:
            kind_sections(doc, run)
        scenario_section(doc, run.scenario)
        _attitude_section(doc, run)
        _bias_section(doc, run)
        _calibration_section(doc, run.summary.get("gyro_calibration"))
        _consistency_section(doc, run)
        sensor_section(doc, run)
        address_section(doc, run)
        frame_section(doc, run)
        comparison_section(doc, summary)
        notes_section(doc, summary)
        _absent_section(doc, run)
        return doc.compile()


def _key_results(doc, run):
    summary = run.summary

    def get(*path):
        return stats.lookup(summary, path)

    doc.heading("Key results")
    sentences = []
    if get("cross_boresight_rms_arcsec") is not None:
        sentences.append(
            f"After the settling time of {number(get('settle_s'), 1)} s the cross-boresight attitude error RMS is "
            f"{number(get('cross_boresight_rms_arcsec'))} arcsec and the roll (about the boresight) error RMS "
            f"is {number(get('roll_rms_arcsec'))} arcsec.")
    rms = [get("attitude_error_rms_arcsec", axis) for axis in "xyz"]
    if any(v is not None for v in rms):
        sentences.append(f"Per body axis the RMS errors are {xyz(rms)} arcsec.")
    dof, band = summary["nees"]["dof"], summary["nees"]["band_95"]
    if get("nees", "mean") is not None:
        sentences.append(
            f"The NEES ({dof:g} dof) averages {number(get('nees', 'mean'))} and "
            f"{number(get('nees', 'fraction_in_band'), 1, 100)} % of the frames lie inside the 95 % "
            f"chi-square band [{number(band[0])}, {number(band[1])}].")
    if get("nis", "mean_per_dof") is not None:
        sentences.append(f"The NIS per degree of freedom averages {number(get('nis', 'mean_per_dof'), 3)} "
                         "(expected 1).")
    if get("updates", "measurements") is not None:
        sentences.append(f"The gate accepted {number(get('updates', 'accepted'), 0)} of "
                         f"{number(get('updates', 'measurements'), 0)} star measurements in "
                         f"{number(get('updates', 'frames_with_measurements'), 0)} frames.")
    doc.paragraph(*(markup(x) for x in sentences))
    quantities = [  # (label, value or per-axis values, unit, decimals)
        ("cross-boresight RMS", get("cross_boresight_rms_arcsec"), "arcsec", 2),
        ("roll RMS", get("roll_rms_arcsec"), "arcsec", 2),
        *((f"RMS error {axis}", v, "arcsec", 2) for axis, v in zip("xyz", rms)),
        ("final filter 1σ", [get("attitude_sigma_final_arcsec", i) for i in range(3)], "arcsec", 2),
        ("final bias error", [get("bias_error_final_deg_per_h", i) for i in range(3)], "deg/h", 4),
        ("NEES mean", get("nees", "mean"), f"{dof:g} dof", 2),
        ("NEES inside 95 % band", None if get("nees", "fraction_in_band") is None
         else 100 * get("nees", "fraction_in_band"), "%", 1),
        ("NIS mean per dof", get("nis", "mean_per_dof"), "", 3),
        ("wall time", get("timing", "wall_seconds"), "s", 2),
    ]
    rows = [(label, xyz(v, digits) if isinstance(v, list) else number(v, digits), unit)
            for label, v, unit, digits in quantities
            if (any(x is not None for x in v) if isinstance(v, list) else v is not None)]
    if rows:
        doc.add(table(("Quantity", "Value", "Unit"), rows, ("left", "right", "left")))


def _attitude_section(doc, run):
    doc.heading("Attitude estimation error")
    s = run.series
    err = units.rad_to_arcsec(s["attitude_error"])
    peak = [float(abs(err[:, i]).max()) for i in range(3)]
    text = ("The error δθ is the small rotation from the estimate to the truth in body axes "
            f"(q_true = q_est ⊗ δq(δθ)). Peak |δθ| over the run: {xyz(peak)} arcsec.")
    if "P_diag" in s:
        final = 3.0 * units.rad_to_arcsec(s["P_diag"][-1, ATTITUDE] ** 0.5)
        text += f" The dashed lines are the filter's ±3σ; at the end of the run 3σ is {xyz(final)} arcsec."
    doc.paragraph(markup(text))
    doc.figure(attitude_figures.attitude_error(run), "Attitude estimation error per body axis with the filter's ±3σ bounds "
                                            "(y axis scaled to the run after its first 10 %).")


def _bias_section(doc, run):
    fig = attitude_figures.gyro_bias(run)
    if fig is None:
        return
    doc.heading("Gyro bias estimate")
    bias = run.summary.get("bias_error_final_deg_per_h")
    if isinstance(bias, list) and len(bias) == 3:
        doc.paragraph(markup(f"Final bias estimation error (truth minus estimate): {xyz(bias, 4)} deg/h."))
    doc.figure(fig, "Gyro bias: truth (black) and the filter's estimate with its ±3σ band, deg/h.")


def _calibration_section(doc, calibration):
    """The gyro calibration states at the end of the run: truth, estimate, σ and the normalised error."""
    if not calibration:
        return
    doc.heading("Gyro calibration states")
    axes = {"scale_factor_ppm": ("scale factor", ("x", "y", "z"), "ppm"),
            "misalignment_arcsec": ("misalignment", ("xy", "xz", "yx", "yz", "zx", "zy"), "arcsec")}
    rows = []
    for key, (label, names, unit) in axes.items():
        if key in calibration:
            c = calibration[key]
            rows += [(f"{label} {axis}", unit, number(t, 1), number(e, 1), number(sig, 1), number(z, 2))
                     for axis, t, e, sig, z in zip(names, c["true"], c["estimate"], c["sigma"], c["normalised_error"])]
    doc.paragraph(markup("The gyro error matrix K of the measured rate (I + K) ω + b (scale factors on its diagonal, axis "
                         "misalignments off it) at the end of the run: a term the motion made observable has a σ "
                         "well below its datasheet prior; the normalised error (estimate − truth)/σ of a consistent "
                         "filter lies within ±3."))
    doc.add(table(("State", "Unit", "Truth", "Estimate", "1σ", "Normalised error"), rows,
                  ("left", "left", "right", "right", "right", "right")))


def _consistency_section(doc, run):
    fig = figures.consistency(run)
    if fig is None:
        return
    doc.heading("Filter consistency")
    doc.paragraph(markup(
        "For a consistent filter the NEES of the attitude and bias errors follows a chi-square law with 6 degrees "
        "of freedom and the NIS of each update a chi-square law with 2 degrees of freedom per accepted star; the "
        "shaded bands are the two-sided 95 % intervals (the NIS band varies with the number of stars)."))
    doc.figure(fig, "NEES and NIS per degree of freedom (log scale) with their 95 % chi-square bands.")


ABSENT = (
    (("mode",), "sensor modes"),
    (("n_detected", "n_identified", "n_stacked"), "detected, identified and stacked star counts"),
    (("id_ms",), "identification times"),
    (("boresight_radec",), "boresight track and sub-catalog addresses"),
    (("bias_true", "bias_est"), "gyro bias truth and estimate"),
    (("nees", "nis"), "NEES and NIS"),
)


def _absent_section(doc, run):
    missing = [label for keys, label in ABSENT if not any(k in run.series for k in keys)]
    if run.frame is None:
        missing.append("a rendered frame")
    if missing:
        doc.heading("Not logged in this run")
        doc.paragraph(markup("This run did not log " + "; ".join(missing)
                             + " (vector-fidelity runs log no image-chain quantities), so those figures are omitted."))


def campaign_report(campaign, kind_sections=None) -> bytes:
    """The PDF (bytes) of a Monte Carlo campaign directory's report; ``kind_sections(doc, campaign)`` adds a kind's
    own sections after the tables."""
    name = campaign.campaign.get("scenario")
    if not isinstance(name, str) or not name:
        name = scenario_name(campaign.runs[0].summary, campaign.scenario, campaign.directory)
    env = envelopes(campaign)
    avg = stats.averaged_nees(campaign)
    success, criterion = stats.identification_success(campaign)
    metrics = stats.metric_table(campaign, RUN_METRICS)
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim Monte Carlo report: {name}", f"navsim Monte Carlo · {name}")
        doc.title(f"Monte Carlo campaign report: {name}", str(campaign.directory))
        doc.paragraph(markup(campaign_headline(campaign, f"{env.t.size} frames per run over {number(float(env.t[-1]), 1)} s")))
        doc.heading("Key results")
        doc.paragraph(*(markup(x) for x in _campaign_sentences(env, avg, metrics, success, criterion)))
        campaign_tables(doc, campaign, metrics)
        if kind_sections is not None:
            kind_sections(doc, campaign)
        _campaign_figures(doc, env, avg, len(campaign.runs))
        if success:
            doc.heading("Identification success per mode")
            doc.paragraph(markup(f"Success counts {criterion}, pooled over all runs."))
            doc.add(table(("Mode", "Frames", "Identified", "Success [%]"),
                          [(r.name, str(r.frames), str(r.identified), number(100 * r.fraction, 1)) for r in success]))
            doc.figure(figures.identification_success(success, criterion), "Identification success per mode.")
        campaign_summary_section(doc, campaign, "The campaign's own aggregate (summary.json), as written by the campaign runner.")
        return doc.compile()


def _campaign_sentences(env, avg, metrics, success, criterion):
    """The key results of an attitude campaign, one sentence each."""
    sentences = []
    by_label = {r.label: r for r in metrics}
    if "cross-boresight RMS" in by_label:
        r = by_label["cross-boresight RMS"]
        sentences.append(f"Across the {r.runs} runs the cross-boresight RMS error is {number(r.mean)} arcsec on "
                         f"average (σ {number(r.std)}, median {number(r.median)}, 95th percentile "
                         f"{number(r.p95)}, worst {number(r.maximum)} arcsec).")
    if "roll RMS" in by_label:
        r = by_label["roll RMS"]
        sentences.append(f"The roll RMS error is {number(r.mean)} arcsec on average (worst {number(r.maximum)}).")
    final_rms = (env.final**2).mean(axis=0) ** 0.5
    sentences.append(f"The RMS over runs of the final error is {xyz(final_rms)} arcsec"
                     + (f" against a mean filter 1σ of {xyz(env.final_sigma_filter)} arcsec."
                        if env.final_sigma_filter is not None else "."))
    if avg is not None:
        sentences.append(nees_sentence(avg))
    if success:
        sentences.append(f"Success ({criterion}): " + "; ".join(
            f"{r.name} {number(100 * r.fraction, 1)} % ({r.identified} of {r.frames} frames)" for r in success) + ".")
    return sentences


def _campaign_figures(doc, env, avg, m):
    """Attitude error envelopes, NEES over the runs and the final errors against the filter's σ."""
    doc.heading("Attitude error envelopes")
    doc.paragraph(markup(
        "At each frame: the mean of the error over the runs with ± one run-to-run standard deviation, the "
        "5-95 % percentile envelope, the RMS over runs, and the filter's ±3σ from the covariance averaged over "
        "the runs. A consistent filter keeps the RMS curve near one third of the dashed bound."))
    doc.figure(figures.error_envelopes(env), f"Attitude error envelopes over {m} runs per body axis, arcsec.")
    if avg is not None:
        doc.heading("Filter consistency over runs")
        doc.paragraph(markup(
            f"The average of M independent NEES values times M follows a chi-square law with M n degrees of "
            f"freedom; with M = {avg.runs} and n = {avg.dof} the 95 % band of the average is "
            f"[{number(avg.band[0])}, {number(avg.band[1])}]."))
        doc.figure(figures.nees_band(avg), "NEES averaged over the runs with the 95 % chi-square band for M runs.")
    doc.heading("Final errors")
    final_rms = (env.final**2).mean(axis=0) ** 0.5
    sigma = env.final_sigma_filter
    rows = [(a, number(float(final_rms[i])), number(float(sigma[i])) if sigma is not None else "n/a",
             number(float(final_rms[i] / sigma[i])) if sigma is not None else "n/a") for i, a in enumerate("xyz")]
    doc.add(table(("Axis", "RMS of final error [arcsec]", "filter σ [arcsec]", "ratio"), rows))
    doc.figure(attitude_figures.final_error_histogram(env),
               "Histogram of the final attitude error over the runs with the normal law of the filter's σ.")
