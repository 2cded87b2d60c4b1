"""What the command line prints of a navigation run and campaign beside what it prints of every run
(consistency, updates, wall time)."""

from navsim.estimation.intervals import interval_text


def run_lines(summary):
    """The scenario, the position, velocity and attitude errors and the final IMU bias errors of a run."""
    nav, position = summary["navigation"], summary["position_error_m"]
    horizontal, vertical, nmi = position["horizontal"], position["vertical"], summary["position_error_nmi"]["horizontal"]
    velocity = summary["velocity_error_m_per_s"]
    lines = [
        f"scenario            {summary['scenario']}  (seed {summary['seed']}, {summary['duration_s']:g} s, INS at "
        f"{nav['imu_rate_hz']:g} Hz, aiding: {', '.join(nav['aiding']) or 'none (free INS)'})",
        f"horizontal error    final {horizontal['final']:.2f} m ({nmi['final']:.3f} nmi, {nmi['final_per_hour']:.3f} nmi/h)  "
        f"RMS {horizontal['rms']:.2f} m  max {horizontal['max']:.2f} m",
        f"along/cross track   RMS {position['along_track']['rms']:.2f} m / {position['cross_track']['rms']:.2f} m  "
        f"final {position['along_track']['final']:.2f} m / {position['cross_track']['final']:.2f} m",
        f"vertical error      final {vertical['final']:.2f} m  RMS {vertical['rms']:.2f} m  max {vertical['max']:.2f} m",
        f"velocity error RMS  horizontal {velocity['horizontal']['rms']:.3f} m/s  vertical {velocity['vertical']['rms']:.3f} m/s",
        f"attitude error RMS  tilt {summary['tilt_error_arcsec']['rms']:.1f}\"  heading {summary['heading_error_arcsec']['rms']:.1f}\"",
        "final bias error    gyro " + "  ".join(f"{v:+.4f}" for v in summary["bias_error_final_deg_per_h"]) + " deg/h, "
        "accelerometer " + "  ".join(f"{v:+.1f}" for v in summary["accel_bias_error_final_micro_g"]) + " µg",
    ]
    ident = (summary.get("celestial") or {}).get("star_identification")
    if ident:
        lines.append(f"star identification {ident['stars_identified']} of {ident['stars_detected']} detections identified "
                     f"with the prior in {ident['frames_identified']} of {ident['frames_detected']} frames, "
                     f"{ident['wrong']} wrong (truth)")
    return lines


def campaign_lines(summary):
    """CEP50/95 of the final horizontal error and the vertical p95 [m] with their 95 % intervals (and which of
    them too few runs leave unbounded), and the pooled accelerometer bias states, of a campaign with finished
    runs."""
    lines = []
    if summary.get("position_error_m"):
        horizontal, nmi = summary["position_error_m"]["horizontal"], summary["position_error_nmi"]["horizontal"]
        vertical = summary["position_error_m"]["vertical"]
        lines.append(f"final horizontal    CEP50 {horizontal['cep50']:.2f} m ({nmi['cep50']:.3f} nmi)  CEP95 "
                     f"{horizontal['cep95']:.2f} m ({nmi['cep95']:.3f} nmi)   vertical p95 {vertical['p95']:.2f} m")
        quoted = (("CEP50", horizontal, "cep50"), ("CEP95", horizontal, "cep95"), ("vertical p95", vertical, "p95"))
        lines.append("95 % intervals      " + "  ".join(f"{label} {interval_text(part['interval_95'][name], unit='m')}"
                                                        for label, part, name in quoted))
        short = [(label, part["runs_to_bound"][name]) for label, part, name in quoted if part["interval_95"][name][1] is None]
        if short:
            lines.append(f"too few runs        {summary['runs_finished']} runs leave these 95 % intervals unbounded above: "
                         + ", ".join(f"{label} ({runs}{' runs bound it' if k == 0 else ''})"
                                     for k, (label, runs) in enumerate(short)))
    ident = summary.get("star_identification")
    if ident:
        lines.append(f"star identification {ident['stars_identified']} of {ident['stars_detected']} detections identified "
                     f"with the prior in {ident['frames_identified']} frames of {ident['runs']} runs ({ident['stars_tracked']} on "
                     f"their tracks), {ident['wrong']} wrong for {ident['wrong_expected']:.2f} expected (largest stated "
                     f"wrong-match probability {ident['wrong_probability_max']:.1e})")
    accel = (summary.get("imu_calibration") or {}).get("accel_bias_micro_g")
    if accel:
        lines.append(f"accelerometer bias  {100 * accel['within_3_sigma']:.1f} % of the final errors within 3σ "
                     f"(normalised RMS {', '.join(f'{v:.2f}' for v in accel['normalised_error_rms'])})")
    return lines
