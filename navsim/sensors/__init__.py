"""Sensor models: the gyro, faults acting on the sensors, and the star sensor at vector and image fidelity."""
