"""Typeset the report: Typst source (text, tables, SVG figures) compiled to PDF by the ``typst``
package (the Typst compiler with its bundled fonts; no network, no system fonts).

Every string that comes from the data (scenario text, keys, error messages, numbers) enters the
Typst source either escaped for markup (:func:`markup`) or as a string literal (:func:`literal`),
so nothing in a run directory can change the document's structure. Key numbers are written as
plain text ("cross-boresight RMS 1.99 arcsec") so they can be extracted from the PDF.
"""

import math
import tempfile
from pathlib import Path

import matplotlib
import numpy as np
import typst

from navsim.report import figures
from navsim.report import statistics as stats
from navsim.studies import STUDIES
from startrack import address, units

PREAMBLE = """\
#set document(title: {title}, author: "navsim", date: none)
#set page(paper: "a4", margin: (x: 2cm, y: 2.2cm), numbering: "1 / 1",
  header: align(right, text(size: 8pt, fill: luma(90), {header})))
#set text(size: 10pt, lang: "en")
#set par(justify: true)
#set heading(numbering: "1.")
#show heading.where(level: 1): set block(above: 1.4em, below: 0.8em)
#show table: set text(size: 8pt)
#show figure.caption: set text(size: 9pt)
#set table(stroke: (x, y) => if y == 0 {{ (bottom: 0.7pt) }} else {{ (bottom: 0.2pt + luma(200)) }},
  inset: (x: 4pt, y: 3pt))
"""


def literal(value) -> str:
    """A Typst string literal holding ``value`` verbatim."""
    text = str(value).replace("\\", "\\\\").replace('"', '\\"')
    text = text.replace("\r", " ").replace("\n", " ").replace("\t", " ")
    return '"' + text + '"'


def markup(value) -> str:
    """``value`` as Typst markup that shows it verbatim (ASCII punctuation backslash-escaped)."""
    out = []
    for ch in " ".join(str(value).split()):
        out.append("\\" + ch if ch.isascii() and not ch.isalnum() and ch != " " else ch)
    return "".join(out)


def number(x, digits=2, scale=1.0) -> str:
    """Fixed-point text of ``scale * x`` (``digits`` decimals); 'n/a' for anything not a finite number."""
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        return "n/a"
    return f"{scale * x:.{digits}f}"


def xyz(values, digits=2) -> str:
    """'x a, y b, z c' for three per-axis values."""
    return ", ".join(f"{axis} {number(None if v is None else float(v), digits)}" for axis, v in zip("xyz", values))


def general(x) -> str:
    """A JSON value as table text: numbers to 6 significant digits, lists in brackets, booleans, text."""
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        return f"{x:.6g}"
    if isinstance(x, list):
        return "[" + ", ".join(general(v) for v in x) + "]"
    return str(x)


def flatten(tree, prefix=""):
    """(dotted key, value) pairs of the scalar and list leaves of nested dictionaries, nulls left out."""
    rows = []
    for key in sorted(tree) if isinstance(tree, dict) else []:
        value = tree[key]
        path = f"{prefix}{key}"
        if isinstance(value, dict):
            rows.extend(flatten(value, path + "."))
        elif isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
            continue
        elif value is not None:
            rows.append((path, value))
    return rows


def table(header, rows, align=None) -> str:
    """A Typst table with a bold header row; every cell a string literal."""
    columns = len(header)
    align = align or ("left",) + ("right",) * (columns - 1)
    cells = ", ".join(f"[*{markup(h)}*]" for h in header)
    body = ",\n  ".join(", ".join(literal(c) for c in row) for row in rows)
    return (f"#table(columns: {columns}, align: ({', '.join(align)},),\n"
            f"  table.header({cells}),\n  {body}\n)\n")


class Document:
    """Typst source under construction plus the figure files it refers to (in one directory)."""

    def __init__(self, workdir: Path, title: str, header: str):
        self.workdir = workdir
        self.parts = [PREAMBLE.format(title=literal(title), header=literal(header))]
        self.lead = []  # paragraphs kept on the page of the figure that follows them
        self.count = 0

    def add(self, source: str):
        self.parts.extend(self.lead)
        self.lead = []
        self.parts.append(source)

    def title(self, title, subtitle):
        self.add(f"#align(center, text(size: 17pt, weight: \"bold\", {literal(title)}))\n"
                 f"#align(center, text(size: 10pt, fill: luma(60), {literal(subtitle)}))\n#v(1em)\n")

    def heading(self, text):
        self.add(f"\n= {markup(text)}\n")

    def paragraph(self, *sentences):
        """Sentences are markup already (build them with :func:`markup` and :func:`number`)."""
        self.lead.append(" ".join(s for s in sentences if s) + "\n\n")

    def figure(self, fig, caption):
        """Save ``fig`` as SVG beside the source and place it with the paragraphs just before it, on one page;
        a None figure adds nothing."""
        if fig is None:
            return
        self.count += 1
        name = f"figure_{self.count:02d}.svg"
        figures.save(fig, self.workdir / name)
        lead, self.lead = "".join(self.lead), []
        self.add(f"#block(breakable: false, width: 100%)[\n{lead}"
                 f"#figure(image({literal(name)}, width: 100%), caption: [{markup(caption)}])\n]\n")

    def source(self) -> str:
        return "".join(self.parts + self.lead)

    def compile(self) -> bytes:
        path = self.workdir / "report.typ"
        path.write_text(self.source(), encoding="utf-8")
        return typst.compile(str(path), root=str(self.workdir), ignore_system_fonts=True)


def scenario_name(summary, scenario, directory):
    for name in ((summary or {}).get("scenario"), (scenario or {}).get("name")):
        if isinstance(name, str) and name:
            return name
    return directory.name


# ------------------------------------------------------------------------------- one run


def run_report(run) -> bytes:
    """The PDF (bytes) of one run directory's report."""
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
        scenario_section(doc, run.scenario)
        _attitude_section(doc, run)
        _bias_section(doc, run)
        _calibration_section(doc, run.summary.get("gyro_calibration"))
        _consistency_section(doc, run)
        _sensor_section(doc, run)
        _address_section(doc, run)
        _frame_section(doc, run)
        comparison_section(doc, summary)
        _notes_section(doc, summary)
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


def scenario_section(doc, scenario):
    if not scenario:
        return
    doc.heading("Scenario parameters")
    doc.paragraph(markup("The validated scenario (scenario.json); units are in the key names. "
                         "Keys left empty take the values of the chosen presets and are not listed."))
    rows = [(k, general(v)) for k, v in flatten(scenario) if k != "description"]
    doc.add(table(("Parameter", "Value"), rows, ("left", "left")))


def _attitude_section(doc, run):
    doc.heading("Attitude estimation error")
    s = run.series
    err = units.rad_to_arcsec(s["attitude_error"])
    peak = [float(abs(err[:, i]).max()) for i in range(3)]
    text = ("The error δθ is the small rotation from the estimate to the truth in body axes "
            f"(q_true = q_est ⊗ δq(δθ)). Peak |δθ| over the run: {xyz(peak)} arcsec.")
    if "P_diag" in s:
        final = 3.0 * units.rad_to_arcsec(s["P_diag"][-1, stats.ATTITUDE] ** 0.5)
        text += f" The dashed lines are the filter's ±3σ; at the end of the run 3σ is {xyz(final)} arcsec."
    doc.paragraph(markup(text))
    doc.figure(figures.attitude_error(run), "Attitude estimation error per body axis with the filter's ±3σ bounds "
                                            "(y axis scaled to the run after its first 10 %).")


def _bias_section(doc, run):
    fig = figures.gyro_bias(run)
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


def _sensor_section(doc, run):
    s = run.series
    rows = stats.mode_table(run)
    counts = figures.star_counts(run)
    timeline = figures.mode_timeline(run)
    timing = figures.identification_time(run)
    if not (rows or counts or timeline or timing):
        return
    doc.heading("Star sensor: modes, stars and identification time")
    sentences = []
    if "mode" in s:
        transitions = int((s["mode"][1:] != s["mode"][:-1]).sum())
        sentences.append(f"The sensor changed mode {transitions} times.")
    for key, label in (("n_detected", "detected"), ("n_identified", "identified"), ("n_stacked", "stacked")):
        if key in s:
            sentences.append(f"Mean stars {label} per frame: {number(float(s[key].mean()))}.")
    if "n_accepted" in s:
        sentences.append(f"Frames with at least one accepted measurement: "
                         f"{number(100 * float((s['n_accepted'] > 0).mean()), 1)} %.")
    doc.paragraph(markup(" ".join(sentences)))
    if rows:
        doc.add(table(
            ("Mode", "Frames", "Time [%]", "Identified (mean)", "id ms median", "id ms 95 %", "id ms max"),
            [(r.name, str(r.frames), number(100 * r.fraction, 1), number(r.identified_mean),
              number(r.id_ms_median, 3), number(r.id_ms_p95, 3), number(r.id_ms_max, 3)) for r in rows]))
    doc.figure(timeline, "Sensor mode timeline.")
    doc.figure(counts, "Stars per frame.")
    doc.figure(timing, "Identification time per mode (box: quartiles and median; whiskers: 5 % and 95 %).")


def _address_section(doc, run):
    n_d = stats.declination_divisions(run)
    fig = figures.boresight_track(run, n_d)
    if fig is None:
        return
    doc.heading("Boresight track and sub-catalog addresses")
    if n_d is None:
        doc.paragraph(markup("The run names no base-point grid (no n_d) and logs no sub-catalog addresses, "
                             "so the boresight track is drawn without the grid."))
        doc.figure(fig, "Boresight track (left: whole sky; right: the track).")
        return
    index = stats.sub_catalog_indices(run.series, n_d)
    doc.paragraph(markup(
        f"The predicted boresight is addressed on the base-point grid of n_d = {n_d} declination divisions "
        f"({address.base_point_count(n_d)} base points; eq. 1-2 and 7-8 of document 000) at every frame. "
        f"The run used {np.unique(index).size} distinct sub-catalogs and changed address "
        f"{int(np.count_nonzero(index[1:] != index[:-1]))} times."))
    doc.figure(fig, "Boresight track over the base-point grid (left: whole sky; right: the track with the "
                    "addresses (l_d, l_ra) of the sub-catalogs used).")


def _frame_section(doc, run):
    fig = figures.rendered_frame(run)
    if fig is None:
        return
    doc.heading("A rendered frame")
    h, w = run.frame.shape
    det = run.detections or []
    identified = sum(1 for d in det if d[2] is not None)
    doc.paragraph(markup(f"One {w} x {h} frame as rendered and processed: {len(det)} detections, "
                         f"{identified} identified (green, labelled with their Hipparcos numbers), "
                         f"{len(det) - identified} not identified (red)."))
    doc.figure(fig, "Rendered frame (asinh stretch of the brightness above the median) with detections and "
                    "identifications.")


def _with_timing(summary, key):
    """(the summary's ``key`` list, the same list of its wall-clock ``timing``) for a section."""
    rows = summary.get(key) if isinstance(summary.get(key), list) else []
    timing = summary.get("timing") if isinstance(summary.get("timing"), dict) else {}
    return rows, timing.get(key) if isinstance(timing.get(key), list) else []


def comparison_section(doc, summary):
    """The summary's comparison with the source documents; rows of wall-clock figures marked as such."""
    comparison, timed = _with_timing(summary, "paper_comparison")
    rows = [tuple(general(row.get(k, "")) for k in ("quantity", "ours", "paper", "source"))
            for row in [*comparison, *timed] if isinstance(row, dict)]
    if not rows:
        return
    doc.heading("Comparison with the source documents")
    doc.paragraph(markup("Our figures beside those reported in the source documents"
                         + (f"; the last {len(timed)} rows are times measured on this machine." if timed else ".")))
    doc.add(table(("Quantity", "Ours", "Source document", "Source"), rows, ("left", "right", "right", "left")))


def _notes_section(doc, summary):
    """The summary's notes on the comparison, then those on wall-clock figures."""
    notes, timed = _with_timing(summary, "notes")
    if not notes and not timed:
        return
    doc.heading("What the comparison shows")
    for note in [*notes, *timed]:
        doc.paragraph(markup(str(note)))


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


# -------------------------------------------------------------------------- static studies


def study_report(study) -> bytes:
    """The PDF (bytes) of a static study's directory: key results, parameters, our figures beside the
    source document's, the explanation of every difference, and the study's figures."""
    summary = study.summary
    kind = summary["study"]
    module = STUDIES[kind]
    parameters = study.scenario["study"][kind]
    name = scenario_name(summary, study.scenario, study.directory)
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim study report: {name}", f"navsim study · {name}")
        doc.title(f"Static study report: {name}", study.scenario.get("description") or str(study.directory))
        doc.paragraph(markup(f"Study directory {study.directory}; kind {kind}; seed {summary.get('seed', 'n/a')}; "
                             f"wall time {number(summary.get('wall_seconds'), 1)} s."))
        doc.heading("Key results")
        doc.add(table(("Quantity", "Value", "Unit"), module.key_results(summary, parameters), ("left", "right", "left")))
        scenario_section(doc, study.scenario)
        comparison_section(doc, summary)
        _notes_section(doc, summary)
        doc.heading("Figures")
        for fig, caption in module.figures(summary, study.arrays, parameters):
            doc.figure(fig, caption)
        return doc.compile()


# ----------------------------------------------------------------------------- campaigns


def campaign_report(campaign) -> bytes:
    """The PDF (bytes) of a Monte Carlo campaign directory's report."""
    name = campaign.campaign.get("scenario")
    if not isinstance(name, str) or not name:
        name = scenario_name(campaign.runs[0].summary, campaign.scenario, campaign.directory)
    env = stats.envelopes(campaign)
    avg = stats.averaged_nees(campaign)
    success, criterion = stats.identification_success(campaign)
    metrics = stats.metric_table(campaign)
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim Monte Carlo report: {name}", f"navsim Monte Carlo · {name}")
        doc.title(f"Monte Carlo campaign report: {name}", str(campaign.directory))
        doc.paragraph(markup(campaign_headline(campaign, f"{env.t.size} frames per run over {number(float(env.t[-1]), 1)} s")))
        doc.heading("Key results")
        doc.paragraph(*(markup(x) for x in _campaign_sentences(env, avg, metrics, success, criterion)))
        campaign_tables(doc, campaign, metrics)
        _campaign_figures(doc, env, avg, len(campaign.runs))
        if success:
            doc.heading("Identification success per mode")
            doc.paragraph(markup(f"Success counts {criterion}, pooled over all runs."))
            doc.add(table(("Mode", "Frames", "Identified", "Success [%]"),
                          [(r.name, str(r.frames), str(r.identified), number(100 * r.fraction, 1)) for r in success]))
            doc.figure(figures.identification_success(success, criterion), "Identification success per mode.")
        campaign_summary_section(doc, campaign, "The campaign's own aggregate (summary.json), as written by the campaign runner.")
        return doc.compile()


def campaign_headline(campaign, span):
    """The opening sentence of a campaign report: runs finished, failed and requested, backend, ``span``."""
    requested = campaign.campaign.get("runs")
    return (f"Campaign directory {campaign.directory}: {len(campaign.runs)} finished runs, {len(campaign.failed)} failed"
            + (f", {general(requested)} requested" if requested is not None else "")
            + (f"; backend {general(campaign.campaign['backend'])}" if "backend" in campaign.campaign else "")
            + f"; {span}.")


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
        sentences.append(f"The NEES averaged over the {avg.runs} runs has mean {number(avg.mean_after_settle)} "
                         f"after {number(avg.settle_s, 1)} s and {number(100 * avg.fraction_in_band, 1)} % of "
                         f"those frames lie inside the 95 % band [{number(avg.band[0])}, {number(avg.band[1])}] "
                         f"for {avg.runs} runs of {avg.dof} dof.")
    if success:
        sentences.append(f"Success ({criterion}): " + "; ".join(
            f"{r.name} {number(100 * r.fraction, 1)} % ({r.identified} of {r.frames} frames)" for r in success) + ".")
    return sentences


def campaign_tables(doc, campaign, metrics):
    """The campaign's settings, its scenario and the per-run metrics' distribution over the runs."""
    doc.heading("Campaign")
    settings = {k: v for k, v in campaign.campaign.items() if not isinstance(v, dict)}  # scenario: next section
    doc.add(table(("Setting", "Value"), [(k, short(general(v))) for k, v in flatten(settings)], ("left", "left")))
    scenario_section(doc, campaign.scenario)
    doc.heading("Statistics across runs")
    doc.paragraph(markup("Per-run metrics from each run's summary.json (after its settling time), "
                         "with their distribution over the finished runs."))
    if metrics:
        doc.add(table(("Metric", "Unit", "Runs", "Mean", "σ", "Median", "95 %", "Max"),
                      [(r.label, r.unit, str(r.runs), number(r.mean, 3), number(r.std, 3), number(r.median, 3),
                        number(r.p95, 3), number(r.maximum, 3)) for r in metrics],
                      ("left", "left", "right", "right", "right", "right", "right", "right")))


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
    doc.figure(figures.final_error_histogram(env),
               "Histogram of the final attitude error over the runs with the normal law of the filter's σ.")


def campaign_summary_section(doc, campaign, explanation):
    """The campaign's own aggregate (``explanation`` says what it holds), the comparison, notes, failed runs."""
    if campaign.summary:
        rows = [(k, short(general(v))) for k, v in flatten(campaign.summary.to_json())]
        if rows:
            doc.heading("Aggregate summary")
            doc.paragraph(markup(explanation))
            doc.add(table(("Key", "Value"), rows[:200], ("left", "left")))
        comparison_section(doc, campaign.summary)
        _notes_section(doc, campaign.summary)
    if campaign.failed:
        doc.heading("Failed runs")
        doc.add(table(("Run", "Error"), [(f.name, short(f.message, 160)) for f in campaign.failed], ("left", "left")))


def short(text, limit=90):
    return text if len(text) <= limit else text[: limit - 3] + "..."
