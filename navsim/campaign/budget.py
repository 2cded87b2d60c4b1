"""The error budget of a scenario, by linear covariance analysis (the default: one pass with each error
source apart, :mod:`navsim.estimation.lincov`; the kind's ``covariance_analysis`` and :func:`navsim.analysis.budget`) or by
Monte Carlo: one campaign per part (each error source alone in the truth under the scenario's own filter, then
the whole scenario), resumable, and the budget the kind draws from them
(:func:`navsim.navigation.budget.budget_parts`, ``summarize_budget``: the star-aided navigation kind's sources,
metres and predictions).

    navsim budget SCENARIO.toml --out DIR [--method covariance | --method montecarlo [--runs N] [--workers W]]

A covariance budget writes ``DIR/budget.json`` (its format says the method) and ``DIR/timeseries.npz`` (each
quantity's shares over time).

Each part is a campaign of N runs with the same seeds in ``DIR/parts/<key>/`` (a second call runs only
what is missing; its campaign.json records what the truth leaves out); ``DIR/budget.json`` holds the
budget, and ``navsim report DIR`` (:mod:`navsim.report.budget`) typesets it.

``--compare DIR`` (covariance method) checks a covariance budget against a Monte Carlo one of the same scenario:
each part's runs against the analysis of that source alone under the same filter (:func:`compare_budget`).
"""

from pathlib import Path

from navsim.analysis import budget as analysis_budget
from navsim.campaign.montecarlo import finished_series, run_campaign
from navsim.kinds import resolve_scenario, run_kind
from navsim.output import write_json, write_npz
from navsim.places import check_output, mark, output_kind
from startrack import InputError

#: Runs per source by default.
DEFAULT_RUNS = 5
MAX_RUNS = 10_000
#: How a budget is computed.
METHODS = ("covariance", "montecarlo")


def run_budget(scenario, out, runs=None, workers=None, base_seed=None, overrides=(), progress=True, method="covariance",
               compare=None):
    """Run (or resume) the budget of ``scenario`` into ``out`` by ``method`` (:data:`METHODS`); returns the budget
    (also ``out/budget.json``), with the covariance method checked against the Monte Carlo budget in the directory
    ``compare`` when given. Bad input (runs, workers or a seed with the covariance method, --compare with the Monte
    Carlo one, a scenario whose kind or tables have no budget) is an InputError before anything is written."""
    scenario = resolve_scenario(scenario, overrides)
    if method not in METHODS:
        raise InputError(f"--method {method}: must be one of {', '.join(METHODS)}")
    if method == "covariance":
        given = [name for name, value in (("--runs", runs), ("--workers", workers), ("--seed", base_seed)) if value is not None]
        if given:
            raise InputError(f"{', '.join(given)}: Monte Carlo options; the covariance method draws nothing "
                             "(add --method montecarlo)")
        return _covariance_budget(scenario, out, compare)
    if compare is not None:
        raise InputError("--compare: checks a covariance budget against a Monte Carlo one; give it without --method montecarlo")
    runs = DEFAULT_RUNS if runs is None else runs
    if not 1 <= runs <= MAX_RUNS:
        raise InputError(f"--runs must be from 1 to {MAX_RUNS:,}, got {runs}")
    if workers is not None and workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    kind = run_kind(scenario, "an error budget")
    parts = kind.budget_parts(scenario)
    directory = check_output(out, "budget")
    mark(directory, "budget")
    seed = scenario["seed"] if base_seed is None else int(base_seed)
    for part in parts:
        if part.scenario is not None:
            run_campaign(part.scenario, runs, directory / "parts" / part.key, base_seed=seed, workers=workers,
                         progress=progress, truth_off=part.truth_off)
    budget = kind.summarize_budget(scenario, directory, parts, runs, seed)
    write_json(directory / "budget.json", budget)
    return budget


def _covariance_budget(scenario, out, compare):
    """The budget by linear covariance analysis: ``out/budget.json`` and ``out/timeseries.npz``."""
    kind = run_kind(scenario, "an error budget")
    analysis = kind.covariance_analysis(scenario, split=True)  # seconds: bad input found before --out is made
    budget = analysis_budget(scenario, analysis, kind.COVARIANCE_SOURCES)
    if compare is not None:
        budget["comparison"] = compare_budget(scenario, compare)
    directory = check_output(out, "budget")
    mark(directory, "budget")
    write_npz(directory / "timeseries.npz", analysis.series())
    write_json(directory / "budget.json", budget)
    return budget


def compare_budget(scenario, directory):
    """{part: comparison}: each part of the Monte Carlo budget in ``directory`` (``navsim budget --method
    montecarlo`` of ``scenario``) against the covariance analysis of the same part, the part's source alone in
    the truth under the part's filter (the whole analysis for the total), by :func:`navsim.analysis.compare`: its
    summary quantities at ten times against the sampling band of the part's runs. An InputError unless the
    directory holds such a budget."""
    directory = Path(directory)
    if not directory.is_dir() or output_kind(directory) != "budget" or not (directory / "parts").is_dir():
        raise InputError(f"--compare {directory}: not a Monte Carlo budget directory (navsim budget --method montecarlo --out)")
    kind = run_kind(scenario, "an error budget")
    out = {}
    for part in kind.budget_parts(scenario):
        if part.scenario is None or not (directory / "parts" / part.key).is_dir():
            continue
        runs = finished_series(directory / "parts" / part.key, part.scenario, "--compare", part.truth_off)
        total = part.key == "total"
        analysis = kind.covariance_analysis(part.scenario, split=not total)
        out[part.key] = {"label": part.label, **(analysis if total else analysis.only(part.covariance)).compare(runs)}
    if not out:
        raise InputError(f"--compare {directory}: no part of the budget has run")
    return out
