"""Spacecraft runs: the seed-free preparation of a scenario (the orbit, the attitude from the dynamics following the
attitude law, the frames' sky for every head), then seeded runs of the gyro, the heads and the MEKF through the closed
loop (:func:`navsim.closed_loop.run_loop`).

Random sub-streams (numpy ``SeedSequence(seed).spawn(3)``, in this fixed order, as the attitude kind's): 0 gyro,
1 star sensor (which spawns one stream per head, in head order: :mod:`navsim.sensors.star_heads`), 2 the filter's
initial error. The same seed gives the same numbers in one process, a pool or a cluster.
"""

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from navsim import star_run
from navsim.attitude.run import (  # noqa: F401 (the kind interface: the attitude kind's)
    IMAGE_LANES,
    NEES_DOF,
    TRUTH_SOURCES,
    VECTOR_LANES,
    budget_parts,
    calibration_summary,
    check_truth_off,
)
from navsim.closed_loop import FrameGrid, run_loop
from navsim.earth.bodies import geocentric
from navsim.earth.frames import c_ei, slowly, tt_epoch
from navsim.earth.wgs84 import ecef_to_geodetic
from navsim.estimation.attitude_filter import AttitudeFilter
from navsim.estimation.consistency import nees
from navsim.orbit.earth_disc import EarthDisc
from navsim.orbit.eclipse import PENUMBRA, UMBRA, shadow
from navsim.records import RunResult
from navsim.sensors.star_heads import ImageHeads, StarHeads
from navsim.spacecraft import build
from navsim.spacecraft.exclusion import excluding, head_sky
from navsim.spacecraft.summary import summarize
from navsim.truth.pointing import reference_rates
from navsim.truth.profiles import TruthRecord, interval_mean_rates
from startrack import InputError, earth_barycentric_velocity, load_star_catalog, units
from startrack import rotation as rot


@dataclass(frozen=True)
class Frames:
    """The truth at the F star-sensor frames: times t [s], the spacecraft's geocentric position ``r_I`` and velocity
    ``v_sat`` (F, 3) [m, m/s], its barycentric velocity ``v_I`` (F, 3) [m/s] (what aberrates the stars), the sunlit
    fraction and shadow state (F,) (:mod:`navsim.orbit.eclipse`), the geocentric Sun (F, 3) [m], the geodetic
    position (L, λ, h) (F,) each [rad, rad, m], and each head's :class:`HeadSky`."""

    t: np.ndarray
    r_I: np.ndarray
    v_sat: np.ndarray
    v_I: np.ndarray
    sunlit: np.ndarray
    shadow: np.ndarray
    sun: np.ndarray
    geodetic: tuple
    heads: tuple


@dataclass(frozen=True)
class Prepared:
    """The seed-free part of a scenario, shared by the runs of a batch: the truth on the gyro grid, the frame grid,
    the frames' sky, the attitude motion (wheels, pointing error), the gyro and the heads built in SI units."""

    scenario: object
    truth: TruthRecord
    grid: FrameGrid
    frames: Frames
    motion: object
    gyro: object
    sensor: StarHeads
    q_BS: np.ndarray
    R_BS: np.ndarray
    q_BS_true: np.ndarray


def lanes(scenario):
    """The compile-ahead lanes of a run: the image chain's and the filter's at image fidelity, else the inertial
    sensors' and the attitude filter's."""
    return IMAGE_LANES if scenario["star_sensor"][0]["fidelity"] == "image" else VECTOR_LANES


def motion(scenario, orbit, n_truth):
    """The attitude motion of the dynamics following the attitude law over ``n_truth`` truth steps
    (:meth:`navsim.truth.spacecraft.Spacecraft.simulate`), and the control grid's times."""
    body, momentum = build.spacecraft(scenario)
    truth_hz, control_hz = scenario["spacecraft"]["truth_rate_hz"], scenario["spacecraft"]["controller"]["rate_hz"]
    steps = round(truth_hz / control_hz)
    t = np.arange(-(-n_truth // steps)) / control_hz
    r, v = orbit.states(t)
    sun, _ = geocentric(scenario["epoch_utc"], t)
    q_ref = build.attitude_law(scenario).attitude(t, r, v, sun)
    omega_ref, domega_ref = reference_rates(q_ref, 1.0 / control_hz)
    return body.simulate(1.0 / truth_hz, steps, q_ref, omega_ref, domega_ref, r, momentum), t


def prepare(scenario, star_catalog=None, truth_off=frozenset()):
    """Everything of a validated spacecraft scenario that does not depend on the seed; ``star_catalog`` (a startrack
    StarCatalog) is loaded at the scenario's epoch when the heads measure stars."""
    check_truth_off(scenario, truth_off)
    heads = scenario["star_sensor"]
    gyro_hz, truth_hz = scenario["gyro"]["rate_hz"], scenario["spacecraft"]["truth_rate_hz"]
    ratio, factor = round(gyro_hz / heads[0]["rate_hz"]), round(truth_hz / gyro_hz)
    n_gyro = int(np.floor(scenario["duration_s"] * gyro_hz + 1e-9))
    orbit = build.orbit(scenario)
    moving, _ = motion(scenario, orbit, n_gyro * factor)
    q_fine = moving.q_IB[: n_gyro * factor + 1]
    truth = TruthRecord(t=np.arange(n_gyro + 1) / gyro_hz, q_IB=q_fine[::factor],
                        omega_mean=interval_mean_rates(q_fine, factor, 1.0 / gyro_hz))
    grid = FrameGrid(dt=1.0 / gyro_hz, ratio=ratio, n_frames=n_gyro // ratio)
    if heads[0]["measurement"] == "stars" and star_catalog is None:
        star_catalog = load_star_catalog(epoch=scenario["epoch_jyear"])
    frames = frame_truth(scenario, orbit, truth, grid)
    truth = dataclasses.replace(truth, v_I=frames.v_I, frame_ratio=ratio)
    q_BS, q_BS_true = build.mountings(scenario)
    sensors = []
    for head, sky in zip(heads, frames.heads):
        sensor = build.head_sensor(head, star_catalog, ratio * grid.dt, scenario["epoch_jyear"], lanes(scenario))
        if hasattr(sensor, "occultation"):  # the stars behind the Earth and its bright limb are not seen
            disc = EarthDisc(frames.r_I, 1e3 * head["earth_limb_height_km"], tuple(build.pole(scenario)))
            sensor = dataclasses.replace(sensor, occultation=disc)
        if head["fidelity"] == "image":
            sensor = dataclasses.replace(sensor, sky=build.stray_light(head, sky, frames),
                                         radiation=build.radiation_hits(scenario, head, frames))
        sensors.append(excluding(sensor, sky, frames.t))
    names = tuple(h["name"] for h in heads)
    sigmas = tuple(float(units.arcsec_to_rad(h["misalignment_sigma_arcsec"])) for h in heads)
    if heads[0]["fidelity"] == "image":
        sensor = ImageHeads(heads=tuple(sensors), names=names, q_BS=q_BS, misalignment_sigma=sigmas,
                            aberration_correction=tuple(h["aberration_correction"] for h in heads))
    else:
        sensor = StarHeads(heads=tuple(sensors), names=names, misalignment_sigma=sigmas,
                           aberration_correction=tuple(h["aberration_correction"] for h in heads))
    return Prepared(scenario=scenario, truth=truth, grid=grid, frames=frames, motion=moving, gyro=build.gyro(scenario),
                    sensor=sensor, q_BS=q_BS, R_BS=rot.to_matrix(q_BS), q_BS_true=q_BS_true)


def frame_truth(scenario, orbit, truth, grid):
    """The :class:`Frames` of the run: the orbit, the barycentric velocity, the shadow and every head's sky."""
    t = truth.t[grid.frame_k]
    r, v = orbit.states(t)
    epoch = scenario["epoch_utc"]
    v_I = v + slowly(lambda s: earth_barycentric_velocity(*tt_epoch(epoch, s)), t)
    sun, moon = geocentric(epoch, t)
    axis = build.pole(scenario)
    sunlit, state = shadow(r, sun, axis)
    _, q_BS_true = build.mountings(scenario)
    q_IB = truth.q_IB[grid.frame_k]
    skies = tuple(head_sky(head, q_IB, q, r, sun, moon, axis) for head, q in zip(scenario["star_sensor"], q_BS_true))
    r_e = np.einsum("fij,fj->fi", c_ei(epoch, t), r)
    geodetic = ecef_to_geodetic(r_e[:, 0], r_e[:, 1], r_e[:, 2])
    return Frames(t=t, r_I=r, v_sat=v, v_I=v_I, sunlit=sunlit, shadow=state, sun=sun, geodetic=geodetic, heads=skies)


def simulate(prepared, seed, compiled=True):
    """The seeded part of one run on a :class:`Prepared` scenario: a :class:`~navsim.records.RunResult`.
    ``compiled=False`` keeps the step-by-step loop where the filter's fast path would run."""
    started = time.perf_counter()
    p, scenario, grid = prepared, prepared.scenario, prepared.grid
    gyro_ss, sensor_ss, init_ss = np.random.SeedSequence(seed).spawn(3)
    record = p.gyro.measure(p.truth.omega_mean, gyro_ss)
    config = build.filter_config(scenario, p.gyro)
    dtheta0 = np.sqrt(np.diag(config.P0)[0:3]) * np.random.default_rng(init_ss).standard_normal(3)
    if scenario["filter"]["initial_attitude_error_arcsec"] is not None:
        dtheta0 = -units.arcsec_to_rad(np.asarray(scenario["filter"]["initial_attitude_error_arcsec"], dtype=float))
    filt = AttitudeFilter(rot.multiply(p.truth.q_IB[0], rot.from_rotation_vector(dtheta0)), np.zeros(3), config)
    frame_k = grid.frame_k
    if isinstance(p.sensor, ImageHeads):
        sensor_run = p.sensor.start(sensor_ss, grid.n_frames)
    else:
        sensor_run = p.sensor.start(sensor_ss, p.truth.q_IB[frame_k], p.truth.t[frame_k], p.frames.v_I)
    log = run_loop(filt, sensor_run, record.omega, p.truth, grid, None, (), compiled)
    series = {"t": p.truth.t[frame_k], "q_true": p.truth.q_IB[frame_k], "bias_true": record.bias[frame_k - 1], **log.arrays}
    series["attitude_error"] = rot.attitude_error(series["q_est"], series["q_true"])
    series["nees"] = nees(series["P"][:, :NEES_DOF, :NEES_DOF],
                          np.concatenate([series["attitude_error"], series["bias_true"] - series["bias_est"]], axis=1))
    series.update(sky_series(p.frames, sensor_run.record() or series))
    summary = summarize(p, seed, series, sensor_run, filt).replace(gyro_calibration=calibration_summary(filt, record.matrix))
    summary, timing = star_run.finish(summary, series, log, (), series["t"] >= scenario["settle_s"])
    summary = summary.replace(timing={"wall_seconds": round(time.perf_counter() - started, 4), **timing})
    series["P_diag"] = np.diagonal(series.pop("P"), axis1=1, axis2=2).copy()
    return RunResult(summary=summary, series=series, scenario=scenario.data, sample_frame=sensor_run.sample,
                     timing_series=log.timing)


def sky_series(frames, record):
    """The run series of the frames' sky: per head (F, H) the angles of the Sun and the Moon from its boresight and
    of its boresight above the limb [rad], its exclusion (an index of :data:`~navsim.spacecraft.exclusion.REASONS`,
    −1: none) and its stars or fix; the sunlit fraction (F,) and the spacecraft's height [m]."""
    def stack(name):
        return np.stack([getattr(sky, name) for sky in frames.heads], axis=1)

    return {"sun_angle": stack("sun_angle"), "moon_angle": stack("moon_angle"), "limb_angle": stack("limb_angle"),
            "head_excluded": stack("reason"), "head_measurements": head_counts(record, len(frames.heads)),
            "sunlit": frames.sunlit, "in_shadow": np.isin(frames.shadow, (PENUMBRA, UMBRA)),
            "height_m": np.linalg.norm(frames.r_I, axis=1)}


def head_counts(record, heads):
    """(F, H) int: the stars each head gave each frame (0 or 1 for fixes), as the filter took them: from the record at
    vector fidelity, from the image chain's log (``head_identified``) at image fidelity."""
    if isinstance(record, dict):
        return record["head_identified"]
    if record.fixes is not None:
        return np.asarray(record.available, dtype=np.int32).reshape(len(record.available), heads)
    stars = record.stars
    frame = np.repeat(np.arange(len(stars.offsets) - 1), stars.counts)
    counts = np.zeros((len(stars.offsets) - 1, heads), dtype=np.int32)
    np.add.at(counts, (frame, stars.head_index()), 1)
    return counts


def star_availability(scenario, star_catalog=None):
    """The sky from orbit is in every run's summary and series (its heads' exclusions and stars); ``navsim sky``
    is the navigation kind's (an observer on the Earth): an InputError."""
    raise InputError(f"{scenario.source}: a spacecraft scenario: each run's summary gives its heads' availability "
                     "(navsim sky is for observers on the Earth)")
