"""Typed, versioned records of a run and of a campaign: one writer (:meth:`Record.to_json`) and one
reader (:meth:`Record.read`) for ``summary.json``.

A record is a frozen dataclass that also reads as the JSON mapping it writes
(``summary["cross_boresight_rms_arcsec"]``), so scripts written against ``summary.json`` and the
Python API see the same keys. Optional fields left at None are not written. ``findings`` holds the
per-frame observers' statistics (:mod:`navsim.studies`), written at the top level under each
observer's key. The ``format`` key names the record and its version; a file of another version is
refused with one clear message.

Every wall-clock measurement (run time, identification and frame times, the time comparisons of
000 §5) lives under the key ``timing``: the rest of a summary is reproduced exactly by the same seed.

A run is of one of two kinds (:attr:`RunSummary.kind`): an attitude run (a star sensor and a gyro)
or a navigation run (the INS); each has its own fields beside the common ones (:data:`KIND_FIELDS`),
and campaign aggregation, tuning and reports dispatch once on the kind.

Units at this edge: attitude in arcsec, gyro bias in deg/h, accelerometer bias in µg, positions in
metres and nautical miles, velocities in m/s, times in seconds.
"""

import dataclasses
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from startrack.errors import InputError

RUN_FORMAT = "navsim.run-summary/1"
CAMPAIGN_FORMAT = "navsim.campaign-summary/1"


class Record(Mapping):
    """Base of the records: JSON writer and reader, and read-only mapping access to the JSON form."""

    FORMAT = ""

    def to_json(self):
        """The JSON object (a dict of plain values) of this record, ``format`` first."""
        out = {"format": self.FORMAT}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name == "findings":
                out.update(value)
            elif value is not None:
                out[f.name] = value
        return out

    @classmethod
    def from_json(cls, payload, source="summary.json"):
        """The record of a JSON object written by :meth:`to_json`; anything else is an InputError."""
        if not isinstance(payload, dict):
            raise InputError(f"{source}: expected a JSON object, got {type(payload).__name__}.")
        if payload.get("format") != cls.FORMAT:
            raise InputError(f"{source}: not a {cls.FORMAT} record (format {payload.get('format')!r}); it was written by "
                             "another version of navsim: run it again into a new directory.")
        names = {f.name for f in dataclasses.fields(cls)}
        required = [f.name for f in dataclasses.fields(cls)
                    if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
        missing = [name for name in required if name not in payload]
        if missing:
            raise InputError(f"{source}: the key '{missing[0]}' is missing.")
        fields = {k: v for k, v in payload.items() if k in names}
        findings = {k: v for k, v in payload.items() if k not in names and k != "format"}
        if "findings" in names:
            fields["findings"] = findings
        return cls(**fields)

    @classmethod
    def read(cls, path):
        path = Path(path)
        try:
            payload = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
            raise InputError(f"{path}: cannot read it as JSON ({error}).") from None
        return cls.from_json(payload, str(path))

    def replace(self, **changes):
        return dataclasses.replace(self, **changes)

    def __getitem__(self, key):
        return self.to_json()[key]

    def __iter__(self):
        return iter(self.to_json())

    def __len__(self):
        return len(self.to_json())


#: The two kinds of run and, for each, the fields its summary must hold beside the common ones.
KIND_FIELDS = {
    "attitude": ("fidelity", "measurement", "gyro_rate_hz", "star_sensor_rate_hz", "attitude_error_rms_arcsec",
                 "cross_boresight_rms_arcsec", "roll_rms_arcsec", "attitude_sigma_final_arcsec", "bias_error_final_deg_per_h"),
    "navigation": ("navigation", "position_error_m", "position_error_nmi", "velocity_error_m_per_s", "tilt_error_arcsec",
                   "heading_error_arcsec", "position_sigma_final_m", "bias_error_final_deg_per_h",
                   "accel_bias_error_final_micro_g", "imu_calibration"),
}
#: Each kind's headline errors (label, unit, path in the summary): what `navsim tune` and the
#: console print beside the consistency statistics.
HEADLINE = {
    "attitude": (("cross-boresight RMS", "arcsec", ("cross_boresight_rms_arcsec",)),
                 ("roll RMS", "arcsec", ("roll_rms_arcsec",))),
    "navigation": (("horizontal RMS", "m", ("position_error_m", "horizontal", "rms")),
                   ("vertical RMS", "m", ("position_error_m", "vertical", "rms"))),
}


@dataclass(frozen=True)
class RunSummary(Record):
    """The metrics of one run (``summary.json`` of a run directory), over the frames after ``settle_s``.

    Common to both kinds: ``nees``: {dof, runs, band_95, mean, fraction_in_band} of the filter's
    error state (dof: the attitude and gyro-bias errors, 6, of the attitude filter; the navigation
    filter's whole error state, 15 or 21); ``nis``: {mean_per_dof}; ``updates``:
    {frames_with_measurements, measurements, accepted, rejected}; ``bias_error_final_deg_per_h``: the
    gyro bias error (truth − estimate) at the end; ``timing``: the wall-clock figures {wall_seconds,
    identification_ms, frame_ms, observers' times with their comparison rows and notes}.

    An attitude run (star sensor and gyro) has the attitude errors [arcsec] and the sensor's set-up;
    ``gyro_calibration``: per calibration group the filter carries (scale factors [ppm], misalignment
    [arcsec]) the truth, the final estimate, its σ and the normalised error;
    ``identification``/``modes``: the image-fidelity sensor's modes, counts and transitions;
    ``paper_comparison``: rows {quantity, ours, paper, source}; ``notes``: sentences explaining them.

    A navigation run (the INS) has ``navigation``: {imu_rate_hz, frame_rate_hz, aiding (the kinds),
    filter_states, epoch_utc}; ``position_error_m``/``velocity_error_m_per_s``: {horizontal, vertical},
    each {final, rms, max} of the error's magnitude; ``position_error_nmi``: {horizontal: {final, rms,
    max, final_per_hour}}; ``tilt_error_arcsec``, ``heading_error_arcsec``: {final, rms, max};
    ``position_sigma_final_m`` (N, E, D); ``accel_bias_error_final_micro_g``; ``imu_calibration``:
    the IMU error states at the end (biases [deg/h, µg], scale factors [ppm], the star-sensor mounting
    [arcsec]) as ``gyro_calibration``. A star-aided run (SINS/CNS) adds ``celestial``
    (:func:`navsim.ins.celestial.summary`: the star sensor, the analytic-horizon floor against the
    Schuler-mean position error, the aberration and what skipping its correction costs, the
    observability of each state) and, at image fidelity, ``identification``/``modes``.
    """

    FORMAT = RUN_FORMAT

    scenario: str
    seed: int
    duration_s: float
    frames: int
    settle_s: float
    nees: dict
    nis: dict
    updates: dict
    fidelity: str | None = None
    measurement: str | None = None
    gyro_rate_hz: float | None = None
    star_sensor_rate_hz: float | None = None
    attitude_error_rms_arcsec: dict | None = None
    cross_boresight_rms_arcsec: float | None = None
    roll_rms_arcsec: float | None = None
    attitude_sigma_final_arcsec: list | None = None
    bias_error_final_deg_per_h: list | None = None
    navigation: dict | None = None
    position_error_m: dict | None = None
    position_error_nmi: dict | None = None
    velocity_error_m_per_s: dict | None = None
    tilt_error_arcsec: dict | None = None
    heading_error_arcsec: dict | None = None
    position_sigma_final_m: list | None = None
    accel_bias_error_final_micro_g: list | None = None
    imu_calibration: dict | None = None
    celestial: dict | None = None
    timing: dict = field(default_factory=dict)
    gyro_calibration: dict | None = None
    identification: dict | None = None
    modes: list | None = None
    paper_comparison: list | None = None
    notes: list | None = None
    findings: dict = field(default_factory=dict)

    @property
    def kind(self):
        """'navigation' for a run of the INS (it has the ``navigation`` block), else 'attitude'."""
        return "navigation" if self.navigation is not None else "attitude"

    def headline(self):
        """{label: (value, unit)} of the kind's headline errors (:data:`HEADLINE`)."""
        out = {}
        for label, unit, path in HEADLINE[self.kind]:
            value = self.to_json()
            for key in path:
                value = value[key]
            out[label] = (value, unit)
        return out

    @classmethod
    def from_json(cls, payload, source="summary.json"):
        record = super().from_json(payload, source)
        missing = [name for name in KIND_FIELDS[record.kind] if getattr(record, name) is None]
        if missing:
            raise InputError(f"{source}: the key '{missing[0]}' is missing ({record.kind} run).")
        return record


@dataclass(frozen=True)
class CampaignSummary(Record):
    """The aggregate of a campaign's finished runs (``summary.json`` of a campaign directory), computed
    from the run files in run order, so identical whichever backend produced them.

    Both kinds: ``nees`` is the run-averaged NEES against its band for ``runs`` runs, with the dof the
    runs' summaries record; ``divergent_runs`` lists runs with an error beyond 5σ or a NEES mean above
    5 dof; ``updates`` the accepted and rejected measurements.

    Attitude runs: errors pool every steady frame of every run; ``gyro_calibration`` pools the final
    normalised errors of the calibration states (RMS per state, expected 1, and the share within 3σ,
    expected 99.7 %); findings, ``paper_comparison`` and ``notes`` pool the observers' per-run figures.

    Navigation runs: ``position_error_m`` {horizontal: {cep50, cep95, rms, max} of the final horizontal
    error over the runs, vertical: {p50, p95, rms, max} of the final vertical error};
    ``position_error_nmi`` {horizontal: {cep50, cep95}}; ``velocity_error_m_per_s`` {horizontal,
    vertical}, ``tilt_error_arcsec`` and ``heading_error_arcsec``: the spread {mean, p50, p95, max} of
    the runs' RMS errors; ``imu_calibration`` pools the IMU error states as ``gyro_calibration``."""

    FORMAT = CAMPAIGN_FORMAT

    scenario: str
    base_seed: int
    runs_requested: int
    runs_finished: int
    runs_failed: int
    failures: list
    attitude_error_rms_arcsec: dict | None = None
    attitude_error_percentiles_arcsec: dict | None = None
    filter_sigma_mean_arcsec: dict | None = None
    cross_boresight_rms_arcsec: dict | None = None
    roll_rms_arcsec: dict | None = None
    position_error_m: dict | None = None
    position_error_nmi: dict | None = None
    velocity_error_m_per_s: dict | None = None
    tilt_error_arcsec: dict | None = None
    heading_error_arcsec: dict | None = None
    nees: dict | None = None
    updates: dict | None = None
    divergent_runs: list | None = None
    gyro_calibration: dict | None = None
    imu_calibration: dict | None = None
    identification: dict | None = None
    paper_comparison: list | None = None
    notes: list | None = None
    timing: dict = field(default_factory=dict)
    findings: dict = field(default_factory=dict)


@dataclass(frozen=True)
class RunResult:
    """``summary``: the run's :class:`~navsim.records.RunSummary` (reads as the JSON mapping of
    summary.json); ``series``: arrays logged at every frame (star-sensor frames; the aiding epochs of a
    navigation run); ``scenario``: the validated
    scenario (units in key names) the run used; ``sample_frame``: one rendered frame with its
    detections and identifications (image fidelity); ``timing_series``: per-frame wall-clock times
    [ms] (image fidelity), apart from ``series`` because they differ between runs of one seed."""

    summary: RunSummary
    series: dict
    scenario: dict
    sample_frame: dict | None = None
    timing_series: dict = field(default_factory=dict)
