"""What a replay's summary says: its error against the held-out fixes in each outage (horizontal max, RMS and at the
end, vertical max), beside the filter's own σ there, the aided epochs' one-step error, the updates, the constraints
(ZUPT and non-holonomic: accepted, rejected, mean NIS), the gaps, the alignment, the timing and, with a star sensor,
its frames and the heading error against the reference attitude. The horizontal error of an epoch is √(δN² + δE²) of
the solution before any update against the fix moved to the epoch's time (:mod:`navsim.replay.run`); the RMS is over
the outage's fixes at 4 Hz (or the solution's rate)."""

import numpy as np

from startrack import rotation as rot


def horizontal(series):
    """(F,) [m] the horizontal error of each logged epoch."""
    return np.hypot(series["error_ned"][:, 0], series["error_ned"][:, 1])


def outage_rows(series, windows):
    """One dict per outage window: its start and duration [s], the fixes held, the horizontal error's max, RMS and
    last value [m], the vertical error's max [m] and the filter's horizontal 1σ at its end [m]."""
    error, rows = horizontal(series), []
    for i, (start, duration) in enumerate(windows):
        inside = series["outage"] == i
        e, sigma = error[inside], series["sigma_ned"][inside]
        rows.append({"start_s": float(start), "duration_s": float(duration), "fixes": int(inside.sum()),
                     "max_horizontal_m": float(e.max()) if e.size else None,
                     "rms_horizontal_m": float(np.sqrt(np.mean(e**2))) if e.size else None,
                     "end_horizontal_m": float(e[-1]) if e.size else None,
                     "max_vertical_m": float(np.abs(series["error_ned"][inside, 2]).max()) if e.size else None,
                     "sigma_horizontal_end_m": float(np.hypot(*sigma[-1, :2])) if e.size else None})
    return rows


def summarize(name, replay, series, counts):
    """The summary dictionary of a replay (module docstring)."""
    aided = series["accepted"] == 1
    error = horizontal(series)
    after_first = aided & (np.concatenate([[False], aided[:-1]]))  # an aided epoch after an aided one: the 4 Hz step
    return {
        "name": name, "kind": "replay",
        "start_gpst_s": replay.start, "duration_s": float(series["t"][-1]) if series["t"].size else 0.0,
        "imu": {"interval_s": replay.imu.dt, "intervals": counts["imu_intervals"], "gaps": counts["gaps"],
                "gap_seconds": counts["gap_seconds"], "filled_intervals": counts["filled_intervals"]},
        "alignment": {"level_end_s": replay.level_end, "heading_aligned_s": replay.aligned,
                      **dict(zip(("roll_deg", "pitch_deg"), np.degrees(first_level(series)).tolist()))},
        "updates": {"accepted": int(aided.sum()), "rejected": int((series["accepted"] == 0).sum()),
                    "held_out": int(series["held_out"].sum())},
        "aided_one_step_horizontal_m": {"median": float(np.median(error[after_first])) if after_first.any() else None,
                                        "rms": float(np.sqrt(np.mean(error[after_first] ** 2))) if after_first.any() else None},
        "constraints": constraint_counts(series),
        "outages": outage_rows(series, replay.windows),
        "free_ins": bool(replay.config["outages"]["free_ins"]),
        **({} if replay.stars is None else {"star_sensor": star_sensor(replay, series)}),
        "timing": {"wall_seconds": counts["wall_seconds"]},
    }


def constraint_counts(series):
    """The epochs the detector found at rest and, for the ZUPT (3 dof) and the non-holonomic constraint (2 dof), the
    updates accepted and rejected by the gate and the accepted ones' mean NIS (its expectation the dof when the σ is
    right; None without any)."""
    out = {"at_rest_epochs": int(series["at_rest"].sum())}
    for name, dof in (("zupt", 3), ("nhc", 2)):
        accepted = series[name] == 1
        out[name] = {"accepted": int(accepted.sum()), "rejected": int((series[name] == 0).sum()), "dof": dof,
                     "mean_nis": float(np.mean(series[f"{name}_nis"][accepted])) if accepted.any() else None}
    return out


def star_sensor(replay, series):
    """The star sensor's block: its frames applied, accepted, rejected, their NIS's mean (3 dof) and, against the
    reference attitude, the heading error's (|φ_D|) RMS and max over every frame and by outage (with the filter's
    heading σ at the outage's end) [deg]."""
    accepted, heading = series["star_accepted"], np.degrees(np.abs(series["star_attitude_error"][:, 2]))
    nis = series["star_nis"][accepted >= 0]
    rows = []
    for i, (start, duration) in enumerate(replay.windows):
        inside = series["star_outage"] == i
        e = heading[inside]
        rows.append({"start_s": float(start), "duration_s": float(duration), "frames": int(inside.sum()),
                     "max_heading_error_deg": float(e.max()) if e.size else None,
                     "heading_sigma_end_deg": float(np.degrees(series["star_attitude_sigma"][inside][-1, 2])) if e.size else None})
    return {"applied": bool(replay.stars.applied), "frames": int(accepted.size), "accepted": int((accepted == 1).sum()),
            "rejected": int((accepted == 0).sum()), "nis_mean": float(np.mean(nis)) if nis.size else None, "nis_dof": 3,
            "rate_hz": replay.config["star_sensor"]["rate_hz"],
            "heading_error_deg": {"rms": float(np.sqrt(np.mean(heading**2))), "max": float(heading.max())},
            "outages": rows}


def first_level(series):
    """(roll, pitch) [rad] of the first logged attitude."""
    C = rot.to_matrix(series["q_nb"][0])
    return np.array([np.arctan2(C[2, 1], C[2, 2]), -np.arcsin(C[2, 0])])


def lines(summary):
    """What the command line prints of a replay."""
    out = [f"replay              {summary['name']} ({summary['duration_s']:.1f} s, IMU interval "
           f"{1e3 * summary['imu']['interval_s']:.3f} ms, {summary['imu']['gaps']} gaps of {summary['imu']['gap_seconds']:.3f} s)",
           f"alignment           levelled to {summary['alignment']['level_end_s']:.1f} s, heading from the GNSS course at "
           f"{summary['alignment']['heading_aligned_s']:.1f} s",
           f"updates             {summary['updates']['accepted']} accepted, {summary['updates']['rejected']} rejected, "
           f"{summary['updates']['held_out']} held out"]
    c = summary["constraints"]
    for name, label in (("zupt", "ZUPT"), ("nhc", "NHC")):
        if c[name]["accepted"] or c[name]["rejected"]:
            out.append(f"{label:20s}{c[name]['accepted']} accepted, {c[name]['rejected']} rejected, mean NIS "
                       f"{c[name]['mean_nis'] or float('nan'):.2f} of {c[name]['dof']} dof"
                       + (f" ({c['at_rest_epochs']} epochs at rest)" if name == "zupt" else ""))
    for row in summary["outages"]:
        if row["fixes"]:
            out.append(f"outage {row['start_s']:7.1f} s + {row['duration_s']:5.1f} s   horizontal max {row['max_horizontal_m']:8.2f} m, "
                       f"RMS {row['rms_horizontal_m']:8.2f} m (filter 1σ at end {row['sigma_horizontal_end_m']:.2f} m)")
    if "star_sensor" in summary:
        s = summary["star_sensor"]
        used = (f"{s['accepted']} accepted, {s['rejected']} rejected, NIS mean {s['nis_mean']:.2f} (3 dof)" if s["applied"]
                else "drawn, not applied")
        out.append(f"star sensor         {s['frames']} frames at {s['rate_hz']:g} Hz: {used}; heading error against the "
                   f"reference RMS {s['heading_error_deg']['rms']:.4f} deg, max {s['heading_error_deg']['max']:.4f} deg")
    out.append(f"wall time           {summary['timing']['wall_seconds']:.2f} s")
    return out

