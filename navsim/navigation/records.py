"""The records of navigation runs and campaigns (:mod:`navsim.records`): what a run of the INS and its
campaign write into ``summary.json`` beside what every kind writes.

Units at this edge: positions in metres and nautical miles, velocities in m/s, attitude in arcsec,
gyro bias in deg/h, accelerometer bias in µg, times in seconds.
"""

from dataclasses import dataclass, field
from typing import ClassVar

from navsim import records


@dataclass(frozen=True, kw_only=True)
class RunSummary(records.RunSummary):
    """A navigation run (the INS): ``bias_error_final_deg_per_h`` the gyro bias error (truth − estimate)
    at the end; ``navigation``: {imu_rate_hz, frame_rate_hz, aiding (the kinds), filter_states,
    epoch_utc}; ``position_error_m``: {horizontal, vertical, along_track, cross_track} and
    ``velocity_error_m_per_s``: {horizontal, vertical}, each {final, rms, max} of the error's magnitude (along and
    across the true track: :func:`navsim.navigation.summary.track_metres`); ``position_error_nmi``: {horizontal: {final, rms, max,
    final_per_hour}}; ``tilt_error_arcsec``, ``heading_error_arcsec``: {final, rms, max};
    ``position_sigma_final_m`` (N, E, D); ``accel_bias_error_final_micro_g``; ``imu_calibration``: the
    IMU error states at the end (biases [deg/h, µg], scale factors [ppm], the star-sensor mounting
    [arcsec]): truth, estimate, σ and normalised error. A star-aided run (SINS/CNS) adds ``celestial``
    (:func:`navsim.navigation.celestial.summary`: the star sensor, the analytic-horizon floor against
    the Schuler-mean position error, the aberration and what skipping its correction costs, the
    observability of each state); ``timing``: the wall-clock figures; besides, the star sensor's modes and the
    observers' findings of every kind's record."""

    kind: ClassVar[str] = "navigation"
    HEADLINE: ClassVar[tuple] = (("horizontal RMS", "m", ("position_error_m", "horizontal", "rms")),
                                 ("vertical RMS", "m", ("position_error_m", "vertical", "rms")))

    bias_error_final_deg_per_h: list
    navigation: dict
    position_error_m: dict
    position_error_nmi: dict
    velocity_error_m_per_s: dict
    tilt_error_arcsec: dict
    heading_error_arcsec: dict
    position_sigma_final_m: list
    accel_bias_error_final_micro_g: list
    imu_calibration: dict
    celestial: dict | None = None
    timing: dict = field(default_factory=dict)


@dataclass(frozen=True, kw_only=True)
class CampaignSummary(records.CampaignSummary):
    """A navigation campaign: ``position_error_m`` {horizontal: {cep50, cep95, rms, max} of the final
    horizontal error over the runs, vertical: {p50, p95, rms, max} of the final vertical error}, each
    percentile with ``interval_95`` {name: [lo, hi]} its distribution-free 95 % interval (hi null: too few runs
    to bound it) and ``runs_to_bound`` {name: the runs that do} (:func:`navsim.navigation.campaign.percentiles`);
    ``position_error_nmi`` {horizontal: {cep50, cep95, interval_95, runs_to_bound}}; ``velocity_error_m_per_s``
    {horizontal, vertical}, ``tilt_error_arcsec`` and ``heading_error_arcsec``: the spread {mean, p50, p95, max} of
    the runs' RMS errors; the run-averaged NEES against its band, with the 95 % interval of its mean
    (``nees``: :func:`navsim.pooling.averaged_nees`), the accepted and rejected
    updates, the divergent runs; ``imu_calibration`` pools the IMU error states (normalised error RMS
    per state, expected 1, and the share within 3σ); ``star_identification`` the stars identified with the INS's
    prior over all runs and the wrong ones (None without); besides, what every kind's campaign record has."""

    position_error_m: dict | None = None
    position_error_nmi: dict | None = None
    velocity_error_m_per_s: dict | None = None
    tilt_error_arcsec: dict | None = None
    heading_error_arcsec: dict | None = None
    nees: dict | None = None
    updates: dict | None = None
    divergent_runs: list | None = None
    imu_calibration: dict | None = None
    star_identification: dict | None = None
