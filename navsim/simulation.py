"""One simulation run at vector fidelity: truth -> gyro -> MEKF with star-sensor updates -> log.

Random sub-streams (numpy SeedSequence(seed).spawn, in this fixed order): 0 gyro,
1 star sensor, 2 filter initial error. The same seed gives the same numbers in one process,
a pool or a cluster.
"""

import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from navsim.closed_loop import (
    MODES,
    ImageSensor,
    dim_star_statistics,
    mode_statistics,
    paper000_comparison,
    paper000_notes,
    paper004_comparison,
    paper004_notes,
    probe_statistics,
    run_image_loop,
)
from navsim.estimation import kernels
from navsim.scenario import Scenario, build, resolve_scenario
from navsim.sensors import faults
from navsim.sensors.star_vector import AttitudeFixSensor
from navsim.studies import STUDIES, StudyResult
from navsim.truth.profiles import interval_mean_rates
from startrack import rotation as rot
from startrack import units
from startrack.attitude_angles import quaternion_from_radec_roll
from startrack.errors import InputError
from startrack.star_catalog import load_star_catalog

NEES_DOF = 6


@dataclass(frozen=True)
class RunResult:
    """``summary``: JSON-ready metrics; ``series``: arrays logged at every star-sensor frame;
    ``scenario``: the validated scenario (units in key names) the run used; ``sample_frame``: one
    rendered frame with its detections and identifications (image fidelity)."""

    summary: dict
    series: dict
    scenario: dict
    sample_frame: dict | None = None


@dataclass(frozen=True)
class Prepared:
    """The seed-free part of a scenario, computed once and shared by all runs of a batch:
    the truth on the gyro grid, the interval-mean rates the gyro integrates, and the models."""

    scenario: Scenario
    t_gyro: np.ndarray
    q_true: np.ndarray
    omega_mean: np.ndarray
    ratio: int
    dt: float
    n_frames: int
    gyro: object
    sensor: object
    R_BS: np.ndarray
    q_BS_true: np.ndarray
    image_sensor: object = None


def initial_attitude(scenario):
    """q_IB at t = 0: ``truth.initial_radec_roll_deg`` (boresight RA, Dec, roll through the nominal
    mounting) when given, else ``truth.initial_q_IB``."""
    radec_roll = scenario["truth"]["initial_radec_roll_deg"]
    if radec_roll is None:
        return rot.normalize(scenario["truth"]["initial_q_IB"])
    q_IS = quaternion_from_radec_roll(*np.radians(radec_roll))
    q_BS, _ = build.mounting(scenario)
    return rot.normalize(rot.multiply(q_IS, rot.conjugate(q_BS)))


def prepare(scenario, overrides=(), star_catalog=None):
    """Validate ``scenario`` and compute everything that does not depend on the seed."""
    scenario = resolve_scenario(scenario, overrides)
    scenario.require_simulation("a simulation run")
    gyro_hz = scenario["gyro"]["rate_hz"]
    ratio = int(round(gyro_hz / scenario["star_sensor"]["rate_hz"]))
    factor = int(round(scenario["truth"]["rate_hz"] / gyro_hz))
    n_gyro = int(round(scenario["duration_s"] * gyro_hz))
    dt = 1.0 / gyro_hz
    q0 = initial_attitude(scenario)
    t_truth = np.arange(n_gyro * factor + 1) / (gyro_hz * factor)
    q_truth, _ = build.truth_profile(scenario).simulate(t_truth, q0)
    if scenario["star_sensor"]["measurement"] == "stars" and star_catalog is None:
        star_catalog = load_star_catalog(epoch=scenario["epoch_jyear"])
    q_BS, q_BS_true = build.mounting(scenario)
    image = scenario["star_sensor"]["fidelity"] == "image"
    return Prepared(
        scenario=scenario,
        t_gyro=np.arange(n_gyro + 1) * dt,
        q_true=q_truth[::factor],
        omega_mean=interval_mean_rates(q_truth, factor, dt),
        ratio=ratio,
        dt=dt,
        n_frames=n_gyro // ratio,
        gyro=build.gyro_model(scenario),
        sensor=None if image else build.star_sensor(scenario, star_catalog),
        R_BS=rot.to_matrix(q_BS),
        q_BS_true=q_BS_true,
        image_sensor=ImageSensor.build(scenario, star_catalog) if image else None,
    )


def simulate(prepared, seed):
    """The seeded part of one run on a :class:`Prepared` scenario. Returns a :class:`RunResult`."""
    started = time.perf_counter()
    p = prepared
    scenario = p.scenario
    gyro_ss, sensor_ss, init_ss = np.random.SeedSequence(seed).spawn(3)
    record = p.gyro.measure(p.omega_mean, gyro_ss)
    omega_measured, bias_true = faults.apply_bias_steps(record.omega, record.bias, p.t_gyro[1:],
                                                        scenario["faults"]["gyro_bias_steps"])
    P0 = build.initial_covariance(scenario, p.gyro)
    dtheta0 = np.sqrt(np.diag(P0)[0:3]) * np.random.default_rng(init_ss).standard_normal(3)
    filt = build.attitude_filter(scenario, p.gyro, rot.multiply(p.q_true[0], rot.from_rotation_vector(dtheta0)), P0)
    frame_k = np.arange(1, p.n_frames + 1) * p.ratio  # gyro sample index of each frame
    t_frames = p.t_gyro[frame_k]
    log = {"t": t_frames, "q_true": p.q_true[frame_k], "bias_true": bias_true[frame_k - 1]}
    extras = {}
    if p.image_sensor is None:
        measurements = p.sensor.observe_frames(p.q_true[frame_k], np.random.default_rng(sensor_ss))
        meas_scale = scenario["filter"]["measurement_noise_scale"] ** 2
        available = faults.frames_available(t_frames, scenario["faults"], p.ratio * p.dt)
        log.update(run_vector_filter(filt, omega_measured[: p.n_frames * p.ratio], p.ratio, p.dt, p.sensor,
                                     measurements, meas_scale, available))
    else:
        image_log, extras = run_image_loop(p, filt, omega_measured, frame_k, p.omega_mean[frame_k - 1], sensor_ss)
        log.update(image_log)
    log["attitude_error"] = rot.attitude_error(log["q_est"], log["q_true"])
    log["nees"] = nees(log)
    summary = summarize(scenario, seed, log, p.R_BS)
    if p.image_sensor is not None:
        summary["identification"] = mode_statistics(log, extras["transitions"])
        summary["modes"] = list(MODES)
        probes = probe_statistics(extras["probes"])
        if probes is not None:
            summary["tracking_failure_probes"] = probes
            summary["paper_comparison"] = paper000_comparison(probes)
            summary["notes"] = paper000_notes(probes)
        if extras["shadow_q_est"] is not None or any(extras["solver_errors"].values()):
            shadow_error = None
            if extras["shadow_q_est"] is not None:
                shadow_error = rot.attitude_error(extras["shadow_q_est"], log["q_true"])
                log["attitude_error_without_stacking"] = shadow_error
            dim = dim_star_statistics(extras, log["attitude_error"], shadow_error, log["t"] >= scenario["settle_s"])
            summary["dim_star"] = dim
            summary["paper_comparison"] = summary.get("paper_comparison", []) + paper004_comparison(dim)
            summary["notes"] = summary.get("notes", []) + paper004_notes(dim)
    summary["wall_seconds"] = round(time.perf_counter() - started, 4)
    series = {key: value for key, value in log.items() if key != "P"}
    series["P_diag"] = np.diagonal(log["P"], axis1=1, axis2=2).copy()
    return RunResult(summary=summary, series=series, scenario=scenario.data, sample_frame=extras.get("sample_frame"))


def run(scenario, seed=None, overrides=(), star_catalog=None):
    """Simulate one run; ``seed`` overrides the scenario's. Returns a :class:`RunResult`.

    ``overrides`` is a dict {"gyro.rate_hz": 200} or a list of "key=value" strings.
    ``star_catalog`` (a startrack StarCatalog) is loaded from the scenario epoch when needed.
    """
    started = time.perf_counter()
    prepared = prepare(scenario, overrides, star_catalog)
    result = simulate(prepared, prepared.scenario["seed"] if seed is None else int(seed))
    result.summary["wall_seconds"] = round(time.perf_counter() - started, 4)
    return result


def run_study(scenario, seed=None, overrides=(), progress=False):
    """Run a static study (a scenario with a ``[study]`` table, :mod:`navsim.studies`); ``seed``
    overrides the scenario's. Returns a :class:`~navsim.studies.StudyResult`."""
    started = time.perf_counter()
    scenario = resolve_scenario(scenario, overrides)
    if not scenario.is_study:
        raise InputError(f"{scenario.source}: a simulation scenario, not a static study; run it with navsim.run")
    seed = scenario["seed"] if seed is None else int(seed)
    kind = scenario["study"]["kind"]
    summary, arrays = STUDIES[kind].run(scenario.study_parameters, seed, progress)
    summary = {"scenario": scenario.name, "study": kind, "seed": seed} | summary
    summary["wall_seconds"] = round(time.perf_counter() - started, 4)
    return StudyResult(scenario=scenario.data, summary=summary, arrays=arrays)


def run_batch(scenario, seeds, overrides=(), star_catalog=None, threads=1):
    """Many runs of one scenario sharing its seed-free part (truth, models, catalog): a batch of
    one equals :func:`run` with that seed. The compiled filter loop releases the GIL, so
    ``threads`` > 1 runs members concurrently. Returns the list of :class:`RunResult`."""
    prepared = prepare(scenario, overrides, star_catalog)
    if threads <= 1:
        return [simulate(prepared, int(seed)) for seed in seeds]
    with ThreadPoolExecutor(max_workers=threads) as pool:
        return list(pool.map(lambda seed: simulate(prepared, int(seed)), seeds))


def run_vector_filter(filt, omega, ratio, dt, sensor, measurements, meas_scale=1.0, available=None):
    """Run ``filt`` over a whole record in compiled code (:func:`navsim.estimation.kernels.run_filter`).

    ``omega`` (F*ratio, 3) gyro samples; ``measurements``: the sensor's ``observe_frames`` output
    (q_IS per frame for an :class:`AttitudeFixSensor`, else :class:`StarFrames`); the sensor's
    noise is scaled by ``meas_scale`` (variance factor) in the filter's R; frames not ``available``
    (outages, dropped frames) only propagate. Returns the per-frame log arrays and leaves ``filt`` in
    its final state.
    """
    fix_mode = isinstance(sensor, AttitudeFixSensor)
    n_frames = omega.shape[0] // ratio
    if fix_mode:
        q_meas, R_S = np.ascontiguousarray(measurements), meas_scale * sensor.R_S
        offsets, ref_I, obs_S, variance = np.zeros(n_frames + 1, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0)
    else:
        q_meas, R_S = np.zeros((n_frames, 4)), np.zeros((3, 3))
        offsets = measurements.offsets.astype(np.int64)
        ref_I = np.ascontiguousarray(measurements.ref_I)
        obs_S = np.ascontiguousarray(measurements.obs_S)
        variance = np.full(len(ref_I), meas_scale * sensor.sigma**2)
    available = np.ones(n_frames, dtype=np.bool_) if available is None else np.asarray(available, dtype=np.bool_)
    out = kernels.run_filter(
        filt.q, filt.b, filt.s, filt.q_BS, filt.P, np.ascontiguousarray(omega), ratio, dt,
        filt.arw, filt.rrw, filt.scale_factor_rw, filt.process_noise_scale, filt.sf_start, filt.mis_start,
        fix_mode, q_meas, R_S, offsets, ref_I, obs_S, variance, filt.gate[3 if fix_mode else 2], available,
    )
    names = ("q_est", "bias_est", "P", "n_measurements", "n_accepted", "nis", "nis_dof", "innovation_rms")
    log = dict(zip(names, out))
    filt.q, filt.b, filt.P = log["q_est"][-1].copy(), log["bias_est"][-1].copy(), log["P"][-1].copy()
    return log


def nees(log):
    """Normalised estimation error squared of attitude and bias (6 dof) at every frame."""
    e = np.concatenate([log["attitude_error"], log["bias_true"] - log["bias_est"]], axis=1)
    return kernels.quadratic_forms(np.ascontiguousarray(log["P"][:, :NEES_DOF, :NEES_DOF]), e)


def summarize(scenario, seed, log, R_BS):
    """The metrics of summary.json (arcsec, deg/h) over the frames after ``settle_s``."""
    t = log["t"]
    steady = t >= scenario["settle_s"]
    err_B = log["attitude_error"]
    err_S = err_B @ R_BS  # rows R_BSᵀ δθ: sensor axes
    arcsec = units.rad_to_arcsec

    def rms(x):
        return float(np.sqrt(np.mean(np.square(x[steady]))))

    eps = log["nees"]
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
