"""What the studies share: the static studies' result type, the observers' findings, the
paper-difference helper and the progress bar."""

import sys
from dataclasses import dataclass, field

from tqdm import tqdm


@dataclass
class StudyResult:
    """A static study's outcome: ``summary`` (JSON: every point, ``paper_comparison`` rows, ``notes``)
    and ``arrays`` (per-sample numbers the figures draw, written to ``study.npz``)."""

    scenario: dict
    summary: dict
    arrays: dict = field(default_factory=dict)


class Findings:
    """A per-frame observer's findings for a run or a campaign: ``stats`` (the summary's entry under
    ``key``), ``timing`` (its wall-clock figures, under the summary's ``timing``), ``series`` (extra
    per-frame arrays of a run) and, from the subclass, ``rows`` and ``timing_rows`` (the comparison
    table) and ``notes`` and ``timing_notes`` (sentences explaining it)."""

    key = ""
    timing_rows = ()
    timing_notes = ()

    def __init__(self, stats, series=None, timing=None):
        self.stats = stats
        self.series = series or {}
        self.timing = timing or {}


def percent(ours, paper):
    """Relative differences [%] of ours from the paper's figures, one decimal."""
    return [round(100.0 * (o - p) / p, 1) for o, p in zip(ours, paper)]


def progress_bar(items, enabled, description):
    """``items`` with a tqdm bar on stderr when ``enabled`` (shown after a second)."""
    return tqdm(items, desc=description, disable=not enabled, file=sys.stderr, delay=1.0, leave=False)


def add_timing(timing, findings):
    """Put the findings' wall-clock figures, time comparisons and notes into a summary's ``timing``."""
    for found in findings:
        if found.timing:
            timing[found.key] = found.timing
    rows = [r for f in findings for r in f.timing_rows]
    notes = [n for f in findings for n in f.timing_notes]
    if rows:
        timing["paper_comparison"] = rows
    if notes:
        timing["notes"] = notes
