"""Attitude runs (a star sensor and a gyro on a truth attitude profile): the seed-free preparation of a
scenario, then seeded runs through the closed loop (:func:`navsim.closed_loop.run_loop`).

Random sub-streams (numpy ``SeedSequence(seed).spawn(3)``, in this fixed order): 0 gyro, 1 star
sensor, 2 filter initial error. At vector fidelity the star sensor draws its noise from stream 1
directly; at image fidelity stream 1 spawns four, all before the first frame
(:func:`navsim.star_run.start_image`). The same seed gives the same numbers in one process, a pool or
a cluster.
"""

import time
from dataclasses import dataclass

import numpy as np

from navsim import star_run
from navsim.attitude import build
from navsim.attitude.records import RunSummary
from navsim.build import faults
from navsim.build.star_sensor import observers, star_sensor
from navsim.closed_loop import FrameGrid, run_loop
from navsim.estimation.attitude_filter import AttitudeFilter
from navsim.estimation.consistency import nees, nees_statistics
from navsim.pooling import divergence
from navsim.records import RunResult
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.faults import apply_bias_steps
from navsim.truth.profiles import sample_truth
from startrack import InputError, load_star_catalog, units
from startrack import rotation as rot

#: The attitude filter's NEES is over its attitude and gyro-bias errors.
NEES_DOF = 6
#: The lanes of a run compiled ahead (:mod:`startrack.compiled.compile_ahead`) at image fidelity, balanced on two cores
#: (40-46 s each on the test machine, benchmarks/cold_start.py): the identifier's pattern searches and the
#: position fit, against the inertial sensor, the filter and tracking (which loads what the first lane
#: compiled before it gets there).
IMAGE_LANES = (("startrack.compile_tasks:pattern_search", "startrack.compile_tasks:psf_fit"),
               ("navsim.sensors.warmup:inertial_sensors", "navsim.estimation.warmup:attitude_filter",
                "startrack.compile_tasks:star_tracking"))
#: At vector fidelity: one lane (compiling ahead then only says what is compiled, once).
VECTOR_LANES = (("navsim.sensors.warmup:inertial_sensors", "navsim.estimation.warmup:attitude_filter"),)
#: The error sources a run can switch off in the truth alone: none (an error budget is the navigation kind's).
TRUTH_SOURCES = {}


@dataclass(frozen=True)
class Prepared:
    """The seed-free part of a scenario, computed once and shared by all runs of a batch: the truth
    on the gyro grid, the frame grid, and the gyro, star sensor and observers built in SI units."""

    scenario: object
    truth: object
    grid: FrameGrid
    gyro: object
    sensor: object
    observers: tuple
    bias_steps: tuple
    attitude_jumps: tuple
    R_BS: np.ndarray


def check_truth_off(scenario, truth_off):
    """An attitude run switches no error source off in its truth alone: any ``truth_off`` is an InputError."""
    if truth_off:
        raise InputError(f"{scenario.source}: truth_off needs a navigation scenario")
    return frozenset()


def lanes(scenario):
    """The compile-ahead lanes of a run of ``scenario``."""
    return IMAGE_LANES if scenario["star_sensor"]["fidelity"] == "image" else VECTOR_LANES


def prepare(scenario, star_catalog=None, truth_off=frozenset()):
    """Everything of a validated attitude scenario that does not depend on the seed; ``star_catalog`` (a
    startrack StarCatalog) is loaded at the scenario's epoch when the sensor measures stars."""
    check_truth_off(scenario, truth_off)
    gyro_hz = scenario["gyro"]["rate_hz"]
    ratio = int(round(gyro_hz / scenario["star_sensor"]["rate_hz"]))
    factor = int(round(scenario["truth"]["rate_hz"] / gyro_hz))
    n_gyro = int(round(scenario["duration_s"] * gyro_hz))
    truth = sample_truth(build.truth_profile(scenario), build.initial_attitude(scenario), n_gyro, gyro_hz, factor)
    if scenario["star_sensor"]["measurement"] == "stars" and star_catalog is None:
        star_catalog = load_star_catalog(epoch=scenario["epoch_jyear"])
    grid = FrameGrid(dt=1.0 / gyro_hz, ratio=ratio, n_frames=n_gyro // ratio)
    sensor = star_sensor(scenario, star_catalog, ratio * grid.dt, scenario["epoch_jyear"], lanes(scenario))
    q_BS, _ = mounting(scenario["star_sensor"])
    return Prepared(scenario=scenario, truth=truth, grid=grid, gyro=build.gyro(scenario), sensor=sensor,
                    observers=observers(scenario, sensor), bias_steps=faults.bias_steps(scenario["faults"]),
                    attitude_jumps=faults.attitude_jumps(scenario["faults"]), R_BS=rot.to_matrix(q_BS))


def simulate(prepared, seed, compiled=True):
    """The seeded part of one run on a :class:`Prepared` scenario. Returns a
    :class:`~navsim.records.RunResult`. ``compiled=False`` keeps the step-by-step loop where the
    filter's fast path would run."""
    started = time.perf_counter()
    p, scenario, grid = prepared, prepared.scenario, prepared.grid
    gyro_ss, sensor_ss, init_ss = np.random.SeedSequence(seed).spawn(3)
    record = p.gyro.measure(p.truth.omega_mean, gyro_ss)
    omega, bias_true = apply_bias_steps(record.omega, record.bias, p.truth.t[1:], p.bias_steps)
    config = build.filter_config(scenario, p.gyro)
    dtheta0 = np.sqrt(np.diag(config.P0)[0:3]) * np.random.default_rng(init_ss).standard_normal(3)
    if scenario["filter"]["initial_attitude_error_arcsec"] is not None:  # the error δθ: q_est = q_true ⊗ δq(−δθ)
        dtheta0 = -units.arcsec_to_rad(np.asarray(scenario["filter"]["initial_attitude_error_arcsec"], dtype=float))
    filt = AttitudeFilter(rot.multiply(p.truth.q_IB[0], rot.from_rotation_vector(dtheta0)), np.zeros(3), config)
    frame_k = grid.frame_k
    if scenario["star_sensor"]["fidelity"] == "image":
        sensor_run, observer_runs, jumps = star_run.start_image(p.sensor, sensor_ss, grid.n_frames, filt, p.observers,
                                                                p.attitude_jumps)
    else:
        observer_runs, jumps = [], None
        sensor_run = p.sensor.start(sensor_ss, p.truth.q_IB[frame_k], p.truth.t[frame_k])
    log = run_loop(filt, sensor_run, omega, p.truth, grid, jumps, observer_runs, compiled)
    series = {"t": p.truth.t[frame_k], "q_true": p.truth.q_IB[frame_k], "bias_true": bias_true[frame_k - 1], **log.arrays}
    series["attitude_error"] = rot.attitude_error(series["q_est"], series["q_true"])
    series["nees"] = nees(series["P"][:, :NEES_DOF, :NEES_DOF],
                          np.concatenate([series["attitude_error"], series["bias_true"] - series["bias_est"]], axis=1))
    summary = summarize(scenario, seed, series, p.R_BS).replace(gyro_calibration=calibration_summary(filt, record.matrix))
    summary, timing = star_run.finish(summary, series, log, observer_runs, series["t"] >= scenario["settle_s"])
    summary = summary.replace(timing={"wall_seconds": round(time.perf_counter() - started, 4), **timing})
    series["P_diag"] = np.diagonal(series.pop("P"), axis1=1, axis2=2).copy()
    return RunResult(summary=summary, series=series, scenario=scenario.data, sample_frame=sensor_run.sample,
                     timing_series=log.timing)


#: Calibration groups of the gyro error matrix K: (name in the summary, flat indices in K, unit).
CALIBRATION_GROUPS = {"scale_factor": ("scale_factor_ppm", [0, 4, 8], units.PPM),
                      "gyro_misalignment": ("misalignment_arcsec", [1, 2, 3, 5, 6, 7], units.ARCSEC)}


def calibration_summary(filt, matrix_true):
    """The gyro calibration states the filter carries at the end of the run: truth (from the gyro's
    (I + S)(I + M) − I), estimate and σ, in ppm / arcsec, and the errors normalised by σ; None
    without calibration states."""
    K_true, K_est, P = (np.asarray(matrix_true) - np.eye(3)).ravel(), filt.K.ravel(), filt.P
    out = {}
    for group, span in filt.calibration_slices().items():
        if group not in CALIBRATION_GROUPS:
            continue
        name, flat, unit = CALIBRATION_GROUPS[group]
        sigma = np.sqrt(np.diag(P)[span])
        out[name] = {"true": [float(v) for v in K_true[flat] / unit], "estimate": [float(v) for v in K_est[flat] / unit],
                     "sigma": [float(v) for v in sigma / unit],
                     "normalised_error": [float(v) for v in (K_est[flat] - K_true[flat]) / sigma]}
    return out or None


def summarize(scenario, seed, series, R_BS):
    """The run's :class:`~navsim.attitude.records.RunSummary` (arcsec, deg/h) over the frames after ``settle_s``."""
    t = series["t"]
    steady = t >= scenario["settle_s"]
    err_B = series["attitude_error"]
    err_S = err_B @ R_BS  # rows R_BSᵀ δθ: sensor axes

    def rms_arcsec(x):
        return float(units.rad_to_arcsec(np.sqrt(np.mean(np.square(x[steady])))))

    nis_frames = np.isfinite(series["nis"]) & steady
    sigma_att = np.sqrt(np.diagonal(series["P"][-1])[0:3])
    measurements, accepted = int(series["n_measurements"].sum()), int(series["n_accepted"].sum())
    return RunSummary(
        scenario=scenario.name, seed=seed, duration_s=scenario["duration_s"],
        fidelity=scenario["star_sensor"]["fidelity"], measurement=scenario["star_sensor"]["measurement"],
        gyro_rate_hz=scenario["gyro"]["rate_hz"], star_sensor_rate_hz=scenario["star_sensor"]["rate_hz"],
        frames=int(t.size), settle_s=scenario["settle_s"],
        attitude_error_rms_arcsec={axis: rms_arcsec(err_B[:, i]) for i, axis in enumerate("xyz")},
        cross_boresight_rms_arcsec=rms_arcsec(np.hypot(err_S[:, 0], err_S[:, 1])),
        roll_rms_arcsec=rms_arcsec(err_S[:, 2]),
        attitude_sigma_final_arcsec=[float(v) for v in units.rad_to_arcsec(sigma_att)],
        bias_error_final_deg_per_h=[float(v) for v in units.rad_per_s_to_deg_per_h(series["bias_true"][-1] - series["bias_est"][-1])],
        nees=nees_statistics(series["nees"][steady], NEES_DOF),
        divergence=attitude_divergence(series, steady),
        nis={"mean_per_dof": float(np.sum(series["nis"][nis_frames]) / max(int(np.sum(series["nis_dof"][nis_frames])), 1))},
        updates={"frames_with_measurements": int(np.count_nonzero(series["n_measurements"])),
                 "measurements": measurements, "accepted": accepted, "rejected": measurements - accepted},
    )


def attitude_divergence(series, steady):
    """The run's divergence test (:func:`navsim.pooling.divergence`) on the attitude errors of the ``steady`` frames
    against the filter's σ."""
    sigma = np.sqrt(np.diagonal(series["P"], axis1=1, axis2=2)[steady, 0:3])
    return divergence(series["attitude_error"][steady], sigma)


def star_availability(scenario, star_catalog=None):
    """An attitude scenario has no sky (its sensor looks at the stars from nowhere on the Earth): an InputError."""
    raise InputError(f"{scenario.source}: not a navigation scenario (no [trajectory] table): the sky's star availability "
                     "needs an observer on the Earth")


def budget_parts(scenario):
    """An attitude scenario has no error budget (it is the star-aided INS's): an InputError."""
    raise InputError(f"{scenario.source}: not a navigation scenario (no [trajectory] table): an error budget needs a "
                     "star-aided INS")
