"""Read what a report is made from: a run directory or a Monte Carlo campaign directory.

A run directory holds ``summary.json`` (its kind's :class:`~navsim.records.RunSummary`), ``timeseries.npz``
and ``scenario.json`` (optionally ``frame.npy`` with ``frame_detections.json``). A campaign directory
holds ``campaign.json`` (with the validated scenario) and ``runs/run_NNNNN/`` run directories (a run
that raised leaves ``error.json`` instead), with the aggregate in ``summary.json`` (its kind's
:class:`~navsim.records.CampaignSummary`). Which kind's records they are the caller says (the scenario's
kind, :mod:`navsim.kinds`). Only the arrays a report
draws are checked; everything optional may be absent. Bad input raises
:class:`~startrack.base.errors.InputError` with one sentence naming the file and the problem.
"""

import json
import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from startrack import InputError

#: A finished or failed run's directory (a leftover ``run_NNNNN.partial`` is neither).
RUN_NAME = re.compile(r"run_\d{5,}")
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


def read_series(path: Path, required, names=None) -> dict:
    """The arrays of ``timeseries.npz`` of a run (all, or those of ``names`` present), shape-checked; each of
    ``required`` must be there."""
    if not zipfile.is_zipfile(path):
        raise InputError(f"{path}: not an .npz array file (not a zip archive).")
    try:
        with np.load(path, allow_pickle=False) as data:
            present = [n for n in data.files if names is None or n in names]
            series = {name: data[name] for name in present}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
        raise InputError(f"{path}: cannot read it as an .npz array file ({error}).") from None
    for name in required:
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
    """'run', 'study', 'campaign', 'budget', 'covariance', 'sweep' or 'replay'; anything else is an InputError."""
    if not directory.exists():
        raise InputError(f"{directory}: no such directory.")
    if not directory.is_dir():
        raise InputError(f"{directory}: is not a directory (expected a run or campaign output directory).")
    if (directory / "campaign.json").is_file():
        return "campaign"
    if (directory / "budget.json").is_file():
        return "budget"
    if (directory / "sweep.json").is_file():
        return "sweep"
    if (directory / "summary.json").is_file() and '"navsim.covariance-summary/' in (directory / "summary.json").read_text(
            encoding="utf-8", errors="replace"):
        return "covariance"
    if (directory / "timeseries.npz").is_file() and (directory / "summary.json").is_file():
        return "replay" if '"kind": "replay"' in (directory / "summary.json").read_text(encoding="utf-8", errors="replace") else "run"
    if (directory / "study.npz").is_file() and (directory / "summary.json").is_file():
        return "study"
    raise InputError(f"{directory}: neither a run directory (summary.json and timeseries.npz), a static-study "
                     "directory (summary.json and study.npz), a campaign directory (campaign.json), an error "
                     "budget's (budget.json), a covariance analysis's nor a sweep's (sweep.json).")


def load_run(directory: Path, kind) -> RunData:
    """A run directory of the run ``kind`` (:mod:`navsim.kinds`; its scenario.json says which)."""
    summary = kind.RunSummary.read(directory / "summary.json")
    series = read_series(directory / "timeseries.npz", kind.REQUIRED_SERIES)
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


def campaign_runs(directory: Path):
    """(the finished runs' directories, the failed runs) of a campaign directory, in name order; an InputError
    when no run finished."""
    runs_dir = directory / "runs"
    run_dirs = sorted(p for p in runs_dir.iterdir() if p.is_dir() and RUN_NAME.fullmatch(p.name)) if runs_dir.is_dir() else []
    finished, failed = [], []
    for run_dir in run_dirs:
        if (run_dir / "error.json").is_file():
            error = read_json(run_dir / "error.json")
            message = error.get("error") or error.get("message") or json.dumps(error, sort_keys=True)
            failed.append(FailedRun(run_dir.name, str(message)))
        elif (run_dir / "summary.json").is_file() and (run_dir / "timeseries.npz").is_file():
            finished.append(run_dir)
    if not finished:
        raise InputError(f"{directory}: the campaign has no finished runs under runs/ "
                         f"({len(failed)} failed); nothing to report.")
    return finished, failed


def load_campaign(directory: Path, campaign, kind, finished, failed) -> CampaignData:
    """A campaign directory of the run ``kind`` (its ``campaign`` request read already, its
    :func:`campaign_runs`); its aggregate summary.json, which the report quotes, must be there."""
    summary_path = directory / "summary.json"
    if not summary_path.is_file():
        raise InputError(f"{summary_path}: missing: the campaign stopped before its aggregate; run the same "
                         "`navsim montecarlo` command again (it keeps the finished runs) to write it.")
    runs = [RunData(run_dir, kind.RunSummary.read(run_dir / "summary.json"),
                    read_series(run_dir / "timeseries.npz", kind.REQUIRED_SERIES, kind.CAMPAIGN_SERIES))
            for run_dir in finished]
    return CampaignData(directory, campaign, kind.CampaignSummary.read(summary_path), runs, failed,
                        scenario=campaign.get("scenario_data"))
