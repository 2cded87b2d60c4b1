"""Navigation runs (a scenario with a ``[trajectory]`` table): the INS through the closed loop.

:func:`prepare` computes the seed-free part once (the truth trajectory with its exactly consistent
IMU increments, the sensor models, the frame grid and, with a star sensor, the Earth's orientation at
the frames and the star sensor); :func:`simulate` is one seeded run: the IMU and aiding measurements
are drawn, the navigation filter starts from an error drawn from its P0 and runs through
:func:`navsim.closed_loop.run_loop` (its compiled fast path for the open-loop position and baro
aiding; frame by frame with a star sensor, which sees the sky from the truth and, at image
fidelity, points itself with the filter's prediction, with the per-frame observers the scenario
asks for), and the run's series and :class:`~navsim.navigation.records.RunSummary` follow
(:mod:`navsim.navigation.summary`, :mod:`navsim.navigation.celestial`).

Random sub-streams (``SeedSequence(seed).spawn(7)``, in this fixed order): 0 gyro, 1 accelerometer,
2 the filter's initial error, 3 position fixes, 4 baro, 5 a random gravity disturbance (the truth
is then generated per run), 6 the star sensor (at vector fidelity its noise directly; at image
fidelity it spawns four, all before the first frame: :func:`navsim.star_run.start_image`).

A run may switch error sources off in the truth alone (``truth_off``, :data:`TRUTH_SOURCES`; the
error budget, :mod:`navsim.navigation.budget`): the filter is still built from the unchanged scenario
(the same P0, Q, R, consider states and mounting σ) and every draw still comes from its sub-stream
(a source switched off has its terms zero, not its draws skipped), so runs with different sources
off share the other sources' draws exactly.
"""

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from navsim import star_run
from navsim.build import faults
from navsim.build.star_sensor import observers
from navsim.closed_loop import FrameGrid, run_loop
from navsim.earth.gravity import GravityDisturbance
from navsim.earth.orientation import EarthOrientation
from navsim.earth.wander import carried_ned, displaced
from navsim.estimation.nav_filter import NavFilter
from navsim.navigation import build, celestial, exclusion, sky_background
from navsim.navigation.scenario import frame_rate
from navsim.navigation.summary import navigation_series, summarize
from navsim.records import RunResult
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.aiding import AidingRun, draw_record
from navsim.sensors.celestial_aiding import CelestialAidingRun
from navsim.sensors.faults import apply_bias_steps
from navsim.truth import trajectory
from navsim.truth.sky import SkyTruth
from startrack import InputError, load_star_catalog, units
from startrack import rotation as rot

#: The lanes of a run compiled ahead (:mod:`startrack.compiled.compile_ahead`) at image fidelity: the identifier's and
#: the position fit's (the INS's kernels compile at first call).
IMAGE_LANES = (("startrack.compile_tasks:pattern_search",),
               ("navsim.sensors.warmup:inertial_sensors", "startrack.compile_tasks:star_tracking",
                "startrack.compile_tasks:psf_fit"))
#: Without a star sensor or at vector fidelity: one lane (a campaign's parent compiles it once for its workers).
VECTOR_LANES = (("navsim.navigation.warmup:run",),)

@dataclass(frozen=True)
class Prepared:
    """The seed-free part of a navigation scenario: the truth (None when a random gravity disturbance
    makes it the run's own: then its seed-free ``kinematics``, which every run completes), the frame grid,
    the IMU, baro and position-fix models, the star sensor (None without one) with the Earth's orientation
    at the frames and its per-frame observers, and the faults."""

    scenario: object
    truth: trajectory.Trajectory | None
    grid: FrameGrid
    gyro: object
    accel: object
    baro: object
    baro_every: int
    position_sensor: object
    disturbance: GravityDisturbance | None
    star_sensor: object = None
    orientation: EarthOrientation | None = None
    sky_geometry: exclusion.SkyGeometry | None = None
    observers: tuple = ()
    bias_steps: tuple = ()
    attitude_jumps: tuple = ()
    truth_off: frozenset = frozenset()
    kinematics: trajectory.Kinematics | None = None


#: The error sources a run can switch off in the truth alone (``truth_off``), what each zeroes:
TRUTH_SOURCES = {
    "accel_bias": "the accelerometer's turn-on bias, bias instability and bias random walk",
    "inertial": "the gyro errors, the accelerometer's VRW, scale factors, misalignments and quantization, "
                "the gyro bias steps",
    "gravity": "the gravity disturbance (deflections of the vertical, anomaly)",
    "star_noise": "the star sensor's measurement noise (vector fidelity)",
    "mounting": "the star sensor's mounting error (its true mounting is the nominal one)",
    "refraction": "the real air's departure from the standard atmosphere the refraction correction models",
    "initial": "the filter's initial error x0 (the filter starts at the truth)",
    "aiding": "the baro's noise, bias and lag and the position fixes' noise",
}
#: The model terms each of "accel_bias" and "inertial" zeroes in the truth's gyro and accelerometer.
ACCEL_BIAS_TERMS = {"bias_turn_on_sigma": 0.0, "bias_instability_sigma": 0.0, "bias_rw": 0.0, "bias_turn_on": None}
GYRO_TERMS = {"arw": 0.0, "rrw": 0.0, "bias_turn_on_sigma": 0.0, "bias_instability_sigma": 0.0, "bias_turn_on": None,
              "scale_factor_sigma": 0.0, "misalignment_sigma": 0.0, "quantization": 0.0}
ACCEL_OTHER_TERMS = {"vrw": 0.0, "scale_factor_sigma": 0.0, "misalignment_sigma": 0.0, "quantization": 0.0}


def check_truth_off(scenario, truth_off):
    """``truth_off`` as a frozenset of :data:`TRUTH_SOURCES`; InputError for an unknown name, for a
    star sensor's source without one, or for the star noise at image fidelity (it comes from the pixels)."""
    truth_off = frozenset(truth_off)
    unknown = sorted(truth_off - set(TRUTH_SOURCES))
    if unknown:
        raise InputError(f"truth_off: unknown source(s) {', '.join(unknown)}; choose from {', '.join(TRUTH_SOURCES)}")
    sensor = scenario.data.get("star_sensor")
    if sensor is None and truth_off & {"star_noise", "mounting", "refraction"}:
        raise InputError("truth_off: star_noise, mounting and refraction need a star sensor")
    if "star_noise" in truth_off and sensor["fidelity"] == "image":
        raise InputError("truth_off: the star noise cannot be switched off at image fidelity (it comes from the pixels)")
    return truth_off


def lanes(scenario):
    """The compile-ahead lanes of a run of ``scenario``."""
    image = scenario.data.get("star_sensor", {}).get("fidelity") == "image"
    return IMAGE_LANES if image else VECTOR_LANES


def prepare(scenario, star_catalog=None, truth_off=frozenset()):
    """The :class:`Prepared` of a validated navigation scenario; ``star_catalog`` (a
    startrack StarCatalog) is loaded at the scenario's epoch when a star sensor needs it;
    ``truth_off`` names error sources the truth leaves out (:data:`TRUTH_SOURCES`), not the filter."""
    truth_off = check_truth_off(scenario, truth_off)
    imu_hz = scenario["imu"]["rate_hz"]
    frame_hz = frame_rate(scenario.data, scenario.source)
    ratio = int(round(imu_hz / frame_hz))
    n_frames = int(round(scenario["duration_s"] * imu_hz)) // ratio
    grid = FrameGrid(dt=1.0 / imu_hz, ratio=ratio, n_frames=n_frames)
    disturbance = None if "gravity" in truth_off else build.gravity_disturbance(scenario)
    random_field = disturbance is not None and disturbance.correlation_length > 0.0
    kinematics = trajectory.kinematics(build.profile(scenario), imu_hz, duration=scenario["duration_s"])
    truth = None if random_field else trajectory.with_gravity(kinematics, disturbance)
    gyro, accel = build.imu(scenario)
    baro = build.baro(scenario)
    star_sensor = orientation = sky_geometry = None
    if "star_sensor" in scenario.data:
        star_catalog = star_catalog or load_star_catalog(epoch=build.catalog_epoch(scenario))
        star_sensor = build.star_sensor(scenario, star_catalog, lanes(scenario))
        if "mounting" in truth_off:
            star_sensor = dataclasses.replace(star_sensor, q_BS_true=mounting(scenario["star_sensor"])[0])
        orientation = EarthOrientation.compute(scenario["epoch_utc"], grid.frame_k * grid.dt)
        sky_geometry = exclusion.geometry(scenario, kinematics, orientation, grid.frame_k, star_sensor.q_BS_true)
        star_sensor = sky_background.seeing(exclusion.excluding(star_sensor, sky_geometry, grid.frame_k * grid.dt),
                                            scenario, sky_geometry, kinematics, grid.frame_k)
    return Prepared(scenario=scenario, truth=truth, grid=grid, gyro=gyro, accel=accel, baro=baro,
                              baro_every=0 if baro is None else int(round(frame_hz / baro.rate_hz)),
                              position_sensor=build.position_sensor(scenario, frame_hz), disturbance=disturbance,
                              star_sensor=star_sensor, orientation=orientation, sky_geometry=sky_geometry,
                              observers=() if star_sensor is None else observers(scenario, star_sensor),
                              bias_steps=faults.bias_steps(scenario["faults"]),
                              attitude_jumps=faults.attitude_jumps(scenario["faults"]), truth_off=truth_off,
                              kinematics=kinematics if random_field else None)


def simulate(prepared, seed, compiled=True):
    """One seeded navigation run; returns a :class:`~navsim.records.RunResult`. ``compiled=False``
    keeps the step-by-step loop where the filter's fast path would run. The filter is the scenario's
    whatever ``prepared.truth_off`` switches off in the truth."""
    started = time.perf_counter()
    p, scenario, grid = prepared, prepared.scenario, prepared.grid
    gyro_ss, accel_ss, init_ss, position_ss, baro_ss, gravity_ss, star_ss, air_ss = np.random.SeedSequence(seed).spawn(8)
    truth = p.truth if p.truth is not None else trajectory.with_gravity(p.kinematics, p.disturbance, gravity_ss)
    n = grid.n_frames * grid.ratio
    gyro_truth, accel_truth = truth_imu(p)
    gyro = gyro_truth.measure(truth.dtheta[:n] / grid.dt, gyro_ss)
    if "inertial" not in p.truth_off:
        omega, bias = apply_bias_steps(gyro.omega, gyro.bias, truth.t[1:n + 1], p.bias_steps)
        gyro = dataclasses.replace(gyro, omega=omega, bias=bias)
    accel = accel_truth.measure(truth.dv[:n] / grid.dt, accel_ss)
    config = build.filter_config(scenario, p.gyro, p.accel, truth.lat[0], truth.h[0], grid.dt, p.orientation)
    fixed = fixed_initial_error(scenario)
    filt = NavFilter(*_start(truth, config.P0, init_ss, zero="initial" in p.truth_off, fixed=fixed), config)
    record = _aiding_record(p, truth, position_ss, baro_ss)
    sensor_run, loop_truth, jumps, sky, observer_runs = AidingRun(record), truth, None, None, []
    air = None if p.star_sensor is None else build.real_air(scenario, p.truth_off, np.random.default_rng(air_ss))
    if p.star_sensor is not None:
        sky = SkyTruth.of(truth, p.orientation, grid.frame_k, air)
        stars, observer_runs, jumps = _star_run(p, sky, star_ss, filt)
        sensor_run, loop_truth = CelestialAidingRun(stars, sensor_run), sky
    log = run_loop(filt, sensor_run, np.hstack([gyro.omega, accel.force]), loop_truth, grid, jumps, observer_runs,
                   compiled)
    q_BS_true = p.star_sensor.q_BS_true if p.star_sensor is not None else None
    refraction_true = None if air is None else build.refraction_fraction(scenario, truth.h[grid.frame_k], air)
    series = navigation_series(truth, grid.frame_k, log.arrays, gyro, accel, filt.layout, q_BS_true, refraction_true)
    series["error_sigma_initial"] = np.sqrt(np.diag(config.P0))
    if p.star_sensor is not None:
        series["mounting_true"] = np.broadcast_to(rot.to_rotation_vector(rot.multiply(rot.conjugate(filt.star_sensor.q_BS),
                                                                                      q_BS_true)), (grid.n_frames, 3)).copy()
        series["mounting_estimate"] = rot.to_rotation_vector(rot.multiply(rot.conjugate(filt.star_sensor.q_BS),
                                                                          series["q_bs"]))
        series.update(exclusion.series(p.sky_geometry))
        series["n_stars"] = _stars_per_frame(stars, series)
        if getattr(p.star_sensor, "sky", None) is not None:
            series.update(p.star_sensor.sky.series())
    summary = summarize(scenario, seed, series, grid)
    if p.star_sensor is not None:
        summary = summary.replace(celestial=celestial.summary(scenario, series, sky, p.orientation, q_BS_true,
                                                              p.sky_geometry, air))
    summary, timing = star_run.finish(summary, series, log, observer_runs, series["t"] >= scenario["settle_s"])
    summary = summary.replace(timing={"wall_seconds": round(time.perf_counter() - started, 4), **timing})
    return RunResult(summary=summary, series=series, scenario=scenario.data, sample_frame=sensor_run.sample,
                     timing_series=log.timing)


def truth_imu(prepared):
    """(gyro, accelerometer) models the truth's IMU record is drawn with: the scenario's, with the
    terms of the sources in ``prepared.truth_off`` zero (the filter keeps ``prepared.gyro``, ``.accel``)."""
    gyro, accel = prepared.gyro, prepared.accel
    if "accel_bias" in prepared.truth_off:
        accel = dataclasses.replace(accel, **ACCEL_BIAS_TERMS)
    if "inertial" in prepared.truth_off:
        gyro, accel = dataclasses.replace(gyro, **GYRO_TERMS), dataclasses.replace(accel, **ACCEL_OTHER_TERMS)
    return gyro, accel


def _aiding_record(prepared, truth, position_ss, baro_ss):
    """The baro and position-fix record of a run; without their errors when ``truth_off`` has
    "aiding" (the record keeps the sensors' σ, the filter's R)."""
    p = prepared
    record = draw_record(truth, p.grid.frame_k, p.position_sensor, p.baro, p.baro_every, position_ss, baro_ss)
    if "aiding" not in p.truth_off:
        return record
    fixes = None if p.position_sensor is None else dataclasses.replace(p.position_sensor, sigma_ned=np.zeros(3))
    baro = None if p.baro is None else dataclasses.replace(p.baro, noise_sigma=0.0, bias_sigma=0.0, bias_rw=0.0,
                                                           lag_time_constant=0.0)
    exact = draw_record(truth, p.grid.frame_k, fixes, baro, p.baro_every, position_ss, baro_ss)
    return dataclasses.replace(exact, position_sigma=record.position_sigma, baro_sigma=record.baro_sigma)


def _star_run(prepared, sky, seed, filt):
    """(the star sensor's run, the observers' runs, its attitude jumps or None) for the sky truth ``sky``:
    at vector fidelity every frame drawn from ``seed`` (without noise when ``truth_off`` has "star_noise":
    the record keeps the stars' σ, the filter's R); at image fidelity :func:`navsim.star_run.start_image`."""
    sensor, grid = prepared.star_sensor, prepared.grid
    if prepared.scenario["star_sensor"]["fidelity"] == "image":
        return star_run.start_image(sensor, seed, grid.n_frames, filt, prepared.observers, prepared.attitude_jumps)
    return sensor.start(seed, sky.q_IB, grid.frame_k * grid.dt, sky.v_I, noise="star_noise" not in prepared.truth_off,
                        air=sky.air(slice(None))), [], None


def _stars_per_frame(stars, series):
    """(F,) the stars the star sensor measured at each frame: its record's where it drew them before the run (an
    attitude fix counts as one, as in ``navsim sky``), else the identified and stacked stars of its log (image
    fidelity)."""
    record = stars.record()
    if record is None:
        return (series["n_identified"] + series["n_stacked"]).astype(np.int32)  # image fidelity, prior identification
    if record.stars is None:
        return record.available.astype(np.int32)
    return np.where(record.available, record.stars.counts, 0).astype(np.int32)


def _start(truth, P0, seed, zero=False, fixed=None):
    """(L, λ, h, v_n, q_nb) of the filter: the truth at t = 0 with an error x0 ~ N(0, P0) in attitude
    (C_nb,est = (I − [φ×]) C_nb,true: q_est = q(−φ) ⊗ q_true), velocity and position in the truth's NED, each part
    the scenario fixes (``fixed``: :func:`fixed_initial_error`, NaN where drawn) taken instead of its draw (``zero``:
    x0 = 0); the attitude and velocity then carried to the NED of the displaced position
    (:func:`navsim.earth.wander.carried_ned`: the meridians' convergence, any angle at a pole)."""
    x0 = np.linalg.cholesky(P0[:9, :9]) @ np.random.default_rng(seed).standard_normal(9) * (0.0 if zero else 1.0)
    if fixed is not None and not zero:
        x0 = np.where(np.isnan(fixed), x0, fixed)
    lat, lon = displaced(truth.lat[0], truth.lon[0], truth.h[0], x0[6], x0[7])
    C = carried_ned(truth.lat[0], truth.lon[0], lat, lon)
    q0 = rot.multiply(rot.from_matrix(C), rot.multiply(rot.from_rotation_vector(-x0[0:3]), truth.q_nb[0]))
    return float(lat), float(lon), truth.h[0] + x0[8], C @ (truth.v_n[0] + x0[3:6]), q0


def fixed_initial_error(scenario):
    """The filter's initial error x0[0:9] (φ, δv, δN, δE, δh) the scenario fixes, NaN where it is drawn
    (``filter.initial_attitude_error_arcsec``, ``initial_velocity_error_m_per_s``, ``initial_position_error_m``)."""
    f = scenario["filter"]
    x0 = np.full(9, np.nan)
    if f["initial_attitude_error_arcsec"] is not None:
        x0[0:3] = units.arcsec_to_rad(np.asarray(f["initial_attitude_error_arcsec"], dtype=float))
    if f["initial_velocity_error_m_per_s"] is not None:
        x0[3:6] = f["initial_velocity_error_m_per_s"]
    if f["initial_position_error_m"] is not None:
        north, east, down = f["initial_position_error_m"]
        x0[6:9] = north, east, -down
    return x0
