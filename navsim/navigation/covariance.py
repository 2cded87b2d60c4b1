"""Linear covariance analysis of a navigation scenario (``navsim covariance``): the true RMS of every
error state and of the summary quantities along the scenario's nominal trajectory, the filter's own σ
beside it, and the share of each error source (:mod:`navsim.estimation.lincov`, eq. 1-3, driven by
:func:`navsim.estimation.nav_lincov.run`).

The truth model is the simulation's, term by term: the filter's initial errors (drawn from its P0), the
gyro's and accelerometer's turn-on biases, bias random walks, Gauss-Markov bias instability (σ_g, τ:
its own states, where the filter carries a random walk), white noise, scale factors and axis
misalignments, gyro bias steps (a mean), the gravity disturbance (a Gauss-Markov field in travelled
distance, or a constant one: a mean), the star sensor's mounting error (the scenario gives its value:
a mean) and direction noise, the baro's white noise, bias and lag (a mean offset) and the position
fixes' noise. The filter is the scenario's (:func:`navsim.navigation.build.filter_config`: its states,
consider states, Q, R, noise scales). Left out (the runs have them): quantisation (the increments'
accumulated LSB, bounded), NIS gating (every measurement is taken) and the second-order terms of large
errors. At image fidelity the star sensor is its vector-fidelity equivalent: the catalog's stars of its
magnitude limit in its field, at most ``max_identified_stars``, each with the centroid σ of the image
table through the camera's focal length (the summary's notes say so).

A fixed truth error (the mounting, a constant gravity disturbance, a given turn-on bias, a bias step, the
baro's lag) is carried as the mean error m beside the covariance; an RMS is √(σ² + m²).
"""

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from navsim.analysis import Analysis, Quantity
from navsim.build.faults import bias_steps
from navsim.build.star_sensor import vector_equivalent
from navsim.earth.apparent import ApparentPlace
from navsim.earth.gravity import normal_gravity
from navsim.earth.orientation import EarthOrientation
from navsim.estimation.nav_filter import NavFilter, state_names
from navsim.estimation.nav_kernels import layout as nav_layout
from navsim.estimation.nav_lincov import BLOCK, Measurements, TruthLayout, run
from navsim.ins.strapdown import wander_rows
from navsim.navigation import build, exclusion, sky_background
from navsim.navigation.budget import SOURCES as BUDGET_SOURCES
from navsim.navigation.run import fixed_initial_error
from navsim.navigation.scenario import frame_rate
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.star_sensor import isotropic_covariance
from navsim.sensors.star_vector import AttitudeFixSensor
from navsim.truth import trajectory
from navsim.truth.sky import SkyTruth
from startrack import load_star_catalog, units
from startrack import rotation as rot

#: The error sources of the budget, in order, with their labels (those of :data:`navsim.navigation.budget.SOURCES`).
COVARIANCE_SOURCES = {key: {s.key: s.label for s in BUDGET_SOURCES}[key] for key in ("initial", "inertial", "accel_bias", "gravity", "mounting", "star_noise",
                                                   "aberration", "refraction", "aiding")}
SOURCES = tuple(COVARIANCE_SOURCES)
#: The nominal is sampled at the IMU rate coarsened by a whole factor to no less than this [Hz] (:func:`_coarsening`).
MIN_RATE_HZ = 10.0
#: At most this many output rows (frames are kept at a stride to stay under it).
MAX_ROWS = 4000
#: The summary quantities: their unit at the edge and its size in SI.
COVARIANCE_QUANTITIES = {"horizontal_position": ("m", 1.0), "vertical_position": ("m", 1.0),
              "horizontal_velocity": ("m/s", 1.0), "vertical_velocity": ("m/s", 1.0),
              "tilt": ("arcsec", units.ARCSEC), "heading": ("arcsec", units.ARCSEC)}
#: Edge units of the error states by the first letters of their names.
STATE_UNITS = (("phi", "arcsec", units.ARCSEC), ("dv", "m/s", 1.0), ("dN", "m", 1.0), ("dE", "m", 1.0),
               ("dh", "m", 1.0), ("eps", "deg/h", units.DEG / units.HOUR), ("nabla", "micro_g", 1e-6 * units.STANDARD_GRAVITY),
               ("ggm", "deg/h", units.DEG / units.HOUR), ("agm", "micro_g", 1e-6 * units.STANDARD_GRAVITY),
               ("dsg", "ppm", units.PPM), ("dsa", "ppm", units.PPM), ("mu", "arcsec", units.ARCSEC),
               ("dg", "mGal", units.MILLIGAL), ("mg", "arcsec", units.ARCSEC), ("ma", "arcsec", units.ARCSEC),
               ("baro", "m", 1.0), ("refraction", "%", 0.01))


@dataclass(frozen=True)
class Model:
    """The truth model and the filter of one analysis: the truth's :class:`TruthLayout` and state names,
    the maps W (n_t, n_f) and T (n_f, n_t), the initial covariance of each source (S, n_t, n_t) and mean
    (S, n_t), the noise densities (S, n_t), the sources' names, and the filter (a
    :class:`~navsim.estimation.nav_filter.NavFilter` at the start: its model, P0 and consider states)."""

    layout: TruthLayout
    names: tuple
    W: np.ndarray
    T: np.ndarray
    P0: np.ndarray
    m0: np.ndarray
    q: np.ndarray
    sources: tuple
    filt: NavFilter
    inv_length: float
    inv_tau: np.ndarray
    gravity_drive: np.ndarray


def truth_layout(scenario, gyro, accel, baro, filter_layout):
    """The truth's :class:`TruthLayout` and state names: the filter's groups plus those the truth has."""
    gravity = build.gravity_disturbance(scenario)
    base = nav_layout(scale_factors=filter_layout.scale >= 0 or gyro.scale_factor_sigma > 0 or accel.scale_factor_sigma > 0,
                      mounting="star_sensor" in scenario.data,
                      gravity=filter_layout.gravity >= 0 or gravity is not None, refraction=filter_layout.refraction >= 0)
    names, n, starts = list(state_names(base)), base.n, []
    extras = (("ggm", 3, gyro.bias_instability_sigma > 0), ("agm", 3, accel.bias_instability_sigma > 0),
              ("mg", 6, gyro.misalignment_sigma > 0), ("ma", 6, accel.misalignment_sigma > 0),
              ("baro", 1, baro is not None and (baro.bias_sigma > 0 or baro.bias_rw > 0)))
    for prefix, size, present in extras:
        starts.append(n if present else -1)
        if present:
            names += [prefix] if size == 1 else [f"{prefix}_{i}" for i in _suffixes(size)]
            n += size
    return TruthLayout(base, *starts, n), tuple(names)


def _suffixes(size):
    return ("x", "y", "z") if size == 3 else ("xy", "xz", "yx", "yz", "zx", "zy")


def maps(truth_names, filter_names, tl):
    """(W (n_t, n_f), T (n_f, n_t)): each filter state at its truth state; its ε and ∇ also hold the
    truth's Gauss-Markov bias parts."""
    W = np.zeros((len(truth_names), len(filter_names)))
    for j, name in enumerate(filter_names):
        W[truth_names.index(name), j] = 1.0
    T = W.T.copy()
    for first, start in ((9, tl.gyro_gm), (12, tl.accel_gm)):
        if start >= 0:
            T[first:first + 3, start:start + 3] += np.eye(3)
    return W, T


def model(scenario, nominal, filt, gyro, accel, baro):
    """The :class:`Model` of ``scenario`` for the filter ``filt`` on the ``nominal`` trajectory."""
    tl, names = truth_layout(scenario, gyro, accel, baro, filt.layout)
    W, T = maps(list(names), state_names(filt.layout), tl)
    S, n = len(SOURCES), tl.n
    P0, m0, q = np.zeros((S, n, n)), np.zeros((S, n)), np.zeros((S, n))
    src = {name: i for i, name in enumerate(SOURCES)}
    P0[src["initial"], :9, :9] = filt.config.P0[:9, :9]
    fixed = fixed_initial_error(scenario)
    given = np.zeros(n, dtype=bool)
    given[:9] = ~np.isnan(fixed)
    P0[src["initial"]][given, :] = 0.0
    P0[src["initial"]][:, given] = 0.0
    m0[src["initial"], :9] = np.where(given[:9], fixed, 0.0)

    def var(source, start, values, size=3):
        P0[src[source], start + np.arange(size), start + np.arange(size)] = np.square(values)

    for sensor, first, gm, source in ((gyro, 9, tl.gyro_gm, "inertial"), (accel, 12, tl.accel_gm, "accel_bias")):
        if sensor.bias_turn_on is not None:
            m0[src[source], first:first + 3] = sensor.bias_turn_on
        else:
            var(source, first, sensor.bias_turn_on_sigma)
        q[src[source], first:first + 3] = sensor.random_walk**2
        if gm >= 0:
            var(source, gm, sensor.bias_instability_sigma)
            q[src[source], gm:gm + 3] = 2.0 * sensor.bias_instability_sigma**2 / sensor.bias_correlation_time
    q[src["inertial"], 0:3], q[src["inertial"], 3:6] = gyro.arw**2, accel.vrw**2
    if tl.base.scale >= 0:
        var("inertial", tl.base.scale, gyro.scale_factor_sigma)
        var("inertial", tl.base.scale + 3, accel.scale_factor_sigma)
    for sensor, start in ((gyro, tl.gyro_mis), (accel, tl.accel_mis)):
        if start >= 0:
            var("inertial", start, sensor.misalignment_sigma, 6)
    if tl.base.mounting >= 0:
        m0[src["mounting"], tl.base.mounting:tl.base.mounting + 3] = units.arcsec_to_rad(
            np.asarray(scenario["star_sensor"]["misalignment_arcsec"], dtype=float))
    inv_length, drive = 0.0, np.zeros(3)
    gravity = build.gravity_disturbance(scenario)
    if gravity is not None:
        gamma = normal_gravity(nominal.lat[0], nominal.h[0])
        scale = np.array([-gamma, -gamma, 1.0])
        g = tl.base.gravity
        if gravity.correlation_length > 0.0:
            inv_length = 1.0 / gravity.correlation_length
            var("gravity", g, scale * np.asarray(gravity.sigma))
            drive = 2.0 * np.square(scale * np.asarray(gravity.sigma)) * inv_length
        else:
            m0[src["gravity"], g:g + 3] = scale * np.asarray(gravity.value)
    if tl.base.refraction >= 0:  # the real air's refraction fraction (eq. 3 of navsim.earth.refraction): its mean,
        r = tl.base.refraction  # and its σ when each run draws the air
        m0[src["refraction"], r] = build.refraction_fraction(scenario, nominal.h[0], build.real_air(scenario))
        if scenario["star_sensor"]["refraction"]["drawn"]:
            var("refraction", r, build.refraction_sigma(scenario, nominal.h[0]), 1)
    if tl.baro >= 0:
        var("aiding", tl.baro, baro.bias_sigma, 1)
        q[src["aiding"], tl.baro] = baro.bias_rw**2
    inv_tau = np.array([1.0 / gyro.bias_correlation_time, 1.0 / accel.bias_correlation_time])
    return Model(layout=tl, names=names, W=W, T=T, P0=P0, m0=m0, q=q, sources=SOURCES, filt=filt,
                 inv_length=inv_length, inv_tau=inv_tau, gravity_drive=drive)


@dataclass(frozen=True)
class Nominal:
    """What the pass runs along: the ``trajectory`` (normal gravity only: the disturbance is an error state)
    sampled every ``dt`` [s], the frame grid (``ratio`` samples per frame, ``frames``), the covariance
    interval (``every`` samples), the Earth's orientation at the frames
    and the sky truth (q_IB, observer velocity) there."""

    trajectory: object
    dt: float
    ratio: int
    frames: int
    every: int
    orientation: EarthOrientation | None
    sky: SkyTruth | None

    @property
    def frame_k(self):
        return (np.arange(self.frames) + 1) * self.ratio


def nominal(scenario):
    """The :class:`Nominal` of a validated navigation scenario, sampled at :func:`linearisation_rate`."""
    imu_hz = scenario["imu"]["rate_hz"]
    imu_ratio = int(round(imu_hz / frame_rate(scenario.data, scenario.source)))
    frames = int(round(scenario["duration_s"] * imu_hz)) // imu_ratio
    step = _coarsening(imu_hz, imu_ratio, int(scenario["filter"]["covariance_interval"]))
    rate = imu_hz / step
    kin = trajectory.kinematics(build.profile(scenario), rate, duration=frames * imu_ratio / imu_hz)
    path = trajectory.with_gravity(kin, None)
    ratio = imu_ratio // step
    orientation = sky = None
    if "star_sensor" in scenario.data:
        k = (np.arange(frames) + 1) * ratio
        orientation = EarthOrientation.compute(scenario["epoch_utc"], k / rate)
        sky = SkyTruth.of(path, orientation, k, build.real_air(scenario))
    return Nominal(trajectory=path, dt=1.0 / rate, ratio=ratio, frames=frames, every=int(scenario["filter"]["covariance_interval"]) // step,
                   orientation=orientation, sky=sky)


def _coarsening(imu_hz, ratio, every):
    """How many IMU intervals one sample of the nominal spans: the largest divisor of both the frame's and
    the covariance interval's IMU intervals that keeps :data:`MIN_RATE_HZ` (1: the IMU's own rate). The
    filter's F takes interval means over each covariance interval; the truth's increments are exact
    integrals at any rate, and C_nb at the start of each sample stands for its interval."""
    common = math.gcd(ratio, every)
    return max(d for d in range(1, common + 1) if common % d == 0 and imu_hz / d >= min(MIN_RATE_HZ, imu_hz))


def measurements(scenario, nom, filt, star_catalog, src):
    """(the pass's :class:`~navsim.estimation.nav_lincov.Measurements`, a note on the star sensor's model or
    None) of the scenario's sensors along the nominal; ``src`` the stack index of each source."""
    F, dt = nom.frames, nom.dt
    empty3, note = np.zeros((0, 3)), None
    offsets, ref, ref_real, obs, cov = np.zeros(F + 1, np.int64), empty3, empty3, empty3, np.zeros((0, 3, 3))
    fix_mask, fix_q, fix_q_real, fix_R = np.zeros(F, np.bool_), np.zeros((F, 4)), np.zeros((F, 4)), np.zeros((3, 3))
    shift, fix_rho = empty3, np.zeros((F, 3))
    if nom.sky is not None:
        catalog = star_catalog or load_star_catalog(epoch=build.catalog_epoch(scenario))
        sensor, note = vector_equivalent(scenario, catalog, 1.0 / scenario["star_sensor"]["rate_hz"], build.catalog_epoch(scenario))
        geometry = exclusion.geometry(scenario, nom.trajectory, nom.orientation, nom.frame_k, sensor.q_BS_true)
        sensor = sky_background.seeing(exclusion.excluding(sensor, geometry, nom.frame_k * dt), scenario, geometry,
                                       nom.trajectory, nom.frame_k)
        available = sensor.faults.available(nom.frame_k * dt)
        real = nom.sky.air(slice(None))
        place, place_real = (_apparent_place(scenario, nom, air) for air in (processed_air(scenario, nom), real))
        if isinstance(sensor, AttitudeFixSensor):
            fix_R = sensor.R_S
            seen = sensor.observe_frames(nom.sky.q_IB, np.random.default_rng(0), nom.sky.v_I, noise=False, air=real)
            fix_q, fix_q_real = place.turn_back(seen), place_real.turn_back(seen)
            fix_mask = available
            if filt.layout.refraction >= 0:
                fix_rho = place.refraction_rotation(rot.rotate(seen, np.array([0.0, 0.0, 1.0])))
        else:
            stars = sensor.observe_frames(nom.sky.q_IB, np.random.default_rng(0), nom.sky.v_I, noise=False, air=real)
            frame = np.repeat(np.arange(F), np.diff(stars.offsets))
            keep = available[frame]
            frame, catalog, obs = frame[keep], stars.ref_I[keep], stars.obs_S[keep]
            offsets = np.concatenate([[0], np.cumsum(np.bincount(frame, minlength=F))])
            aberrated, ref = place.rows(frame).directions(catalog)
            ref_real = place_real.rows(frame).apparent(catalog)
            cov = isotropic_covariance(obs, stars.sigma[keep])
            shift = ref - aberrated if filt.layout.refraction >= 0 else np.zeros_like(ref)
    position, baro = build.position_sensor(scenario, 1.0 / (nom.ratio * dt)), build.baro(scenario)
    position_mask, position_sigma = np.zeros(F, np.bool_), np.zeros(3)
    if position is not None:
        position_mask[position.every - 1::position.every] = True
        position_sigma = np.asarray(position.sigma_ned, dtype=float)
    baro_mask, baro_offset, baro_var, baro_filter_var = np.zeros(F, np.bool_), np.zeros(F), 0.0, 1.0
    if baro is not None:
        every = int(round(1.0 / (nom.ratio * dt) / baro.rate_hz))
        baro_mask[every - 1::every] = True
        h = nom.trajectory.h[nom.frame_k[every - 1::every]]
        lagged = dataclasses.replace(baro, noise_sigma=0.0, bias_sigma=0.0, bias_rw=0.0).measure(h, 0).h
        baro_offset[every - 1::every] = h - lagged
        baro_var, baro_filter_var = baro.noise_sigma**2, float(np.hypot(baro.noise_sigma, baro.bias_sigma)) ** 2
    meas = Measurements(star_offsets=offsets, star_ref=np.ascontiguousarray(ref),
                        star_ref_real=np.ascontiguousarray(ref_real), star_shift=np.ascontiguousarray(shift, dtype=float),
                        star_obs=np.ascontiguousarray(obs), star_cov=np.ascontiguousarray(cov), fix_mask=fix_mask,
                        fix_q=np.ascontiguousarray(fix_q), fix_q_real=np.ascontiguousarray(fix_q_real),
                        fix_rho=np.ascontiguousarray(fix_rho, dtype=float), fix_R=np.ascontiguousarray(fix_R, dtype=float),
                        position_mask=position_mask,
                        position_sigma=position_sigma, baro_mask=baro_mask, baro_var=float(baro_var),
                        baro_filter_var=float(baro_filter_var), baro_offset=baro_offset,
                        r_scale2=float(scenario["filter"]["measurement_noise_scale"]) ** 2,
                        star_source=src("star_noise"), aiding_source=src("aiding"), offset_source=src("aberration"),
                        refraction_source=src("refraction"))
    return meas, note


def processed_air(scenario, nom):
    """The refraction the processing corrects along the nominal (its model air at the nominal heights, the frames'
    (up_I, A, B)), or None when it does not correct it."""
    air = build.modelled_air(scenario)
    if air is None:
        return None
    a, b = air.coefficients(nom.trajectory.h[nom.frame_k])
    return nom.sky.up_I, a, b


def _apparent_place(scenario, nom, air):
    """The processing's :class:`~navsim.earth.apparent.ApparentPlace` along the nominal, a row per frame: aberration
    with the nominal's velocity when it corrects aberration, refraction by ``air`` (the frames' (up_I, A, B); None:
    none)."""
    return ApparentPlace(nom.sky.v_I if scenario["star_sensor"]["aberration_correction"] else None, air)


def covariance_analysis(scenario, split=False, star_catalog=None):
    """The linear covariance analysis of a validated navigation scenario: an :class:`Analysis`, each error
    source apart when ``split`` (the budget), else their sum ("total")."""
    started = time.perf_counter()
    nom = nominal(scenario)
    gyro, accel = build.imu(scenario)
    baro = build.baro(scenario)
    path = nom.trajectory
    config = build.filter_config(scenario, gyro, accel, path.lat[0], path.h[0], nom.dt, nom.orientation)
    filt = NavFilter(path.lat[0], path.lon[0], path.h[0], path.v_n[0], path.q_nb[0], config)
    mod = model(scenario, path, filt, gyro, accel, baro)
    if split:
        present = [i for i, name in enumerate(SOURCES) if _present(mod, i, scenario, name)]
        sources, P0, m0, q = tuple(SOURCES[i] for i in present), mod.P0[present], mod.m0[present], mod.q[present]
        index = {name: i for i, name in enumerate(sources)}

        def src(name):
            return index.get(name, -1)
    else:
        sources, P0, m0, q = ("total",), mod.P0.sum(axis=0)[None], mod.m0.sum(axis=0)[None], mod.q.sum(axis=0)[None]

        def src(name):
            return 0
    meas, note = measurements(scenario, nom, filt, star_catalog, src)
    steps = bias_steps(scenario["faults"])
    step_frames = np.array([int(t // (nom.ratio * nom.dt)) for t, _ in steps], dtype=np.int64)
    step_values = np.array([v for _, v in steps], dtype=float).reshape(-1, 3)
    stride = max(1, -(-nom.frames // MAX_ROWS))
    q_BS = mounting(scenario["star_sensor"])[0] if "star_sensor" in scenario.data else np.array([0.0, 0.0, 0.0, 1.0])
    q_ie = nom.orientation.q_ie if nom.orientation is not None else np.zeros((nom.frames, 4))
    P, mean, P_f = np.ascontiguousarray(P0), np.ascontiguousarray(m0), np.array(filt.P)
    out = run(np.ascontiguousarray(wander_rows(path)), path.dtheta, path.dv, nom.dt, nom.ratio,
              nom.every, stride, mod.layout, np.ascontiguousarray(q), mod.inv_length,
              mod.inv_tau, mod.gravity_drive, max(src("gravity"), 0), filt.model, np.ascontiguousarray(mod.W),
              np.ascontiguousarray(mod.T), filt.estimated, filt.baro_estimated, P, mean, P_f, q_ie,
              np.asarray(q_BS, dtype=float), meas, step_frames, step_values, max(src("inertial"), 0))
    t, mean_out, diag_t, diag_f, block, filter_diag, filter_block, nees = out
    k = np.rint(t / nom.dt).astype(int)
    names_f = tuple(state_names(filt.layout))
    return Analysis(t=t, sources=sources, truth_names=mod.names, filter_names=names_f, mean=mean_out, diag_t=diag_t,
                    diag_f=diag_f, block=block, filter_diag=filter_diag, filter_block=filter_block, nees=nees,
                    nees_dof=len(names_f), T=mod.T, quantities=quantities(k.size),
                    units_t=tuple(state_unit(n)[0] for n in mod.names), scale_t=edge_scale(mod.names, k.size),
                    units_f=tuple(state_unit(n)[0] for n in names_f), scale_f=edge_scale(names_f, k.size),
                    run_errors=run_errors, notes=() if note is None else (note,), wall_seconds=time.perf_counter() - started)


def _present(mod, i, scenario, name):
    """Whether source ``name`` (stack index i of the model) acts in this scenario."""
    if name == "star_noise":
        return "star_sensor" in scenario.data
    if name == "aberration":
        return "star_sensor" in scenario.data and not scenario["star_sensor"]["aberration_correction"]
    if name == "refraction":
        return "star_sensor" in scenario.data and build.refraction_residual(scenario)
    if name == "aiding":
        return "baro" in scenario.data or "position" in scenario["aiding"]
    return bool(np.any(mod.P0[i]) or np.any(mod.m0[i]) or np.any(mod.q[i])) or (
        name == "gravity" and np.any(mod.gravity_drive)) or (name == "inertial" and bool(scenario["faults"]["gyro_bias_steps"]))


def state_unit(name):
    """(unit, SI size) of an error state at the edge."""
    for prefix, unit, size in STATE_UNITS:
        if name.startswith(prefix):
            return unit, size
    raise KeyError(name)


def edge_scale(names, count):
    """(count, len(names)) SI size of each state's edge unit."""
    return np.tile([state_unit(name)[1] for name in names], (count, 1))


def quantities(count):
    """{name: :class:`~navsim.analysis.Quantity`} of the summary quantities at ``count`` rows: the NED position
    (δN, δE, −δh), velocity and φ components of the leading block."""
    rows = {"horizontal_position": ((6, 1.0), (7, 1.0)), "vertical_position": ((8, -1.0),),
            "horizontal_velocity": ((3, 1.0), (4, 1.0)), "vertical_velocity": ((5, 1.0),),
            "tilt": ((0, 1.0), (1, 1.0)), "heading": ((2, 1.0),)}
    out = {}
    for name, components in rows.items():
        sel = np.zeros((count, len(components), BLOCK))
        for r, (column, scale) in enumerate(components):
            sel[:, r, column] = scale
        out[name] = Quantity(unit=COVARIANCE_QUANTITIES[name][0], size=COVARIANCE_QUANTITIES[name][1], rows=sel)
    return out


def run_errors(series_arrays):
    """({quantity: (F, r)}, the error state (F, n_f)) of a navigation run's series [SI]: the NED position
    errors, the velocity and φ components (:func:`quantities`'s rows)."""
    e, p = series_arrays["error_state"], series_arrays["position_error_m"]
    return ({"horizontal_position": p[:, 0:2], "vertical_position": p[:, 2:3], "horizontal_velocity": e[:, 3:5],
             "vertical_velocity": e[:, 5:6], "tilt": e[:, 0:2], "heading": e[:, 2:3]}, e)


def covariance_run_errors(scenario):
    """The errors of a run series of ``scenario`` that make its summary quantities (:func:`run_errors`)."""
    return run_errors
