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

Units at this edge: attitude in arcsec, gyro bias in deg/h, times in seconds.
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


@dataclass(frozen=True)
class RunSummary(Record):
    """The metrics of one run (``summary.json`` of a run directory), over the frames after ``settle_s``.

    ``nees``: {dof, runs, band_95, mean, fraction_in_band} of the attitude and gyro-bias errors;
    ``nis``: {mean_per_dof}; ``updates``: {frames_with_measurements, measurements, accepted, rejected};
    ``gyro_calibration``: per calibration group the filter carries (scale factors [ppm], misalignment
    [arcsec]) the truth, the final estimate, its σ and the normalised error;
    ``identification``/``modes``: the image-fidelity sensor's modes, counts and transitions;
    ``paper_comparison``: rows {quantity, ours, paper, source}; ``notes``: sentences explaining them;
    ``timing``: the wall-clock figures {wall_seconds, identification_ms, frame_ms, observers' times with
    their comparison rows and notes}.
    """

    FORMAT = RUN_FORMAT

    scenario: str
    seed: int
    duration_s: float
    fidelity: str
    measurement: str
    gyro_rate_hz: float
    star_sensor_rate_hz: float
    frames: int
    settle_s: float
    attitude_error_rms_arcsec: dict
    cross_boresight_rms_arcsec: float
    roll_rms_arcsec: float
    attitude_sigma_final_arcsec: list
    bias_error_final_deg_per_h: list
    nees: dict
    nis: dict
    updates: dict
    timing: dict = field(default_factory=dict)
    gyro_calibration: dict | None = None
    identification: dict | None = None
    modes: list | None = None
    paper_comparison: list | None = None
    notes: list | None = None
    findings: dict = field(default_factory=dict)


@dataclass(frozen=True)
class CampaignSummary(Record):
    """The aggregate of a campaign's finished runs (``summary.json`` of a campaign directory), computed
    from the run files in run order, so identical whichever backend produced them.

    Errors pool every steady frame of every run; ``nees`` is the run-averaged NEES against its band
    for ``runs`` runs; ``divergent_runs`` lists runs with an error beyond 5σ or a NEES mean above
    5 dof; ``gyro_calibration`` pools the final normalised errors of the calibration states (RMS per
    state, expected 1, and the share within 3σ, expected 99.7 %); findings, ``paper_comparison`` and
    ``notes`` pool the observers' per-run figures."""

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
    nees: dict | None = None
    updates: dict | None = None
    divergent_runs: list | None = None
    gyro_calibration: dict | None = None
    identification: dict | None = None
    paper_comparison: list | None = None
    notes: list | None = None
    timing: dict = field(default_factory=dict)
    findings: dict = field(default_factory=dict)
