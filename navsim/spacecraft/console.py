"""What the command line prints of a spacecraft run and campaign beside what it prints of every run (consistency,
updates, wall time): the attitude kind's lines, the orbit and pointing, and a line per head."""

from navsim.attitude.console import campaign_lines as attitude_campaign_lines
from navsim.attitude.console import run_lines as attitude_run_lines


def run_lines(summary):
    """The attitude kind's lines, the orbit and the pointing, then each head's availability and accuracy."""
    orbit, pointing = summary["orbit"], summary["pointing"]
    lines = attitude_run_lines(summary) + [
        (f"orbit               {orbit['propagator']}, {orbit['height_km']['min']:.0f}-{orbit['height_km']['max']:.0f} km, "
         f"{100 * orbit['shadow_fraction']:.1f} % in the Earth's shadow"),
        (f"pointing            {pointing['law']}: truth from the law {pointing['error_rms_arcsec']:.2f}\" RMS "
         f"(max {pointing['error_max_arcsec']:.1f}\"), wheels up to {pointing['wheel_momentum_max_N_m_s']:.2f} N m s")]
    for head in summary["heads"]:
        excluded = ", ".join(f"{reason.split(' ')[0].replace(chr(39) + 's', '')} {count}"
                             for reason, count in head["excluded_frames"].items() if count)
        lines.append(f"{head['name']:<20}{100 * head['availability']:.1f} % of frames, {head['measurements_per_frame']:.1f} "
                     f"per frame; about its boresight: cross {head['cross_boresight_rms_arcsec']:.2f}\" roll "
                     f"{head['roll_rms_arcsec']:.2f}\" (ratio {head['roll_to_cross_boresight']:.2f})"
                     + (f"; excluded: {excluded}" if excluded else ""))
        if "image" in head:
            lines.append(image_line(head["image"]))
    return lines


def image_line(image):
    """A head's image chain: particle hits, the frames they cost, wrong identifications."""
    return (f"{'':<20}{image['hits']} particle hits in {image['frames_with_hits']} frames, {image['frames_lost_with_hits']} of "
            f"them without a star ({image['frames_lost_without_hits']} without hits); {image['wrong_identifications']} "
            "wrong identifications")


def campaign_lines(summary):
    """The attitude kind's line and each head's mean cross-boresight and roll RMS over the runs."""
    lines = attitude_campaign_lines(summary)
    for head in summary.get("heads") or []:
        lines.append(f"{head['name']:<20}availability {100 * head['availability']['mean']:.1f} %, cross "
                     f"{head['cross_boresight_rms_arcsec']['mean']:.2f}\" roll {head['roll_rms_arcsec']['mean']:.2f}\" "
                     f"(ratio {head['roll_to_cross_boresight']['mean']:.2f})")
        if "image" in head:
            lines.append(image_line(head["image"]))
    return lines
