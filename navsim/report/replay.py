"""The PDF of a replay directory (``navsim replay --report``, ``navsim report DIR``): the horizontal error against the
held-out fixes along the drive with the outages shaded and the filter's σ beside it, and the table by outage."""

import tempfile
from pathlib import Path

import matplotlib
import numpy as np

from navsim.typeset import figures
from navsim.typeset.document import Document, markup, number, table


def replay_report(summary, series) -> bytes:
    """The PDF (bytes) of a replay's ``summary`` (summary.json) and ``series`` (timeseries.npz)."""
    name = summary["name"]
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim replay: {name}", f"navsim replay · {name}")
        doc.title(f"Replay: {name}", "a recorded IMU through the strapdown INS and the navigation filter")
        imu, updates, a = summary["imu"], summary["updates"], summary["alignment"]
        doc.paragraph(markup(
            f"{number(summary['duration_s'], 1)} s of the recording on an IMU interval of {number(1e3 * imu['interval_s'], 3)} ms "
            f"({imu['gaps']} gaps, {number(imu['gap_seconds'], 3)} s, {imu['filled_intervals']} intervals filled). Levelled "
            f"over the first {number(a['level_end_s'], 1)} s (roll {number(a['roll_deg'])} deg, pitch {number(a['pitch_deg'])} "
            f"deg), heading from the GNSS course at {number(a['heading_aligned_s'], 1)} s. Fixes: {updates['accepted']} "
            f"accepted, {updates['rejected']} rejected, {updates['held_out']} held out"
            + (" (a free INS: every fix after the alignment)." if summary["free_ins"] else " in the outages.")))
        if "star_sensor" in summary:
            doc.paragraph(markup(_star_sentence(summary["star_sensor"])))
        doc.figure(_figure(series, summary["outages"]), "Horizontal error of the solution before each update against the "
                   "fix [m] (log scale), the filter's horizontal 1σ dashed; the outages shaded.")
        rows = [(number(r["start_s"], 1), number(r["duration_s"], 1), str(r["fixes"]), number(r["max_horizontal_m"]),
                 number(r["rms_horizontal_m"]), number(r["end_horizontal_m"]), number(r["max_vertical_m"]),
                 number(r["sigma_horizontal_end_m"])) for r in summary["outages"]]
        doc.add(table(("Start [s]", "Length [s]", "Fixes", "Max horiz. [m]", "RMS horiz. [m]", "End horiz. [m]",
                       "Max vert. [m]", "Filter 1σ at end [m]"), rows))
        return doc.compile()


def _star_sentence(block):
    """The star sensor's sentence: its frames, their use and the heading error against the reference attitude."""
    used = (f"applied ({block['accepted']} accepted, {block['rejected']} rejected, NIS mean "
            f"{number(block['nis_mean'])} of 3 dof)" if block["applied"] else "drawn but not applied")
    return (f"A simulated star sensor from the reference attitude: {block['frames']} frames at {number(block['rate_hz'])} "
            f"Hz, {used}; the heading error against the reference RMS {number(block['heading_error_deg']['rms'], 4)} deg, "
            f"max {number(block['heading_error_deg']['max'], 4)} deg.")


def _figure(series, outages):
    fig, axes = figures.new_figure(3.2)
    ax = axes[0, 0]
    error = np.hypot(series["error_ned"][:, 0], series["error_ned"][:, 1])
    ax.semilogy(series["t"], np.maximum(error, 1e-4), color="k", lw=0.6, label="horizontal error")
    ax.semilogy(series["t"], np.hypot(series["sigma_ned"][:, 0], series["sigma_ned"][:, 1]), color="tab:blue", lw=0.8,
                ls="--", label="filter 1σ")
    for row in outages:
        ax.axvspan(row["start_s"], row["start_s"] + row["duration_s"], color="tab:orange", alpha=0.2, lw=0)
    ax.set(xlabel="time since the start [s]", ylabel="[m]")
    ax.legend(loc="upper left")
    return fig
