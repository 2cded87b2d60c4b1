"""The summary of a spacecraft run (:class:`~navsim.spacecraft.records.RunSummary`) from its series: the attitude
kind's figures, each head's availability and the fused accuracy about its boresight, the orbit, the pointing."""

import numpy as np

from navsim.attitude.run import NEES_DOF, attitude_divergence
from navsim.estimation.consistency import nees_statistics
from navsim.orbit.eclipse import PENUMBRA, UMBRA
from navsim.sensors.star_sensor import MODES
from navsim.spacecraft.exclusion import REASONS
from navsim.spacecraft.records import RunSummary
from startrack import rotation as rot
from startrack import units

ARCSEC = units.ARCSEC


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else float("nan")


def head_accuracy(err_B, R_BS):
    """(cross-boresight, roll) errors (F,) [rad] of the body-axes attitude errors ``err_B`` (F, 3) in a head's axes
    (R_BS S -> B): |δθ_xy| and δθ_z of R_BSᵀ δθ."""
    err_S = err_B @ R_BS
    return np.hypot(err_S[:, 0], err_S[:, 1]), err_S[:, 2]


def heads_summary(prepared, series, sensor_run, filt, steady):
    """Per head: availability, exclusions, stars, the fused accuracy in its axes (cross-boresight |δθ_xy| and roll
    δθ_z RMS, and roll over cross-boresight), its mounting error δm = rotvec(q_BS⁻¹ ⊗ q_BS,true) against the
    estimate's."""
    out = []
    mount = filt.calibration_slices().get("mounting")
    for h, (name, sky) in enumerate(zip(prepared.sensor.names, prepared.frames.heads)):
        cross, roll = head_accuracy(series["attitude_error"][steady], prepared.R_BS[h])
        counts = series["head_measurements"][:, h]
        entry = {"name": name, "frames": int(counts.size), "frames_measured": int(np.count_nonzero(counts)),
                 "availability": float(np.mean(counts > 0)),
                 "excluded_frames": {reason: int(np.sum(sky.reason == k)) for k, reason in enumerate(REASONS)},
                 "measurements_per_frame": float(np.mean(counts)),
                 "cross_boresight_rms_arcsec": _rms(cross) / ARCSEC, "roll_rms_arcsec": _rms(roll) / ARCSEC}
        entry["roll_to_cross_boresight"] = entry["roll_rms_arcsec"] / entry["cross_boresight_rms_arcsec"]
        if "head_mode" in series:
            entry["image"] = image_summary(series, h, sky.reason >= 0)
        if mount is not None and filt.config.mountings[h] != "ignore":
            span = slice(mount.start + 3 * h, mount.start + 3 * h + 3)
            nominal = rot.conjugate(prepared.q_BS[h])
            true = rot.to_rotation_vector(rot.multiply(nominal, sensor_run.q_BS_true[h]))
            estimate = rot.to_rotation_vector(rot.multiply(nominal, filt.q_BS[h]))
            sigma = np.sqrt(np.diag(filt.P)[span])
            entry["mounting_arcsec"] = {"true": [float(v) for v in true / ARCSEC], "estimate": [float(v) for v in estimate / ARCSEC],
                                        "sigma": [float(v) for v in sigma / ARCSEC],
                                        "normalised_error": [float(v) for v in (estimate - true) / sigma]}
        out.append(entry)
    return out


def image_summary(series, h, excluded):
    """Head ``h``'s image chain over the run: frames per mode, identified stars per frame, the particle hits (frames
    with hits, and those of them the head took no star from though the sky let it), the wrong identifications."""
    mode, identified, hits = series["head_mode"][:, h], series["head_identified"][:, h], series["head_hits"][:, h]
    hit = hits > 0
    return {"frames_per_mode": {name: int(np.sum(mode == code)) for code, name in enumerate(MODES) if np.any(mode == code)},
            "identified_per_frame": float(np.mean(identified)), "hits": int(hits.sum()), "frames_with_hits": int(hit.sum()),
            "frames_lost_with_hits": int(np.sum(hit & (identified == 0) & ~excluded)),
            "frames_lost_without_hits": int(np.sum(~hit & (identified == 0) & ~excluded)),
            "wrong_identifications": int(series["head_wrong"][:, h].sum())}


def orbit_summary(prepared, series):
    """The orbit's figures: propagator, heights [km], the time in the Earth's shadow."""
    frames, scenario = prepared.frames, prepared.scenario
    height = (np.linalg.norm(frames.r_I, axis=1) - 6378137.0) / 1e3
    shadowed = np.isin(frames.shadow, (PENUMBRA, UMBRA))
    return {"propagator": scenario["orbit"]["propagator"], "height_km": {"min": float(height.min()), "max": float(height.max())},
            "speed_km_per_s": float(np.mean(np.linalg.norm(frames.v_sat, axis=1)) / 1e3),
            "shadow_fraction": float(np.mean(shadowed)), "umbra_fraction": float(np.mean(frames.shadow == UMBRA))}


def pointing_summary(prepared, steady_t):
    """The pointing law, the truth's error from it [arcsec] after ``steady_t`` [s], body rates, wheels."""
    m, scenario = prepared.motion, prepared.scenario
    control_t = np.arange(len(m.pointing_error)) / scenario["spacecraft"]["controller"]["rate_hz"]
    after = control_t >= steady_t
    error = m.pointing_error[after] / ARCSEC
    return {"law": scenario["pointing"]["law"], "error_rms_arcsec": _rms(error), "error_max_arcsec": float(error.max()),
            "rate_max_deg_per_s": float(np.degrees(np.linalg.norm(m.omega_B, axis=1).max())),
            "wheel_momentum_max_N_m_s": float(np.abs(m.wheel_momentum).max()),
            "wheel_saturated_fraction": float(np.mean(m.saturated))}


def summarize(prepared, seed, series, sensor_run, filt):
    """The run's :class:`~navsim.spacecraft.records.RunSummary` (arcsec, deg/h) over the frames after ``settle_s``;
    ``sensor_run`` the run's :class:`~navsim.sensors.star_heads.HeadsRun` (its heads' true mountings)."""
    scenario = prepared.scenario
    t = series["t"]
    steady = t >= scenario["settle_s"]
    err_B = series["attitude_error"]
    cross, roll = head_accuracy(err_B[steady], prepared.R_BS[0])
    nis_frames = np.isfinite(series["nis"]) & steady
    sigma_att = np.sqrt(np.diagonal(series["P"][-1])[0:3])
    measurements, accepted = int(series["n_measurements"].sum()), int(series["n_accepted"].sum())
    head = scenario["star_sensor"][0]
    return RunSummary(
        scenario=scenario.name, seed=seed, duration_s=scenario["duration_s"], fidelity=head["fidelity"],
        measurement=head["measurement"], gyro_rate_hz=scenario["gyro"]["rate_hz"], star_sensor_rate_hz=head["rate_hz"],
        frames=int(t.size), settle_s=scenario["settle_s"],
        attitude_error_rms_arcsec={axis: _rms(err_B[steady, i]) / ARCSEC for i, axis in enumerate("xyz")},
        cross_boresight_rms_arcsec=_rms(cross) / ARCSEC, roll_rms_arcsec=_rms(roll) / ARCSEC,
        attitude_sigma_final_arcsec=[float(v) for v in sigma_att / ARCSEC],
        bias_error_final_deg_per_h=[float(v) for v in units.rad_per_s_to_deg_per_h(series["bias_true"][-1] - series["bias_est"][-1])],
        nees=nees_statistics(series["nees"][steady], NEES_DOF),
        divergence=attitude_divergence(series, steady),
        nis={"mean_per_dof": float(np.sum(series["nis"][nis_frames]) / max(int(np.sum(series["nis_dof"][nis_frames])), 1))},
        updates={"frames_with_measurements": int(np.count_nonzero(series["n_measurements"])), "measurements": measurements,
                 "accepted": accepted, "rejected": measurements - accepted},
        heads=heads_summary(prepared, series, sensor_run, filt, steady), orbit=orbit_summary(prepared, series),
        pointing=pointing_summary(prepared, scenario["settle_s"]))
