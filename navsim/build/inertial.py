"""The inertial sensors of a scenario's datasheet tables (``gyro``, ``imu.gyro``, ``imu.accelerometer``:
:mod:`navsim.scenario.inertial_fields`) in SI units: a preset, if named, with every given field
overriding it."""

from navsim.sensors.accelerometer import AccelerometerModel
from navsim.sensors.gyro import GyroModel, bias_instability_to_sigma
from startrack import units


def gyro_model(table, rate_hz):
    """The gyro of a scenario table (``gyro``, ``imu.gyro``) at ``rate_hz``: a preset (if named) with any
    given datasheet field (:data:`~navsim.scenario.inertial_fields.GYRO_ERRORS`) overriding it."""
    base = GyroModel.preset(table["preset"], rate_hz) if table.get("preset") else GyroModel(rate_hz=rate_hz)
    fields = {
        "arw_deg_per_sqrt_h": ("arw", units.arw_to_si),
        "rrw_deg_per_h_per_sqrt_h": ("rrw", units.rrw_to_si),
        "bias_turn_on_deg_per_h": ("bias_turn_on_sigma", units.deg_per_h_to_rad_per_s),
        "bias_fixed_deg_per_h": ("bias_turn_on", lambda v: tuple(float(x) for x in units.deg_per_h_to_rad_per_s(v))),
        "bias_instability_deg_per_h": ("bias_instability_sigma", _bias_instability),
        "bias_correlation_s": ("bias_correlation_time", float),
        "scale_factor_ppm": ("scale_factor_sigma", lambda v: v * 1e-6),
        "misalignment_arcsec": ("misalignment_sigma", units.arcsec_to_rad),
        "quantization_arcsec": ("quantization", units.arcsec_to_rad),
        "saturation_deg_per_s": ("saturation", units.deg_to_rad),
    }
    return GyroModel(**{**base.__dict__, **_changes(table, fields)})


def accelerometer_model(table, rate_hz):
    """The accelerometer of ``imu.accelerometer`` at ``rate_hz``: a preset (if named) with any given
    datasheet field (:data:`~navsim.scenario.inertial_fields.ACCELEROMETER_ERRORS`) overriding it."""
    base = AccelerometerModel.preset(table["preset"], rate_hz) if table.get("preset") else AccelerometerModel(rate_hz=rate_hz)
    fields = {
        "vrw_m_per_s_per_sqrt_h": ("vrw", units.vrw_to_si),
        "bias_rw_micro_g_per_sqrt_h": ("bias_rw", units.micro_g_per_sqrt_h_to_si),
        "bias_turn_on_micro_g": ("bias_turn_on_sigma", units.micro_g_to_si),
        "bias_fixed_micro_g": ("bias_turn_on", lambda v: tuple(float(x) for x in units.micro_g_to_si(v))),
        "bias_instability_micro_g": ("bias_instability_sigma", lambda v: bias_instability_to_sigma(units.micro_g_to_si(v))),
        "bias_correlation_s": ("bias_correlation_time", float),
        "scale_factor_ppm": ("scale_factor_sigma", lambda v: v * units.PPM),
        "misalignment_arcsec": ("misalignment_sigma", units.arcsec_to_rad),
        "quantization_m_per_s": ("quantization", float),
        "saturation_m_per_s2": ("saturation", float),
    }
    return AccelerometerModel(**{**base.__dict__, **_changes(table, fields)})


def _changes(table, fields):
    """{model field: SI value} of the datasheet keys ``table`` gives (``fields``: key -> (model field, conversion))."""
    out = {}
    for key, (name, convert) in fields.items():
        if table.get(key) is not None:
            value = convert(table[key])
            out[name] = value if isinstance(value, tuple) else float(value)
    return out


def _bias_instability(deg_per_h):
    return bias_instability_to_sigma(units.deg_per_h_to_rad_per_s(deg_per_h))
