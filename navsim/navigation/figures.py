"""Report figures of navigation runs and campaigns (the INS): the ground track on an azimuthal equidistant map, the position,
velocity and attitude errors with the filter's ±3σ, the IMU error estimates, and across a campaign the
horizontal error percentiles (CEP) over time and the final errors with their CEP circles.

Units at this edge: kilometres on the map, metres, m/s, arcsec, deg/h and µg; time in
minutes. The error state and its σ are the filter's (:mod:`navsim.navigation.summary`).
"""

import numpy as np

from navsim.estimation.intervals import interval_text
from navsim.navigation.celestial import floor_ned
from navsim.navigation.summary import ACCEL_BIAS, GYRO_BIAS, MICRO_G, group, ned_metres
from navsim.typeset.figures import COLORS, new_figure
from startrack import azimuthal_equidistant, radec_to_vector, units, vector_to_radec

NED = ("north", "east", "down")
#: The radius of the ground-track map's sphere [km] (IUGG mean radius, (2a + b)/3 of WGS-84).
EARTH_MEAN_RADIUS_KM = 6371.0088


def _minutes(t):
    return np.asarray(t) / 60.0


def ground_track(run):
    """The estimated and true ground tracks on the azimuthal equidistant map centred on the true track (on the
    sphere of the Earth's mean radius, :data:`EARTH_MEAN_RADIUS_KM`: distances and bearings from the centre true,
    the poles and the 180° meridian ordinary points), with the start and end marked and a pole the track comes within
    the map of."""
    s = run.series
    true_u = radec_to_vector(s["lon_true"], s["lat_true"])
    centre = vector_to_radec(np.mean(true_u, axis=0))

    def project(lat, lon):
        x, y = azimuthal_equidistant(lon, lat, *centre)
        return EARTH_MEAN_RADIUS_KM * x, EARTH_MEAN_RADIUS_KM * y

    (x_t, y_t), (x_e, y_e) = project(s["lat_true"], s["lon_true"]), project(s["lat"], s["lon"])
    fig, axes = new_figure(4.6)
    ax = axes[0, 0]
    ax.plot(x_t, y_t, color="k", lw=1.2, label="truth")
    ax.plot(x_e, y_e, color="tab:red", lw=0.8, ls="--", label="estimate")
    ax.plot(x_t[0], y_t[0], "o", color="tab:green", ms=5, label="start")
    ax.plot(x_t[-1], y_t[-1], "s", color="k", ms=4, label="end (truth)")
    ax.plot(x_e[-1], y_e[-1], "s", color="tab:red", ms=4, mfc="none", label="end (estimate)")
    span = max(np.ptp(x_t), np.ptp(y_t), 1.0)
    for pole, name in ((0.5 * np.pi, "North Pole"), (-0.5 * np.pi, "South Pole")):
        x_p, y_p = project(np.array(pole), np.array(0.0))
        if np.hypot(x_p - np.mean(x_t), y_p - np.mean(y_t)) < span:
            ax.plot(x_p, y_p, "+", color="tab:blue", ms=8, label=name)
    ax.set_aspect(1.0, adjustable="datalim")
    lat0, lon0 = np.degrees(centre[1]), np.degrees(np.mod(centre[0] + np.pi, 2.0 * np.pi) - np.pi)
    ax.set(xlabel=f"east of {lat0:.2f}°, {lon0:.2f}° [km]", ylabel="north [km]")
    ax.legend(loc="best", ncols=2)
    return fig


def error_with_bounds(t, errors, sigmas, labels, unit, title=None, references=()):
    """Error components (one per label) against time [min] with the filter's ±3σ and references drawn
    over them, each (values (F, n), label, colour)."""
    fig, axes = new_figure(1.4 * len(labels), len(labels), 1)
    for i, ax in enumerate(axes[:, 0]):
        ax.plot(_minutes(t), errors[:, i], color=COLORS[i], lw=0.8, label="error")
        ax.plot(_minutes(t), 3.0 * sigmas[:, i], "k--", lw=0.7, label="±3σ (filter)")
        ax.plot(_minutes(t), -3.0 * sigmas[:, i], "k--", lw=0.7)
        for values, label, color in references:
            ax.plot(_minutes(t), values[:, i], color=color, lw=0.9, label=label)
        ax.set_ylabel(f"{labels[i]} [{unit}]")
        ax.legend(loc="upper right", ncols=3)
    if title:
        axes[0, 0].set_title(title)
    axes[-1, 0].set_xlabel("time [min]")
    return fig


def _position_sigma(s):
    return np.abs(ned_metres(s["error_sigma"][:, 6:9]))


def position_errors(run):
    """Position error north, east, down [m] with ±3σ."""
    s = run.series
    return error_with_bounds(s["t"], s["position_error_m"], _position_sigma(s), [f"δ{a}" for a in NED], "m")


def horizon_floor(run):
    """Horizontal position error north and east [m] with ±3σ and the analytic-horizon floor of eq. (1)
    (:func:`navsim.navigation.celestial.floor_ned`) of the true accelerometer bias and of the bias the
    filter's estimate leaves (its ∇ state), each with the gravity disturbance."""
    s = run.series
    floors = ((sum(floor_ned(s)), "floor of eq. (1), true ∇", "tab:red"),
              (sum(floor_ned(s, s["error_state"][:, ACCEL_BIAS])), "floor, ∇ left by the filter", "tab:purple"))
    return error_with_bounds(s["t"], s["position_error_m"][:, :2], _position_sigma(s)[:, :2], [f"δ{a}" for a in NED[:2]],
                             "m", references=floors)


def velocity_errors(run):
    """Velocity error north, east, down [m/s] with ±3σ."""
    s = run.series
    return error_with_bounds(s["t"], s["error_state"][:, 3:6], s["error_sigma"][:, 3:6],
                             [f"δv {a}" for a in NED], "m/s")


def attitude_errors(run):
    """Tilt about north and east and heading error (est − true = −φ_D) [arcsec] with ±3σ."""
    s = run.series
    phi = s["error_state"][:, 0:3] * np.array([1.0, 1.0, -1.0])
    return error_with_bounds(s["t"], units.rad_to_arcsec(phi), units.rad_to_arcsec(s["error_sigma"][:, 0:3]),
                             ["tilt φN", "tilt φE", "heading"], "arcsec")


def imu_biases(run):
    """Gyro [deg/h] and accelerometer [µg] bias: truth and estimate with the estimate's ±3σ; None
    when the run did not log the truths."""
    s = run.series
    if "gyro_bias_true" not in s or "accel_bias_true" not in s:
        return None
    return truth_and_estimate(s, (("gyro", "gyro_bias", GYRO_BIAS, units.DEG / units.HOUR, "deg/h"),
                                  ("accel", "accel_bias", ACCEL_BIAS, MICRO_G, "µg")))


def mounting(run):
    """The star-sensor mounting error μ [arcsec] per sensor axis: truth and estimate with ±3σ; None
    without the filter's mounting states."""
    s = run.series
    span = group(s, "mu_x")
    if span is None or "mounting_true" not in s:
        return None
    return truth_and_estimate(s, (("μ", "mounting", span, units.ARCSEC, "arcsec"),), suffixes=("_true", "_estimate"))


def truth_and_estimate(s, columns, suffixes=("_true", "")):
    """One column per (label, series name, error-state slice, unit, unit label) of three axes: the truth
    (``name + suffixes[0]``) and the estimate (``name + suffixes[1]``) with the estimate's ±3σ."""
    fig, axes = new_figure(4.6, 3, len(columns))
    for col, (label, name, span, unit, unit_label) in enumerate(columns):
        true, est = s[name + suffixes[0]] / unit, s[name + suffixes[1]] / unit
        sigma3 = 3.0 * s["error_sigma"][:, span] / unit
        for i, ax in enumerate(axes[:, col]):
            ax.plot(_minutes(s["t"]), true[:, i], color="k", lw=1.0, label="truth")
            ax.plot(_minutes(s["t"]), est[:, i], color=COLORS[i], lw=0.8, label="estimate")
            ax.fill_between(_minutes(s["t"]), est[:, i] - sigma3[:, i], est[:, i] + sigma3[:, i], color=COLORS[i],
                            alpha=0.15, lw=0, label="±3σ")
            ax.set_ylabel(f"{label} {'xyz'[i]} [{unit_label}]")
        axes[0, col].legend(loc="upper right", ncols=3)
        axes[-1, col].set_xlabel("time [min]")
    return fig


def horizontal_percentiles(percentiles, runs_to_bound):
    """Horizontal position error over the runs against time: CEP50 and CEP95 with their 95 % intervals shaded
    (where the runs bound them: else the legend says how many runs would, ``runs_to_bound`` {cep50, cep95}), RMS
    and the filter's mean 3σ (horizontal, √(σ_N² + σ_E²))."""
    fig, axes = new_figure(2.8)
    ax = axes[0, 0]
    t = _minutes(percentiles.t)
    for name, label, color in (("cep50", "CEP50 (median)", "tab:blue"), ("cep95", "CEP95", "tab:red")):
        lo, hi = getattr(percentiles, f"{name}_interval")
        bounded = bool(np.all(np.isfinite(hi)))
        ax.plot(t, getattr(percentiles, name), color=color, lw=0.9, label=label + (
            "" if bounded else f" (95 % interval unbounded above: {runs_to_bound[name]} runs bound it)"))
        if bounded:
            ax.fill_between(t, lo, hi, color=color, alpha=0.15, lw=0, label=f"{label.split()[0]} 95 % interval")
    ax.plot(t, percentiles.rms, color="k", lw=0.7, ls=":", label="RMS over runs")
    ax.plot(t, 3.0 * percentiles.sigma, "k--", lw=0.7, label="filter 3σ (mean P)")
    ax.set(xlabel="time [min]", ylabel="horizontal error [m]", title=f"{percentiles.runs} runs")
    ax.legend(loc="upper left", ncols=2)
    return fig


def final_scatter(final_ne, horizontal):
    """Final north/east position errors of the runs [m] with the CEP50 and CEP95 circles, their 95 % intervals
    in the legend (``horizontal``: the campaign summary's final horizontal error, in metres)."""
    fig, axes = new_figure(3.6)
    ax = axes[0, 0]
    ax.plot(final_ne[:, 1], final_ne[:, 0], ".", color="tab:blue", ms=4, label="runs")
    angle = np.linspace(0.0, 2.0 * np.pi, 200)
    for name, color, label in (("cep50", "tab:green", "CEP50"), ("cep95", "tab:red", "CEP95")):
        radius = horizontal[name]
        ax.plot(radius * np.sin(angle), radius * np.cos(angle), color=color, lw=0.9,
                label=f"{label} {radius:.3g} m, 95 % interval {interval_text(horizontal['interval_95'][name], 3, 'm')}")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set(xlabel="final east error [m]", ylabel="final north error [m]")
    ax.legend(loc="upper right")
    return fig


def observability(names, ratios):
    """σ_end/σ_0 of each error state (log scale): a bar well below 1 is a state the measurements and
    manoeuvres observed; one near 1 or above was left unobserved (or grew)."""
    fig, axes = new_figure(2.6)
    ax = axes[0, 0]
    ax.bar(range(len(names)), ratios, color="tab:blue")
    ax.axhline(1.0, color="k", lw=0.7, ls="--", label="σ_0 (no reduction)")
    ax.set_yscale("log")
    ax.set_xticks(range(len(names)), names, rotation=90)
    ax.set(ylabel="σ_end / σ_0")
    ax.legend(loc="upper right")
    return fig


def floor_scatter(floor, error):
    """Per run: the Schuler mean of the horizontal position error against the analytic-horizon floor
    of eq. (1) [m], with the line where they are equal."""
    fig, axes = new_figure(3.2)
    ax = axes[0, 0]
    ax.plot(floor, error, ".", color="tab:blue", ms=5, label="runs")
    top = 1.05 * max(float(np.max(floor)), float(np.max(error)), 1e-9)
    ax.plot([0.0, top], [0.0, top], "k--", lw=0.7, label="error = floor")
    ax.set(xlabel="floor of eq. (1) [m]", ylabel="Schuler-mean horizontal error [m]", xlim=(0.0, top), ylim=(0.0, top))
    ax.legend(loc="upper left")
    return fig


def budget_bars(labels, values, predictions):
    """The error budget: per source the Schuler-mean, final and RMS horizontal error [m] (grouped bars,
    ``values`` {metric label: list}) with the prediction of eq. (1) where there is one (None elsewhere)."""
    fig, axes = new_figure(3.4)
    ax = axes[0, 0]
    x, width = np.arange(len(labels)), 0.8 / len(values)
    for i, (name, heights) in enumerate(values.items()):
        ax.bar(x + (i - (len(values) - 1) / 2) * width, heights, width, color=COLORS[i], label=name)
    known = [(k, p) for k, p in enumerate(predictions) if p is not None]
    if known:
        ax.plot([k for k, _ in known], [p for _, p in known], "k_", ms=24, mew=1.5, label="eq. (1) / R·r_h prediction")
    ax.set_xticks(x, labels, rotation=20, ha="right")
    ax.set(ylabel="horizontal error [m]")
    ax.legend(loc="upper left")
    return fig


def budget_shares(t, shares, labels):
    """The covariance budget over time: each source's share of the horizontal position error's mean square
    [m²] (``shares`` (S, K)) stacked against time ``t`` [s] in hours (negative shares drawn below zero)."""
    fig, axes = new_figure(3.0)
    ax = axes[0, 0]
    hours = np.asarray(t) / 3600.0
    positive, negative = np.clip(shares, 0.0, None), np.clip(shares, None, 0.0)
    ax.stackplot(hours, positive, labels=labels, alpha=0.85)
    if np.any(negative < 0.0):
        ax.stackplot(hours, negative, alpha=0.4)
    ax.set(xlabel="time [h]", ylabel="share of mean square [m²]")
    ax.legend(loc="upper left", ncol=2)
    return fig


def sky(run):
    """The Sun's and the Moon's angles from the boresight, the boresight's and the Sun's elevations [deg] against
    time [min], the scenario's exclusion angles dashed and the excluded frames shaded."""
    s, sensor = run.series, (run.scenario or {}).get("star_sensor") or {}
    t = _minutes(s["t"])
    fig, axes = new_figure(3.2)
    ax = axes[0, 0]
    for key, label, color in (("sun_angle", "Sun from the boresight", "tab:orange"), ("moon_angle", "Moon from the boresight", "tab:blue"),
                              ("boresight_elevation", "boresight elevation", "k"), ("sun_elevation", "Sun elevation", "tab:red")):
        ax.plot(t, np.degrees(s[key]), color=color, lw=0.9, ls=":" if key == "sun_elevation" else "-", label=label)
    for key, none, color in (("sun_exclusion_deg", 0.0, "tab:orange"), ("moon_exclusion_deg", 0.0, "tab:blue"),
                             ("min_elevation_deg", -90.0, "k")):
        if sensor.get(key, none) != none:
            ax.axhline(sensor[key], color=color, lw=0.7, ls="--")
    excluded = s["sky_excluded"] >= 0
    if excluded.any():
        ax.fill_between(t, 0.0, 1.0, where=excluded, transform=ax.get_xaxis_transform(), color="0.85", label="excluded")
    ax.set(xlabel="time [min]", ylabel="angle [deg]", ylim=(-90.0, 180.0))
    ax.legend(loc="upper right", ncols=3)
    return fig


def sky_stars(run):
    """Stars measured per frame, and the sky's brightness at the boresight with the limiting magnitude there, against
    time [h] (a sensor with a light budget)."""
    s = run.series
    hours = s["t"] / 3600.0
    fig, axes = new_figure(4.0, 2, 1)
    axes[0, 0].plot(hours, s["n_stars"], color="k", lw=0.6)
    axes[0, 0].set(ylabel="stars per frame")
    ax = axes[1, 0]
    ax.plot(hours, s["sky_background_mag"], color="tab:blue", lw=0.9, label="sky [mag/arcsec²]")
    limit = np.where(np.isfinite(s["limiting_mag"]), s["limiting_mag"], np.nan)
    ax.plot(hours, limit, color="tab:red", lw=0.9, label="limiting magnitude")
    ax.invert_yaxis()
    ax.set(xlabel="time [h]", ylabel="magnitude")
    ax.legend(loc="lower right")
    return fig
