"""The PDF of an error budget (``budget.json``: :mod:`navsim.campaign.budget`): by Monte Carlo (the star-aided
navigation kind's :mod:`navsim.navigation.budget`) which source leaves how many metres of horizontal position
error, as a table and a bar chart, with the total and the root-sum-square of the parts; by covariance analysis
(:func:`navsim.analysis.budget`) each source's share of every summary quantity, as a
table and its horizontal position error's shares stacked over time."""

import tempfile
from pathlib import Path

import matplotlib

from navsim.navigation import figures as nav_figures
from navsim.typeset import figures
from navsim.typeset.document import Document, markup, number, table

METRIC_LABELS = {"schuler_mean_m": "Schuler mean", "final_m": "final", "rms_m": "RMS"}


def budget_report(budget, series=None) -> bytes:
    """The PDF (bytes) of a budget (the dictionary of budget.json; a covariance budget's ``series`` its
    timeseries.npz)."""
    if budget.get("method") == "covariance":
        return covariance_budget_report(budget, series)
    name = budget["scenario"]
    rows = [*budget["parts"], budget["total"]]
    run = [r for r in rows if r["status"] == "run"]
    rss = budget["root_sum_square"]
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim error budget: {name}", f"navsim error budget · {name}")
        doc.title(f"Error budget: {name}", budget["source"])
        doc.paragraph(markup(
            f"Each source alone in the truth, every other switched off, under the scenario's own filter (the same "
            f"P0, Q, R and consider states in every part), over {budget['runs']} runs with the same seeds (base seed "
            f"{budget['base_seed']}: each source drawn from the same stream in every part); the figures are RMS over the "
            "runs of each run's Schuler-mean (the mean over the steady frames), final and RMS horizontal position error, "
            "in metres, beside the prediction of eq. (1) (R·∇/g, R times the deflection of the vertical) or of the "
            "aberration's horizontal part (R·r_h). Eq. (1) is taken with the true bias resolved in the navigation frame "
            "and averaged over the steady frames: with turns that mean shrinks (and the filter estimates ∇), while the "
            f"error keeps what the bias did before. In every part: {budget['in_every_part']}. The aberration part is the "
            "cost of not correcting the aberration: the filter without the correction on a truth with no other source"
            + (" (the scenario corrects it, so the total and the root-sum-square leave it out)."
               if budget["aberration_corrected"] else " (the scenario does not correct it: the other parts run with the "
               "correction and this part is one of the sources).")))
        total = budget["total"]
        ratio = rss["ratio_to_total"]
        sentence = (f"The total (all sources) has a Schuler-mean horizontal error of {number(total.get('schuler_mean_m'))} m "
                    f"and the root-sum-square of the parts ({', '.join(rss['parts'])}) is {number(rss['schuler_mean_m'])} m "
                    f"(ratio {_ratio(ratio['schuler_mean_m'])}); final {number(total.get('final_m'))} m against "
                    f"{number(rss['final_m'])} m (ratio {_ratio(ratio['final_m'])}), RMS {number(total.get('rms_m'))} m "
                    f"against {number(rss['rms_m'])} m (ratio {_ratio(ratio['rms_m'])}). With one filter the errors are "
                    "a linear system driven by the sources, so the parts add up: exactly as vectors in each run, and in "
                    "root-sum-square over the runs up to the runs' cross terms: sampling noise for the sources drawn per "
                    "run, shrinking as the runs grow, but sources the scenario fixes (a constant deflection, the given "
                    "mounting error) are the same vector in every run and add linearly among themselves.")
        sup = budget.get("superposition")
        if sup is not None:
            sentence += (f" Per run, the total's Schuler-mean error vector minus the sum of the parts' is {number(sup['residual_m'])} m "
                         f"RMS against {number(sup['total_m'])} m (what the filter's linearisation and gating leave).")
        doc.paragraph(markup(sentence))
        table_rows = [(r["label"], *(number(r[m]) for m in METRIC_LABELS),
                       "–" if r.get("prediction_m") is None else number(r["prediction_m"]))
                      if r["status"] == "run" else (r["label"], r["note"], "", "", "") for r in rows]
        table_rows.append(("root-sum-square of the parts", *(number(rss[m]) for m in METRIC_LABELS), ""))
        table_rows.append(("its ratio to the total", *(_ratio(ratio[m]) for m in METRIC_LABELS), ""))
        doc.add(table(("Source", "Schuler mean [m]", "Final [m]", "RMS [m]", "Predicted [m]"), table_rows,
                      ("left", "right", "right", "right", "right")))
        doc.figure(nav_figures.budget_bars([r["label"] for r in run], {label: [r[m] for r in run]
                                                                        for m, label in METRIC_LABELS.items()},
                                           [r.get("prediction_m") for r in run]),
                   "Horizontal position error each source leaves (RMS over the runs), with the predictions.")
        return doc.compile()


def _ratio(value):
    return "–" if value is None else f"{value:.3f}"


def covariance_budget_report(budget, series) -> bytes:
    """The PDF (bytes) of a covariance budget: its table per quantity and the stacked shares over time."""
    name = budget["scenario"]
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim error budget: {name}", f"navsim error budget · {name}")
        doc.title(f"Error budget: {name}", budget["source"])
        doc.paragraph(markup(
            "Linear covariance analysis along the scenario's nominal trajectory (one pass, nothing drawn): the truth's "
            "errors driven by each source alone under the scenario's own filter, whose gains come from its own model. "
            "For each source, the error it leaves alone (what runs with only that source in the truth average to) and "
            "its share of the total mean square, tr(J P_s Jᵀ) + (J m_s)·(J m): the variances of the sources add up, and "
            "the fixed errors (a given mounting, a constant deflection) add as vectors, so a share can be negative when "
            f"two fixed errors cancel. The shares add up to the total's square exactly. Steady: after {number(budget['settle_s'])} s."
            + "".join(f" {note}." for note in budget["notes"])))
        for quantity, q in budget["quantities"].items():
            rows = [(row["label"], number(row["alone_final"]), number(row["share_final"]), number(row["alone_rms"]),
                     number(row["share_steady"])) for row in q["sources"].values()]
            rows.append(("total", number(q["total_final"]), number(q["total_final"] ** 2), number(q["total_rms"]),
                         number(q["total_rms"] ** 2)))
            unit = q["unit"]
            doc.paragraph(markup(f"{quantity.replace('_', ' ').capitalize()} [{unit}]"))
            doc.add(table(("Source", f"Alone, end [{unit}]", f"Share, end [{unit}²]", f"Alone, steady RMS [{unit}]",
                           f"Share, steady [{unit}²]"), rows, ("left", "right", "right", "right", "right")))
        if "comparison" in budget:
            _comparison_table(doc, budget["comparison"], budget["headline"])
        if series is not None:
            labels = [budget["quantities"]["horizontal_position"]["sources"][key]["label"] for key in budget["sources"]]
            doc.figure(nav_figures.budget_shares(series["t"], series["horizontal_position_share"], labels),
                       "Shares of the horizontal position error's mean square over time, stacked; the top is the total.")
        return doc.compile()


def _comparison_table(doc, comparison, headline):
    """The covariance budget against a Monte Carlo one, part by part: the headline quantity's RMS at the end by
    each method with the runs' 95 % band, and how many RMS values of the part lie inside their bands."""
    doc.paragraph(markup(
        "Against the Monte Carlo budget of the same scenario: each part's runs (its source alone in the truth under "
        "the same filter) beside the analysis of that source alone; every summary quantity and filter state is checked "
        "at ten times against the 95 % sampling band of the runs' RMS (chi-square of the sample mean square), and "
        "against the family-wise band that holds all of a part's checks at once."))
    rows = []
    for part in comparison.values():
        final = part["quantities"][headline]["rows"][-1]
        rows.append((part["label"], str(part["runs"]), number(final["analysis"]), number(final["montecarlo"]),
                     f"{number(final['band'][0])} – {number(final['band'][1])}", f"{part['inside']} / {part['checks']}",
                     f"{part['inside_family']} / {part['checks']}"))
    unit = next(iter(comparison.values()))["quantities"][headline]["unit"]
    doc.add(table(("Part", "Runs", f"Analysis, end [{unit}]", f"Runs, end [{unit}]", "95 % band", "Inside 95 %",
                   "Inside family"), rows, ("left", "right", "right", "right", "right", "right", "right")))
