"""Linear covariance analysis of an attitude scenario (``navsim covariance``): the true RMS of the attitude
(body, cross-boresight, roll) and gyro-bias errors along the scenario's truth attitude profile, the MEKF's own
σ beside it, and each error source's share (:mod:`navsim.estimation.lincov`, driven by
:func:`navsim.estimation.att_lincov.run`).

The truth model is the simulation's: the filter's initial attitude error (drawn from its P0), the gyro's
turn-on bias (a mean when the scenario fixes it), rate random walk, Gauss-Markov bias instability (σ_g, τ),
angle random walk, scale factors and axis misalignments, bias steps (a mean), the star sensor's mounting error
(the scenario gives it: a mean) and its noise. The filter is the scenario's
(:func:`navsim.attitude.build.filter_config`: its groups estimated, considered or ignored, its Q and R).
Left out, as a linear analysis must: quantisation, NIS gating, attitude jumps and the re-initialisations
after a lost track. At image fidelity the star sensor is its vector-fidelity equivalent
(:func:`navsim.build.star_sensor.vector_equivalent`; the summary's notes say so).
"""

import functools
import time

import numpy as np

from navsim.analysis import Analysis, Quantity
from navsim.attitude import build
from navsim.build.faults import bias_steps
from navsim.build.star_sensor import vector_equivalent
from navsim.estimation.att_lincov import Measurements, run
from navsim.estimation.attitude_filter import AttitudeFilter
from navsim.estimation.kernels import FilterModel, process_noise
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.star_sensor import isotropic_covariance
from navsim.sensors.star_vector import AttitudeFixSensor
from navsim.truth.profiles import sample_truth
from startrack import load_star_catalog, units
from startrack import rotation as rot

#: The error sources, in order, with their labels.
COVARIANCE_SOURCES = {"initial": "filter's initial attitude error", "gyro_bias": "gyro bias (turn-on, random walk, instability)",
           "gyro_noise": "gyro angle random walk", "gyro_calibration": "gyro scale factors and misalignments",
           "mounting": "star-sensor mounting error", "star_noise": "star-sensor noise"}
#: At most this many output rows.
MAX_ROWS = 4000
#: The summary quantities: their unit at the edge and its size in SI.
COVARIANCE_QUANTITIES = {"attitude": ("arcsec", units.ARCSEC), "cross_boresight": ("arcsec", units.ARCSEC),
              "roll": ("arcsec", units.ARCSEC), "gyro_bias": ("deg/h", units.DEG / units.HOUR)}
#: The groups of the error state after δθ and δb, their name prefixes and edge units.
GROUPS = (("bias_instability", "dg", 3, "deg/h", units.DEG / units.HOUR), ("scale_factor", "ds", 3, "ppm", units.PPM),
          ("gyro_misalignment", "dk", 6, "arcsec", units.ARCSEC), ("mounting", "dm", 3, "arcsec", units.ARCSEC))


def _names(present):
    """(names, units, SI sizes) of an error state with the groups ``present`` (a set of group names)."""
    names, unit, size = [f"dtheta_{a}" for a in "xyz"] + [f"db_{a}" for a in "xyz"], ["arcsec"] * 3 + ["deg/h"] * 3, \
        [units.ARCSEC] * 3 + [units.DEG / units.HOUR] * 3
    for group, prefix, count, edge, si in GROUPS:
        if group in present:
            names += [f"{prefix}_{i}" for i in range(count)]
            unit += [edge] * count
            size += [si] * count
    return tuple(names), tuple(unit), np.array(size)


def _start(names, group):
    prefix = dict((g, p) for g, p, *_ in GROUPS)[group]
    return names.index(f"{prefix}_0")


def truth_model(gyro, filter_model):
    """The truth's :data:`~navsim.estimation.kernels.FilterModel`: every group the gyro or the filter has, the
    mounting always; the gyro's own noise."""
    n_bi = 3 if gyro.bias_instability_sigma > 0.0 or filter_model.n_bi else 0
    n_sf = 3 if gyro.scale_factor_sigma > 0.0 or filter_model.n_sf else 0
    n_gm = 6 if gyro.misalignment_sigma > 0.0 or filter_model.n_gm else 0
    tau = gyro.bias_correlation_time if gyro.bias_instability_sigma > 0.0 else filter_model.gm_tau
    return FilterModel(arw=float(gyro.arw), rrw=float(gyro.rrw), gm_sigma=float(gyro.bias_instability_sigma),
                       gm_tau=float(tau) if np.isfinite(tau) else 1e30, cal_rw=0.0, q_scale=1.0, n_bi=n_bi, n_sf=n_sf,
                       n_gm=n_gm, mounting=True)


def _present(model):
    return {g for g, size in (("bias_instability", model.n_bi), ("scale_factor", model.n_sf),
                              ("gyro_misalignment", model.n_gm), ("mounting", 3 * model.mounting)) if size}


def _initial(scenario, gyro, filt, tm, names, dt):
    """(P0 (S, n, n), m0 (S, n), Q (S, n, n)) of the truth by source (:data:`COVARIANCE_SOURCES`)."""
    S, n = len(COVARIANCE_SOURCES), len(names)
    src = {key: i for i, key in enumerate(COVARIANCE_SOURCES)}
    P0, m0 = np.zeros((S, n, n)), np.zeros((S, n))
    fixed = scenario["filter"]["initial_attitude_error_arcsec"]
    if fixed is None:
        P0[src["initial"], 0:3, 0:3] = filt.config.P0[0:3, 0:3]
    else:
        m0[src["initial"], 0:3] = units.arcsec_to_rad(np.asarray(fixed, dtype=float))
    b = src["gyro_bias"]
    if gyro.bias_turn_on is not None:
        m0[b, 3:6] = gyro.bias_turn_on
    else:
        P0[b, 3:6, 3:6] += np.eye(3) * gyro.bias_turn_on_sigma**2
    if tm.n_bi:
        g, s2 = _start(names, "bias_instability"), gyro.bias_instability_sigma**2
        for i in range(3):
            P0[b, 3 + i, 3 + i] += s2
            P0[b, 3 + i, g + i] = P0[b, g + i, 3 + i] = P0[b, g + i, g + i] = s2
    c = src["gyro_calibration"]
    for group, sigma in (("scale_factor", gyro.scale_factor_sigma), ("gyro_misalignment", gyro.misalignment_sigma)):
        if group in _present(tm):
            start, count = _start(names, group), 3 if group == "scale_factor" else 6
            P0[c, start:start + count, start:start + count] = np.eye(count) * sigma**2
    m0[src["mounting"], n - 3:] = units.arcsec_to_rad(np.asarray(scenario["star_sensor"]["misalignment_arcsec"], float))
    Q = np.zeros((S, n, n))
    Q[src["gyro_noise"]] = process_noise(tm._replace(rrw=0.0, gm_sigma=0.0), dt, n)
    Q[src["gyro_bias"]] = process_noise(tm._replace(arw=0.0), dt, n)
    return P0, m0, Q


def _measurements(scenario, truth, ratio, frames, dt, star_catalog, src):
    """(:data:`~navsim.estimation.att_lincov.Measurements`, a note on the star sensor's model or None)."""
    table = scenario["star_sensor"]
    if table["measurement"] == "stars" and star_catalog is None:
        star_catalog = load_star_catalog(epoch=scenario["epoch_jyear"])
    sensor, note = vector_equivalent(scenario, star_catalog, ratio * dt, scenario["epoch_jyear"])
    k = (np.arange(frames) + 1) * ratio
    available = sensor.faults.available(k * dt)
    offsets, ref, obs, cov = np.zeros(frames + 1, np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3, 3))
    fix_mask, fix_q, fix_R = np.zeros(frames, np.bool_), np.zeros((frames, 4)), np.zeros((3, 3))
    if isinstance(sensor, AttitudeFixSensor):
        fix_mask, fix_q, fix_R = available, rot.multiply(truth.q_IB[k], sensor.q_BS_true), sensor.R_S
    else:
        stars = sensor.observe_frames(truth.q_IB[k], np.random.default_rng(0), noise=False)
        frame = np.repeat(np.arange(frames), np.diff(stars.offsets))
        keep = available[frame]
        frame, ref, obs = frame[keep], stars.ref_I[keep], stars.obs_S[keep]
        offsets = np.concatenate([[0], np.cumsum(np.bincount(frame, minlength=frames))])
        cov = isotropic_covariance(obs, stars.sigma[keep])
    meas = Measurements(star_offsets=offsets, star_ref=np.ascontiguousarray(ref), star_obs=np.ascontiguousarray(obs),
                        star_cov=np.ascontiguousarray(cov), fix_mask=fix_mask, fix_q=np.ascontiguousarray(fix_q),
                        fix_R=np.ascontiguousarray(fix_R, dtype=float),
                        r_scale2=float(scenario["filter"]["measurement_noise_scale"]) ** 2, star_source=src("star_noise"))
    return meas, note


def covariance_analysis(scenario, split=False, star_catalog=None):
    """The linear covariance analysis of a validated attitude scenario: a :class:`navsim.analysis.Analysis`, each
    error source apart when ``split`` (the budget), else their sum ("total")."""
    started = time.perf_counter()
    gyro_hz = scenario["gyro"]["rate_hz"]
    dt = 1.0 / gyro_hz
    ratio = int(round(gyro_hz / scenario["star_sensor"]["rate_hz"]))
    n_gyro = int(round(scenario["duration_s"] * gyro_hz))
    factor = int(round(scenario["truth"]["rate_hz"] / gyro_hz))
    truth = sample_truth(build.truth_profile(scenario), build.initial_attitude(scenario), n_gyro, gyro_hz, factor)
    gyro = build.gyro(scenario)
    config = build.filter_config(scenario, gyro)
    filt = AttitudeFilter(truth.q_IB[0], np.zeros(3), config)
    tm = truth_model(gyro, filt.model)
    names_t, units_t, size_t = _names(_present(tm))
    names_f, units_f, size_f = _names(_present(filt.model))
    W = np.zeros((len(names_t), len(names_f)))
    for j, name in enumerate(names_f):
        W[names_t.index(name), j] = 1.0
    P0, m0, Q = _initial(scenario, gyro, filt, tm, names_t, dt)
    keys = tuple(COVARIANCE_SOURCES)
    if split:
        present = [i for i in range(len(keys)) if np.any(P0[i]) or np.any(m0[i]) or np.any(Q[i]) or keys[i] == "star_noise"]
        sources, P0, m0, Q = tuple(keys[i] for i in present), P0[present], m0[present], Q[present]

        def src(name):
            return sources.index(name) if name in sources else -1
    else:
        sources, P0, m0, Q = ("total",), P0.sum(axis=0)[None], m0.sum(axis=0)[None], Q.sum(axis=0)[None]

        def src(name):
            return 0
    frames = n_gyro // ratio
    meas, note = _measurements(scenario, truth, ratio, frames, dt, star_catalog, src)
    steps = bias_steps(scenario["faults"])
    step_frames = np.array([int(t // (ratio * dt)) for t, _ in steps], dtype=np.int64)
    step_values = np.array([v for _, v in steps], dtype=float).reshape(-1, 3)
    Q_f = filt.model.q_scale * process_noise(filt.model, dt, filt.n)
    q_BS = np.asarray(mounting(scenario["star_sensor"])[0], dtype=float)
    stride = max(1, -(-frames // MAX_ROWS))
    out = run(np.ascontiguousarray(truth.omega_mean[:frames * ratio]), truth.q_IB, dt, ratio, stride, tm, np.ascontiguousarray(Q),
              filt.model, Q_f, W, np.ascontiguousarray(W.T), filt.estimated, np.ascontiguousarray(P0), np.ascontiguousarray(m0),
              np.array(filt.P), q_BS, meas, step_frames, step_values, max(src("gyro_bias"), 0), 6)
    t, mean_out, diag_t, diag_f, block, filter_diag, filter_block, nees = out
    K = t.size
    return Analysis(t=t, sources=sources, truth_names=names_t, filter_names=names_f, mean=mean_out, diag_t=diag_t,
                    diag_f=diag_f, block=block, filter_diag=filter_diag, filter_block=filter_block, nees=nees, nees_dof=6,
                    T=np.ascontiguousarray(W.T), quantities=quantities(rot.to_matrix(q_BS), K), units_t=units_t,
                    scale_t=np.broadcast_to(size_t, (K, size_t.size)), units_f=units_f,
                    scale_f=np.broadcast_to(size_f, (K, size_f.size)), run_errors=covariance_run_errors(scenario),
                    notes=() if note is None else (note,), wall_seconds=time.perf_counter() - started)


def quantities(R_BS, K):
    """{name: :class:`~navsim.analysis.Quantity`}: the body-axes attitude error, its cross-boresight and roll parts
    in sensor axes (R_SB δθ) and the gyro-bias error, on the leading block (δθ, δb)."""
    rows = {"attitude": np.hstack([np.eye(3), np.zeros((3, 3))]), "cross_boresight": np.hstack([R_BS.T[0:2], np.zeros((2, 3))]),
            "roll": np.hstack([R_BS.T[2:3], np.zeros((1, 3))]), "gyro_bias": np.hstack([np.zeros((3, 3)), np.eye(3)])}
    return {name: Quantity(unit=COVARIANCE_QUANTITIES[name][0], size=COVARIANCE_QUANTITIES[name][1],
                           rows=np.broadcast_to(J, (K, *J.shape)).copy()) for name, J in rows.items()}


def run_errors(R_BS, series):
    """({quantity: (F, r)}, the errors (F, 6) of δθ and δb) of an attitude run's series [SI], its sensor mounted
    by R_BS (S -> B)."""
    e, bias = series["attitude_error"], series["bias_true"] - series["bias_est"]
    e_S = e @ R_BS  # rows R_SB δθ: sensor axes
    return {"attitude": e, "cross_boresight": e_S[:, 0:2], "roll": e_S[:, 2:3], "gyro_bias": bias}, np.hstack([e, bias])


def covariance_run_errors(scenario):
    """The errors of a run series of ``scenario`` that make its summary quantities (:func:`run_errors` with its
    mounting)."""
    return functools.partial(run_errors, rot.to_matrix(mounting(scenario["star_sensor"])[0]))
