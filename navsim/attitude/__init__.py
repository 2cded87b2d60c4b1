"""The attitude run kind: a star sensor and a gyro on a truth attitude profile (a scenario without a
``[trajectory]`` or ``[study]`` table), estimated by the MEKF.

Its modules: ``scenario`` (schema and rules), ``build`` (its tables to SI models), ``run`` (prepare,
simulate, summarize), ``records`` (its run and campaign summaries), ``campaign`` (what a campaign pools),
``console`` (what the command line prints), ``report`` and ``figures`` (its PDF sections). The names below
are the run-kind interface of :mod:`navsim.kinds`, each loaded on first use.
"""

from startrack import lazy_exports

#: The kind's name, and the table that marks a scenario of it (None: a scenario no other kind claims).
NAME, TABLE = "attitude", None

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "navsim.attitude.scenario": ("validate", "check_tuning"),
    "navsim.attitude.run": ("prepare", "simulate", "lanes", "check_truth_off", "budget_parts", "star_availability",
                            "TRUTH_SOURCES"),
    "navsim.attitude.records": ("RunSummary", "CampaignSummary"),
    "navsim.attitude.covariance": ("covariance_analysis", "COVARIANCE_QUANTITIES", "COVARIANCE_SOURCES",
                                   "covariance_run_errors"),
    "navsim.attitude.campaign": ("pool",),
    "navsim.attitude.console": ("run_lines", "campaign_lines"),
    "navsim.attitude.report": ("run_report", "campaign_report", "REQUIRED_SERIES", "CAMPAIGN_SERIES"),
})
