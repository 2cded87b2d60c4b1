"""The spacecraft run kind (issue 51): a star sensor of one to three heads and a gyro on a spacecraft in orbit — the
orbit (SGP4 or the numerical propagator), the attitude from the rigid body with its wheels and controller following
an attitude law, the Sun, the Moon and the Earth's limb taking frames from each head, the stars behind the Earth
hidden and every star aberrated by the orbit's velocity — estimated by the MEKF with a mounting per head. A scenario
with an ``[orbit]`` table.

Its modules: ``scenario`` (schema and rules), ``build`` (its tables to SI models), ``exclusion`` (the heads' sky from
orbit), ``run`` (prepare, simulate), ``summary`` and ``records`` (its run and campaign summaries), ``campaign``
(what a campaign pools), ``console`` (what the command line prints), ``report`` (its PDF sections). It builds on the
attitude kind (its filter configuration, campaign pooling and report sections). The names below are the run-kind
interface of :mod:`navsim.kinds`, each loaded on first use.
"""

from startrack import lazy_exports

#: The kind's name, and the table that marks a scenario of it.
NAME, TABLE = "spacecraft", "orbit"

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "navsim.spacecraft.scenario": ("validate", "check_tuning"),
    "navsim.spacecraft.run": ("prepare", "simulate", "lanes", "check_truth_off", "budget_parts", "star_availability",
                              "TRUTH_SOURCES"),
    "navsim.spacecraft.records": ("RunSummary", "CampaignSummary"),
    "navsim.spacecraft.covariance": ("covariance_analysis", "COVARIANCE_QUANTITIES", "COVARIANCE_SOURCES",
                                     "covariance_run_errors"),
    "navsim.spacecraft.campaign": ("pool",),
    "navsim.spacecraft.console": ("run_lines", "campaign_lines"),
    "navsim.spacecraft.report": ("run_report", "campaign_report", "REQUIRED_SERIES", "CAMPAIGN_SERIES"),
})
