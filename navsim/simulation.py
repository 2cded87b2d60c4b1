"""The front door of every simulation run: the seed-free preparation of a scenario, then seeded runs,
whatever the scenario's kind (:mod:`navsim.kinds`: attitude, navigation), and the static studies.

    prepared = prepare("scenarios/sins_cns_psins.toml", truth_off={"gravity"})
    result = simulate(prepared, seed=3)

Random sub-streams are each kind's (docs/design.md, "Randomness"); the same seed gives the same numbers
in one process, a pool or a cluster.
"""

import dataclasses
import time
from concurrent.futures import ThreadPoolExecutor

from navsim import studies
from navsim.kinds import KINDS, STUDY, resolve_scenario, run_kind
from navsim.studies import STUDIES, StudyResult
from startrack import InputError


def prepare(scenario, overrides=(), star_catalog=None, truth_off=frozenset()):
    """Validate ``scenario`` (a path, a dictionary or a Scenario, with ``overrides``) and compute everything
    of a run that does not depend on the seed; ``star_catalog`` (a startrack StarCatalog) is loaded at the
    scenario's epoch when needed; ``truth_off`` names error sources the truth leaves out, not the filter
    (the kind's ``TRUTH_SOURCES``)."""
    scenario = resolve_scenario(scenario, overrides)
    return run_kind(scenario, "a simulation run").prepare(scenario, star_catalog, truth_off)


def simulate(prepared, seed, compiled=True):
    """The seeded part of one run on a prepared scenario; returns a :class:`~navsim.records.RunResult`.
    ``compiled=False`` keeps the step-by-step loop where the filter's fast path would run."""
    return KINDS[prepared.scenario.kind].simulate(prepared, seed, compiled)


def run(scenario, seed=None, overrides=(), star_catalog=None):
    """Simulate one run; ``seed`` overrides the scenario's. Returns a :class:`~navsim.records.RunResult`.

    ``overrides`` is a dict {"gyro.rate_hz": 200} or a list of "key=value" strings.
    ``star_catalog`` (a startrack StarCatalog) is loaded from the scenario epoch when needed.
    """
    started = time.perf_counter()
    prepared = prepare(scenario, overrides, star_catalog)
    result = simulate(prepared, prepared.scenario["seed"] if seed is None else int(seed))
    summary = result.summary.replace(timing={**result.summary.timing, "wall_seconds": round(time.perf_counter() - started, 4)})
    return dataclasses.replace(result, summary=summary)


def covariance(scenario, overrides=(), split=False, star_catalog=None):
    """The linear covariance analysis of ``scenario`` (a path, a dictionary or a Scenario, with ``overrides``)
    by its kind: the true RMS of its errors, the filter's σ beside it and, when ``split``, each error source's
    share (:mod:`navsim.estimation.lincov`)."""
    scenario = resolve_scenario(scenario, overrides)
    return run_kind(scenario, "a covariance analysis").covariance_analysis(scenario, split, star_catalog)


def run_study(scenario, seed=None, overrides=(), progress=False):
    """Run a static study (a scenario with a ``[study]`` table, :mod:`navsim.studies`); ``seed``
    overrides the scenario's. Returns a :class:`~navsim.studies.StudyResult`."""
    started = time.perf_counter()
    scenario = resolve_scenario(scenario, overrides)
    if scenario.kind != STUDY:
        raise InputError(f"{scenario.source}: a simulation scenario, not a static study; run it with navsim.run")
    seed = scenario["seed"] if seed is None else int(seed)
    kind = scenario["study"]["kind"]
    summary, arrays = STUDIES[kind].run(studies.parameters(scenario), seed, progress)
    summary = {"scenario": scenario.name, "study": kind, "seed": seed} | summary
    summary["wall_seconds"] = round(time.perf_counter() - started, 4)
    return StudyResult(scenario=scenario.data, summary=summary, arrays=arrays)


def run_batch(scenario, seeds, overrides=(), star_catalog=None, threads=1, on_run=None):
    """Many runs of one scenario sharing its seed-free part (truth, models, catalog): a batch of
    one equals :func:`run` with that seed. The compiled filter loop releases the GIL, so
    ``threads`` > 1 runs members concurrently; ``on_run()`` is called as each run ends. Returns the list of
    :class:`~navsim.records.RunResult`."""
    prepared = prepare(scenario, overrides, star_catalog)

    def one(seed):
        result = simulate(prepared, int(seed))
        if on_run is not None:
            on_run()
        return result

    if threads <= 1:
        return [one(seed) for seed in seeds]
    with ThreadPoolExecutor(max_workers=threads) as pool:
        return list(pool.map(one, seeds))
