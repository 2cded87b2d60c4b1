"""Run outputs: ``scenario.json`` (the validated scenario), ``summary.json`` and ``timeseries.npz``
(``study.npz`` for a static study), identical for the same seed but for the summary's ``timing``;
the per-frame wall-clock times go to ``timing.npz``.

``np.savez`` stamps the current time into the zip; :func:`write_npz` writes the same format
(a zip of ``.npy`` members, readable by ``np.load(..., allow_pickle=False)``) with a fixed
timestamp, so the same seed gives the same bytes.
"""

import io
import json
import zipfile
from pathlib import Path

import numpy as np

FIXED_ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def write_npz(path, arrays):
    """Write ``arrays`` (name -> ndarray, no object arrays) to an .npz file deterministically."""
    path = Path(path)
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name in sorted(arrays):
            buffer = io.BytesIO()
            np.lib.format.write_array(buffer, np.ascontiguousarray(arrays[name]), allow_pickle=False)
            info = zipfile.ZipInfo(f"{name}.npy", date_time=FIXED_ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, buffer.getvalue())


def read_npz(path):
    """Load an .npz written by :func:`write_npz` into a dict (no pickle)."""
    with np.load(path, allow_pickle=False) as data:
        return {name: data[name] for name in data.files}


def write_json(path, payload):
    Path(path).write_text(json.dumps(payload, indent=2, sort_keys=True) + "\n", encoding="utf-8")


def write_run(directory, result, max_frames=None):
    """Write a :class:`~navsim.records.RunResult` into ``directory`` (created if needed).

    ``max_frames`` keeps every k-th frame of the time series so that at most that many remain
    (campaigns keep envelopes, not every frame, of thousands of runs); the summary is unchanged.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    write_json(directory / "scenario.json", result.scenario)
    write_json(directory / "summary.json", result.summary.to_json())
    series = result.series
    frames = len(series["t"])
    if max_frames is not None and frames > max_frames:
        stride = -(-frames // max_frames)
        series = {k: (v[stride - 1 :: stride] if v.shape[:1] == (frames,) else v) for k, v in series.items()}
    write_npz(directory / "timeseries.npz", series)
    if result.timing_series:
        write_npz(directory / "timing.npz", result.timing_series)
    if result.sample_frame is not None:
        np.save(directory / "frame.npy", result.sample_frame["image"], allow_pickle=False)
        write_json(directory / "frame_detections.json", result.sample_frame["detections"])
    return directory


def write_study(directory, result):
    """Write a :class:`~navsim.studies.StudyResult`: scenario.json, summary.json and study.npz."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    write_json(directory / "scenario.json", result.scenario)
    write_json(directory / "summary.json", result.summary)
    write_npz(directory / "study.npz", result.arrays)
    return directory


def write_covariance(directory, scenario, analysis, comparison=None):
    """Write a covariance analysis into ``directory``: ``scenario.json``, ``summary.json`` (its kind's
    ``summary``), ``timeseries.npz`` (its ``series``) and, when compared with a Monte Carlo campaign,
    ``comparison.json``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    write_json(directory / "scenario.json", scenario.data)
    write_json(directory / "summary.json", analysis.summary(scenario))
    write_npz(directory / "timeseries.npz", analysis.series())
    if comparison is not None:
        write_json(directory / "comparison.json", comparison)
