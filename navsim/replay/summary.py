"""What a replay's summary says: its error against the held-out fixes in each outage (horizontal max, RMS and at the
end, vertical max), beside the filter's own σ there, the aided epochs' one-step error, the updates, the constraints
(ZUPT and non-holonomic: accepted, rejected, mean NIS), the gaps, the alignment and the timing. The horizontal error of an epoch is √(δN² + δE²) of the solution before any update against
the fix moved to the epoch's time (:mod:`navsim.replay.run`); the RMS is over the outage's fixes at 4 Hz (or the
solution's rate)."""

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
    out.append(f"wall time           {summary['timing']['wall_seconds']:.2f} s")
    return out

