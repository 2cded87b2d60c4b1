"""Read what a report is made from: a run directory, a static-study directory or a Monte Carlo
campaign directory.

A run directory holds ``summary.json`` (a :class:`~navsim.records.RunSummary`), ``timeseries.npz``
and ``scenario.json`` (optionally ``frame.npy`` with ``frame_detections.json``). A campaign directory
holds ``campaign.json`` (with the validated scenario) and ``runs/run_NNNNN/`` run directories (a run
that raised leaves ``error.json`` instead), with the aggregate in ``summary.json`` (a
:class:`~navsim.records.CampaignSummary`). Only the arrays a report
draws are checked; everything optional may be absent. Bad input raises
:class:`~startrack.errors.InputError` with one sentence naming the file and the problem.
"""

import json
import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from navsim.records import CampaignSummary, RunSummary
from navsim.studies import STUDIES
from startrack.errors import InputError

#: A finished or failed run's directory (a leftover ``run_NNNNN.partial`` is neither).
RUN_NAME = re.compile(r"run_\d{5,}")
#: Arrays every run of a kind must have; the report cannot say anything without them.
REQUIRED_SERIES = {"attitude": ("t", "attitude_error"),
                   "navigation": ("t", "lat", "lon", "lat_true", "lon_true", "error_state", "error_sigma", "position_error_m")}
#: Per-frame arrays with columns of their own count: the least number of columns (the filter's states).
MIN_COLUMNS = {"P_diag": 6, "error_state": 15, "error_sigma": 15}
#: Per-frame arrays and the trailing shape each must have when present (() for one number per frame,
#: None for the arrays of :data:`MIN_COLUMNS`).
SERIES_SHAPES = {
    "t": (),
    "attitude_error": (3,),
    "P_diag": None,
    "error_state": None,
    "error_sigma": None,
    "position_error_m": (3,),
    "lat": (),
    "lon": (),
    "h": (),
    "lat_true": (),
    "lon_true": (),
    "h_true": (),
    "v_n": (3,),
    "v_n_true": (3,),
    "gyro_bias": (3,),
    "accel_bias": (3,),
    "gyro_bias_true": (3,),
    "accel_bias_true": (3,),
    "bias_true": (3,),
    "bias_est": (3,),
    "nees": (),
    "nis": (),
    "nis_dof": (),
    "n_measurements": (),
    "n_accepted": (),
    "innovation_rms": (),
    "mode": (),
    "n_detected": (),
    "n_identified": (),
    "n_stacked": (),
    "id_ms": (),
    "boresight_radec": (2,),
    "subcatalog_index": (),
    "subcatalog_address": (2,),
}
#: The arrays a campaign report reads from each run of a kind (the rest are not loaded).
CAMPAIGN_SERIES = {"attitude": ("t", "attitude_error", "P_diag", "nees", "mode", "n_identified", "n_stacked", "n_accepted"),
                   "navigation": ("t", "error_state", "error_sigma", "position_error_m", "lat_true", "h_true", "nees")}


@dataclass
class RunData:
    """One run: its summary, per-frame series (SI units), scenario and optional rendered frame."""

    directory: Path
    summary: dict
    series: dict
    scenario: dict | None = None
    frame: np.ndarray | None = None
    detections: list | None = None

    @property
    def frames(self) -> int:
        return int(self.series["t"].size)


@dataclass
class StudyData:
    """A static study: its summary, scenario (with the kind's parameters) and per-sample arrays."""

    directory: Path
    summary: dict
    scenario: dict
    arrays: dict


@dataclass
class FailedRun:
    name: str
    message: str


@dataclass
class CampaignData:
    """A campaign: its description, aggregate summary, finished runs (in name order) and failures."""

    directory: Path
    campaign: dict
    summary: dict | None
    runs: list = field(default_factory=list)
    failed: list = field(default_factory=list)
    scenario: dict | None = None


def read_json(path: Path) -> dict:
    try:
        payload = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise InputError(f"{path}: cannot read it as JSON ({error}).") from None
    if not isinstance(payload, dict):
        raise InputError(f"{path}: expected a JSON object, got {type(payload).__name__}.")
    return payload


def read_series(path: Path, kind, names=None) -> dict:
    """The arrays of ``timeseries.npz`` of a run of ``kind`` (all, or those of ``names`` present), shape-checked."""
    if not zipfile.is_zipfile(path):
        raise InputError(f"{path}: not an .npz array file (not a zip archive).")
    try:
        with np.load(path, allow_pickle=False) as data:
            present = [n for n in data.files if names is None or n in names]
            series = {name: data[name] for name in present}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
        raise InputError(f"{path}: cannot read it as an .npz array file ({error}).") from None
    for name in REQUIRED_SERIES[kind]:
        if name not in series and (names is None or name in names):
            raise InputError(f"{path}: the array '{name}' is missing.")
    n = series["t"].shape[0] if series["t"].ndim == 1 else -1
    if n < 1:
        raise InputError(f"{path}: 't' must be a non-empty 1-D array of frame times, got shape {series['t'].shape}.")
    for name, trailing in SERIES_SHAPES.items():
        if name not in series:
            continue
        shape = series[name].shape
        ok = shape[:1] == (n,) and (len(shape) == 2 and shape[1] >= MIN_COLUMNS[name] if trailing is None
                                    else shape[1:] == trailing)
        if not ok:
            expected = f"({n}, >= {MIN_COLUMNS[name]})" if trailing is None else str((n, *trailing))
            raise InputError(f"{path}: array '{name}' has shape {shape}, expected {expected} (one row per frame).")
        if series[name].dtype.kind not in "biuf":
            raise InputError(f"{path}: array '{name}' is not numeric (dtype {series[name].dtype}).")
    return series


def directory_kind(directory: Path) -> str:
    """'run', 'study' or 'campaign'; anything else is an InputError."""
    if not directory.exists():
        raise InputError(f"{directory}: no such directory.")
    if not directory.is_dir():
        raise InputError(f"{directory}: is not a directory (expected a run or campaign output directory).")
    if (directory / "campaign.json").is_file():
        return "campaign"
    if (directory / "timeseries.npz").is_file() and (directory / "summary.json").is_file():
        return "run"
    if (directory / "study.npz").is_file() and (directory / "summary.json").is_file():
        return "study"
    raise InputError(f"{directory}: neither a run directory (summary.json and timeseries.npz), a static-study "
                     "directory (summary.json and study.npz) nor a campaign directory (campaign.json).")


def load_run(directory: Path) -> RunData:
    summary = RunSummary.read(directory / "summary.json")
    series = read_series(directory / "timeseries.npz", summary.kind)
    if (directory / "timing.npz").is_file():  # wall-clock times per frame, kept apart from the reproducible series
        series |= _read_timing(directory / "timing.npz", series["t"].size)
    scenario = read_json(directory / "scenario.json")
    frame, detections = None, None
    if (directory / "frame.npy").is_file():
        frame = _read_frame(directory / "frame.npy")
        detections_path = directory / "frame_detections.json"
        if detections_path.is_file():
            detections = _read_detections(detections_path)
    return RunData(directory, summary, series, scenario, frame, detections)


def load_study(directory: Path) -> StudyData:
    summary = read_json(directory / "summary.json")
    scenario = read_json(directory / "scenario.json") if (directory / "scenario.json").is_file() else {}
    kind = summary.get("study")
    if kind not in STUDIES:
        raise InputError(f"{directory / 'summary.json'}: 'study' must name a static study "
                         f"({', '.join(STUDIES)}), got {kind!r}.")
    parameters = scenario.get("study", {}).get(kind)
    if not isinstance(parameters, dict):
        raise InputError(f"{directory / 'scenario.json'}: missing, or without the study.{kind} parameters.")
    path = directory / "study.npz"
    if not zipfile.is_zipfile(path):
        raise InputError(f"{path}: not an .npz array file (not a zip archive).")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
        raise InputError(f"{path}: cannot read it as an .npz array file ({error}).") from None
    return StudyData(directory, summary, scenario, arrays)


def _read_timing(path: Path, frames: int) -> dict:
    """The per-frame arrays of ``timing.npz`` (one value per frame each)."""
    try:
        with np.load(path, allow_pickle=False) as data:
            timing = {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
        raise InputError(f"{path}: cannot read it as an .npz array file ({error}).") from None
    for name, values in timing.items():
        if values.shape != (frames,) or values.dtype.kind != "f":
            raise InputError(f"{path}: array '{name}' has shape {values.shape}, expected ({frames},) times in ms.")
    return timing


def _read_frame(path: Path) -> np.ndarray:
    try:
        frame = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError) as error:
        raise InputError(f"{path}: cannot read it as a .npy image ({error}).") from None
    if frame.ndim != 2 or frame.dtype.kind not in "biuf" or min(frame.shape) < 1:
        raise InputError(f"{path}: expected a 2-D numeric image, got shape {frame.shape} dtype {frame.dtype}.")
    return frame


def _read_detections(path: Path) -> list:
    try:
        payload = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise InputError(f"{path}: cannot read it as JSON ({error}).") from None
    if isinstance(payload, dict):
        payload = payload.get("detections")
    if not isinstance(payload, list):
        raise InputError(f"{path}: expected a list of {{u, v, hip}} detections.")
    detections = []
    for i, item in enumerate(payload):
        try:
            u, v = float(item["u"]), float(item["v"])
            hip = item.get("hip")
            hip = None if hip is None else int(hip)
        except (TypeError, KeyError, ValueError):
            raise InputError(f"{path}: detection {i} is not an object with numbers u, v and hip (or null).") from None
        detections.append((u, v, hip))
    return detections


def load_campaign(directory: Path) -> CampaignData:
    campaign = read_json(directory / "campaign.json")
    summary_path = directory / "summary.json"
    summary = CampaignSummary.read(summary_path) if summary_path.is_file() else None
    data = CampaignData(directory, campaign, summary, scenario=campaign.get("scenario_data"))
    runs_dir = directory / "runs"
    run_dirs = sorted(p for p in runs_dir.iterdir() if p.is_dir() and RUN_NAME.fullmatch(p.name)) if runs_dir.is_dir() else []
    for run_dir in run_dirs:
        if (run_dir / "error.json").is_file():
            error = read_json(run_dir / "error.json")
            message = error.get("error") or error.get("message") or json.dumps(error, sort_keys=True)
            data.failed.append(FailedRun(run_dir.name, str(message)))
        elif (run_dir / "summary.json").is_file() and (run_dir / "timeseries.npz").is_file():
            summary = RunSummary.read(run_dir / "summary.json")
            series = read_series(run_dir / "timeseries.npz", summary.kind, CAMPAIGN_SERIES[summary.kind])
            data.runs.append(RunData(run_dir, summary, series))
    if not data.runs:
        raise InputError(f"{directory}: the campaign has no finished runs under runs/ "
                         f"({len(data.failed)} failed); nothing to report.")
    return data
