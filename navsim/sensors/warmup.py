"""The compile-ahead task of the inertial sensors (:mod:`startrack.compiled.compile_ahead`; the run kinds' ``lanes``)."""

import numpy as np

from navsim.sensors.gyro import GyroModel


def inertial_sensors():
    """Task: the noise synthesis of the inertial sensors (a second of a tactical gyro, every error on)."""
    GyroModel.preset("tactical", 100.0).measure(np.zeros((100, 3)), 0)
