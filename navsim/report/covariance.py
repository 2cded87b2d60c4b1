"""The PDFs of a covariance analysis (``navsim covariance --report``: each summary quantity's true RMS over time
beside the filter's σ, the table of the end values and the expected NEES) and of a trade sweep (``navsim
sweep``: the requirement chart — a line over one key, a heat map with the requirement's contour over two —
and the table of the points)."""

import tempfile
from pathlib import Path

import matplotlib
import numpy as np

from navsim.typeset import figures
from navsim.typeset.document import Document, markup, number, table


def covariance_report(summary, series) -> bytes:
    """The PDF (bytes) of a covariance analysis directory's ``summary.json`` and ``timeseries.npz``."""
    name = summary["scenario"]
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim covariance analysis: {name}", f"navsim covariance analysis · {name}")
        doc.title(f"Covariance analysis: {name}", summary["method"])
        nees = summary["nees_expected"]
        doc.paragraph(markup(
            "One pass along the scenario's nominal trajectory propagates the covariance of the truth's errors (every "
            "error source of the simulation, including those the filter does not model) under the filter's own gains, "
            "computed from its own model along the way: the true RMS of each error, beside the σ the filter believes. "
            f"The filter's expected NEES after settling is {number(nees['mean'])} for {nees['dof']} states (a consistent "
            "filter: equal to the states). Fixed truth errors are carried as a mean error beside the covariance (RMS "
            "= √(σ² + m²))." + "".join(f" {note}." for note in summary["notes"])))
        rows = [(q.replace("_", " "), number(v["final"], 4), number(v["filter_sigma_final"], 4),
                 number(v["true_over_filter_final"], 3), number(v["mean_final"], 4), number(v["rms"], 4), v["unit"])
                for q, v in summary["quantities"].items()]
        doc.add(table(("Quantity", "True RMS, end", "Filter σ, end", "True/filter", "Mean error, end", "RMS, steady",
                       "Unit"), rows))
        doc.figure(_quantities_figure(summary, series), "True RMS (solid) and the filter's σ (dashed) of each summary "
                                                         "quantity over time.")
        return doc.compile()


def _quantities_figure(summary, series):
    names = list(summary["quantities"])
    fig, axes = figures.new_figure(1.3 * len(names), len(names), 1)
    hours = series["t"] / 3600.0
    for ax, name in zip(axes[:, 0], names):
        ax.plot(hours, series[f"{name}_rms"], color="tab:blue", label="true RMS")
        ax.plot(hours, series[f"{name}_sigma_filter"], "--", color="tab:orange", label="filter σ")
        ax.set_ylabel(f"{name.replace('_', ' ')}\n[{summary['quantities'][name]['unit']}]")
    axes[0, 0].legend(loc="upper right")
    axes[-1, 0].set_xlabel("time [h]")
    return fig


def sweep_report(result) -> bytes:
    """The PDF (bytes) of a sweep's ``sweep.json``."""
    name, unit = result["scenario"], result["unit"]
    keys = [key for key, _ in result["vary"]]
    metric = result["metric"] + ("" if result["time_s"] is None else f" at {result['time_s']:g} s")
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim sweep: {name}", f"navsim sweep · {name}")
        doc.title(f"Trade sweep: {name}", result["source"])
        how = ("linear covariance analysis (the true RMS, one pass per point)" if result["method"] == "covariance"
               else f"Monte Carlo ({result['runs']} runs per point: the RMS over the runs)")
        requirement = result.get("requirement")
        doc.paragraph(markup(
            f"The {metric} [{unit}] over a grid of {', '.join(keys)}, by {how}."
            + ("" if requirement is None else f" The requirement is {requirement:g} {unit}: "
               f"{sum(p['value'] <= requirement for p in result['points'])} of {len(result['points'])} points meet it.")))
        chart = _sweep_figure(result)
        if chart is not None:
            doc.figure(chart, f"{metric} [{unit}]" + ("" if requirement is None else f"; the requirement {requirement:g} {unit} "
                                                                                  "drawn as a line or contour."))
        rows = [(*(str(v) for v in p["values"]), number(p["value"], 4), number(p.get("filter_sigma"), 4),
                 "" if requirement is None else ("yes" if p["value"] <= requirement else "no")) for p in result["points"]]
        doc.add(table((*keys, f"{result['metric']} [{unit}]", f"filter σ [{unit}]", "meets"), rows))
        return doc.compile()


def _sweep_figure(result):
    """A line over one key, a heat map with the requirement's contour over two, None over more."""
    vary, points, requirement = result["vary"], result["points"], result.get("requirement")
    if len(vary) > 2:
        return None
    values = np.array([p["value"] for p in points])
    if len(vary) == 1:
        fig, axes = figures.new_figure(2.8)
        ax = axes[0, 0]
        x = np.arange(len(vary[0][1]))
        ax.plot(x, values, "o-")
        ax.set_xticks(x, [str(v) for v in vary[0][1]])
        if requirement is not None:
            ax.axhline(requirement, color="tab:red", ls="--", label="requirement")
            ax.legend()
        ax.set(xlabel=vary[0][0], ylabel=f"{result['metric']} [{result['unit']}]")
        return fig
    (key_x, xs), (key_y, ys) = vary[1], vary[0]
    grid = values.reshape(len(ys), len(xs))
    fig, axes = figures.new_figure(3.6)
    ax = axes[0, 0]
    mesh = ax.pcolormesh(np.arange(len(xs)), np.arange(len(ys)), grid, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label=f"{result['metric']} [{result['unit']}]")
    if requirement is not None and grid.min() < requirement < grid.max() and min(grid.shape) > 1:
        ax.contour(np.arange(len(xs)), np.arange(len(ys)), grid, levels=[requirement], colors="white", linewidths=2)
    for (i, j), v in np.ndenumerate(grid):
        ax.text(j, i, f"{v:.4g}", ha="center", va="center", color="white", fontsize=6)
    ax.set_xticks(np.arange(len(xs)), [str(v) for v in xs])
    ax.set_yticks(np.arange(len(ys)), [str(v) for v in ys])
    ax.set(xlabel=key_x, ylabel=key_y)
    ax.grid(False)
    return fig
