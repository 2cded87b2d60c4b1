"""One simulation run at vector fidelity: truth -> gyro -> MEKF with star-sensor updates -> log.

Random sub-streams (numpy SeedSequence(seed).spawn, in this fixed order): 0 gyro,
1 star sensor, 2 filter initial error. The same seed gives the same numbers in one process,
a pool or a cluster.
"""

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from navsim import build
from navsim import quaternion as quat
from navsim import units
from navsim.scenario import Scenario, load_scenario, scenario_from_dict
from navsim.star_sensor import AttitudeFixSensor
from navsim.truth import interval_mean_rates
from startrack.star_catalog import load_star_catalog

NEES_DOF = 6


@dataclass(frozen=True)
class RunResult:
    """``summary``: JSON-ready metrics; ``series``: arrays logged at every star-sensor frame."""

    summary: dict
    series: dict


def resolve_scenario(scenario, overrides=()):
    """A :class:`Scenario` from a path, a dictionary or a Scenario, with overrides applied."""
    if isinstance(scenario, Scenario):
        if overrides:
            return scenario_from_dict(scenario.data, overrides, source=scenario.source)
        return scenario
    if isinstance(scenario, dict):
        return scenario_from_dict(scenario, overrides)
    return load_scenario(Path(scenario), overrides)


def run(scenario, seed=None, overrides=(), star_catalog=None):
    """Simulate one run; ``seed`` overrides the scenario's. Returns a :class:`RunResult`.

    ``overrides`` is a dict {"gyro.rate_hz": 200} or a list of "key=value" strings.
    ``star_catalog`` (a startrack StarCatalog) is loaded from the scenario epoch when needed.
    """
    started = time.perf_counter()
    scenario = resolve_scenario(scenario, overrides)
    seed = scenario["seed"] if seed is None else int(seed)
    gyro_ss, sensor_ss, init_ss = np.random.SeedSequence(seed).spawn(3)

    gyro_hz = scenario["gyro"]["rate_hz"]
    ratio = int(round(gyro_hz / scenario["star_sensor"]["rate_hz"]))
    factor = int(round(scenario["truth"]["rate_hz"] / gyro_hz))
    n_gyro = int(round(scenario["duration_s"] * gyro_hz))
    n_frames = n_gyro // ratio
    dt = 1.0 / gyro_hz

    q0 = quat.normalize(scenario["truth"]["initial_q_IB"])
    t_truth = np.arange(n_gyro * factor + 1) / (gyro_hz * factor)
    q_truth, _ = build.truth_profile(scenario).simulate(t_truth, q0)
    gyro = build.gyro_model(scenario)
    record = gyro.measure(interval_mean_rates(q_truth, factor, dt), gyro_ss)
    q_true = q_truth[::factor]

    if scenario["star_sensor"]["measurement"] == "stars" and star_catalog is None:
        star_catalog = load_star_catalog(epoch=scenario["epoch_jyear"])
    sensor = build.star_sensor(scenario, star_catalog)
    q_BS, _ = build.mounting(scenario)
    R_BS = quat.to_matrix(q_BS)

    P0 = build.initial_covariance(scenario, gyro)
    init_rng = np.random.default_rng(init_ss)
    dtheta0 = np.sqrt(np.diag(P0)[0:3]) * init_rng.standard_normal(3)
    filt = build.attitude_filter(scenario, gyro, quat.multiply(q_true[0], quat.from_rotation_vector(dtheta0)), P0)
    sensor_rng = np.random.default_rng(sensor_ss)
    meas_scale = scenario["filter"]["measurement_noise_scale"] ** 2

    n = filt.n
    frame_k = np.arange(1, n_frames + 1) * ratio  # gyro sample index of each frame
    measurements = sensor.observe_frames(q_true[frame_k], sensor_rng)
    fix_mode = isinstance(sensor, AttitudeFixSensor)
    R_S = meas_scale * sensor.R_S if fix_mode else None
    sigma = np.sqrt(meas_scale) * sensor.sigma if not fix_mode else None
    log = {
        "t": frame_k * dt,
        "q_true": q_true[frame_k],
        "q_est": np.empty((n_frames, 4)),
        "bias_true": record.bias[frame_k - 1],
        "bias_est": np.empty((n_frames, 3)),
        "P": np.empty((n_frames, n, n)),
        "n_measurements": np.zeros(n_frames, dtype=np.int32),
        "n_accepted": np.zeros(n_frames, dtype=np.int32),
        "nis": np.full(n_frames, np.nan),
        "nis_dof": np.zeros(n_frames, dtype=np.int32),
        "innovation_rms": np.full(n_frames, np.nan),
    }
    omega = record.omega
    for j in range(n_frames):
        filt.predict(omega[j * ratio : (j + 1) * ratio], dt)
        if fix_mode:
            result = filt.update_attitude(measurements[j], R_S)
        else:
            ref_I, obs_S, _ = measurements.frame(j)
            result = filt.update_stars(ref_I, obs_S, sigma) if len(ref_I) else None
        if result is not None:
            accepted = result.accepted
            n_accepted = np.count_nonzero(accepted)
            log["n_measurements"][j] = accepted.size
            log["n_accepted"][j] = n_accepted
            if n_accepted:
                z = result.z[accepted].ravel()
                log["nis"][j] = np.dot(result.nis, accepted)
                log["nis_dof"][j] = (3 if fix_mode else 2) * n_accepted
                log["innovation_rms"][j] = np.sqrt(np.dot(z, z) / z.size)
        log["q_est"][j] = filt.q
        log["bias_est"][j] = filt.b
        log["P"][j] = filt.P
    log["attitude_error"] = quat.attitude_error(log["q_est"], log["q_true"])
    summary = summarize(scenario, seed, log, R_BS)
    summary["wall_seconds"] = round(time.perf_counter() - started, 4)
    series = {key: value for key, value in log.items() if key != "P"}
    series["P_diag"] = np.diagonal(log["P"], axis1=1, axis2=2).copy()
    series["nees"] = nees(log)
    return RunResult(summary=summary, series=series)


def nees(log):
    """Normalised estimation error squared of attitude and bias (6 dof) at every frame."""
    e = np.concatenate([log["attitude_error"], log["bias_true"] - log["bias_est"]], axis=1)
    P = log["P"][:, :NEES_DOF, :NEES_DOF]
    return np.einsum("ni,ni->n", e, np.linalg.solve(P, e[..., None])[..., 0])


def summarize(scenario, seed, log, R_BS):
    """The metrics of summary.json (arcsec, deg/h) over the frames after ``settle_s``."""
    t = log["t"]
    steady = t >= scenario["settle_s"]
    err_B = log["attitude_error"]
    err_S = err_B @ R_BS  # rows R_BSᵀ δθ: sensor axes
    arcsec = units.rad_to_arcsec

    def rms(x):
        return float(np.sqrt(np.mean(np.square(x[steady]))))

    eps = nees(log)
    lo, hi = chi2.ppf([0.025, 0.975], NEES_DOF)
    nis_frames = np.isfinite(log["nis"]) & steady
    sigma_att = np.sqrt(np.diagonal(log["P"][-1])[0:3])
    accepted = int(log["n_accepted"].sum())
    return {
        "scenario": scenario.name,
        "seed": seed,
        "duration_s": scenario["duration_s"],
        "fidelity": scenario["star_sensor"]["fidelity"],
        "measurement": scenario["star_sensor"]["measurement"],
        "gyro_rate_hz": scenario["gyro"]["rate_hz"],
        "star_sensor_rate_hz": scenario["star_sensor"]["rate_hz"],
        "frames": int(t.size),
        "settle_s": scenario["settle_s"],
        "attitude_error_rms_arcsec": {
            axis: float(arcsec(rms(err_B[:, i]))) for i, axis in enumerate("xyz")
        },
        "cross_boresight_rms_arcsec": float(arcsec(rms(np.hypot(err_S[:, 0], err_S[:, 1])))),
        "roll_rms_arcsec": float(arcsec(rms(err_S[:, 2]))),
        "attitude_sigma_final_arcsec": [float(v) for v in arcsec(sigma_att)],
        "bias_error_final_deg_per_h": [
            float(v) for v in units.rad_per_s_to_deg_per_h(log["bias_true"][-1] - log["bias_est"][-1])
        ],
        "nees": {
            "dof": NEES_DOF,
            "mean": float(np.mean(eps[steady])),
            "band_95": [float(lo), float(hi)],
            "fraction_in_band": float(np.mean((eps[steady] >= lo) & (eps[steady] <= hi))),
        },
        "nis": {
            "mean_per_dof": float(np.sum(log["nis"][nis_frames]) / max(int(np.sum(log["nis_dof"][nis_frames])), 1)),
        },
        "updates": {
            "frames_with_measurements": int(np.count_nonzero(log["n_measurements"])),
            "measurements": int(log["n_measurements"].sum()),
            "accepted": accepted,
            "rejected": int(log["n_measurements"].sum()) - accepted,
        },
    }
