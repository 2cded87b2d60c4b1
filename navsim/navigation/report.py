"""The report of a navigation run or campaign (the INS): key results, the ground track on a map,
position, velocity and attitude errors with the filter's ±3σ, the IMU error estimates, NEES; across
a campaign CEP50/95 over time and at the end, error envelopes and the pooled IMU error states.

Built with :mod:`navsim.typeset`; key numbers are written as plain text ("horizontal error at the end
12.34 m") so they can be extracted from the PDF; the campaign's pooled statistics (CEP, run-averaged
NEES) are its summary's.
"""

import tempfile
from pathlib import Path

import matplotlib
import numpy as np

from navsim.estimation.intervals import interval_text
from navsim.navigation import figures as nav_figures
from navsim.navigation.report_statistics import RUN_METRICS, horizontal_percentiles, position_envelopes
from navsim.typeset import figures
from navsim.typeset import statistics as stats
from navsim.typeset.document import Document, general, markup, number, scenario_name, table
from navsim.typeset.sections import (
    campaign_headline,
    campaign_summary_section,
    campaign_tables,
    comparison_section,
    nees_sentence,
    notes_section,
    scenario_section,
)
from startrack import units

#: Arrays every navigation run must have, and those a campaign report reads from each run.
REQUIRED_SERIES = ("t", "lat", "lon", "lat_true", "lon_true", "error_state", "error_sigma", "position_error_m")
CAMPAIGN_SERIES = ("t", "error_state", "error_sigma", "position_error_m", "lat_true", "h_true", "nees")
CALIBRATION_LABELS = {"gyro_bias_deg_per_h": ("gyro bias", "deg/h", 4), "accel_bias_micro_g": ("accelerometer bias", "µg", 1),
                      "gyro_scale_factor_ppm": ("gyro scale factor", "ppm", 1),
                      "accel_scale_factor_ppm": ("accelerometer scale factor", "ppm", 1)}
MOUNTING_LABELS = {"mounting_arcsec": ("mounting μ", "arcsec", 2)}
#: Directions of the normalised covariance's spectrum listed as the least observed.
LEAST_OBSERVED = 4


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
        doc.paragraph(markup("The true track (black) and the filter's estimate (red, dashed) on the azimuthal "
                             "equidistant map centred on the true track: distances and bearings from the centre are "
                             "true, and the poles and the 180° meridian are ordinary points (Snyder 1987, ch. 25)."))
        doc.figure(nav_figures.ground_track(run), "Ground track: truth and estimate.")
        doc.heading("Navigation errors")
        doc.paragraph(markup(
            "Estimate minus truth in the local north-east-down frame, with the filter's ±3σ (dashed). Tilt and heading "
            "come from the error angle φ of C_nb,est = (I − [φ×]) C_nb,true; the heading error is −φ_D."))
        doc.figure(nav_figures.position_errors(run), "Position error north, east, down with ±3σ, metres.")
        doc.figure(nav_figures.velocity_errors(run), "Velocity error north, east, down with ±3σ, m/s.")
        doc.figure(nav_figures.attitude_errors(run), "Tilt and heading errors with ±3σ, arcsec.")
        _calibration_section(doc, summary.get("imu_calibration"), nav_figures.imu_biases(run))
        _star_sensor_section(doc, run)
        doc.heading("Filter consistency")
        doc.paragraph(markup(
            f"The NEES of the whole error state ({summary['nees']['dof']} dof) and the NIS of each update per degree of "
            "freedom, with their two-sided 95 % chi-square bands."))
        doc.figure(figures.consistency(run), "NEES and NIS per degree of freedom (log scale) with their 95 % bands.")
        comparison_section(doc, summary)
        notes_section(doc, summary)
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
    track = [(f"{side}-track position", position[f"{side}_track"], "m", 2) for side in ("along", "cross")
             if f"{side}_track" in position]  # runs written before issue 31 have none
    for label, block, unit, digits in (("horizontal position", position["horizontal"], "m", 2), *track,
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
    _estimates_table(doc, calibration, CALIBRATION_LABELS)
    doc.figure(fig, "Gyro and accelerometer biases: truth (black) and the filter's estimate with ±3σ.")


def _estimates_table(doc, calibration, labels):
    """Truth, estimate, 1σ and normalised error per axis of the ``calibration`` groups named in ``labels``
    ({key: (label, unit, decimals)})."""
    rows = []
    for key, (label, unit, digits) in labels.items():
        if key in calibration:
            c = calibration[key]
            rows += [(f"{label} {axis}", unit, number(t, digits), number(e, digits), number(sig, digits), number(z, 2))
                     for axis, t, e, sig, z in zip("xyz", c["true"], c["estimate"], c["sigma"], c["normalised_error"])]
    doc.add(table(("State", "Unit", "Truth", "Estimate", "1σ", "Normalised error"), rows,
                  ("left", "left", "right", "right", "right", "right")))


def _star_sensor_section(doc, run):
    """A star-aided run (SINS/CNS): the horizontal error against the analytic-horizon floor, the
    aberration, the mounting estimate and the observability of each state."""
    celestial = run.summary.get("celestial")
    if not celestial:
        return
    doc.heading("Star sensor aiding")
    floor, aberration = celestial["horizon_floor"], celestial["aberration"]
    doc.paragraph(markup(
        "The star sensor fixes the inertial attitude and the accelerometers the local vertical; together they fix "
        "latitude and longitude (the analytic horizon). The horizontal error then oscillates at the Schuler period about "
        "the floor of eq. (1), δN = (R_M + h)(∇_N − δg_N)/γ and δE = (R_N + h)(∇_E − δg_E)/γ, of the true accelerometer "
        "bias ∇ and gravity disturbance δg; manoeuvres that make ∇ observable bring the error below it. "
        f"Over {number(floor['schuler_periods'])} Schuler periods after the settling time the mean horizontal error is "
        f"{number(floor['position_error_mean_m'])} m against a floor of {number(floor['floor_m'])} m."))
    doc.figure(nav_figures.horizon_floor(run), "Horizontal position error north and east with the filter's ±3σ and "
                                               "the analytic-horizon floor of eq. (1) of the true "
                                               "accelerometer bias and of the bias the filter's estimate leaves, metres.")
    if "sky" in celestial and "sun_angle" in run.series:
        _sky_section(doc, run, celestial["sky"])
    corrected = "corrected" if aberration["corrected"] else "not corrected"
    doc.paragraph(markup(
        f"The aberration of the star directions is {corrected} by the processing; left uncorrected, its horizontal part "
        f"would move the position by {number(aberration['uncorrected_position_m'])} m."))
    refraction = celestial.get("refraction")
    if refraction is not None:
        doc.paragraph(markup(_refraction_text(refraction)))
    identification = celestial.get("star_identification")
    if identification is not None:
        doc.paragraph(markup(_identification_text(identification)))
    doc.add(table(("Quantity", "Value", "Unit"), _horizon_rows(floor) + _aberration_rows(aberration),
                  ("left", "right", "left")))
    calibration = run.summary.get("imu_calibration") or {}
    if "mounting_arcsec" in calibration:
        doc.paragraph(markup("The star-sensor mounting error μ (sensor axes) at the end of the run: truth, estimate, "
                             "the filter's σ and the normalised error."))
        _estimates_table(doc, calibration, MOUNTING_LABELS)
        doc.figure(nav_figures.mounting(run), "Star-sensor mounting error μ: truth (black) and the filter's estimate "
                                              "with ±3σ, arcsec.")
    _observability_section(doc, celestial["observability"])


def _sky_section(doc, run, sky):
    """The Sun, the Moon and the horizon: the frames each exclusion took and the geometry over time."""
    excluded = ", ".join(f"{count} ({reason})" for reason, count in sky["frames_excluded"].items() if count) or "none"
    doc.paragraph(markup(
        f"The Sun comes within {number(sky['sun_angle_min_deg'])} deg of the boresight and the Moon within "
        f"{number(sky['moon_angle_min_deg'])} deg (mean illuminated fraction {number(sky['moon_illuminated_mean'])}); the "
        f"boresight's lowest elevation is {number(sky['boresight_elevation_min_deg'])} deg and the Sun is up for "
        f"{sky['frames_sun_up']} frames. Frames excluded: {excluded}."))
    doc.figure(nav_figures.sky(run), "The Sun's and the Moon's angles from the boresight and the elevations of the "
                                     "boresight and the Sun, deg; the exclusion angles dashed, excluded frames shaded.")
    if "hours_with_stars" in sky:
        per_frame = sky["stars_per_frame"]
        text = (f"Stars were measured for {number(sky['hours_with_stars'])} h, {number(per_frame['mean'])} per frame on "
                f"average (at most {per_frame['max']}).")
        if "limiting_mag" in sky:
            limit, background = sky["limiting_mag"], sky["sky_background_mag"]
            text += (f" The sky decides what the sensor sees (its light budget in the {sky['band']} band): at the boresight "
                     f"the sky is {number(background['min'])} to {number(background['max'])} mag/arcsec² and the limiting "
                     f"magnitude {number(limit['min'])} to {number(limit['max'])} (median {number(limit['median'])}) when "
                     "the sky leaves the detector any room.")
        reasons = {k: v for k, v in sky.get("frames_without_stars", {}).items() if v}
        if reasons:
            text += " Frames without a star: " + ", ".join(f"{v} ({k})" for k, v in reasons.items()) + "."
        doc.paragraph(markup(text))
    if "limiting_mag" in run.series:
        doc.figure(nav_figures.sky_stars(run), "Stars measured per frame (top); the sky's brightness at the boresight "
                                               "[mag/arcsec²] and the limiting magnitude there (bottom; none while the "
                                               "sky fills the detector's well).")


def _horizon_rows(floor):
    def ne(values):
        return ", ".join(number(v) for v in values)

    return [("Schuler-mean position error (N, E)", ne(floor["position_error_mean_ne_m"]), "m"),
            ("Schuler-mean horizontal error", number(floor["position_error_mean_m"]), "m"),
            ("floor of eq. (1) (N, E)", ne(floor["floor_ne_m"]), "m"),
            ("floor of eq. (1), horizontal", number(floor["floor_m"]), "m"),
            ("floor: accelerometer-bias part", number(floor["accel_bias_m"]), "m"),
            ("floor: gravity-disturbance part", number(floor["gravity_m"]), "m"),
            ("Schuler periods averaged", number(floor["schuler_periods"]), "")]


def _refraction_text(refraction):
    """The refraction of the boresight, what the processing does with it and what is left."""
    corrected = "corrects it with the standard atmosphere at the INS's height" if refraction["corrected"] else "does not correct it"
    return (f"The air raises the boresight by {number(refraction['total_arcsec']['mean'])}\" on average (at most "
            f"{number(refraction['total_arcsec']['max'])}\"); the processing {corrected}. The real air departs from that "
            f"model by {number(refraction['pressure_error_percent'])} % in pressure and {number(refraction['temperature_error_k'])} K"
            f"{' (drawn for this run from the stated σ)' if refraction.get('drawn') else ''}, "
            f"leaving {number(refraction['residual_arcsec']['mean'])}\" ({number(refraction['residual_position_m'])} m of "
            f"position); left uncorrected the refraction would cost {number(refraction['uncorrected_position_m'])} m."
            + _considered_text(refraction.get("considered")))


def _considered_text(considered):
    """The filter's refraction consider state, if it carries one."""
    if considered is None:
        return " The filter does not know of the model air's error."
    return (f" The filter carries the model air's fractional error as a consider state of σ "
            f"{number(100.0 * considered['fraction_sigma'])} % (the real air's: {number(100.0 * considered['fraction_true'])} %).")


def _identification_text(ident):
    """What naming the detections with the INS's prior did."""
    return (f"The sensor named its detections with the INS's prior: {ident['stars_identified']} of "
            f"{ident['stars_detected']} detections identified in {ident['frames_identified']} of "
            f"{ident['frames_detected']} frames with detections ({ident['stars_tracked']} of them on the tracks of stars "
            f"identified before), {ident['wrong']} wrongly (checked against the truth) where the stated probabilities of "
            f"a wrong match sum to {ident['wrong_expected']:.2f}; the largest was {ident['wrong_probability_max']:.1e}.")


def _aberration_rows(aberration):
    rows = [(f"{label} aberration (mean / max)", f"{number(aberration[key]['mean'])} / {number(aberration[key]['max'])}",
             "arcsec") for label, key in (("annual", "annual_arcsec"), ("vehicle", "vehicle_arcsec"),
                                          ("total", "total_arcsec"), ("horizontal part of the total", "horizontal_arcsec"))]
    return rows + [("position error if uncorrected", number(aberration["uncorrected_position_m"]), "m"),
                   ("aberration corrected", "yes" if aberration["corrected"] else "no", "")]


def _observability_section(doc, observability):
    names, ratios = observability["states"], observability["sigma_ratio_final"]
    observed = [n for n, r in zip(names, ratios) if r < 0.1]
    unobserved = [n for n, r in zip(names, ratios) if r > 0.5]
    doc.paragraph(markup(
        "Observability: per state the filter's σ at the end over its initial σ. "
        f"Reduced below 10 %: {', '.join(observed) or 'none'}. Left above 50 % (unobserved, or grown): "
        f"{', '.join(unobserved) or 'none'}."))
    doc.figure(nav_figures.observability(names, ratios), "Observability: σ_end/σ_0 per error state (log scale).")
    least = observability["spectrum"][::-1][:LEAST_OBSERVED]
    doc.paragraph(markup(
        "The least-observed directions: the largest eigenvalues of the final covariance normalised by the initial σ "
        "(Ham & Brown 1983; an eigenvalue near 1 is a direction the measurements left as it was, near 0 one they "
        "observed), each with its largest components."))
    doc.add(table(("Eigenvalue", "σ ratio", "Main components"),
                  [(f"{m['eigenvalue']:.3g}", f"{np.sqrt(max(m['eigenvalue'], 0.0)):.3g}",
                    ", ".join(f"{name} {weight:+.2f}" for name, weight in m["components"])) for m in least],
                  ("right", "right", "left")))


#: What a navigation campaign's summary.json holds, for its report.
CAMPAIGN_AGGREGATE = ("The campaign's own aggregate (summary.json), as written by the campaign runner: CEP50/95 of the "
                      "final horizontal error, the IMU error states pooled over the runs (normalised error RMS, "
                      "expected 1, and the share within 3σ, expected 99.7 %).")


def cep_interval_sentence(summary):
    """The 95 % intervals of CEP50 and CEP95 of a campaign ``summary`` and, when its runs leave one unbounded
    above, how many runs would bound it."""
    final = summary["position_error_m"]["horizontal"]
    interval = {name: interval_text(final["interval_95"][name], unit="m") for name in ("cep50", "cep95")}
    short = [name for name in ("cep50", "cep95") if final["interval_95"][name][1] is None]
    caveat = ""
    if short:
        needs = ", ".join(f"{name.upper()} needs {final['runs_to_bound'][name]}" for name in short)
        caveat = (f"; {summary['runs_finished']} runs are too few to bound {' and '.join(n.upper() for n in short)} "
                  f"above ({needs} runs)")
    return (f"Their 95 % intervals (distribution-free: the order statistics of the runs) are CEP50 {interval['cep50']} "
            f"and CEP95 {interval['cep95']}{caveat}.")


def _campaign_floor(doc, campaign):
    """Star-aided runs: each run's Schuler-mean horizontal error against its analytic-horizon floor."""
    floors = [(r.summary.get("celestial") or {}).get("horizon_floor") for r in campaign.runs]
    if not all(floors):
        return
    floor = np.array([f["floor_m"] for f in floors])
    error = np.array([f["position_error_mean_m"] for f in floors])
    doc.heading("Analytic-horizon floor across runs")
    doc.paragraph(markup(
        f"Over the {floor.size} runs (each mean over {number(floors[0]['schuler_periods'])} Schuler periods) the "
        f"Schuler-mean horizontal error has RMS {number(float(np.sqrt(np.mean(error**2))))} m "
        f"against an RMS floor of eq. (1) of {number(float(np.sqrt(np.mean(floor**2))))} m (each run's own accelerometer "
        "bias and gravity disturbance)."))
    doc.figure(nav_figures.floor_scatter(floor, error), "Schuler-mean horizontal error against the floor of eq. (1), per run.")


def campaign_report(campaign) -> bytes:
    """The PDF (bytes) of a navigation campaign directory's report."""
    name = campaign.campaign.get("scenario") or scenario_name(campaign.runs[0].summary, campaign.scenario,
                                                                 campaign.directory)
    percentiles, env = horizontal_percentiles(campaign), position_envelopes(campaign)
    avg, metrics = stats.averaged_nees(campaign), stats.metric_table(campaign, RUN_METRICS)
    final_ne = env.final[:, :2]
    final = campaign.summary["position_error_m"]["horizontal"]
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim Monte Carlo report: {name}", f"navsim Monte Carlo · {name}")
        doc.title(f"Monte Carlo campaign report: {name}", str(campaign.directory))
        doc.paragraph(markup(campaign_headline(campaign, f"{env.t.size} frames per run over "
                                                       f"{number(float(env.t[-1]) / 60.0, 1)} min")))
        doc.heading("Key results")
        sentences = [f"At the end of the runs the horizontal position error has CEP50 {number(final['cep50'])} m "
                     f"({number(final['cep50'] / units.NAUTICAL_MILE, 3)} nmi) and CEP95 {number(final['cep95'])} m "
                     f"({number(final['cep95'] / units.NAUTICAL_MILE, 3)} nmi) over the {len(campaign.runs)} runs.",
                     cep_interval_sentence(campaign.summary)]
        if avg is not None:
            sentences.append(nees_sentence(avg))
        doc.paragraph(*(markup(x) for x in sentences))
        campaign_tables(doc, campaign, metrics)
        doc.heading("Horizontal error over time")
        doc.paragraph(markup("At each frame the median (CEP50) and 95th percentile (CEP95) of the horizontal error over "
                             "the runs, their RMS and the filter's 3σ from the covariance averaged over the runs."))
        doc.figure(nav_figures.horizontal_percentiles(percentiles, final["runs_to_bound"]),
                   "Horizontal position error percentiles over the runs, with their 95 % intervals.")
        doc.heading("Position error envelopes")
        doc.figure(figures.error_envelopes(env, [f"δ{a} [m]" for a in nav_figures.NED], "time [min]", 60.0),
                   "Position error envelopes north, east, down over the runs, metres, with the filter's mean ±3σ.")
        doc.figure(nav_figures.final_scatter(final_ne, final),
                   "Final north and east errors of the runs with the CEP50 and CEP95 circles.")
        if avg is not None:
            doc.heading("Filter consistency over runs")
            doc.figure(figures.nees_band(avg), "NEES averaged over the runs with the 95 % chi-square band for M runs.")
        _campaign_floor(doc, campaign)
        campaign_summary_section(doc, campaign, CAMPAIGN_AGGREGATE)
        return doc.compile()
