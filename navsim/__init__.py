"""navsim: the INS / star-sensor navigation system simulator.

Truth attitude motion, gyro models, quaternion kinematics (RK4), the multiplicative error-state
Kalman filter, the closed loop that runs the star sensor inside the simulation, faults, scenarios,
Monte Carlo campaigns, filter tuning, the static studies of the source documents
(:mod:`navsim.studies`) and the ``navsim`` command line.

    >>> import navsim
    >>> result = navsim.run("scenarios/paper000_high_dynamic.toml", seed=1, overrides={"duration_s": 20})
    >>> result.summary["cross_boresight_rms_arcsec"]   # doctest: +SKIP

PDF reports live in :mod:`navsim.report` (not imported here: it loads matplotlib and typst).
"""

from navsim.campaign.montecarlo import run_campaign
from navsim.campaign.tuning import tune
from navsim.estimation.attitude_filter import AttitudeFilter
from navsim.output import read_npz, write_run
from navsim.scenario import Scenario, load_scenario
from navsim.sensors.gyro import GyroModel
from navsim.simulation import RunResult, prepare, run, run_batch, run_study, simulate
from navsim.studies import StudyResult

__all__ = [
    "AttitudeFilter",
    "GyroModel",
    "RunResult",
    "Scenario",
    "StudyResult",
    "load_scenario",
    "prepare",
    "read_npz",
    "run",
    "run_batch",
    "run_campaign",
    "run_study",
    "simulate",
    "tune",
    "write_run",
]
