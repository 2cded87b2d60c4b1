"""The compile-ahead task of the attitude filter (:mod:`startrack.compiled.compile_ahead`; the run kinds' ``lanes``).

It calls the filter's kernels through the constructor and the methods a run calls, on made-up inputs of a
run's shapes and types (the methods convert what they are given, so the kernels see the run's types);
``tests/navsim/test_compile_ahead.py`` checks that a run compiles nothing after its lanes.
"""

import numpy as np

from navsim.estimation.attitude_filter import AttitudeFilter, AttitudeFilterConfig
from navsim.estimation.consistency import nees
from navsim.sensors.star_sensor import isotropic_covariance
from startrack import rotation as rot


def attitude_filter():
    """Task: the MEKF's steps -- prediction, the sensor's predicted attitude, star and attitude-fix updates
    and their statistics -- with every calibration group estimated, and NEES."""
    n = 21
    filt = AttitudeFilter([0.0, 0.0, 0.0, 1.0], np.zeros(3), AttitudeFilterConfig(
        np.eye(n) * 1e-6, 1e-6, 1e-9, bias_instability="estimate", scale_factor="estimate", gyro_misalignment="estimate",
        mounting="estimate", bias_instability_sigma=1e-6, bias_correlation_time=300.0))
    filt.predict(np.zeros((5, 3)), 0.01)
    q_IS, _ = filt.sensor_prediction(np.zeros(3))
    ref_I = rot.rotate(q_IS, np.array([[0.0, 0.0, 1.0], [0.1, 0.0, 1.0], [0.0, 0.1, 1.0]]) / np.sqrt([[1.0], [1.01], [1.01]]))
    obs_S = rot.rotate(rot.conjugate(q_IS), ref_I)
    filt.update_stars(ref_I, obs_S, isotropic_covariance(obs_S, 1e-5)).statistics()
    filt.update_attitude(q_IS, np.eye(3) * 1e-10).statistics()
    nees(filt.P[None, :6, :6], np.zeros((1, 6)))
