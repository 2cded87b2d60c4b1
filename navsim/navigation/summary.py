"""What a navigation run keeps: its per-frame series (estimate, truth, the error state and its σ)
and its :class:`~navsim.records.RunSummary` (position, velocity, tilt and heading errors, the IMU
error states, NEES over the filter's own error state).

The error state is the filter's (docs/design.md): x = [φ, δv_n, δL, δλ, δh, ε, ∇ (, δs_g, δs_a) (, μ)
(, δg) (, ε_r)], est − true except the IMU and star-sensor errors and the gravity disturbance (true − est),
with C_nb,est = (I − [φ×]) C_nb,true, so φ_N, φ_E are the tilts and the heading error (est − true) is
−φ_D. The position error in NED metres is (δL (R_M + h), δλ (R_N + h) cos L, −δh); along and across the true
track it is that horizontal error resolved on the track's direction and its right (:func:`track_metres`).
"""

import numpy as np

from navsim.earth.wander import carried_ned, ned_offset
from navsim.estimation.consistency import nees, nees_statistics
from navsim.estimation.nav_filter import error_state, mounting_error, state_names
from navsim.navigation.records import RunSummary
from navsim.pooling import divergence
from startrack import rotation as rot
from startrack import units

#: Slices of the error state: tilt (φ_N, φ_E), heading (φ_D), velocity, position, biases; the optional
#: groups are found by their names (:func:`group`).
TILT, HEADING, VELOCITY, POSITION = slice(0, 2), 2, slice(3, 6), slice(6, 9)
GYRO_BIAS, ACCEL_BIAS = slice(9, 12), slice(12, 15)
#: The accelerometer-bias unit of the summaries [m/s²].
MICRO_G = 1e-6 * units.STANDARD_GRAVITY
#: Below this ground speed [m/s] the track is the body's heading (a vehicle at rest has no course).
MIN_TRACK_SPEED = 0.1


def ned_metres(delta_position):
    """The error state's position part (δN, δE, δh) (..., 3) [m] as NED metres (..., 3)."""
    return np.stack([delta_position[..., 0], delta_position[..., 1], -delta_position[..., 2]], axis=-1)


def track_metres(error_ne, v_n, q_nb):
    """Horizontal position errors (F, 2) [m] along and across the true track (across positive to the right): the
    NED errors ``error_ne`` (F, 2) resolved on the course χ of the true ground velocity ``v_n`` (F, 3), along = δN cos χ
    + δE sin χ, across = −δN sin χ + δE cos χ; where the speed is below :data:`MIN_TRACK_SPEED` the course is the
    heading of the true body x axis (``q_nb`` (F, 4))."""
    forward = rot.rotate(q_nb, np.array([1.0, 0.0, 0.0]))
    slow = np.hypot(v_n[:, 0], v_n[:, 1]) < MIN_TRACK_SPEED
    course = np.where(slow, np.arctan2(forward[:, 1], forward[:, 0]), np.arctan2(v_n[:, 1], v_n[:, 0]))
    c, s = np.cos(course), np.sin(course)
    return np.stack([error_ne[:, 0] * c + error_ne[:, 1] * s, -error_ne[:, 0] * s + error_ne[:, 1] * c], axis=-1)


def group(series, first, size=3):
    """The slice of the error state whose first component is named ``first`` (``state_names``), or None."""
    names = list(series["state_names"])
    return slice(names.index(first), names.index(first) + size) if first in names else None


def navigation_series(truth, frame_k, arrays, gyro, accel, layout, q_BS_true=None, refraction_true=None):
    """The run's per-frame series from the loop's log ``arrays`` (the filter's snapshots and update
    statistics) at the frames' IMU samples ``frame_k``, the truth trajectory and the gyro and
    accelerometer records, for the filter's error-state ``layout`` (and the true star-sensor mounting
    ``q_BS_true`` and the truth's refraction fraction ε_r (F,) ``refraction_true``): estimates and truths (lat, lon, h, v_n, q_nb, biases), ``state_names``,
    ``error_state`` (F, n), ``error_sigma`` (F, n) = √diag P, ``covariance_final`` (n, n) (P at the
    last frame), ``position_error_m`` (F, 3) NED, ``nees`` and the truth's gravity disturbance
    ``gravity_disturbance_true`` (F, 3) [m/s²] (zero without one)."""
    k = frame_k
    series = {"t": truth.t[k], "lat_true": truth.lat[k], "lon_true": truth.lon[k], "h_true": truth.h[k],
              "v_n_true": truth.v_n[k], "q_nb_true": truth.q_nb[k], "gyro_bias_true": gyro.bias[k - 1],
              "accel_bias_true": accel.bias[k - 1], **arrays}
    P = series.pop("P")
    error = error_state(series["lat"], series["lon"], series["h"], series["v_n"], series["q_nb"], series["gyro_bias"],
                        series["accel_bias"], truth.lat[k], truth.lon[k], truth.h[k], truth.v_n[k], truth.q_nb[k],
                        series["gyro_bias_true"], series["accel_bias_true"])
    parts = [error]
    if layout.scale >= 0:  # scale-factor states: s_true = diag((I + S)(I + M)) − 1
        parts += [np.diag(gyro.matrix) - 1.0 - series["gyro_scale_factor"], np.diag(accel.matrix) - 1.0 - series["accel_scale_factor"]]
    if layout.mounting >= 0:
        parts.append(mounting_error(series["q_bs"], q_BS_true))
    series["gravity_disturbance_true"] = truth.gravity_disturbance[k]
    if layout.gravity >= 0:  # consider states: the truth itself, carried from its NED to the estimate's (as the filter
        C = carried_ned(truth.lat[k], truth.lon[k], series["lat"], series["lon"])  # shows them; any angle at a pole)
        parts.append(np.einsum("...ij,...j->...i", C, series["gravity_disturbance_true"]))
    if layout.refraction >= 0:
        parts.append(np.asarray(refraction_true, dtype=float)[:, None])
    series["state_names"] = np.array(state_names(layout))
    series["error_state"] = np.concatenate(parts, axis=1)
    series["error_sigma"] = np.sqrt(np.diagonal(P, axis1=1, axis2=2))
    series["covariance_final"] = P[-1].copy()
    series["position_error_m"] = ned_offset(series["lat"], series["lon"], series["h"], truth.lat[k], truth.lon[k], truth.h[k])
    series["track_error_m"] = track_metres(series["position_error_m"][:, :2], series["v_n_true"], series["q_nb_true"])
    series["nees"] = nees(P, series["error_state"])
    return series


def magnitudes(series):
    """{quantity: per-frame magnitude} of a navigation series: horizontal, vertical, along- and cross-track position
    [m] and velocity [m/s] errors, tilt and heading errors [rad]."""
    e, p = series["error_state"], series["position_error_m"]
    return {"horizontal": np.hypot(p[:, 0], p[:, 1]), "vertical": np.abs(p[:, 2]),
            "along_track": np.abs(series["track_error_m"][:, 0]), "cross_track": np.abs(series["track_error_m"][:, 1]),
            "velocity_horizontal": np.hypot(e[:, 3], e[:, 4]), "velocity_vertical": np.abs(e[:, 5]),
            "tilt": np.hypot(e[:, 0], e[:, 1]), "heading": np.abs(e[:, HEADING])}


def summarize(scenario, seed, series, grid):
    """The navigation run's :class:`~navsim.records.RunSummary` over the frames after ``settle_s``."""
    t = series["t"]
    steady = t >= scenario["settle_s"]
    size = magnitudes(series)

    def stats(x, scale=1.0):
        x = x / scale
        return {"final": float(x[-1]), "rms": float(np.sqrt(np.mean(x[steady] ** 2))), "max": float(np.max(x[steady]))}

    nmi = stats(size["horizontal"], units.NAUTICAL_MILE)
    nmi["final_per_hour"] = nmi["final"] / (float(t[-1]) / units.HOUR)
    e, sigma = series["error_state"], series["error_sigma"]
    nis_frames = np.isfinite(series["nis"]) & steady
    measurements, accepted = int(series["n_measurements"].sum()), int(series["n_accepted"].sum())
    aiding = [kind for kind, present in (("star_sensor", "star_sensor" in scenario.data),
                                         ("position", "position" in scenario["aiding"]), ("baro", "baro" in scenario.data))
              if present]
    return RunSummary(
        scenario=scenario.name, seed=seed, duration_s=scenario["duration_s"], frames=int(t.size), settle_s=scenario["settle_s"],
        navigation={"imu_rate_hz": scenario["imu"]["rate_hz"], "frame_rate_hz": 1.0 / (grid.ratio * grid.dt),
                    "aiding": aiding, "filter_states": int(e.shape[1]), "epoch_utc": scenario["epoch_utc"]},
        position_error_m={"horizontal": stats(size["horizontal"]), "vertical": stats(size["vertical"]),
                          "along_track": stats(size["along_track"]), "cross_track": stats(size["cross_track"])},
        position_error_nmi={"horizontal": nmi},
        velocity_error_m_per_s={"horizontal": stats(size["velocity_horizontal"]), "vertical": stats(size["velocity_vertical"])},
        tilt_error_arcsec=stats(size["tilt"], units.ARCSEC), heading_error_arcsec=stats(size["heading"], units.ARCSEC),
        position_sigma_final_m=[float(v) for v in np.abs(ned_metres(sigma[-1, POSITION]))],
        bias_error_final_deg_per_h=[float(v) for v in units.rad_per_s_to_deg_per_h(e[-1, GYRO_BIAS])],
        accel_bias_error_final_micro_g=[float(v) for v in e[-1, ACCEL_BIAS] / MICRO_G],
        imu_calibration=imu_calibration(series),
        nees=nees_statistics(series["nees"][steady], e.shape[1]),
        divergence=divergence(e[steady], sigma[steady]),
        nis={"mean_per_dof": float(np.sum(series["nis"][nis_frames]) / max(int(np.sum(series["nis_dof"][nis_frames])), 1))},
        updates={"frames_with_measurements": int(np.count_nonzero(series["n_measurements"])),
                 "measurements": measurements, "accepted": accepted, "rejected": measurements - accepted},
    )


def imu_calibration(series):
    """The IMU error states and the star-sensor mounting at the end of the run: for each, truth,
    estimate and σ per axis and the normalised error (estimate − truth)/σ (deg/h, µg, ppm, arcsec;
    the mounting's estimate and truth are its misalignment from the nominal mounting)."""
    e, sigma = series["error_state"][-1], series["error_sigma"][-1]
    groups = [("gyro_bias_deg_per_h", GYRO_BIAS, series["gyro_bias"][-1], units.DEG / units.HOUR),
              ("accel_bias_micro_g", ACCEL_BIAS, series["accel_bias"][-1], MICRO_G)]
    if group(series, "dsg_x") is not None:
        groups += [("gyro_scale_factor_ppm", group(series, "dsg_x"), series["gyro_scale_factor"][-1], units.PPM),
                   ("accel_scale_factor_ppm", group(series, "dsa_x"), series["accel_scale_factor"][-1], units.PPM)]
    if group(series, "mu_x") is not None:
        groups.append(("mounting_arcsec", group(series, "mu_x"), series["mounting_estimate"][-1], units.ARCSEC))
    out = {}
    for name, span, estimate, unit in groups:
        true = estimate + e[span]  # the IMU error states are true − estimate
        out[name] = {"true": [float(v) for v in true / unit], "estimate": [float(v) for v in estimate / unit],
                     "sigma": [float(v) for v in sigma[span] / unit],
                     "normalised_error": [float(v) for v in (estimate - true) / sigma[span]]}
    return out
