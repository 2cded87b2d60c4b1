"""Filter tuning: scale Q and R until the filter is consistent over a batch of seeded runs.

Consistency means the time-averaged NEES of the filter's error state is at its expected value (its
dof, which each run's summary records: 6 for the attitude filter's attitude and bias, 15 or 21 for
the navigation filter) and the NIS per degree of freedom is 1 (Bar-Shalom, Li & Kirubarajan, *Estimation with
Applications to Tracking and Navigation*, §5.4). With common random numbers (the same seeds at
every evaluation) the two scale factors are fitted together by minimising

    J(q, r) = ln²(NEES/dof) + ln²(NIS/dof)

over (ln q, ln r) with Nelder-Mead (the statistics are smooth in the scales but their coupling is
strong: a smaller R lowers the NIS and raises the NEES), stopping as soon as both statistics are
within the tolerance of 1.
"""

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from navsim.kinds import resolve_scenario, run_kind
from navsim.simulation import run_batch


@dataclass
class TuneStep:
    """Statistics of one iteration's batch with the scales it used; ``errors``: the batch mean of
    each headline error of the runs' kind, {label: (value, unit)} (:meth:`navsim.records.RunSummary.headline`)."""

    process_noise_scale: float
    measurement_noise_scale: float
    nees_per_dof: float
    nis_per_dof: float
    errors: dict


@dataclass
class TuneResult:
    """The iterations (first = the scenario as given) and the fitted scale factors."""

    steps: list = field(default_factory=list)

    @property
    def process_noise_scale(self):
        return self.steps[-1].process_noise_scale

    @property
    def measurement_noise_scale(self):
        return self.steps[-1].measurement_noise_scale

    def as_dict(self):
        return {"process_noise_scale": self.process_noise_scale,
                "measurement_noise_scale": self.measurement_noise_scale,
                "steps": [vars(step) for step in self.steps]}


def batch_statistics(results, settle_s):
    """(NEES per dof, NIS per dof, {label: (batch mean, unit)} of the headline errors) over a batch."""
    nees, nis, dof = [], 0.0, 0
    nees_dof = results[0].summary["nees"]["dof"]
    for result in results:
        steady = result.series["t"] >= settle_s
        nees.append(result.series["nees"][steady])
        accepted = np.isfinite(result.series["nis"]) & steady
        nis += float(np.sum(result.series["nis"][accepted]))
        dof += int(np.sum(result.series["nis_dof"][accepted]))
    headlines = [r.summary.headline() for r in results]
    errors = {label: (float(np.mean([h[label][0] for h in headlines])), unit) for label, (_, unit) in headlines[0].items()}
    return float(np.mean(np.concatenate(nees))) / nees_dof, nis / max(dof, 1), errors


def tune(scenario, runs=20, seed=None, overrides=(), evaluations=30, tolerance=0.05, threads=1):
    """Fit ``filter.process_noise_scale`` and ``filter.measurement_noise_scale`` (module docstring).

    Stops when both NEES/dof and NIS/dof are within ``tolerance`` of 1 or after ``evaluations``
    batches. Returns a :class:`TuneResult`: its first step is the scenario as given, its last the
    best scales found.
    """
    scenario = resolve_scenario(scenario, overrides)
    run_kind(scenario, "filter tuning").check_tuning(scenario)
    base_seed = scenario["seed"] if seed is None else int(seed)
    seeds = [base_seed + k for k in range(runs)]
    outcome = TuneResult()

    def evaluate(log_scales):
        q_scale, r_scale = (float(v) for v in np.exp(log_scales))
        results = run_batch(scenario, seeds, overrides={"filter.process_noise_scale": q_scale,
                                                        "filter.measurement_noise_scale": r_scale}, threads=threads)
        nees, nis, errors = batch_statistics(results, scenario["settle_s"])
        outcome.steps.append(TuneStep(q_scale, r_scale, nees, nis, errors))
        if abs(nees - 1.0) < tolerance and abs(nis - 1.0) < tolerance:
            raise _Converged
        return np.log(nees) ** 2 + np.log(nis) ** 2

    start = np.log([scenario["filter"]["process_noise_scale"], scenario["filter"]["measurement_noise_scale"]])
    try:
        minimize(evaluate, start, method="Nelder-Mead",
                 options={"maxfev": max(evaluations, 1), "initial_simplex": start + np.array([[0, 0], [0.7, 0], [0, 0.3]])})
    except _Converged:
        pass
    best = min(outcome.steps, key=lambda step: np.log(step.nees_per_dof) ** 2 + np.log(step.nis_per_dof) ** 2)
    outcome.steps.append(best) if best is not outcome.steps[-1] else None
    return outcome


class _Converged(Exception):
    """Both statistics are within the tolerance: stop the search."""
