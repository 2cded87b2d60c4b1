"""The report of a navigation run or campaign (the INS): key results, the ground track on a map,
position, velocity and attitude errors with the filter's ±3σ, the IMU error estimates, NEES; across
a campaign CEP50/95 over time and at the end, error envelopes and the pooled IMU error states.

Built with the run report's typesetting (:mod:`navsim.report.document`); key numbers are written as
plain text ("horizontal error at the end 12.34 m") so they can be extracted from the PDF.
"""

import tempfile
from pathlib import Path

import matplotlib
import numpy as np

from navsim.campaign.navigation import cep
from navsim.report import figures
from navsim.report import navigation_figures as nav_figures
from navsim.report import statistics as stats
from navsim.report.document import (
    Document,
    campaign_headline,
    campaign_summary_section,
    campaign_tables,
    general,
    markup,
    number,
    scenario_name,
    scenario_section,
    table,
)
from navsim.report.navigation_statistics import RUN_METRICS, horizontal_percentiles, position_envelopes
from startrack import units

CALIBRATION_LABELS = {"gyro_bias_deg_per_h": ("gyro bias", "deg/h", 4), "accel_bias_micro_g": ("accelerometer bias", "µg", 1),
                      "gyro_scale_factor_ppm": ("gyro scale factor", "ppm", 1),
                      "accel_scale_factor_ppm": ("accelerometer scale factor", "ppm", 1)}


def run_report(run) -> bytes:
    """The PDF (bytes) of one navigation run directory's report."""
    summary, s = run.summary, run.series
    name = scenario_name(summary, run.scenario, run.directory)
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim run report: {name}", f"navsim run · {name}")
        doc.title(f"Navigation run report: {name}", (run.scenario or {}).get("description") or str(run.directory))
        nav = summary["navigation"]
        doc.paragraph(markup(
            f"Run directory {run.directory}; seed {summary['seed']}; {run.frames} frames over "
            f"{number(float(s['t'][-1]) / 60.0, 1)} min; IMU at {general(nav['imu_rate_hz'])} Hz; aiding: "
            f"{', '.join(nav['aiding']) or 'none (free INS)'}; {nav['filter_states']} filter states."))
        _run_key_results(doc, summary)
        scenario_section(doc, run.scenario)
        doc.heading("Ground track")
        doc.paragraph(markup("The true track (black) and the filter's estimate (red, dashed) in longitude and latitude, "
                             "drawn with equal scales at the track's mean latitude."))
        doc.figure(nav_figures.ground_track(run), "Ground track: truth and estimate.")
        doc.heading("Navigation errors")
        doc.paragraph(markup(
            "Estimate minus truth in the local north-east-down frame, with the filter's ±3σ (dashed). Tilt and heading "
            "come from the error angle φ of C_nb,est = (I − [φ×]) C_nb,true; the heading error is −φ_D."))
        doc.figure(nav_figures.position_errors(run), "Position error north, east, down with ±3σ, metres.")
        doc.figure(nav_figures.velocity_errors(run), "Velocity error north, east, down with ±3σ, m/s.")
        doc.figure(nav_figures.attitude_errors(run), "Tilt and heading errors with ±3σ, arcsec.")
        _calibration_section(doc, summary.get("imu_calibration"), nav_figures.imu_biases(run))
        doc.heading("Filter consistency")
        doc.paragraph(markup(
            f"The NEES of the whole error state ({summary['nees']['dof']} dof) and the NIS of each update per degree of "
            "freedom, with their two-sided 95 % chi-square bands."))
        doc.figure(figures.consistency(run), "NEES and NIS per degree of freedom (log scale) with their 95 % bands.")
        return doc.compile()


def _run_key_results(doc, summary):
    position, nmi = summary["position_error_m"], summary["position_error_nmi"]["horizontal"]
    velocity, nees = summary["velocity_error_m_per_s"], summary["nees"]
    doc.heading("Key results")
    doc.paragraph(markup(
        f"The horizontal position error at the end is {number(position['horizontal']['final'])} m "
        f"({number(nmi['final'], 3)} nmi, {number(nmi['final_per_hour'], 3)} nmi/h) and the vertical "
        f"{number(position['vertical']['final'])} m. After {number(summary['settle_s'], 1)} s the horizontal RMS is "
        f"{number(position['horizontal']['rms'])} m. The NEES ({nees['dof']} dof) averages {number(nees['mean'])} and "
        f"{number(100 * nees['fraction_in_band'], 1)} % of the frames lie inside the 95 % band "
        f"[{number(nees['band_95'][0])}, {number(nees['band_95'][1])}]."))
    rows = []
    for label, block, unit, digits in (("horizontal position", position["horizontal"], "m", 2),
                                       ("vertical position", position["vertical"], "m", 2),
                                       ("horizontal velocity", velocity["horizontal"], "m/s", 3),
                                       ("vertical velocity", velocity["vertical"], "m/s", 3),
                                       ("tilt", summary["tilt_error_arcsec"], "arcsec", 1),
                                       ("heading", summary["heading_error_arcsec"], "arcsec", 1)):
        rows.append((label, unit, number(block["final"], digits), number(block["rms"], digits), number(block["max"], digits)))
    doc.add(table(("Error", "Unit", "Final", "RMS", "Max"), rows, ("left", "left", "right", "right", "right")))
    rows = [("final position σ (N, E, D)", ", ".join(number(v) for v in summary["position_sigma_final_m"]), "m"),
            ("NIS mean per dof", number(summary["nis"]["mean_per_dof"], 3), ""),
            ("updates accepted / rejected", f"{summary['updates']['accepted']} / {summary['updates']['rejected']}", ""),
            ("wall time", number(stats.lookup(summary, ("timing", "wall_seconds"))), "s")]
    doc.add(table(("Quantity", "Value", "Unit"), rows, ("left", "right", "left")))


def _calibration_section(doc, calibration, fig):
    if not calibration:
        return
    doc.heading("IMU error estimates")
    doc.paragraph(markup("The IMU error states at the end of the run: truth, estimate, the filter's σ and the normalised "
                         "error (estimate − truth)/σ, which a consistent filter keeps within ±3."))
    rows = []
    for key, (label, unit, digits) in CALIBRATION_LABELS.items():
        if key in calibration:
            c = calibration[key]
            rows += [(f"{label} {axis}", unit, number(t, digits), number(e, digits), number(sig, digits), number(z, 2))
                     for axis, t, e, sig, z in zip("xyz", c["true"], c["estimate"], c["sigma"], c["normalised_error"])]
    doc.add(table(("State", "Unit", "Truth", "Estimate", "1σ", "Normalised error"), rows,
                  ("left", "left", "right", "right", "right", "right")))
    doc.figure(fig, "Gyro and accelerometer biases: truth (black) and the filter's estimate with ±3σ.")


#: What a navigation campaign's summary.json holds, for its report.
CAMPAIGN_AGGREGATE = ("The campaign's own aggregate (summary.json), as written by the campaign runner: CEP50/95 of the "
                      "final horizontal error, the IMU error states pooled over the runs (normalised error RMS, "
                      "expected 1, and the share within 3σ, expected 99.7 %).")


def campaign_report(campaign) -> bytes:
    """The PDF (bytes) of a navigation campaign directory's report."""
    name = campaign.campaign.get("scenario") or scenario_name(campaign.runs[0].summary, campaign.scenario,
                                                                 campaign.directory)
    percentiles, env = horizontal_percentiles(campaign), position_envelopes(campaign)
    avg, metrics = stats.averaged_nees(campaign), stats.metric_table(campaign, RUN_METRICS)
    final_ne = env.final[:, :2]
    final = cep(np.hypot(final_ne[:, 0], final_ne[:, 1]))
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim Monte Carlo report: {name}", f"navsim Monte Carlo · {name}")
        doc.title(f"Monte Carlo campaign report: {name}", str(campaign.directory))
        doc.paragraph(markup(campaign_headline(campaign, f"{env.t.size} frames per run over "
                                                       f"{number(float(env.t[-1]) / 60.0, 1)} min")))
        doc.heading("Key results")
        sentences = [f"At the last logged frame the horizontal position error has CEP50 {number(final['cep50'])} m "
                     f"({number(final['cep50'] / units.NAUTICAL_MILE, 3)} nmi) and CEP95 {number(final['cep95'])} m "
                     f"({number(final['cep95'] / units.NAUTICAL_MILE, 3)} nmi) over the {len(campaign.runs)} runs."]
        if avg is not None:
            sentences.append(f"The NEES averaged over the runs has mean {number(avg.mean_after_settle)} after "
                             f"{number(avg.settle_s, 1)} s and {number(100 * avg.fraction_in_band, 1)} % of those frames "
                             f"lie inside the 95 % band [{number(avg.band[0])}, {number(avg.band[1])}] for {avg.runs} "
                             f"runs of {avg.dof} dof.")
        doc.paragraph(*(markup(x) for x in sentences))
        campaign_tables(doc, campaign, metrics)
        doc.heading("Horizontal error over time")
        doc.paragraph(markup("At each frame the median (CEP50) and 95th percentile (CEP95) of the horizontal error over "
                             "the runs, their RMS and the filter's 3σ from the covariance averaged over the runs."))
        doc.figure(nav_figures.horizontal_percentiles(percentiles), "Horizontal position error percentiles over the runs.")
        doc.heading("Position error envelopes")
        doc.figure(figures.error_envelopes(env, [f"δ{a} [m]" for a in nav_figures.NED], "time [min]", 60.0),
                   "Position error envelopes north, east, down over the runs, metres, with the filter's mean ±3σ.")
        doc.figure(nav_figures.final_scatter(final_ne, final["cep50"], final["cep95"]),
                   "Final north and east errors of the runs with the CEP50 and CEP95 circles.")
        if avg is not None:
            doc.heading("Filter consistency over runs")
            doc.figure(figures.nees_band(avg), "NEES averaged over the runs with the 95 % chi-square band for M runs.")
        campaign_summary_section(doc, campaign, CAMPAIGN_AGGREGATE)
        return doc.compile()
