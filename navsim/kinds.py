"""The kinds of scenario, and how a scenario file or dictionary becomes a validated :class:`Scenario` of
its kind: the one place that knows them all.

A scenario's kind is named by the table that marks it: ``[study]`` a static study
(:mod:`navsim.studies`), a run kind's own table (``[trajectory]``: navigation, ``[orbit]``: spacecraft), and none the kind without
one (attitude). Generic code — the front door :mod:`navsim.simulation`, campaigns, tuning, the error
budget, reports and the command line — asks :func:`run_kind` for the scenario's kind once and calls it,
never testing which kind it is.

A **run kind** is a package providing (each name loaded on first use; :mod:`navsim.attitude`,
:mod:`navsim.navigation` and :mod:`navsim.spacecraft` are the three):

    NAME, TABLE                                   its name, the table that marks its scenarios (None: none)
    validate(data, source) -> dict                its schema and cross-key rules, derived defaults filled
    prepare(scenario, star_catalog, truth_off)    the seed-free part of a run (``.scenario`` on it)
    simulate(prepared, seed, compiled) -> RunResult
    lanes(scenario)                               the kernels a run compiles ahead (startrack.compiled.compile_ahead)
    TRUTH_SOURCES, check_truth_off(scenario, names)   the error sources a run can switch off in its truth
    budget_parts(scenario), summarize_budget(...), budget_text(budget)   its error budget (InputError if none)
    check_tuning(scenario)                        an InputError when filter tuning cannot judge it
    RunSummary, CampaignSummary                   its records (:mod:`navsim.records`)
    pool(finished, settle) -> dict                what a campaign pools of its runs
    run_lines(summary), campaign_lines(summary)   what the command line prints of it
    run_report(run), campaign_report(campaign)    its PDF reports (:mod:`navsim.typeset`)
    REQUIRED_SERIES, CAMPAIGN_SERIES              the arrays its reports need, of a run and per campaign run
    covariance_analysis(scenario, split, star_catalog) -> navsim.analysis.Analysis   its linear covariance analysis
    COVARIANCE_QUANTITIES, COVARIANCE_SOURCES     its summary quantities {name: (unit, SI size)}, error sources {key: label}
    covariance_run_errors(scenario)               the quantities' errors of a run series (Monte Carlo against the analysis)
    star_availability(scenario, star_catalog)     the stars its sensor sees along the run, without a filter
                                                  (``navsim sky``; InputError if it has no sky)

A kind whose ``budget_parts`` returns parts also provides ``summarize_budget`` and ``budget_text``. A third
kind is a new package providing these (:data:`INTERFACE`), and one more entry in :data:`KINDS`.
"""

from pathlib import Path

from navsim import attitude, navigation, spacecraft, studies
from navsim.scenario import Scenario, apply_overrides, read_scenario_file
from startrack import InputError

#: The names every run kind provides (module docstring).
INTERFACE = ("NAME", "TABLE", "validate", "prepare", "simulate", "lanes", "TRUTH_SOURCES", "check_truth_off",
             "budget_parts", "check_tuning", "RunSummary", "CampaignSummary", "pool", "run_lines", "campaign_lines",
             "run_report", "campaign_report", "REQUIRED_SERIES", "CAMPAIGN_SERIES", "covariance_analysis", "COVARIANCE_QUANTITIES",
             "COVARIANCE_SOURCES", "covariance_run_errors", "star_availability")
#: The run kinds by name; the one without a table takes every scenario no other kind claims.
KINDS = {kind.NAME: kind for kind in (attitude, navigation, spacecraft)}
#: The name of the static studies' kind, and the table that marks them.
STUDY = "study"
#: The table that marks a replay file (:mod:`navsim.replay`, ``navsim replay``).
REPLAY = "replay"


def kind_name(data):
    """The name of the kind of a scenario dictionary: by the table that marks it (module docstring)."""
    if isinstance(data, dict) and STUDY in data:
        return STUDY
    marked = [name for name, kind in KINDS.items() if kind.TABLE is not None and isinstance(data, dict) and kind.TABLE in data]
    return marked[0] if marked else next(name for name, kind in KINDS.items() if kind.TABLE is None)


def validate(data, source="<scenario>"):
    """A :class:`Scenario` of ``data`` checked against its kind's schema and rules (a replay file, with a ``[replay]``
    table, is not a scenario: :mod:`navsim.replay`)."""
    if isinstance(data, dict) and REPLAY in data:
        raise InputError(f"{source}: a replay of a recording, not a simulation scenario; run it with `navsim replay`")
    name = kind_name(data)
    checked = studies.validate(data, source) if name == STUDY else KINDS[name].validate(data, source)
    return Scenario(data=checked, source=source, kind=name)


def run_kind(scenario, action):
    """The run kind of ``scenario``; an InputError when it is a static study, which ``action`` cannot take."""
    if scenario.kind == STUDY:
        raise InputError(f"{scenario.source}: a static study (study.kind = {scenario['study']['kind']!r}) cannot be "
                         f"used for {action}: it has no trajectory; run it with `navsim run` "
                         "(Python: navsim.run_study)")
    return KINDS[scenario.kind]


def of(data):
    """The run kind of a validated scenario's dictionary (as a run or campaign directory stores it)."""
    return KINDS[kind_name(data)]


def resolve_scenario(scenario, overrides=()):
    """A :class:`Scenario` from a path, a dictionary or a Scenario, with overrides applied."""
    if isinstance(scenario, Scenario):
        if overrides:
            return scenario_from_dict(scenario.data, overrides, source=scenario.source)
        return scenario
    if isinstance(scenario, dict):
        return scenario_from_dict(scenario, overrides)
    return load_scenario(scenario, overrides)


def load_scenario(path, overrides=()):
    """Read, override and validate a scenario TOML file."""
    path = Path(path)
    return validate(read_scenario_file(path, overrides), source=path.name)


def scenario_from_dict(data, overrides=(), source="<dict>"):
    """Validate a scenario given as a dictionary (the Python API's entry point)."""
    return validate(apply_overrides(data, overrides, source), source=source)
