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

Each run kind has its own records (:mod:`navsim.kinds`): the fields below are what they share; the
run directory's scenario says which kind's record its summary is.

Units at this edge: attitude in arcsec, gyro bias in deg/h, accelerometer bias in µg, positions in
metres and nautical miles, velocities in m/s, times in seconds.
"""

import dataclasses
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from startrack import InputError

RUN_FORMAT = "navsim.run-summary/2"
CAMPAIGN_FORMAT = "navsim.campaign-summary/2"


class Record(Mapping):
    """Base of the records: JSON writer and reader, and read-only mapping access to the JSON form."""

    FORMAT = ""

    def to_json(self):
        """The JSON object (a dict of plain values) of this record, ``format`` first."""
        out = {"format": self.FORMAT}
        for name in (f.name for f in dataclasses.fields(self)):
            value = getattr(self, name)
            if name == "findings":
                out.update(value)
            elif value is not None:
                out[name] = value
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
    """The metrics of one run (``summary.json`` of a run directory) that every kind of run has, over the
    frames after ``settle_s``; each kind's record adds its own (``navsim.attitude.records``,
    ``navsim.navigation.records``) and names itself in :attr:`kind`.

    ``nees``: {dof, runs, band_95, mean, fraction_in_band} of the filter's error state; ``nis``:
    {mean_per_dof}; ``updates``: {frames_with_measurements, measurements, accepted, rejected}; what a run's
    star sensor adds at image fidelity (:mod:`navsim.star_run`):
    ``identification``/``modes`` (its modes, counts and transitions), the per-frame observers' ``findings``
    with their comparison rows (``paper_comparison``: {quantity, ours, paper, source}) and ``notes``.
    """

    FORMAT = RUN_FORMAT
    #: The name of the run kind (:mod:`navsim.kinds`) whose record this is.
    kind: ClassVar[str] = ""
    #: The kind's headline errors (label, unit, path in the summary): what `navsim tune` and the console
    #: print beside the consistency statistics.
    HEADLINE: ClassVar[tuple] = ()

    scenario: str
    seed: int
    duration_s: float
    frames: int
    settle_s: float
    nees: dict
    divergence: dict
    nis: dict
    updates: dict
    identification: dict | None = None
    modes: list | None = None
    paper_comparison: list | None = None
    notes: list | None = None
    findings: dict = field(default_factory=dict)

    def headline(self):
        """{label: (value, unit)} of the kind's headline errors (:attr:`HEADLINE`)."""
        out = {}
        for label, unit, path in self.HEADLINE:
            value = self.to_json()
            for key in path:
                value = value[key]
            out[label] = (value, unit)
        return out


@dataclass(frozen=True)
class CampaignSummary(Record):
    """The aggregate of a campaign's finished runs (``summary.json`` of a campaign directory), computed
    from the run files in run order, so identical whichever backend produced them: what every kind has
    (the runs asked for, finished and failed, and the failures; the frames per identification mode, the
    observers' pooled findings with their comparison rows and notes, their wall-clock figures under
    ``timing``); each kind's record adds the statistics of its runs, pooled by the kind
    (``navsim.attitude.records``, ``navsim.navigation.records``)."""

    FORMAT = CAMPAIGN_FORMAT

    scenario: str
    base_seed: int
    runs_requested: int
    runs_finished: int
    runs_failed: int
    failures: list
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
