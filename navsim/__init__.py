"""navsim: the INS / star-sensor navigation system simulator.

Truth attitude motion, gyro models, quaternion kinematics (RK4), the multiplicative
error-state Kalman filter, scenarios and the ``navsim`` command line.

    >>> import navsim
    >>> result = navsim.run("scenarios/demo.toml", seed=1, overrides={"duration_s": 20})
    >>> result.summary["cross_boresight_rms_arcsec"]   # doctest: +SKIP
"""

from navsim.filter import AttitudeFilter
from navsim.gyro import GyroModel
from navsim.output import read_npz, write_run
from navsim.scenario import Scenario, load_scenario
from navsim.simulation import RunResult, run

__all__ = [
    "AttitudeFilter",
    "GyroModel",
    "RunResult",
    "Scenario",
    "load_scenario",
    "read_npz",
    "run",
    "write_run",
]
