"""A replay: the recorded IMU through the strapdown mechanization and the navigation filter
(:class:`navsim.estimation.nav_filter.NavFilter`), aided by the recording's GNSS fixes outside the simulated outages;
the fixes inside them are the reference the filter's error is measured against.

The filter starts at the first fix at or after the IMU's first row, at rest: position that fix's, velocity zero,
level from the accelerometers over ``alignment.level_s`` (:func:`navsim.replay.alignment.level`), heading the one the
gyros turn into the GNSS course at the first fix at ``heading_speed_m_per_s`` (:func:`navsim.replay.alignment.start_heading`). The IMU is mechanized on its uniform grid
(:mod:`navsim.replay.recording`); a fix at time t_f is applied at the IMU interval's end t_k nearest to it, moved to
t_k along its own velocity (else the filter's): p_f + v (t_k − t_f), so that the grid's half-interval (up to 8 cm at
16 m/s and 100 Hz) is not an error. Every fix epoch is logged (the filter's solution and σ before the update) with
its error against the fix. With a star sensor (:mod:`navsim.replay.star_sensor`) each of its frames is applied
(:meth:`~navsim.estimation.nav_filter.NavFilter.update_attitude`, in the outages too) once the filter has mechanized
the intervals before it, before the fixes at or after it; each frame is logged (its NIS, accepted, the attitude
before it against the reference and the filter's attitude σ). Frames after the last fix are not reached.

With ``[replay.constraints]`` a land vehicle's constraints update the filter at every fix epoch after its fix, in the
outages too: where the IMU's window before the epoch is at rest (:mod:`navsim.replay.stationarity`, the IMU alone) a
zero-velocity update v_n = 0 of σ ``zupt_sigma_m_per_s`` (:meth:`NavFilter.update_velocity`), elsewhere the
non-holonomic constraint, the body's lateral and vertical velocity zero of σ ``nhc_sigma_m_per_s``
(:meth:`NavFilter.update_body_velocity`); each gated like a fix.
"""

import time
from dataclasses import dataclass

import numpy as np

from navsim.earth.wander import displaced, ned_offset
from navsim.estimation.nav_filter import ImuNoise, NavFilter, NavFilterConfig
from navsim.replay import alignment, fixes, outages, recording, star_sensor, stationarity
from startrack import InputError, units
from startrack import rotation as rot


@dataclass(frozen=True)
class Replay:
    """The inputs of a replay read and checked: ``imu`` (:class:`~navsim.replay.recording.ImuRecording`, body axes),
    ``fixes`` (:class:`~navsim.replay.fixes.Fixes`), ``start`` [s] the first fix used and ``k0`` its IMU interval,
    ``level_end`` and ``aligned`` [s after start] the ends of levelling and the heading's alignment, ``windows``
    (K, 2) [s after start] the outages, ``config`` the checked ``[replay]`` table, ``stars`` the star sensor's frames
    (:class:`~navsim.replay.star_sensor.StarFixes`, None without one)."""

    imu: recording.ImuRecording
    fixes: fixes.Fixes
    start: float
    k0: int
    level_end: float
    aligned: float
    windows: np.ndarray
    config: dict
    stars: star_sensor.StarFixes | None = None


def read(config):
    """The :class:`Replay` of a checked ``[replay]`` table (:mod:`navsim.replay.scenario`)."""
    imu_table, gnss = config["imu"], config["gnss"]
    imu = recording.read_imu(imu_table["file"], imu_table["columns"], imu_table["quantity"], imu_table["accel_unit"],
                             imu_table["gyro_unit"], imu_table["time_unit"], imu_table["time_tag_file"] or None,
                             imu_table["time_offset_s"])
    C_b_imu = alignment.euler_matrix(*units.deg_to_rad(imu_table["mounting_rpy_deg"]))
    body = np.concatenate([imu.samples[:, 0:3] @ C_b_imu.T, imu.samples[:, 3:6] @ C_b_imu.T], axis=1)
    keep = body.shape[0] if imu_table["duration_s"] is None else min(body.shape[0], round(imu_table["duration_s"] / imu.dt))
    imu = recording.ImuRecording(t0=imu.t0, dt=imu.dt, samples=body[:keep], filled=imu.filled[:keep],
                                 gaps=imu.gaps[imu.gaps[:, 0] < imu.t0 + keep * imu.dt])
    solution = (fixes.read_pos(gnss["file"], tuple(gnss["qualities"])) if gnss["format"] == "rtklib_pos"
                else fixes.read_csv(gnss["file"], gnss["columns"], tuple(gnss["qualities"])))
    solution = solution.subset((solution.t >= imu.t0) & (solution.t <= imu.end))
    if gnss["use_velocity"] and solution.v_n is None:
        raise InputError(f"{gnss['file']}: replay.gnss.use_velocity, but the solution has no velocity columns")
    if len(solution) < 2:
        raise InputError(f"{gnss['file']}: fewer than two fixes inside the IMU log's time "
                         f"({imu.t0:.3f} to {imu.end:.3f} s); check the time tags and time_offset_s")
    start = float(solution.t[0])
    a = config["alignment"]
    level_end = alignment.rest_span(solution, start, a["level_s"], a["rest_speed_m_per_s"]) - start
    moving = np.flatnonzero((alignment.horizontal_speed(solution) >= a["heading_speed_m_per_s"])
                            & (solution.t >= start + level_end))
    if not moving.size:
        raise InputError(f"{gnss['file']}: the vehicle never reaches alignment.heading_speed_m_per_s "
                         f"({a['heading_speed_m_per_s']:g} m/s); the heading cannot be aligned")
    aligned = float(solution.t[moving[0]] - start)
    o = config["outages"]
    windows = [[w["start_s"], w["duration_s"]] for w in o["windows"]]
    if "schedule" in o:
        windows += outages.scheduled(o["schedule"]["first_s"], o["schedule"]["lengths_s"], o["schedule"]["spacing_s"]).tolist()
    windows = outages.checked(np.array(windows, dtype=float).reshape(-1, 2), aligned, imu.end - start)
    k0 = int(np.ceil((start - imu.t0) / imu.dt - 1e-9))
    stars = star_sensor.draw(config["star_sensor"], imu, solution, k0) if "star_sensor" in config else None
    return Replay(imu=imu, fixes=solution, start=start, k0=k0, level_end=level_end, aligned=aligned, windows=windows,
                  config=config, stars=stars)


def filter_config(replay):
    """The :class:`~navsim.estimation.nav_filter.NavFilterConfig` of ``replay.config['filter']``: P0 of the initial σ
    (the position's the first fix's), the IMU noise the filter assumes, the covariance interval and the gate."""
    f = replay.config["filter"]
    sigma = [*[units.deg_to_rad(f["initial_tilt_sigma_deg"])] * 2, units.deg_to_rad(f["initial_heading_sigma_deg"]),
             *[f["initial_velocity_sigma_m_per_s"]] * 3, *replay.fixes.sigma[0],
             *[units.deg_to_rad(f["initial_gyro_bias_sigma_deg_per_s"])] * 3, *[f["initial_accel_bias_sigma_m_per_s2"]] * 3]
    noise = ImuNoise(arw=float(units.deg_to_rad(f["gyro_arw_deg_per_sqrt_s"])), vrw=f["accel_vrw_m_per_s_per_sqrt_s"],
                     gyro_bias_rw=float(units.deg_to_rad(f["gyro_bias_rw_deg_per_s_per_sqrt_s"])),
                     accel_bias_rw=f["accel_bias_rw_m_per_s2_per_sqrt_s"])
    return NavFilterConfig(np.diag(np.square(np.array(sigma, dtype=float))), noise, replay.imu.dt,
                           star_sensor=None if replay.stars is None else replay.stars.model,
                           covariance_interval=f["covariance_interval"], gate_probability=f["gate_probability"])


def rest_epochs(replay):
    """(N,) whether the vehicle is at rest at each fix epoch, from the IMU's window before it (the detector of
    :mod:`navsim.replay.stationarity` with σ_a = VRW / √Δt of the filter's figure); all False without constraints."""
    c, imu, f = replay.config["constraints"], replay.imu, replay.fixes
    if not (c["zupt"] or c["nhc"]):
        return np.zeros(len(f), dtype=bool)
    window = round(c["zupt_window_s"] / imu.dt)
    if window < 2:
        raise InputError(f"replay.constraints.zupt_window_s: {c['zupt_window_s']:g} s is fewer than two IMU intervals "
                         f"of {imu.dt:g} s")
    ends = [_interval_end(imu, t) for t in f.t]
    sigma = replay.config["filter"]["accel_vrw_m_per_s_per_sqrt_s"] / np.sqrt(imu.dt)
    return stationarity.at_rest(imu.samples[:, 3:6], ends, window, sigma, c["zupt_probability"])


def _interval_end(imu, t):
    """The IMU grid's interval end nearest to the time ``t`` [s] (at most its last)."""
    return min(round((t - imu.t0) / imu.dt), imu.samples.shape[0])


def constrain(nav, constraints, at_rest):
    """(ZUPT, NHC): the :class:`~navsim.estimation.updates.UpdateResult` of the constraint applied at an epoch (module
    docstring), None for the one not applied."""
    if at_rest:
        return (nav.update_velocity(np.zeros(3), constraints["zupt_sigma_m_per_s"]) if constraints["zupt"] else None), None
    return None, (nav.update_body_velocity(np.zeros(2), constraints["nhc_sigma_m_per_s"]) if constraints["nhc"] else None)


def initial_filter(replay):
    """The :class:`NavFilter` at the replay's start: the first fix, at rest, levelled, its heading the one the gyros
    turn into the GNSS course at the aligning fix (module docstring)."""
    imu, k0, f = replay.imu, replay.k0, replay.fixes
    roll, pitch = alignment.level(imu.samples[k0:k0 + max(1, round(replay.level_end / imu.dt)), 3:6])
    j = int(np.searchsorted(f.t, replay.start + replay.aligned - 1e-9))
    course = float(np.arctan2(*alignment.velocity_ne(f)[j, ::-1]))
    k_j = _interval_end(imu, f.t[j])
    heading = alignment.start_heading(course, alignment.q_nb(roll, pitch, 0.0), imu.samples[k0:k_j, 0:3], imu.dt)
    return NavFilter(f.lat[0], f.lon[0], f.h[0], np.zeros(3), alignment.q_nb(roll, pitch, heading), filter_config(replay))


def simulate(replay):
    """Run the replay; returns (series, counts): the per-fix-epoch log (:func:`_log_epoch`) and what the run did."""
    started = time.perf_counter()
    nav = initial_filter(replay)
    imu, f = replay.imu, replay.fixes
    t_rel = f.t - replay.start
    window = outages.held_out(t_rel, replay.windows)
    free = replay.config["outages"]["free_ins"]
    held = (window >= 0) | (free & (t_rel > replay.aligned))
    k = replay.k0
    log = {name: [] for name in ("t", "lat", "lon", "h", "v_n", "q_nb", "sigma_ned", "error_ned", "accepted", "nis",
                                 "gyro_bias", "accel_bias", "sigma_bias", "zupt", "zupt_nis", "nhc", "nhc_nis")}
    rest, constraints = rest_epochs(replay), replay.config["constraints"]
    floor, velocity = replay.config["gnss"]["sigma_floor_m"], replay.config["gnss"]["use_velocity"]
    frames = _StarLog(replay)
    for j in range(1, len(f)):
        k_j = _interval_end(imu, f.t[j])
        k = frames.apply_until(nav, k, k_j)
        if k_j > k:
            nav.predict(imu.samples[k:k_j], imu.dt)
            k = k_j
        t_state = imu.t0 + k * imu.dt
        lat, lon, h = _moved_fix(f, j, nav, t_state - f.t[j])
        before = (nav.position, nav.v_n, nav.q_nb, nav.P, nav.gyro_bias, nav.accel_bias)
        error = ned_offset(*before[0], lat, lon, h)
        result = None if held[j] else nav.update_position(lat, lon, h, np.maximum(f.sigma[j], floor))
        if velocity and not held[j]:
            nav.update_velocity(f.v_n[j], f.v_sigma[j])
        _log_epoch(log, t_rel[j], before, error, result)
        for name, applied in zip(("zupt", "nhc"), constrain(nav, constraints, rest[j])):
            _log_update(log, name, applied)
        if k >= imu.samples.shape[0]:
            break
    series = {name: np.array(values) for name, values in log.items()}
    series["outage"] = window[1:series["t"].size + 1]
    series["held_out"] = held[1:series["t"].size + 1]
    series["at_rest"] = rest[1:series["t"].size + 1]
    series.update(frames.series())
    counts = {"fixes": len(f), "imu_intervals": int(k - replay.k0), "filled_intervals": int(imu.filled[replay.k0:k].sum()),
              "gaps": int(imu.gaps.shape[0]), "gap_seconds": float(imu.gaps[:, 1].sum()) if imu.gaps.size else 0.0,
              "wall_seconds": round(time.perf_counter() - started, 3)}
    return series, counts


def _moved_fix(f, j, nav, lag):
    """(L, λ, h) of fix ``j`` moved by ``lag`` [s] along its velocity (else the filter's, ``nav.v_n``)."""
    v = f.v_n[j] if f.v_n is not None else nav.v_n
    lat, lon = displaced(f.lat[j], f.lon[j], f.h[j], v[0] * lag, v[1] * lag)
    return float(lat), float(lon), float(f.h[j] - v[2] * lag)


def _log_epoch(log, t, before, error, result):
    """Append one fix epoch: the solution before the update ``before`` ((L, λ, h), v_n, q_nb, P, b̂_g, b̂_a), its NED
    position σ and the biases' σ, the error against the fix, whether it was used and accepted (−1: held out) and its
    NIS (NaN: held out)."""
    (lat, lon, h), v_n, q_nb, P, gyro_bias, accel_bias = before
    log["t"].append(t)
    log["lat"].append(lat)
    log["lon"].append(lon)
    log["h"].append(h)
    log["v_n"].append(v_n)
    log["q_nb"].append(q_nb)
    log["sigma_ned"].append(np.sqrt(np.diag(P)[6:9]))
    log["gyro_bias"].append(gyro_bias)
    log["accel_bias"].append(accel_bias)
    log["sigma_bias"].append(np.sqrt(np.diag(P)[9:15]))
    log["error_ned"].append(error)
    _log_update(log, None, result)


def _log_update(log, name, result):
    """Append whether an update was applied and accepted (−1: not applied) and its NIS (NaN: not applied) to the
    columns ``name`` and ``name_nis`` (the fix's: ``accepted`` and ``nis``)."""
    log["accepted" if name is None else name].append(-1 if result is None else int(result.accepted[0]))
    log["nis" if name is None else f"{name}_nis"].append(np.nan if result is None else float(result.nis[0]))


class _StarLog:
    """The star sensor's frames of a replay (none without one), applied in time order, and their log: ``star_t``
    [s after the start], ``star_accepted`` (1, 0; −1 not applied), ``star_nis`` (NaN: not applied), ``star_q_nb``
    (F, 4) the solution's attitude before the frame, ``star_attitude_error`` (F, 3) [rad] its φ against the
    reference (C_nb = (I − [φ×]) C_nb,ref, NED axes) and ``star_attitude_sigma`` (F, 3) [rad] the filter's σ of φ
    there."""

    def __init__(self, replay):
        self.replay, self.stars, self.next = replay, replay.stars, 0
        self.log = {name: [] for name in ("star_t", "star_accepted", "star_nis", "star_q_nb", "star_attitude_error",
                                          "star_attitude_sigma")}

    def apply_until(self, nav, k, k_end):
        """Mechanize from grid index ``k`` through every frame before ``k_end``, applying each; returns the index
        the filter stands at."""
        stars, imu = self.stars, self.replay.imu
        while stars is not None and self.next < stars.k.size and stars.k[self.next] < k_end:
            i, k_s = self.next, int(stars.k[self.next])
            if k_s > k:
                nav.predict(imu.samples[k:k_s], imu.dt)
                k = k_s
            q_nb = nav.q_nb
            error = -rot.to_rotation_vector(rot.multiply(q_nb, rot.conjugate(stars.q_nb_ref[i])))
            sigma = np.sqrt(np.diag(nav.P)[0:3])
            result = nav.update_attitude(stars.q_IS[i], stars.R_S) if stars.applied else None
            self.log["star_t"].append(imu.t0 + k_s * imu.dt - self.replay.start)
            self.log["star_accepted"].append(-1 if result is None else int(result.accepted[0]))
            self.log["star_nis"].append(np.nan if result is None else float(result.nis[0]))
            self.log["star_q_nb"].append(q_nb)
            self.log["star_attitude_error"].append(error)
            self.log["star_attitude_sigma"].append(sigma)
            self.next += 1
        return k

    def series(self):
        """The log as arrays (empty without a star sensor)."""
        if self.stars is None:
            return {}
        out = {name: np.array(values) for name, values in self.log.items()}
        for name, width in (("star_q_nb", 4), ("star_attitude_error", 3), ("star_attitude_sigma", 3)):
            out[name] = out[name].reshape(-1, width)
        out["star_outage"] = outages.held_out(out["star_t"], self.replay.windows)
        return out
