"""The numbers a report of any kind quotes and draws, computed once from a run or a campaign: the image-
fidelity star sensor's modes, identifications and sub-catalog addresses, error envelopes across runs,
the run-averaged NEES (as the campaign summary pooled it) and the per-run metrics' spread.

Units at this edge: arcsec, times in seconds and milliseconds. The consistency bands are those of
:mod:`navsim.estimation.consistency`; the NEES dof is the one each run's summary records.
"""

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from navsim.pooling import run_averaged_nees
from startrack import InputError, address

#: A frame counts as identified when at least this many stars were identified (two fix an attitude).
MIN_IDENTIFIED = 2


def mode_names(summary, codes):
    """Display names of the mode codes: ``summary["modes"][code]`` when given, else "mode <code>"."""
    names = summary.get("modes") if summary else None
    out = {}
    for code in np.unique(codes):
        code = int(code)
        ok = isinstance(names, list) and 0 <= code < len(names) and isinstance(names[code], str)
        out[code] = names[code] if ok else f"mode {code}"
    return out


def mode_segments(t, mode):
    """Consecutive frames in one mode as (code, t_start, t_end), each frame lasting one frame period."""
    period = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    change = np.flatnonzero(np.diff(mode)) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [t.size]])
    return [(int(mode[s]), float(t[s]), float(t[e - 1]) + period) for s, e in zip(starts, ends)]


@dataclass(frozen=True)
class ModeRow:
    """Per-mode statistics of one run: frames spent, identified stars and identification time."""

    name: str
    frames: int
    fraction: float
    identified_mean: float | None
    id_ms_median: float | None
    id_ms_p95: float | None
    id_ms_max: float | None


def mode_table(run):
    """One :class:`ModeRow` per mode present in ``run.series["mode"]`` (empty list without modes)."""
    s = run.series
    if "mode" not in s:
        return []
    names = mode_names(run.summary, s["mode"])
    rows = []
    for code, name in names.items():
        sel = s["mode"] == code
        ident = s["n_identified"][sel] if "n_identified" in s else None
        ms = s["id_ms"][sel] if "id_ms" in s else None
        ms = ms[np.isfinite(ms)] if ms is not None else None
        has_ms = ms is not None and ms.size > 0
        rows.append(ModeRow(
            name=name,
            frames=int(sel.sum()),
            fraction=float(sel.mean()),
            identified_mean=float(ident.mean()) if ident is not None else None,
            id_ms_median=float(np.median(ms)) if has_ms else None,
            id_ms_p95=float(np.percentile(ms, 95)) if has_ms else None,
            id_ms_max=float(ms.max()) if has_ms else None,
        ))
    return rows


def declination_divisions(run):
    """n_d of the base-point grid the run addressed, or None.

    Taken from the scenario (``star_sensor.image.catalog_nd``); for a run without it, the n_d for
    which the logged addresses (l_d, l_ra) and flat indices agree (eq. 7-8 and the flat index
    of document 000), searched over the grids whose ring count covers the largest l_d.
    """
    sensor = (run.scenario or {}).get("star_sensor")
    image = sensor.get("image") if isinstance(sensor, dict) else None  # a spacecraft's heads have no image chain
    if image and "catalog_nd" in image:
        return int(image["catalog_nd"])
    s = run.series
    if "subcatalog_address" not in s or "subcatalog_index" not in s:
        return None
    l_d = s["subcatalog_address"][:, 0].astype(np.int64)
    l_ra = s["subcatalog_address"][:, 1].astype(np.int64)
    index = s["subcatalog_index"].astype(np.int64)
    if l_d.min() < 1 or l_ra.min() < 1:
        return None
    for n_d in range(max(3, int(l_d.max()) + 1), 2001):
        offsets = address.ring_offsets(n_d)
        if np.array_equal(offsets[l_d - 1] + l_ra - 1, index) and np.all(l_ra <= address.ring_sizes(n_d)[l_d - 1]):
            return n_d
    return None


def sub_catalog_indices(series, n_d):
    """Flat sub-catalog index of every frame: logged, from the logged address, or by eq. 7-8 of 000."""
    if "subcatalog_index" in series:
        index = series["subcatalog_index"].astype(np.int64)
    elif "subcatalog_address" in series:
        a = series["subcatalog_address"].astype(np.int64)
        index = address.base_index(a[:, 0], a[:, 1], n_d)
    else:
        index = address.sub_catalog_index(series["boresight_radec"][:, 0], series["boresight_radec"][:, 1], n_d)
    return index[(index >= 0) & (index < address.base_point_count(n_d))]


# --------------------------------------------------------------------------- campaigns


@dataclass(frozen=True)
class Envelopes:
    """Attitude error [arcsec] across M runs at each frame (F frames, 3 body axes)."""

    t: np.ndarray  # (F,)
    runs: int
    mean: np.ndarray  # (F, 3)
    std: np.ndarray  # (F, 3), run-to-run sample standard deviation
    p05: np.ndarray
    p50: np.ndarray
    p95: np.ndarray
    rms: np.ndarray  # (F, 3), root mean square across runs
    sigma3_filter: np.ndarray | None  # (F, 3), 3 sqrt(mean over runs of P_ii)
    final: np.ndarray  # (M, 3) error at the last frame
    final_sigma_filter: np.ndarray | None  # (3,) sqrt(mean over runs of P_ii) at the last frame


def common_frames(campaign):
    """The frame times shared by all finished runs (the shortest run's), checked to coincide."""
    n = min(r.frames for r in campaign.runs)
    t = campaign.runs[0].series["t"][:n]
    for r in campaign.runs[1:]:
        if not np.allclose(r.series["t"][:n], t, rtol=0.0, atol=1e-9):
            raise InputError(f"{r.directory}: frame times differ from those of {campaign.runs[0].directory.name}; "
                             "the runs are not of one scenario.")
    return t


def envelopes_of(t, err, sigma):
    """:class:`Envelopes` of the errors ``err`` (M runs, F frames, 3) with the filter's σ (F, 3) from
    the covariance averaged over the runs (or None)."""
    ddof = 1 if err.shape[0] > 1 else 0
    p05, p50, p95 = np.percentile(err, [5, 50, 95], axis=0)
    return Envelopes(
        t=t, runs=err.shape[0], mean=err.mean(axis=0), std=err.std(axis=0, ddof=ddof),
        p05=p05, p50=p50, p95=p95, rms=np.sqrt(np.mean(err**2, axis=0)),
        sigma3_filter=None if sigma is None else 3.0 * sigma, final=err[:, -1, :],
        final_sigma_filter=None if sigma is None else sigma[-1],
    )


@dataclass(frozen=True)
class AveragedNees:
    """The run-averaged NEES of a campaign: per frame (``t``, ``mean``) and the campaign summary's
    statistics of it after the settling time (its dof, runs, 95 % band, fraction inside, mean and the 95 %
    interval of the mean, [lo, hi] with hi None for one run)."""

    t: np.ndarray
    runs: int
    dof: int
    mean: np.ndarray  # (F,) NEES averaged over the runs
    band: tuple  # (lo, hi) for the average of ``runs`` runs
    settle_s: float
    fraction_in_band: float  # over the frames after settle_s
    mean_after_settle: float
    mean_interval: list


def averaged_nees(campaign):
    """:class:`AveragedNees` of a campaign: its statistics as the campaign summary pooled them
    (:func:`navsim.pooling.averaged_nees`), its curve by the same function from the runs' series; None when
    the runs did not log NEES."""
    if not all("nees" in r.series for r in campaign.runs):
        return None
    t, mean = run_averaged_nees([r.series for r in campaign.runs])
    pooled = campaign.summary["nees"]
    return AveragedNees(t, int(pooled["runs"]), int(pooled["dof"]), mean, tuple(pooled["band_95"]),
                        float(campaign.scenario["settle_s"]), float(pooled["fraction_in_band"]), float(pooled["mean"]),
                        list(pooled["mean_interval_95"]))


@dataclass(frozen=True)
class SuccessRow:
    name: str
    frames: int
    identified: int

    @property
    def fraction(self):
        return self.identified / self.frames if self.frames else float("nan")


def identification_success(campaign):
    """Frames with at least MIN_IDENTIFIED identified stars, pooled over runs, per mode.

    Returns (rows, criterion). Without per-frame identification counts the rows count frames
    with at least one accepted star measurement instead, and ``criterion`` says so.
    """
    runs = campaign.runs
    if all("n_identified" in r.series for r in runs):
        criterion = f"frames with at least {MIN_IDENTIFIED} identified stars"
        hits = [r.series["n_identified"] >= MIN_IDENTIFIED for r in runs]
    elif all("n_accepted" in r.series for r in runs):
        criterion = "frames with at least one accepted star measurement"
        hits = [r.series["n_accepted"] >= 1 for r in runs]
    else:
        return [], None
    if not all("mode" in r.series for r in runs):
        frames = sum(h.size for h in hits)
        return [SuccessRow("all frames", frames, int(sum(h.sum() for h in hits)))], criterion
    codes = np.unique(np.concatenate([r.series["mode"] for r in runs]))
    names = mode_names(campaign_modes_source(campaign), codes)
    rows = []
    for code in codes:
        frames = sum(int(np.count_nonzero(r.series["mode"] == code)) for r in runs)
        good = sum(int(np.count_nonzero(h & (r.series["mode"] == code))) for r, h in zip(runs, hits))
        rows.append(SuccessRow(names[int(code)], frames, good))
    return rows, criterion


def campaign_modes_source(campaign):
    """The summary that names the modes: the aggregate's if it has ``modes``, else the first run's."""
    if campaign.summary and isinstance(campaign.summary.get("modes"), list):
        return campaign.summary
    return campaign.runs[0].summary


@dataclass(frozen=True)
class MetricRow:
    label: str
    unit: str
    runs: int
    mean: float
    std: float
    median: float
    p95: float
    maximum: float


def metric_table(campaign, metrics):
    """Across-run statistics of each per-run metric (label, unit, path) found in the run summaries."""
    rows = []
    for label, unit, path in metrics:
        values = [lookup(r.summary, path) for r in campaign.runs]
        values = np.array([v for v in values if v is not None], dtype=float)
        if values.size == 0:
            continue
        if unit == "%":
            values = 100.0 * values
        rows.append(MetricRow(label, unit, values.size, float(values.mean()),
                              float(values.std(ddof=1)) if values.size > 1 else 0.0,
                              float(np.median(values)), float(np.percentile(values, 95)), float(values.max())))
    return rows


def lookup(tree, path):
    """The finite number at ``path`` (keys or list indices) in nested JSON, else None."""
    for key in path:
        if isinstance(tree, Mapping) and key in tree:
            tree = tree[key]
        elif isinstance(tree, list) and isinstance(key, int) and -len(tree) <= key < len(tree):
            tree = tree[key]
        else:
            return None
    if isinstance(tree, bool) or not isinstance(tree, (int, float)) or not np.isfinite(tree):
        return None
    return float(tree)
