"""The PDF of ``navsim sky --report``: a scenario's star availability along its trajectory (the Sun, the Moon,
the sky's brightness and limiting magnitude at the boresight, the stars each frame shows) without a filter."""

import tempfile
from pathlib import Path

import matplotlib
import numpy as np

from navsim.typeset import figures
from navsim.typeset.document import Document, markup, number, table


def sky_report(availability) -> bytes:
    """The PDF (bytes) of a :class:`navsim.navigation.availability.Availability`."""
    summary, series = availability.summary, availability.series
    name = summary["scenario"]
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim sky: {name}", f"navsim sky · {name}")
        doc.title(f"Star availability: {name}", f"band {summary['band']}")
        per_frame = summary["stars_per_frame"]
        budget = ("The sensor's light budget decides which stars each frame shows: the sky's brightness in its band "
                  "(night sky, moonlight, twilight, daylight) at the boresight, each star's extinction along its line "
                  "of sight and the detector's noise, with the detection threshold of its image chain."
                  if summary["light_budget"] else
                  "The sensor has no light budget: every catalog star in its field counts, day or night.")
        excluded = ", ".join(f"{count} ({reason})" for reason, count in summary["frames_excluded"].items() if count) or "none"
        doc.paragraph(markup(
            f"Along the scenario's nominal trajectory, without a filter: stars in {number(summary['hours_with_stars'])} of "
            f"{number(summary['hours'])} h ({number(100 * summary['fraction_with_stars'])} % of {summary['frames']} frames), "
            f"{number(per_frame['mean'])} per frame on average (at most {per_frame['max']}). {budget} Frames excluded: "
            f"{excluded}." + "".join(f" {n}." for n in summary["notes"])))
        doc.figure(_figure(series), "Top: the elevations of the Sun, the Moon and the boresight [deg]. Middle: the sky's "
                                    "brightness at the boresight [mag/arcsec²] and the limiting magnitude there (none "
                                    "while the sky fills the detector's well). Bottom: stars per frame.")
        rows = [(f"{r['hour']:.0f}", number(r["sun_elevation_deg"]), number(r["moon_elevation_deg"]),
                 number(r["sky_mag"]), number(r["limiting_mag"]), number(r["stars_mean"]),
                 number(100 * r["fraction_with_stars"])) for r in summary["hourly"]]
        doc.add(table(("Hour", "Sun el. [deg]", "Moon el. [deg]", "Sky [mag/arcsec²]", "Limiting mag", "Stars/frame",
                       "Frames with stars [%]"), rows))
        return doc.compile()


def _figure(series):
    hours = series["t"] / 3600.0
    fig, axes = figures.new_figure(6.0, 3, 1)
    ax = axes[0, 0]
    for key, label, color in (("sun_elevation", "Sun", "tab:orange"), ("moon_elevation", "Moon", "tab:blue"),
                              ("boresight_elevation", "boresight", "k")):
        ax.plot(hours, np.degrees(series[key]), color=color, lw=0.9, label=label)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set(ylabel="elevation [deg]")
    ax.legend(loc="upper right", ncols=3)
    ax = axes[1, 0]
    if "sky_background_mag" in series:
        ax.plot(hours, series["sky_background_mag"], color="tab:blue", lw=0.9, label="sky [mag/arcsec²]")
        ax.plot(hours, np.where(np.isfinite(series["limiting_mag"]), series["limiting_mag"], np.nan), color="tab:red",
                lw=0.9, label="limiting magnitude")
        ax.invert_yaxis()
        ax.legend(loc="lower right")
    ax.set(ylabel="magnitude")
    axes[2, 0].plot(hours, series["stars"], color="k", lw=0.6)
    axes[2, 0].set(xlabel="time [h]", ylabel="stars per frame")
    return fig
