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
consider states, Q, R, noise scales). Left out, as the runs have them: quantisation (the increments'
accumulated LSB, bounded), NIS gating (every measurement is taken) and the second-order terms of large
errors. At image fidelity the star sensor is its vector-fidelity equivalent: the catalog's stars of its
magnitude limit in its field, at most ``max_identified_stars``, each with the centroid σ of the image
table through the camera's focal length (``summary['star_sensor_model']`` says so).

A fixed truth error (the mounting, a constant gravity disturbance, a given turn-on bias, a bias step, the
baro's lag) is carried as the mean error m beside the covariance; an RMS is √(σ² + m²).
"""

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from navsim.build.faults import bias_steps, sensor_faults
from navsim.earth.apparent import fix_rotation
from navsim.earth.gravity import normal_gravity
from navsim.earth.orientation import EarthOrientation
from navsim.earth.wgs84 import radii
from navsim.estimation.consistency import mean_square_band
from navsim.estimation.nav_filter import NavFilter, state_names
from navsim.estimation.nav_kernels import layout as nav_layout
from navsim.estimation.nav_lincov import BLOCK, Measurements, TruthLayout, run
from navsim.navigation import build
from navsim.navigation.scenario import frame_rate
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.star_sensor import isotropic_covariance
from navsim.sensors.star_vector import AttitudeFixSensor, StarVectorSensor
from navsim.truth import trajectory
from navsim.truth.sky import SkyTruth
from startrack import rotation as rot
from startrack import units
from startrack.aberration import aberrate
from startrack.errors import InputError
from startrack.star_catalog import load_star_catalog

#: The error sources of the budget, in order (the keys of :data:`navsim.navigation.budget.SOURCES`).
SOURCES = ("initial", "inertial", "accel_bias", "gravity", "mounting", "star_noise", "aberration", "aiding")
#: The nominal is sampled at the IMU rate coarsened by a whole factor to no less than this [Hz] (:func:`_coarsening`).
MIN_RATE_HZ = 10.0
#: At most this many output rows (frames are kept at a stride to stay under it).
MAX_ROWS = 4000
#: The summary quantities: their unit at the edge and its size in SI.
QUANTITIES = {"horizontal_position": ("m", 1.0), "vertical_position": ("m", 1.0),
              "horizontal_velocity": ("m/s", 1.0), "vertical_velocity": ("m/s", 1.0),
              "tilt": ("arcsec", units.ARCSEC), "heading": ("arcsec", units.ARCSEC)}
#: Edge units of the error states by the first letters of their names.
STATE_UNITS = (("phi", "arcsec", units.ARCSEC), ("dv", "m/s", 1.0), ("dlat", "m", None), ("dlon", "m", None),
               ("dh", "m", 1.0), ("eps", "deg/h", units.DEG / units.HOUR), ("nabla", "micro_g", 1e-6 * units.STANDARD_GRAVITY),
               ("ggm", "deg/h", units.DEG / units.HOUR), ("agm", "micro_g", 1e-6 * units.STANDARD_GRAVITY),
               ("dsg", "ppm", units.PPM), ("dsa", "ppm", units.PPM), ("mu", "arcsec", units.ARCSEC),
               ("dg", "mGal", units.MILLIGAL), ("mg", "arcsec", units.ARCSEC), ("ma", "arcsec", units.ARCSEC),
               ("baro", "m", 1.0))


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
                      gravity=filter_layout.gravity >= 0 or gravity is not None)
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
        sky = SkyTruth.of(path, orientation, k)
    return Nominal(trajectory=path, dt=1.0 / rate, ratio=ratio, frames=frames, every=int(scenario["filter"]["covariance_interval"]) // step,
                   orientation=orientation, sky=sky)


def _coarsening(imu_hz, ratio, every):
    """How many IMU intervals one sample of the nominal spans: the largest divisor of both the frame's and
    the covariance interval's IMU intervals that keeps :data:`MIN_RATE_HZ` (1: the IMU's own rate). The
    filter's F takes interval means over each covariance interval; the truth's increments are exact
    integrals at any rate, and C_nb at the start of each sample stands for its interval."""
    common = math.gcd(ratio, every)
    return max(d for d in range(1, common + 1) if common % d == 0 and imu_hz / d >= min(MIN_RATE_HZ, imu_hz))


def vector_star_sensor(scenario, star_catalog):
    """(the vector-fidelity star sensor the analysis sees, with its nominal mounting; a note when it stands
    for an image-fidelity sensor): at image fidelity the stars of the magnitude limit in the field, at most
    ``max_identified_stars``, each of σ = centroid σ / focal length."""
    table = scenario["star_sensor"]
    if table["fidelity"] != "image":
        sensor = build.star_sensor(scenario, star_catalog)
        return dataclasses.replace(sensor, q_BS_true=mounting(table)[0]), None
    from startrack.camera import Camera  # image fidelity only

    image, fov = table["image"], units.deg_to_rad(table["fov_deg"])
    camera = Camera.from_fov(fov, image["width_px"], image["height_px"], circular_fov=image["field"] == "circular")
    if image["camera_file"] is not None:
        camera = Camera.from_file(image["camera_file"])
    stars = star_catalog.brighter_than(table["mag_limit"])
    sigma = image["centroid_sigma_px"] / camera.focal_px
    sensor = StarVectorSensor(star_vectors=np.asarray(stars.vectors), star_ids=np.asarray(stars.hip),
                              star_mags=np.asarray(stars.v_mag), fov=float(fov), sigma=float(sigma),
                              max_stars=image["max_identified_stars"], q_BS_true=mounting(table)[0],
                              faults=sensor_faults(scenario["faults"], 1.0 / table["rate_hz"]))
    note = (f"image fidelity modelled by its vector-fidelity equivalent: the V <= {table['mag_limit']:g} stars in the "
            f"{table['fov_deg']:g} deg field, at most {image['max_identified_stars']}, each "
            f"{units.rad_to_arcsec(sigma):.2f}\" per axis (centroid {image['centroid_sigma_px']:g} px)")
    return sensor, note


def measurements(scenario, nom, filt, star_catalog, src):
    """(the pass's :class:`~navsim.estimation.nav_lincov.Measurements`, a note on the star sensor's model or
    None) of the scenario's sensors along the nominal; ``src`` the stack index of each source."""
    F, dt = nom.frames, nom.dt
    empty3, note = np.zeros((0, 3)), None
    offsets, ref, obs, cov = np.zeros(F + 1, np.int64), empty3, empty3, np.zeros((0, 3, 3))
    fix_mask, fix_q, fix_R = np.zeros(F, np.bool_), np.zeros((F, 4)), np.zeros((3, 3))
    if nom.sky is not None:
        sensor, note = vector_star_sensor(scenario, star_catalog or load_star_catalog(epoch=build.catalog_epoch(scenario)))
        available = sensor.faults.available(nom.frame_k * dt)
        correct = scenario["star_sensor"]["aberration_correction"]
        if isinstance(sensor, AttitudeFixSensor):
            fix_R = sensor.R_S
            quiet = dataclasses.replace(sensor, sigma_cross=0.0, sigma_roll=0.0)
            fix_q = quiet.observe_frames(nom.sky.q_IB, np.random.default_rng(0), nom.sky.v_I)
            if correct:
                boresight = rot.rotate(fix_q, np.array([0.0, 0.0, 1.0]))
                fix_q = rot.multiply(fix_rotation(boresight, nom.sky.v_I), fix_q)
            fix_mask = available
        else:
            stars = dataclasses.replace(sensor, sigma=0.0).observe_frames(nom.sky.q_IB, np.random.default_rng(0), nom.sky.v_I)
            frame = np.repeat(np.arange(F), np.diff(stars.offsets))
            keep = available[frame]
            frame, ref, obs = frame[keep], stars.ref_I[keep], stars.obs_S[keep]
            offsets = np.concatenate([[0], np.cumsum(np.bincount(frame, minlength=F))])
            if correct:
                ref = aberrate(ref, nom.sky.v_I[frame])
            cov = isotropic_covariance(obs, sensor.sigma)
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
    meas = Measurements(star_offsets=offsets, star_ref=np.ascontiguousarray(ref), star_obs=np.ascontiguousarray(obs),
                        star_cov=np.ascontiguousarray(cov), fix_mask=fix_mask, fix_q=np.ascontiguousarray(fix_q),
                        fix_R=np.ascontiguousarray(fix_R, dtype=float), position_mask=position_mask,
                        position_sigma=position_sigma, baro_mask=baro_mask, baro_var=float(baro_var),
                        baro_filter_var=float(baro_filter_var), baro_offset=baro_offset,
                        r_scale2=float(scenario["filter"]["measurement_noise_scale"]) ** 2,
                        star_source=src("star_noise"), aiding_source=src("aiding"), offset_source=src("aberration"))
    return meas, note


@dataclass(frozen=True)
class Analysis:
    """The result of a pass: at the kept frames ``t`` (K,) [s] (the nominal's ``lat``, ``h`` there), per
    source of ``sources`` (one, "total", unless split) the mean error ``mean`` (S, K, n_t), the diagonal of
    its covariance in the truth's (``diag_t``) and the filter's coordinates (``diag_f`` (S, K, n_f)) and its
    leading 9 x 9 block (φ, δv, δp: the same in both); the filter's own ``filter_diag`` (K, n_f) and
    ``filter_block``; the filter's expected NEES (K,); the truth's and the filter's state names; ``notes``."""

    t: np.ndarray
    lat: np.ndarray
    h: np.ndarray
    sources: tuple
    truth_names: tuple
    filter_names: tuple
    mean: np.ndarray
    diag_t: np.ndarray
    diag_f: np.ndarray
    block: np.ndarray
    filter_diag: np.ndarray
    filter_block: np.ndarray
    nees: np.ndarray
    T: np.ndarray
    notes: tuple
    wall_seconds: float

    def selectors(self):
        """{quantity: (K, r, 9)} the rows that take the leading block to each summary quantity (SI)."""
        K = self.t.size
        r_m, r_n = radii(self.lat)
        out = {}
        for name, rows in (("horizontal_position", ((6, r_m + self.h), (7, (r_n + self.h) * np.cos(self.lat)))),
                           ("vertical_position", ((8, -np.ones(K)),)), ("horizontal_velocity", ((3, 1.0), (4, 1.0))),
                           ("vertical_velocity", ((5, 1.0),)), ("tilt", ((0, 1.0), (1, 1.0))), ("heading", ((2, 1.0),))):
            sel = np.zeros((K, len(rows), BLOCK))
            for r, (column, scale) in enumerate(rows):
                sel[:, r, column] = scale
            out[name] = sel
        return out

    def mean_square(self):
        """{quantity: (S, K)} each source's share of the true mean square [SI²]: tr(J P_s Jᵀ) + (J m_s)·(J m),
        m the total mean; the shares add up to the total exactly."""
        total = self.mean.sum(axis=0)[:, :BLOCK]
        out = {}
        for name, sel in self.selectors().items():
            var = np.einsum("kri,skij,krj->sk", sel, self.block, sel)
            out[name] = var + np.einsum("kri,ski,krj,kj->sk", sel, self.mean[:, :, :BLOCK], sel, total)
        return out

    def series(self):
        """The arrays of ``timeseries.npz`` (:func:`series`)."""
        return series(self)

    def summary(self, scenario):
        """The content of ``summary.json`` (:func:`summary`)."""
        return summary(self, scenario)

    def compare(self, runs):
        """The analysis against Monte Carlo run series (:func:`compare`)."""
        return compare(self, runs)

    def alone_mean_square(self):
        """{quantity: (S, K)} the true mean square each source leaves alone, tr(J P_s Jᵀ) + |J m_s|² [SI²]: what a
        run with only that source in its truth averages to (``navsim budget --method montecarlo``'s parts)."""
        out = {}
        for name, sel in self.selectors().items():
            projected = np.einsum("kri,ski->skr", sel, self.mean[:, :, :BLOCK])
            out[name] = np.einsum("kri,skij,krj->sk", sel, self.block, sel) + np.sum(projected**2, axis=2)
        return out

    def filter_variance(self):
        """{quantity: (K,)} the filter's own variance of each summary quantity [SI²]."""
        return {name: np.einsum("kri,kij,krj->k", sel, self.filter_block, sel) for name, sel in self.selectors().items()}


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
    out = run(path.q_nb, path.dtheta, path.dv, path.lat, path.lon, path.h, path.v_n, nom.dt, nom.ratio,
              nom.every, stride, mod.layout, np.ascontiguousarray(q), mod.inv_length,
              mod.inv_tau, mod.gravity_drive, max(src("gravity"), 0), filt.model, np.ascontiguousarray(mod.W),
              np.ascontiguousarray(mod.T), filt.estimated, filt.baro_estimated, P, mean, P_f, q_ie,
              np.asarray(q_BS, dtype=float), meas, step_frames, step_values, max(src("inertial"), 0))
    t, mean_out, diag_t, diag_f, block, filter_diag, filter_block, nees = out
    k = np.rint(t / nom.dt).astype(int)
    return Analysis(t=t, lat=path.lat[k], h=path.h[k], sources=sources, truth_names=mod.names,
                    filter_names=tuple(state_names(filt.layout)), mean=mean_out, diag_t=diag_t, diag_f=diag_f, block=block,
                    filter_diag=filter_diag, filter_block=filter_block, nees=nees, T=mod.T,
                    notes=() if note is None else (note,), wall_seconds=time.perf_counter() - started)


def _present(mod, i, scenario, name):
    """Whether source ``name`` (stack index i of the model) acts in this scenario."""
    if name == "star_noise":
        return "star_sensor" in scenario.data
    if name == "aberration":
        return "star_sensor" in scenario.data and not scenario["star_sensor"]["aberration_correction"]
    if name == "aiding":
        return "baro" in scenario.data or "position" in scenario["aiding"]
    return bool(np.any(mod.P0[i]) or np.any(mod.m0[i]) or np.any(mod.q[i])) or (
        name == "gravity" and np.any(mod.gravity_drive)) or (name == "inertial" and bool(scenario["faults"]["gyro_bias_steps"]))


def state_unit(name):
    """(unit, SI size) of an error state at the edge; position states by their name (metres at the nominal)."""
    for prefix, unit, size in STATE_UNITS:
        if name.startswith(prefix):
            return unit, size
    raise KeyError(name)


def edge_scale(analysis, names):
    """(K, len(names)) SI size of each state's edge unit at each kept frame (δL, δλ in metres there)."""
    r_m, r_n = radii(analysis.lat)
    out = np.empty((analysis.t.size, len(names)))
    for j, name in enumerate(names):
        unit, size = state_unit(name)
        if name == "dlat":
            out[:, j] = 1.0 / (r_m + analysis.h)
        elif name == "dlon":
            out[:, j] = 1.0 / ((r_n + analysis.h) * np.cos(analysis.lat))
        else:
            out[:, j] = size
    return out


def series(analysis):
    """The arrays of ``timeseries.npz`` (edge units: :data:`QUANTITIES`, :data:`STATE_UNITS`): ``t``; per
    summary quantity its true RMS ``<q>_rms``, mean-error size ``<q>_mean`` and the filter's σ ``<q>_sigma_filter``;
    the filter's states (``state_names``): true RMS ``state_rms``, mean ``state_mean``, filter σ ``state_sigma``;
    the truth's (``truth_state_names``): ``truth_state_rms``, ``truth_state_mean``; ``nees_expected``; with the
    sources apart, ``sources`` and each quantity's share of the mean square ``<q>_share`` (S, K) [unit²]."""
    a = analysis
    total_mean = a.mean.sum(axis=0)
    ms, fv = a.mean_square(), a.filter_variance()
    out = {"t": a.t, "nees_expected": a.nees, "state_names": np.array(a.filter_names),
           "truth_state_names": np.array(a.truth_names), "sources": np.array(a.sources)}
    sel = a.selectors()
    for name, (unit, size) in QUANTITIES.items():
        out[f"{name}_rms"] = np.sqrt(np.maximum(ms[name].sum(axis=0), 0.0)) / size
        out[f"{name}_mean"] = np.linalg.norm(np.einsum("kri,ki->kr", sel[name], total_mean[:, :BLOCK]), axis=1) / size
        out[f"{name}_sigma_filter"] = np.sqrt(fv[name]) / size
        if len(a.sources) > 1:
            out[f"{name}_share"] = ms[name] / size**2
    f_scale, t_scale = edge_scale(a, a.filter_names), edge_scale(a, a.truth_names)
    mean_f = total_mean @ a.T.T
    out["state_rms"] = np.sqrt(a.diag_f.sum(axis=0) + mean_f**2) / f_scale
    out["state_mean"] = mean_f / f_scale
    out["state_sigma"] = np.sqrt(a.filter_diag) / f_scale
    out["truth_state_rms"] = np.sqrt(a.diag_t.sum(axis=0) + total_mean**2) / t_scale
    out["truth_state_mean"] = total_mean / t_scale
    return out


def summary(analysis, scenario):
    """The analysis's ``summary.json`` (``navsim.covariance-summary/1``): per summary quantity its true RMS at
    the end (``final``), over the frames after ``settle_s`` (``rms``, √ of the mean square) and its largest
    (``max``), the mean error's size at the end and the filter's own σ at the end beside its ratio; per filter
    state at the end its true RMS, mean and the filter's σ; the filter's expected NEES after ``settle_s``
    against its dof; with the sources apart the budget's shares at the end and over the steady frames."""
    s = series(analysis)
    steady = s["t"] >= scenario["settle_s"]
    steady = steady if steady.any() else np.ones_like(steady)
    quantities = {}
    for name, (unit, _size) in QUANTITIES.items():
        rms, sigma = s[f"{name}_rms"], s[f"{name}_sigma_filter"]
        quantities[name] = {"unit": unit, "final": float(rms[-1]), "rms": float(np.sqrt(np.mean(rms[steady] ** 2))),
                            "max": float(rms[steady].max()), "mean_final": float(s[f"{name}_mean"][-1]),
                            "filter_sigma_final": float(sigma[-1]),
                            "true_over_filter_final": float(rms[-1] / sigma[-1]) if sigma[-1] > 0 else None}
    states = {name: {"unit": state_unit(name)[0], "rms_final": float(s["state_rms"][-1, j]),
                     "mean_final": float(s["state_mean"][-1, j]), "filter_sigma_final": float(s["state_sigma"][-1, j])}
              for j, name in enumerate(analysis.filter_names)}
    out = {"format": "navsim.covariance-summary/1", "scenario": scenario.name, "kind": scenario.kind,
           "method": "linear covariance analysis", "duration_s": float(s["t"][-1]), "rows": int(s["t"].size),
           "settle_s": float(scenario["settle_s"]), "quantities": quantities, "states": states,
           "truth_states": list(analysis.truth_names), "filter_states": list(analysis.filter_names),
           "nees_expected": {"dof": len(analysis.filter_names), "mean": float(np.mean(s["nees_expected"][steady])),
                             "final": float(s["nees_expected"][-1])},
           "notes": list(analysis.notes), "timing": {"wall_seconds": round(analysis.wall_seconds, 4)}}
    if len(analysis.sources) > 1:
        out["budget"] = {name: {source: {"final": float(s[f"{name}_share"][i, -1]),
                                         "steady": float(np.mean(s[f"{name}_share"][i, steady]))}
                                for i, source in enumerate(analysis.sources)} for name in QUANTITIES}
    return out


#: How many times along the run a comparison with Monte Carlo checks.
COMPARE_TIMES = 10


def quantity_errors(series_arrays):
    """{quantity: (F, r)} the errors of a run's series (``error_state``, ``position_error_m``) that make each
    summary quantity (SI): the NED position, velocity and φ components."""
    e, p = series_arrays["error_state"], series_arrays["position_error_m"]
    return {"horizontal_position": p[:, 0:2], "vertical_position": p[:, 2:3], "horizontal_velocity": e[:, 3:5],
            "vertical_velocity": e[:, 5:6], "tilt": e[:, 0:2], "heading": e[:, 2:3]}


def compare(analysis, runs, times=COMPARE_TIMES, probability=0.95):
    """The analysis against Monte Carlo runs (a list of run series: ``t``, ``error_state``,
    ``position_error_m``): at ``times`` instants evenly along the run, each summary quantity's and filter
    state's RMS over the runs beside the analysis's and the ``probability`` sampling band of an N-run RMS
    (:func:`navsim.estimation.consistency.mean_square_band`); the family-wise band holds all checks at once
    at ``probability`` (Šidák). Returns a JSON-able dict."""
    a, N = analysis, len(runs)
    t_run = runs[0]["t"]
    wanted = a.t[-1] * (np.arange(times) + 1) / times
    frames = [int(np.argmin(np.abs(t_run - w))) for w in wanted]
    rows = [int(np.argmin(np.abs(a.t - t_run[f]))) for f in frames]
    block = a.block.sum(axis=0)
    total = a.mean.sum(axis=0)
    sel = a.selectors()
    checks = len(QUANTITIES) * times + len(a.filter_names) * times
    family = probability ** (1.0 / checks)
    out = {"runs": N, "probability": probability, "family_probability": probability, "checks": checks,
           "quantities": {}, "states": {}}

    def entry(expected, variance, samples, size):
        lo, hi = mean_square_band(expected, variance, N, probability)
        flo, fhi = mean_square_band(expected, variance, N, family)
        mc = float(np.mean(samples))
        return {"analysis": float(np.sqrt(expected)) / size, "montecarlo": float(np.sqrt(mc)) / size,
                "band": [float(np.sqrt(lo)) / size, float(np.sqrt(hi)) / size], "inside": bool(lo <= mc <= hi),
                "family_band": [float(np.sqrt(flo)) / size, float(np.sqrt(fhi)) / size],
                "inside_family": bool(flo <= mc <= fhi)}

    errors = [quantity_errors(run) for run in runs]
    for name, (unit, size) in QUANTITIES.items():
        rows_out = []
        for r, f in zip(rows, frames):
            J = sel[name][r]
            C, m = J @ block[r] @ J.T, J @ total[r, :BLOCK]
            expected = np.trace(C) + m @ m
            variance = 2.0 * np.trace(C @ C) + 4.0 * m @ C @ m
            samples = [np.sum(err[name][f] ** 2) for err in errors]
            rows_out.append({"t": float(a.t[r]), **entry(expected, variance, samples, size)})
        out["quantities"][name] = {"unit": unit, "rows": rows_out}
    mean_f = total @ a.T.T
    var_f = a.diag_f.sum(axis=0)
    scale = edge_scale(a, a.filter_names)
    for j, name in enumerate(a.filter_names):
        rows_out = []
        for r, f in zip(rows, frames):
            expected = var_f[r, j] + mean_f[r, j] ** 2
            variance = 2.0 * var_f[r, j] ** 2 + 4.0 * mean_f[r, j] ** 2 * var_f[r, j]
            samples = [run["error_state"][f, j] ** 2 for run in runs]
            rows_out.append({"t": float(a.t[r]), **entry(expected, variance, samples, scale[r, j])})
        out["states"][name] = {"unit": state_unit(name)[0], "rows": rows_out}
    every = [row for group in ("quantities", "states") for item in out[group].values() for row in item["rows"]]
    out["inside"] = sum(row["inside"] for row in every)
    out["inside_family"] = sum(row["inside_family"] for row in every)
    return out


def covariance_lines(summary):
    """What the command line prints of a covariance analysis's summary."""
    lines = [f"{'quantity':<20}{'true RMS end':>14}{'filter σ end':>14}{'true/filter':>12}{'RMS steady':>12}  unit"]
    for name, q in summary["quantities"].items():
        ratio = "-" if q["true_over_filter_final"] is None else f"{q['true_over_filter_final']:.3f}"
        lines.append(f"{name.replace('_', ' '):<20}{q['final']:>14.4g}{q['filter_sigma_final']:>14.4g}{ratio:>12}"
                     f"{q['rms']:>12.4g}  {q['unit']}")
    nees = summary["nees_expected"]
    lines.append(f"expected NEES       {nees['mean']:.2f} after settling for {nees['dof']} dof (consistent: = dof)")
    lines += [f"note                {note}" for note in summary["notes"]]
    return lines


#: The format of a covariance budget's ``budget.json``.
BUDGET_FORMAT = "navsim.covariance-budget/1"


def covariance_budget(scenario, analysis):
    """The error budget of ``scenario`` from its analysis with the sources apart (the content of ``budget.json``,
    :data:`BUDGET_FORMAT`): per summary quantity and source, the RMS the source leaves alone (what a run with
    only that source averages to) and its share of the total mean square (tr(J P_s Jᵀ) + (J m_s)·(J m): the
    shares add up to the total's square exactly), at the end and over the frames after ``settle_s``."""
    from navsim.navigation.budget import SOURCES as LABELLED  # the labels of the same sources

    labels = {source.key: source.label for source in LABELLED}
    t = analysis.t
    steady = t >= scenario["settle_s"]
    steady = steady if steady.any() else np.ones_like(steady)
    share, alone = analysis.mean_square(), analysis.alone_mean_square()
    quantities = {}
    for name, (unit, size) in QUANTITIES.items():
        total = share[name].sum(axis=0)
        rows = {key: {"label": labels[key], "alone_final": float(np.sqrt(alone[name][i, -1])) / size,
                      "alone_rms": float(np.sqrt(np.mean(alone[name][i, steady]))) / size,
                      "share_final": float(share[name][i, -1]) / size**2,
                      "share_steady": float(np.mean(share[name][i, steady])) / size**2}
                for i, key in enumerate(analysis.sources)}
        quantities[name] = {"unit": unit, "total_final": float(np.sqrt(total[-1])) / size,
                            "total_rms": float(np.sqrt(np.mean(total[steady]))) / size, "sources": rows}
    return {"format": BUDGET_FORMAT, "method": "covariance", "scenario": scenario.name, "source": scenario.source,
            "settle_s": float(scenario["settle_s"]), "duration_s": float(t[-1]), "sources": list(analysis.sources),
            "quantities": quantities, "notes": list(analysis.notes)}


def covariance_budget_text(budget):
    """The covariance budget as lines of text: per source the horizontal position error it leaves alone and
    its share of the total's mean square, at the end."""
    q = budget["quantities"]["horizontal_position"]
    lines = [f"error budget        {budget['scenario']}: linear covariance analysis, horizontal position at the end "
             f"({budget['duration_s']:.0f} s)",
             f"{'source':<36} {'alone [m]':>11} {'share [m²]':>12} {'share %':>8}"]
    total2 = q["total_final"] ** 2
    for row in q["sources"].values():
        lines.append(f"{row['label']:<36} {row['alone_final']:11.2f} {row['share_final']:12.4g} "
                     f"{100 * row['share_final'] / total2 if total2 else 0.0:8.1f}")
    lines.append(f"{'total (√ of the summed shares)':<36} {q['total_final']:11.2f} {total2:12.4g} {100.0:8.1f}")
    return lines


def metric_unit(name):
    """The edge unit of the sweep metric ``name`` (a summary quantity)."""
    return QUANTITIES[name][0]


def check_metric(scenario, name, time_s):
    """An InputError unless ``name`` is a summary quantity and ``time_s`` [s] (None: the end) lies in the run."""
    if name not in QUANTITIES:
        raise InputError(f"--metric {name}: unknown; choose one of {', '.join(QUANTITIES)}")
    if time_s is not None and not 0.0 < time_s <= scenario["duration_s"]:
        raise InputError(f"--metric {name}@{time_s:g}s: the time must be inside the run (0, {scenario['duration_s']:g}] s")


def _row(t, time_s):
    return t.size - 1 if time_s is None else int(np.argmin(np.abs(t - time_s)))


def covariance_metric(analysis, name, time_s):
    """{value, filter_sigma, t}: the summary quantity ``name``'s true RMS and the filter's σ at the kept frame
    nearest ``time_s`` [s] (None: the end), in its edge unit."""
    s = analysis.series()
    r = _row(s["t"], time_s)
    return {"value": float(s[f"{name}_rms"][r]), "filter_sigma": float(s[f"{name}_sigma_filter"][r]), "t": float(s["t"][r])}


def montecarlo_metric(runs, name, time_s):
    """{value, t, runs}: the RMS over the run series ``runs`` of the summary quantity ``name`` at the frame nearest
    ``time_s`` [s] (None: the end), in its edge unit."""
    t = runs[0]["t"]
    f = _row(t, time_s)
    squares = [np.sum(quantity_errors(run)[name][f] ** 2) for run in runs]
    return {"value": float(np.sqrt(np.mean(squares))) / QUANTITIES[name][1], "t": float(t[f]), "runs": len(runs)}
