"""navsim: the INS / star-sensor navigation system simulator.

Truth attitude motion, gyro models, quaternion kinematics (RK4), the multiplicative error-state
Kalman filter, the closed loop that runs the star sensor inside the simulation, the strapdown INS
with its navigation filter and aiding (scenarios with a ``[trajectory]`` table), faults, scenarios,
Monte Carlo campaigns, linear covariance analysis and trade sweeps, filter tuning, the static studies of the source documents
(:mod:`navsim.studies`) and the ``navsim`` command line. Each kind of run (attitude, navigation) is a
package of its own behind one registry (:mod:`navsim.kinds`) and one front door
(:mod:`navsim.simulation`).

    >>> import navsim
    >>> result = navsim.run("scenarios/paper000_high_dynamic.toml", seed=1, overrides={"duration_s": 20})
    >>> result.summary["cross_boresight_rms_arcsec"]   # doctest: +SKIP

PDF reports live in :mod:`navsim.report` (not imported here: it loads matplotlib and typst).
"""

from startrack import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "navsim.campaign.montecarlo": ("run_campaign",),
    "navsim.campaign.sweep": ("run_sweep",),
    "navsim.campaign.tuning": ("tune",),
    "navsim.estimation.attitude_filter": ("AttitudeFilter", "AttitudeFilterConfig"),
    "navsim.kinds": ("KINDS", "load_scenario", "resolve_scenario"),
    "navsim.output": ("read_npz", "write_run"),
    "navsim.records": ("CampaignSummary", "RunResult", "RunSummary"),
    "navsim.scenario": ("Scenario",),
    "navsim.sensors.gyro": ("GyroModel",),
    "navsim.simulation": ("covariance", "prepare", "run", "run_batch", "run_study", "simulate"),
    "navsim.studies": ("StudyResult",),
})
