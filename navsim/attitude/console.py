"""What the command line prints of an attitude run and campaign beside what it prints of every run
(consistency, updates, wall time)."""


def run_lines(summary):
    """The scenario, the attitude errors [arcsec] and the final gyro bias error [deg/h] of a run."""
    err = summary["attitude_error_rms_arcsec"]
    return [
        f"scenario            {summary['scenario']}  (seed {summary['seed']}, {summary['duration_s']:g} s, "
        f"{summary['fidelity']}/{summary['measurement']})",
        f"attitude RMS        x {err['x']:.2f}\"  y {err['y']:.2f}\"  z {err['z']:.2f}\"   "
        f"cross-boresight {summary['cross_boresight_rms_arcsec']:.2f}\"  roll {summary['roll_rms_arcsec']:.2f}\"",
        "final bias error    " + "  ".join(f"{v:+.4f}" for v in summary["bias_error_final_deg_per_h"]) + " deg/h",
    ]


def campaign_lines(summary):
    """The spread of the runs' cross-boresight and roll RMS errors [arcsec] of a campaign with finished runs."""
    cross, roll = summary.get("cross_boresight_rms_arcsec"), summary.get("roll_rms_arcsec")
    if not cross:
        return []
    return [f"cross-boresight RMS mean {cross['mean']:.2f}\"  p95 {cross['p95']:.2f}\"   roll RMS mean {roll['mean']:.2f}\"  "
            f"p95 {roll['p95']:.2f}\""]
