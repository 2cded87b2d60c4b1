"""Report sections every kind shares: the scenario's parameters, the comparison with the source
documents and its notes, the image-fidelity star sensor's modes, sub-catalog addresses and a rendered
frame, and a campaign's headline, settings, per-run metrics and aggregate."""

import numpy as np

from navsim.estimation.intervals import interval_text
from navsim.typeset import figures
from navsim.typeset import statistics as stats
from navsim.typeset.document import flatten, general, markup, number, short, table
from startrack import address


def scenario_section(doc, scenario):
    if not scenario:
        return
    doc.heading("Scenario parameters")
    doc.paragraph(markup("The validated scenario (scenario.json); units are in the key names. "
                         "Keys left empty take the values of the chosen presets and are not listed."))
    rows = [(k, general(v)) for k, v in flatten(scenario) if k != "description"]
    doc.add(table(("Parameter", "Value"), rows, ("left", "left")))


def sensor_section(doc, run):
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


def address_section(doc, run):
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


def frame_section(doc, run):
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


def notes_section(doc, summary):
    """The summary's notes on the comparison, then those on wall-clock figures."""
    notes, timed = _with_timing(summary, "notes")
    if not notes and not timed:
        return
    doc.heading("What the comparison shows")
    for note in [*notes, *timed]:
        doc.paragraph(markup(str(note)))


def campaign_headline(campaign, span):
    """The opening sentence of a campaign report: runs finished, failed and requested, backend, ``span``."""
    requested = campaign.campaign.get("runs")
    return (f"Campaign directory {campaign.directory}: {len(campaign.runs)} finished runs, {len(campaign.failed)} failed"
            + (f", {general(requested)} requested" if requested is not None else "")
            + (f"; backend {general(campaign.campaign['backend'])}" if "backend" in campaign.campaign else "")
            + f"; {span}.")


def nees_sentence(avg):
    """The key result of a campaign's run-averaged NEES (:class:`navsim.typeset.statistics.AveragedNees`): its mean
    with the 95 % interval of the mean and the frames inside the band."""
    return (f"The NEES averaged over the {avg.runs} runs has mean {number(avg.mean_after_settle)} after "
            f"{number(avg.settle_s, 1)} s (95 % interval of the mean {interval_text(avg.mean_interval)}, Student's t over "
            f"the runs' own means; expected {avg.dof}) and {number(100 * avg.fraction_in_band, 1)} % of those frames "
            f"lie inside the 95 % band [{number(avg.band[0])}, {number(avg.band[1])}] for {avg.runs} runs of {avg.dof} dof.")


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


def campaign_summary_section(doc, campaign, explanation):
    """The campaign's own aggregate (``explanation`` says what it holds), the comparison, notes, failed runs."""
    if campaign.summary:
        rows = [(k, short(general(v))) for k, v in flatten(campaign.summary.to_json())]
        if rows:
            doc.heading("Aggregate summary")
            doc.paragraph(markup(explanation))
            doc.add(table(("Key", "Value"), rows[:200], ("left", "left")))
        comparison_section(doc, campaign.summary)
        notes_section(doc, campaign.summary)
    if campaign.failed:
        doc.heading("Failed runs")
        doc.add(table(("Run", "Error"), [(f.name, short(f.message, 160)) for f in campaign.failed], ("left", "left")))
