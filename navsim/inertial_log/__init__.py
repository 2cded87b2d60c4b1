"""Inertial sensors from recorded logs: a static IMU log read into SI rates (``reading``), its overlapping Allan
deviation and chi-square interval (``allan``), the covariance of those estimates for a noise model
(``estimate_covariance``), the IEEE 952 noise fit (``noise_fit``), each axis through them (``axis_fit``), the
scenario's ``[imu]`` block and the JSON summary (``preset``) and the figure (``plot``); ``navsim imu fit`` is
:mod:`navsim.imu_command`."""
