"""Simulation runs: the seed-free preparation of a scenario, then seeded runs through the closed loop.

Attitude runs (a star sensor and a gyro) are here; navigation runs (a ``[trajectory]`` table: the
INS) are :mod:`navsim.ins.simulation`'s, reached through the same :func:`prepare` and :func:`simulate`.

Random sub-streams (numpy ``SeedSequence(seed).spawn(3)``, in this fixed order): 0 gyro, 1 star
sensor, 2 filter initial error. At vector fidelity the star sensor draws its noise from stream 1
directly; at image fidelity stream 1 spawns four, all before the first frame: 0 attitude jumps,
1 false-star storms, 2 rendering, 3 the per-frame observers. The same seed gives the same numbers
in one process, a pool or a cluster.
"""

import dataclasses
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from navsim.closed_loop import FrameGrid, mode_statistics, mode_timing, run_loop
from navsim.estimation.consistency import nees, nees_statistics
from navsim.ins import simulation as navigation
from navsim.records import RunResult, RunSummary
from navsim.scenario import build, resolve_scenario
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors import faults
from navsim.sensors.star_sensor import MODES
from navsim.studies import STUDIES, StudyResult
from navsim.truth.profiles import sample_truth
from startrack import rotation as rot
from startrack import units
from startrack.attitude_angles import quaternion_from_radec_roll
from startrack.errors import InputError
from startrack.star_catalog import load_star_catalog

#: The attitude filter's NEES is over its attitude and gyro-bias errors.
NEES_DOF = 6


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


def initial_attitude(scenario):
    """q_IB at t = 0: ``truth.initial_radec_roll_deg`` (boresight RA, Dec, roll through the nominal
    mounting) when given, else ``truth.initial_q_IB``."""
    radec_roll = scenario["truth"]["initial_radec_roll_deg"]
    if radec_roll is None:
        return rot.normalize(scenario["truth"]["initial_q_IB"])
    q_IS = quaternion_from_radec_roll(*units.deg_to_rad(radec_roll))
    q_BS, _ = mounting(scenario["star_sensor"])
    return rot.normalize(rot.multiply(q_IS, rot.conjugate(q_BS)))


def prepare(scenario, overrides=(), star_catalog=None):
    """Validate ``scenario`` and compute everything that does not depend on the seed."""
    scenario = resolve_scenario(scenario, overrides)
    scenario.require_simulation("a simulation run")
    if scenario.is_navigation:
        return navigation.prepare(scenario, star_catalog)
    gyro_hz = scenario["gyro"]["rate_hz"]
    ratio = int(round(gyro_hz / scenario["star_sensor"]["rate_hz"]))
    factor = int(round(scenario["truth"]["rate_hz"] / gyro_hz))
    n_gyro = int(round(scenario["duration_s"] * gyro_hz))
    truth = sample_truth(build.truth_profile(scenario), initial_attitude(scenario), n_gyro, gyro_hz, factor)
    if scenario["star_sensor"]["measurement"] == "stars" and star_catalog is None:
        star_catalog = load_star_catalog(epoch=scenario.catalog_epoch)
    grid = FrameGrid(dt=1.0 / gyro_hz, ratio=ratio, n_frames=n_gyro // ratio)
    sensor = build.star_sensor(scenario, star_catalog, ratio * grid.dt)
    q_BS, _ = mounting(scenario["star_sensor"])
    return Prepared(scenario=scenario, truth=truth, grid=grid, gyro=build.gyro_model(scenario["gyro"], gyro_hz), sensor=sensor,
                    observers=build.observers(scenario, sensor), bias_steps=faults.bias_steps(scenario["faults"]),
                    attitude_jumps=faults.attitude_jumps(scenario["faults"]), R_BS=rot.to_matrix(q_BS))


def simulate(prepared, seed, compiled=True):
    """The seeded part of one run on a :class:`Prepared` scenario (or a navigation one). Returns a
    :class:`~navsim.records.RunResult`. ``compiled=False`` keeps the step-by-step loop where the
    filter's fast path would run."""
    if isinstance(prepared, navigation.NavigationPrepared):
        return navigation.simulate(prepared, seed, compiled)
    started = time.perf_counter()
    p, scenario, grid = prepared, prepared.scenario, prepared.grid
    gyro_ss, sensor_ss, init_ss = np.random.SeedSequence(seed).spawn(3)
    record = p.gyro.measure(p.truth.omega_mean, gyro_ss)
    omega, bias_true = faults.apply_bias_steps(record.omega, record.bias, p.truth.t[1:], p.bias_steps)
    P0 = build.initial_covariance(scenario, p.gyro)
    dtheta0 = np.sqrt(np.diag(P0)[0:3]) * np.random.default_rng(init_ss).standard_normal(3)
    filt = build.attitude_filter(scenario, p.gyro, rot.multiply(p.truth.q_IB[0], rot.from_rotation_vector(dtheta0)), P0)
    frame_k = grid.frame_k
    if scenario["star_sensor"]["fidelity"] == "image":
        jump_ss, storm_ss, render_ss, observer_ss = sensor_ss.spawn(4)
        observer_rng = np.random.default_rng(observer_ss)
        observers = [spec.start(filt, observer_rng, grid.n_frames) for spec in p.observers]
        full_frames = set().union(*(o.full_frames for o in observers))
        sensor_run = p.sensor.start(np.random.default_rng(storm_ss), np.random.default_rng(render_ss), grid.n_frames,
                                    full_frames)
        jumps = faults.AttitudeJumps(p.attitude_jumps, np.random.default_rng(jump_ss))
    else:
        observers, jumps = [], None
        sensor_run = p.sensor.start(sensor_ss, p.truth.q_IB[frame_k], p.truth.t[frame_k])
    log = run_loop(filt, sensor_run, omega, p.truth, grid, jumps, observers, compiled)
    series = {"t": p.truth.t[frame_k], "q_true": p.truth.q_IB[frame_k], "bias_true": bias_true[frame_k - 1], **log.arrays}
    series["attitude_error"] = rot.attitude_error(series["q_est"], series["q_true"])
    series["nees"] = nees(series["P"][:, :NEES_DOF, :NEES_DOF],
                          np.concatenate([series["attitude_error"], series["bias_true"] - series["bias_est"]], axis=1))
    summary = summarize(scenario, seed, series, p.R_BS).replace(gyro_calibration=calibration_summary(filt, record.matrix))
    timing = {}
    if log.logs_modes:
        summary = summary.replace(identification=mode_statistics(series, log.transitions), modes=list(MODES))
        timing = mode_timing(series["mode"], log.timing)
    summary = _with_findings(summary, series, observers, series["t"] >= scenario["settle_s"], timing)
    summary = summary.replace(timing={"wall_seconds": round(time.perf_counter() - started, 4), **timing})
    series["P_diag"] = np.diagonal(series.pop("P"), axis1=1, axis2=2).copy()
    return RunResult(summary=summary, series=series, scenario=scenario.data, sample_frame=sensor_run.sample,
                     timing_series=log.timing)


def _with_findings(summary, series, observers, steady, timing):
    """The summary with each observer's findings, comparison rows and notes; their series join
    ``series`` and their wall-clock figures ``timing``."""
    findings = [found for found in (observer.finish(series, steady) for observer in observers) if found is not None]
    for found in findings:
        series.update(found.series)
    add_timing(timing, findings)
    if not findings:
        return summary
    return summary.replace(findings={f.key: f.stats for f in findings}, paper_comparison=[r for f in findings for r in f.rows],
                           notes=[n for f in findings for n in f.notes])


def add_timing(timing, findings):
    """Put the findings' wall-clock figures, time comparisons and notes into a summary's ``timing``."""
    for found in findings:
        if found.timing:
            timing[found.key] = found.timing
    rows = [r for f in findings for r in f.timing_rows]
    notes = [n for f in findings for n in f.timing_notes]
    if rows:
        timing["paper_comparison"] = rows
    if notes:
        timing["notes"] = notes


def run(scenario, seed=None, overrides=(), star_catalog=None):
    """Simulate one run; ``seed`` overrides the scenario's. Returns a :class:`~navsim.records.RunResult`.

    ``overrides`` is a dict {"gyro.rate_hz": 200} or a list of "key=value" strings.
    ``star_catalog`` (a startrack StarCatalog) is loaded from the scenario epoch when needed.
    """
    started = time.perf_counter()
    prepared = prepare(scenario, overrides, star_catalog)
    result = simulate(prepared, prepared.scenario["seed"] if seed is None else int(seed))
    summary = result.summary.replace(timing={**result.summary.timing, "wall_seconds": round(time.perf_counter() - started, 4)})
    return dataclasses.replace(result, summary=summary)


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
    ``threads`` > 1 runs members concurrently. Returns the list of :class:`~navsim.records.RunResult`."""
    prepared = prepare(scenario, overrides, star_catalog)
    if threads <= 1:
        return [simulate(prepared, int(seed)) for seed in seeds]
    with ThreadPoolExecutor(max_workers=threads) as pool:
        return list(pool.map(lambda seed: simulate(prepared, int(seed)), seeds))


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
    """The run's :class:`~navsim.records.RunSummary` (arcsec, deg/h) over the frames after ``settle_s``."""
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
        nis={"mean_per_dof": float(np.sum(series["nis"][nis_frames]) / max(int(np.sum(series["nis_dof"][nis_frames])), 1))},
        updates={"frames_with_measurements": int(np.count_nonzero(series["n_measurements"])),
                 "measurements": measurements, "accepted": accepted, "rejected": measurements - accepted},
    )
