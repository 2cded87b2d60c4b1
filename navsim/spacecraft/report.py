"""The report of a spacecraft run or campaign: the attitude kind's report (key results, attitude and bias errors with
the filter's ±3σ, calibration, consistency; across a campaign the envelopes and the NEES over the runs) with the
spacecraft's own sections after its key results: the orbit and the pointing, each head's availability and the fused
accuracy about its boresight, the heads' sky along the run (the Sun's, the Moon's and the limb's angles against
their exclusion angles) and the mounting states."""

import numpy as np

from navsim.attitude.report import CAMPAIGN_SERIES as ATTITUDE_CAMPAIGN_SERIES
from navsim.attitude.report import REQUIRED_SERIES as ATTITUDE_REQUIRED_SERIES
from navsim.attitude.report import campaign_report as attitude_campaign_report
from navsim.attitude.report import run_report as attitude_run_report
from navsim.typeset.document import markup, number, table, xyz
from navsim.typeset.figures import COLORS, new_figure

#: Arrays every spacecraft run must have, and those a campaign report reads from each run.
REQUIRED_SERIES = (*ATTITUDE_REQUIRED_SERIES, "head_measurements", "sun_angle", "moon_angle", "limb_angle")
CAMPAIGN_SERIES = ATTITUDE_CAMPAIGN_SERIES


def run_report(run) -> bytes:
    """The PDF (bytes) of one spacecraft run directory's report."""
    return attitude_run_report(run, _run_sections)


def campaign_report(campaign) -> bytes:
    """The PDF (bytes) of a spacecraft campaign directory's report."""
    return attitude_campaign_report(campaign, _campaign_sections)


def _run_sections(doc, run):
    summary = run.summary
    orbit, pointing = summary["orbit"], summary["pointing"]
    doc.heading("Orbit and pointing")
    doc.paragraph(markup(
        f"The orbit ({orbit['propagator']}) stays between {number(orbit['height_km']['min'], 1)} and "
        f"{number(orbit['height_km']['max'], 1)} km above the equatorial radius at {number(orbit['speed_km_per_s'], 3)} km/s; "
        f"the spacecraft spends {number(100 * orbit['shadow_fraction'], 1)} % of the run in the Earth's shadow "
        f"({number(100 * orbit['umbra_fraction'], 1)} % in the umbra). It follows the {pointing['law']} law: its true "
        f"attitude, from the rigid body, the wheels and the controller, departs from the law by "
        f"{number(pointing['error_rms_arcsec'])} arcsec RMS (at most {number(pointing['error_max_arcsec'], 1)} arcsec) after "
        f"the settling time; the body turns at up to {number(pointing['rate_max_deg_per_s'], 3)} deg/s and the wheels hold "
        f"up to {number(pointing['wheel_momentum_max_N_m_s'], 3)} N m s, at a limit in "
        f"{number(100 * pointing['wheel_saturated_fraction'], 2)} % of the control intervals."))
    doc.heading("Star-sensor heads")
    doc.paragraph(markup(
        "Each head's availability (frames it measured), the frames its exclusions took, and the fused attitude's error "
        "about its own boresight: with one head the roll about the boresight is the weak axis; heads whose boresights "
        "are far apart see each other's roll as cross-boresight."))
    rows = []
    for head in summary["heads"]:
        excluded = head["excluded_frames"]
        rows.append((head["name"], number(100 * head["availability"], 1), *(str(v) for v in excluded.values()),
                     number(head["measurements_per_frame"], 2), number(head["cross_boresight_rms_arcsec"]),
                     number(head["roll_rms_arcsec"]), number(head["roll_to_cross_boresight"])))
    doc.add(table(("Head", "Available [%]", "Sun excl.", "Moon excl.", "Limb excl.", "Per frame", "Cross [arcsec]",
                   "Roll [arcsec]", "Roll/cross"), rows))
    for head in summary["heads"]:
        if "mounting_arcsec" in head:
            m = head["mounting_arcsec"]
            doc.paragraph(markup(f"{head['name']}: mounting error truth {xyz(m['true'])} arcsec, estimate "
                                 f"{xyz(m['estimate'])} arcsec, 1σ {xyz(m['sigma'])} arcsec, normalised error "
                                 f"{xyz(m['normalised_error'])}."))
    doc.figure(_sky_figure(run), "Each head's angles from its boresight to the Sun and the Moon and its boresight's angle "
                                 "above the bright Earth limb, deg, with the exclusion angles (dashed) and the frames "
                                 "the head measured (dots at the top).")


def _sky_figure(run):
    s, heads = run.series, run.scenario["star_sensor"]
    t = s["t"]
    fig, axes = new_figure(2.4, len(heads), 1)
    for h, (ax, head) in enumerate(zip(axes[:, 0], heads)):
        for name, key, color in (("Sun", "sun", COLORS[1]), ("Moon", "moon", "0.5"), ("limb", "earth", COLORS[0])):
            angle = np.degrees(s[f"{'limb' if key == 'earth' else key}_angle"][:, h])
            ax.plot(t, angle, color=color, lw=0.8, label=name)
            ax.axhline(head[f"{key}_exclusion_deg"], color=color, ls="--", lw=0.6)
        measured = s["head_measurements"][:, h] > 0
        ax.plot(t[measured], np.full(measured.sum(), 185.0), "|", color="k", ms=2, label="measured")
        ax.set_ylim(-90, 190)
        ax.set_ylabel(f"{head['name']} [deg]")
        ax.legend(loc="lower right", ncols=4, fontsize=6)
    axes[-1, 0].set_xlabel("time [s]")
    return fig


def _campaign_sections(doc, campaign):
    heads = (campaign.summary or {}).get("heads")
    if not heads:
        return
    doc.heading("Star-sensor heads over the runs")
    doc.paragraph(markup("Per head the mean over the runs (and the 95th percentile) of its availability and of the fused "
                         "attitude's cross-boresight and roll RMS about its boresight; the mounting states' normalised "
                         "errors at the end of the runs (RMS per axis, expected 1)."))
    rows = [(h["name"], number(100 * h["availability"]["mean"], 1), number(h["cross_boresight_rms_arcsec"]["mean"]),
             number(h["cross_boresight_rms_arcsec"]["p95"]), number(h["roll_rms_arcsec"]["mean"]),
             number(h["roll_rms_arcsec"]["p95"]), number(h["roll_to_cross_boresight"]["mean"]),
             xyz(h["mounting_normalised_error"]["rms"]) if "mounting_normalised_error" in h else "n/a") for h in heads]
    doc.add(table(("Head", "Available [%]", "Cross mean", "Cross p95", "Roll mean", "Roll p95", "Roll/cross",
                   "Mounting z RMS"), rows))
