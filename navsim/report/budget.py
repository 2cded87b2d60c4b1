"""The PDF of an error budget (``budget.json``: :mod:`navsim.campaign.budget`, the star-aided navigation
kind's :mod:`navsim.navigation.budget`): which source leaves how many metres of horizontal position
error, as a table and a bar chart, with the total and the root-sum-square of the parts."""

import tempfile
from pathlib import Path

import matplotlib

from navsim.navigation import figures as nav_figures
from navsim.typeset import figures
from navsim.typeset.document import Document, markup, number, table

METRIC_LABELS = {"schuler_mean_m": "Schuler mean", "final_m": "final", "rms_m": "RMS"}


def budget_report(budget) -> bytes:
    """The PDF (bytes) of a budget (the dictionary of budget.json)."""
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
