"""The records of attitude runs and campaigns (:mod:`navsim.records`): what an attitude run and its
campaign write into ``summary.json`` beside what every kind writes.

Units at this edge: attitude in arcsec, gyro bias in deg/h, times in seconds.
"""

from dataclasses import dataclass, field
from typing import ClassVar

from navsim import records


@dataclass(frozen=True, kw_only=True)
class RunSummary(records.RunSummary):
    """An attitude run (star sensor and gyro): the sensor's set-up and the attitude errors [arcsec] over
    the frames after ``settle_s``; ``bias_error_final_deg_per_h`` the gyro bias error (truth − estimate)
    at the end; ``timing``: the wall-clock figures {wall_seconds, identification_ms, frame_ms, observers'
    times with their comparison rows and notes}; ``gyro_calibration``: per calibration group the filter
    carries (scale factors [ppm], misalignment [arcsec]) the truth, the final estimate, its σ and the
    normalised error; besides, the star sensor's modes and the observers' findings every kind's record has."""

    kind: ClassVar[str] = "attitude"
    HEADLINE: ClassVar[tuple] = (("cross-boresight RMS", "arcsec", ("cross_boresight_rms_arcsec",)),
                                 ("roll RMS", "arcsec", ("roll_rms_arcsec",)))

    fidelity: str
    measurement: str
    gyro_rate_hz: float
    star_sensor_rate_hz: float
    attitude_error_rms_arcsec: dict
    cross_boresight_rms_arcsec: float
    roll_rms_arcsec: float
    attitude_sigma_final_arcsec: list
    bias_error_final_deg_per_h: list
    timing: dict = field(default_factory=dict)
    gyro_calibration: dict | None = None


@dataclass(frozen=True, kw_only=True)
class CampaignSummary(records.CampaignSummary):
    """An attitude campaign: the errors pooled over every steady frame of every run [arcsec], the spread
    of the runs' RMS errors, the run-averaged NEES against its band for ``runs`` runs with the 95 % interval of
    its mean (``nees``: :func:`navsim.pooling.averaged_nees`), the
    divergent runs (an error beyond 5σ or a NEES mean above 5 dof), the accepted and rejected updates;
    ``gyro_calibration`` pools the final normalised errors of the calibration states (RMS per state,
    expected 1, and the share within 3σ, expected 99.7 %); besides, what every kind's campaign record has
    (the frames per identification mode, the observers' pooled findings)."""

    attitude_error_rms_arcsec: dict | None = None
    attitude_error_percentiles_arcsec: dict | None = None
    filter_sigma_mean_arcsec: dict | None = None
    cross_boresight_rms_arcsec: dict | None = None
    roll_rms_arcsec: dict | None = None
    nees: dict | None = None
    updates: dict | None = None
    divergent_runs: list | None = None
    gyro_calibration: dict | None = None
