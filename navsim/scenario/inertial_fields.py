"""Scenario keys shared by the attitude and navigation schemas: the inertial sensors' datasheet fields
(units in the key names) and the physical bounds on them, far beyond any real vehicle or sensor."""

from navsim.scenario.schema import Value

#: Upper bounds: rates [deg/s], angle errors [arcsec], gyro noise [deg/√h, deg/h/√h] and bias [deg/h].
MAX_RATE, MAX_ARCSEC, MAX_ARW, MAX_RRW, MAX_BIAS = 1e4, 36000.0, 1e3, 1e4, 1e6
#: Upper bounds of the accelerometer: bias [µg], bias random walk [µg/√h], VRW [m/s/√h], specific force [m/s²].
MAX_MICRO_G, MAX_MICRO_G_PER_SQRT_H, MAX_VRW, MAX_FORCE = 1e6, 1e6, 1e3, 1e4

#: The inertial sensors' preset grades (their tables: ``navsim.sensors.gyro.PRESETS`` and the accelerometer's).
PRESETS = ("navigation", "tactical", "mems")

#: The gyro's datasheet errors beside its preset (None: the preset's value, or 0 without a preset).
GYRO_ERRORS = {
    "preset": Value("str", default=None, choices=PRESETS),
    "arw_deg_per_sqrt_h": Value("float", default=None, minimum=0.0, maximum=MAX_ARW),
    "rrw_deg_per_h_per_sqrt_h": Value("float", default=None, minimum=0.0, maximum=MAX_RRW),
    "bias_turn_on_deg_per_h": Value("float", default=None, minimum=0.0, maximum=MAX_BIAS),
    "bias_fixed_deg_per_h": Value("vector", default=None, minimum=-MAX_BIAS, maximum=MAX_BIAS,
                                  doc="the turn-on bias per axis, fixed instead of drawn with bias_turn_on_deg_per_h "
                                      "(PSINS imuerrset's eb)"),
    "bias_instability_deg_per_h": Value("float", default=None, minimum=0.0, maximum=MAX_BIAS),
    "bias_correlation_s": Value("float", default=None, exclusive_minimum=0.0, maximum=1e9),
    "scale_factor_ppm": Value("float", default=None, minimum=0.0, maximum=1e5),
    "misalignment_arcsec": Value("float", default=None, minimum=0.0, maximum=MAX_ARCSEC),
    "quantization_arcsec": Value("float", default=None, minimum=0.0, maximum=MAX_ARCSEC),
    "saturation_deg_per_s": Value("float", default=None, exclusive_minimum=0.0, maximum=MAX_RATE),
}

#: The accelerometer's datasheet errors beside its preset, the twin of :data:`GYRO_ERRORS`.
ACCELEROMETER_ERRORS = {
    "preset": Value("str", default=None, choices=PRESETS),
    "vrw_m_per_s_per_sqrt_h": Value("float", default=None, minimum=0.0, maximum=MAX_VRW),
    "bias_rw_micro_g_per_sqrt_h": Value("float", default=None, minimum=0.0, maximum=MAX_MICRO_G_PER_SQRT_H),
    "bias_turn_on_micro_g": Value("float", default=None, minimum=0.0, maximum=MAX_MICRO_G),
    "bias_fixed_micro_g": Value("vector", default=None, minimum=-MAX_MICRO_G, maximum=MAX_MICRO_G,
                                doc="the turn-on bias per axis, fixed instead of drawn with bias_turn_on_micro_g "
                                    "(PSINS imuerrset's db)"),
    "bias_instability_micro_g": Value("float", default=None, minimum=0.0, maximum=MAX_MICRO_G),
    "bias_correlation_s": Value("float", default=None, exclusive_minimum=0.0, maximum=1e9),
    "scale_factor_ppm": Value("float", default=None, minimum=0.0, maximum=1e5),
    "misalignment_arcsec": Value("float", default=None, minimum=0.0, maximum=MAX_ARCSEC),
    "quantization_m_per_s": Value("float", default=None, minimum=0.0, maximum=1e3),
    "saturation_m_per_s2": Value("float", default=None, exclusive_minimum=0.0, maximum=MAX_FORCE),
}
