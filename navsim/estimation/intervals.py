"""Confidence intervals of what a batch of independent seeded runs measures: the expectation of a figure each
run averages (its NEES per dof, its NIS per dof) and a quantile of a figure each run ends with (CEP50, CEP95).

The runs are independent (each its own seed), the frames of one run are not: a filter's errors, and so its
NEES, stay correlated over its time constants (an INS's over hours), so a χ² law with the dof of every frame
of every run would state an interval far too narrow. The run is the unit:

- the expectation's interval is Student's t over the runs' own means, x̄ ∓ t_{(1+P)/2}(N − 1) s/√N: the method
  of independent replications (Law 2015 §9.4.1, replication/deletion: each run's frames after its settling
  time averaged), whatever the correlation inside a run; exact for Gaussian run means (a long run's mean, by
  the central limit theorem), and it needs N ≥ 2;
- a quantile's interval is distribution-free: the order statistics [X₍r₎, X₍s₎] of the N runs, with B ~ Bin(N, p)
  the runs below the p-quantile, P(X₍r₎ ≤ ξ_p ≤ X₍s₎) = P(r ≤ B ≤ s − 1) (David & Nagaraja 2003 §7.1); equal
  tails, r the largest rank with P(B ≤ r − 1) ≤ (1 − P)/2 and s the smallest with P(B ≤ s − 1) ≥ (1 + P)/2.
  No rank bounds the upper end while p^N > (1 − P)/2, nor the lower while (1 − p)^N > (1 − P)/2: both ends
  need N ≥ ln((1 − P)/2) / ln max(p, 1 − p) runs (:func:`runs_to_bound`: 6 for a median, 72 for a 95th
  percentile at P = 95 %; a one-sided 95 % upper bound of the 95th percentile needs 59, Wilks 1941).
"""

import math

import numpy as np
from scipy.special import bdtr, stdtrit

from navsim.estimation.consistency import BAND_PROBABILITY


def mean_interval(values, probability=BAND_PROBABILITY, lowest=-np.inf):
    """(lo, hi): Student's t interval of the expectation of independent ``values`` (one per run), clipped below
    at ``lowest`` (0 for a NEES); (lowest, inf) for fewer than two values (their spread is unknown)."""
    x = np.asarray(values, dtype=float)
    if x.size < 2:
        return float(lowest), np.inf
    half = float(stdtrit(x.size - 1, 0.5 + 0.5 * probability)) * float(np.std(x, ddof=1)) / math.sqrt(x.size)
    mean = float(np.mean(x))
    return max(mean - half, float(lowest)), mean + half


def order_statistic_ranks(runs, p, probability=BAND_PROBABILITY):
    """(r, s): the 1-based ranks of the order statistics of ``runs`` samples that bound their ``p``-quantile with at
    least ``probability`` (module docstring); r = 0 when no rank bounds it below, s = runs + 1 when none above."""
    tail = 0.5 * (1.0 - probability)
    below = bdtr(np.arange(runs + 1), runs, p)  # P(B <= k), k = 0 .. runs
    return int(np.count_nonzero(below <= tail)), int(np.argmax(below >= 1.0 - tail)) + 1


def quantile_interval(values, p, probability=BAND_PROBABILITY, axis=0, lowest=-np.inf):
    """(lo, hi): the order statistics of ``values`` (runs along ``axis``) that bound their ``p``-quantile with at
    least ``probability`` (:func:`order_statistic_ranks`); an end no rank bounds is ``lowest`` (0 for a size)
    below, inf above."""
    x = np.sort(np.asarray(values, dtype=float), axis=axis)
    runs = x.shape[axis]
    r, s = order_statistic_ranks(runs, p, probability)
    unbounded = np.full(np.delete(x.shape, axis), np.inf)
    lo = np.take(x, r - 1, axis=axis) if r >= 1 else np.full_like(unbounded, lowest)
    hi = np.take(x, s - 1, axis=axis) if s <= runs else unbounded
    return (float(lo), float(hi)) if x.ndim == 1 else (lo, hi)


def runs_to_bound(p, probability=BAND_PROBABILITY):
    """The fewest runs whose order statistics bound the ``p``-quantile at both ends with ``probability``:
    the least N with max(p, 1 − p)^N ≤ (1 − probability)/2."""
    return math.ceil(math.log(0.5 * (1.0 - probability)) / math.log(max(p, 1.0 - p)))


def as_json(interval):
    """[lo, hi] of an interval with an unbounded end as null (JSON has no infinity)."""
    return [float(v) if math.isfinite(v) else None for v in interval]


def contains(interval, value):
    """True when ``value`` lies inside ``interval`` ([lo, hi], a null or infinite end unbounded)."""
    lo, hi = (-np.inf if interval[0] is None else interval[0]), (np.inf if interval[1] is None else interval[1])
    return lo <= value <= hi


def interval_text(interval, digits=2, unit=""):
    """"[lo, hi] unit" of an interval ([lo, hi], a null or infinite end "unbounded")."""
    ends = ["unbounded" if v is None or not math.isfinite(v) else f"{v:.{digits}f}" for v in interval]
    return f"[{ends[0]}, {ends[1]}]" + (f" {unit}" if unit else "")
