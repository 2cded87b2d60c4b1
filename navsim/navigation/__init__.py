"""The navigation run kind: the strapdown INS with its navigation filter on a flight or ship trajectory
(a scenario with a ``[trajectory]`` table), free, aided by position fixes and a baro, or by a star
sensor (SINS/CNS).

Its modules: ``scenario`` (schema and rules), ``build`` (its tables to SI models), ``run`` (prepare,
simulate), ``summary`` and ``celestial`` (its series and summary), ``records`` (its run and campaign
summaries), ``campaign`` (what a campaign pools), ``console`` (what the command line prints),
``budget`` (the error budget's sources and parts), ``covariance`` (its linear covariance analysis), ``exclusion``,
``sky_background`` and ``availability`` (what the sky lets the star sensor see), ``report``, ``figures`` and ``report_statistics``
(its PDF sections), ``warmup`` (its compile-ahead task). The names below are the run-kind interface of
:mod:`navsim.kinds`, each loaded on first use.
"""

from startrack import lazy_exports

#: The kind's name, and the table that marks a scenario of it.
NAME, TABLE = "navigation", "trajectory"

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "navsim.navigation.scenario": ("validate", "check_tuning"),
    "navsim.navigation.run": ("prepare", "simulate", "lanes", "check_truth_off", "TRUTH_SOURCES"),
    "navsim.navigation.budget": ("budget_parts", "summarize_budget", "budget_text"),
    "navsim.navigation.covariance": ("covariance_analysis", "COVARIANCE_QUANTITIES", "COVARIANCE_SOURCES",
                                     "covariance_run_errors"),
    "navsim.navigation.records": ("RunSummary", "CampaignSummary"),
    "navsim.navigation.campaign": ("pool",),
    "navsim.navigation.console": ("run_lines", "campaign_lines"),
    "navsim.navigation.report": ("run_report", "campaign_report", "REQUIRED_SERIES", "CAMPAIGN_SERIES"),
    "navsim.navigation.availability": ("star_availability",),
})
