"""Filter tuning: scale Q and R until the filter is consistent over a batch of seeded runs.

Consistency means the time-averaged NEES of the filter's error state is at its expected value (its
dof, which each run's summary records: 6 for the attitude filter's attitude and bias, 15 or 21 for
the navigation filter) and the NIS per degree of freedom is 1 (Bar-Shalom, Li & Kirubarajan, *Estimation with
Applications to Tracking and Navigation*, §5.4). Each statistic is the mean over the runs of each run's own
(its steady frames' mean NEES per dof; its steady updates' NIS sum over their dof), stated with its 95 %
interval from the runs' spread (:mod:`navsim.estimation.intervals`: the runs are independent, a run's
frames are not). When 1 lies inside both intervals of the scenario as given, the runs cannot tell the
filter from a consistent one and no change is proposed. Otherwise, with common random numbers (the same
seeds at every evaluation), the two scale factors are fitted together by minimising

    J(q, r) = ln²(NEES/dof) + ln²(NIS/dof)

over (ln q, ln r) with Nelder-Mead (the statistics are smooth in the scales but their coupling is
strong: a smaller R lowers the NIS and raises the NEES), stopping as soon as both statistics are
within the tolerance of 1.
"""

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from navsim.estimation.intervals import as_json, contains, mean_interval
from navsim.kinds import resolve_scenario, run_kind
from navsim.simulation import run_batch
from startrack import InputError

#: The fewest runs a tuning takes: the intervals come from the runs' spread.
MIN_RUNS = 2


@dataclass(frozen=True)
class BatchStatistics:
    """NEES/dof and NIS/dof of a batch (means over the runs of each run's own) with their 95 % intervals
    ([lo, hi], hi None unbounded: :func:`navsim.estimation.intervals.mean_interval`) over ``runs`` runs, and
    ``errors``: the batch mean of each headline error of the runs' kind, {label: (value, unit)}
    (:meth:`navsim.records.RunSummary.headline`)."""

    nees_per_dof: float
    nis_per_dof: float
    nees_interval: list
    nis_interval: list
    runs: int
    errors: dict

    @property
    def consistent(self):
        """True when 1 lies inside both intervals: these runs cannot tell the filter from a consistent one."""
        return contains(self.nees_interval, 1.0) and contains(self.nis_interval, 1.0)


@dataclass(frozen=True, kw_only=True)
class TuneStep(BatchStatistics):
    """One evaluation: the batch's statistics with the scales it used."""

    process_noise_scale: float
    measurement_noise_scale: float


@dataclass
class TuneResult:
    """The evaluations (first = the scenario as given) and the fitted scale factors: the given ones when the
    first evaluation is :attr:`BatchStatistics.consistent` (no change proposed)."""

    steps: list = field(default_factory=list)

    @property
    def change_proposed(self):
        return not self.steps[0].consistent

    @property
    def process_noise_scale(self):
        return self.steps[-1].process_noise_scale

    @property
    def measurement_noise_scale(self):
        return self.steps[-1].measurement_noise_scale

    def as_dict(self):
        return {"process_noise_scale": self.process_noise_scale,
                "measurement_noise_scale": self.measurement_noise_scale, "change_proposed": self.change_proposed,
                "steps": [vars(step) for step in self.steps]}


def batch_statistics(results, settle_s):
    """:class:`BatchStatistics` of a batch of runs (their frames after ``settle_s`` [s])."""
    nees, nis = [], []
    for result in results:
        steady = result.series["t"] >= settle_s
        nees.append(np.mean(result.series["nees"][steady]) / result.summary["nees"]["dof"])
        accepted = np.isfinite(result.series["nis"]) & steady
        nis.append(np.sum(result.series["nis"][accepted]) / max(int(np.sum(result.series["nis_dof"][accepted])), 1))
    headlines = [r.summary.headline() for r in results]
    errors = {label: (float(np.mean([h[label][0] for h in headlines])), unit) for label, (_, unit) in headlines[0].items()}
    return BatchStatistics(float(np.mean(nees)), float(np.mean(nis)), as_json(mean_interval(nees, lowest=0.0)),
                           as_json(mean_interval(nis, lowest=0.0)), len(results), errors)


def tune(scenario, runs=20, seed=None, overrides=(), evaluations=30, tolerance=0.05, threads=1, on_step=None,
         on_run=None):
    """Fit ``filter.process_noise_scale`` and ``filter.measurement_noise_scale`` (module docstring).

    Proposes no change when the scenario as given is consistent within its intervals; otherwise stops when
    both NEES/dof and NIS/dof are within ``tolerance`` of 1 or after ``evaluations`` batches. ``on_step(k,
    step)`` is called as each evaluation ends, ``on_run()`` as each run does. Returns a :class:`TuneResult`:
    its first step is the scenario as given, its last the best scales found.
    """
    scenario = resolve_scenario(scenario, overrides)
    run_kind(scenario, "filter tuning").check_tuning(scenario)
    if runs < MIN_RUNS:
        raise InputError(f"--runs must be at least {MIN_RUNS}, got {runs}: the intervals of NEES/dof and NIS/dof "
                         "come from the runs' spread")
    base_seed = scenario["seed"] if seed is None else int(seed)
    seeds = [base_seed + k for k in range(runs)]
    outcome = TuneResult()

    def evaluate(log_scales):
        q_scale, r_scale = (float(v) for v in np.exp(log_scales))
        results = run_batch(scenario, seeds, overrides={"filter.process_noise_scale": q_scale,
                                                        "filter.measurement_noise_scale": r_scale},
                            threads=threads, on_run=on_run)
        step = TuneStep(**vars(batch_statistics(results, scenario["settle_s"])), process_noise_scale=q_scale,
                        measurement_noise_scale=r_scale)
        outcome.steps.append(step)
        if on_step is not None:
            on_step(len(outcome.steps) - 1, step)
        if len(outcome.steps) == 1 and step.consistent:
            raise _Converged
        if abs(step.nees_per_dof - 1.0) < tolerance and abs(step.nis_per_dof - 1.0) < tolerance:
            raise _Converged
        return _misfit(step)

    start = np.log([scenario["filter"]["process_noise_scale"], scenario["filter"]["measurement_noise_scale"]])
    try:
        minimize(evaluate, start, method="Nelder-Mead",
                 options={"maxfev": max(evaluations, 1), "initial_simplex": start + np.array([[0, 0], [0.7, 0], [0, 0.3]])})
    except _Converged:
        pass
    best = min(outcome.steps, key=_misfit)
    outcome.steps.append(best) if best is not outcome.steps[-1] else None
    return outcome


def _misfit(step):
    """J of the module docstring."""
    return np.log(step.nees_per_dof) ** 2 + np.log(step.nis_per_dof) ** 2


class _Converged(Exception):
    """The scenario as given is consistent within its intervals, or both statistics are within the tolerance:
    stop the search."""
