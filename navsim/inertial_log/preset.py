"""The fitted terms as a scenario's ``[imu]`` datasheet block and as the fit's JSON summary.

The keys are the scenarios' own (:mod:`navsim.scenario.inertial_fields`), read back by :mod:`navsim.build.inertial`
into the models of :mod:`navsim.sensors.inertial`, so that each means what the fit found:

- white noise N: σ_v of the model (σ² = N²/τ), ``arw_deg_per_sqrt_h`` / ``vrw_m_per_s_per_sqrt_h``;
- rate random walk K: σ_u of the model (σ² = K² τ/3), ``rrw_deg_per_h_per_sqrt_h`` / ``bias_rw_micro_g_per_sqrt_h``;
- quantisation Q: the model rounds the summed increments to an LSB S, whose error (uniform, S²/12) gives
  σ² = 3 (S²/12)/τ² (IEEE 952 annex C: Q = S/√12), so S = √12 Q: ``quantization_arcsec`` / ``quantization_m_per_s``;
- bias instability B: the model's first-order Gauss-Markov bias of steady σ_g and correlation time T, whose Allan
  deviation peaks at 0.6174 σ_g at τ = 1.893 T (the maximum of :func:`navsim.sensors.inertial.allan_variance`;
  IEEE 952 annex C), is set to the flicker floor 0.664 B (``bias_instability_deg_per_h`` / ``_micro_g`` is B:
  :func:`navsim.sensors.inertial.bias_instability_to_sigma`), the peak at the cluster time where the fitted curve
  is lowest, T = τ_min / 1.893 (``bias_correlation_s``; the flat bottom of the curve is where B shows);
- the rate ramp R, which the models lack, is reported in the summary and the block's comments only.

Each sensor's figure is its worst axis (a datasheet's one number per sensor); the axes' own are in the summary. A
term no axis resolves is 0 in the block (switched off), its largest upper bound in a comment. A static log cannot
tell a turn-on bias, scale factor or misalignment: the block leaves them at 0.
"""

import numpy as np

from navsim.inertial_log.axis_fit import CONFIDENCE
from navsim.inertial_log.reading import AXES
from navsim.scenario.inertial_fields import ACCELEROMETER_ERRORS, GYRO_ERRORS
from startrack import units

FORMAT = "navsim.imu-fit/1"
#: τ of the Gauss-Markov Allan peak in correlation times (the maximum of [2(r − 1 + e^(−r)) − (1 − e^(−r))²]/r²).
GAUSS_MARKOV_PEAK_TAU = 1.8926
_SQRT12 = np.sqrt(12.0)

#: Per sensor: {term: (its key, the SI size of one of the key's units, that unit)}; the ramp's key is the summary's only.
KEYS = {
    "gyro": {
        "Q": ("quantization_arcsec", units.ARCSEC / _SQRT12, "arcsec (LSB)"),
        "N": ("arw_deg_per_sqrt_h", float(units.arw_to_si(1.0)), "deg/√h"),
        "B": ("bias_instability_deg_per_h", float(units.deg_per_h_to_rad_per_s(1.0)), "deg/h"),
        "K": ("rrw_deg_per_h_per_sqrt_h", float(units.rrw_to_si(1.0)), "deg/h/√h"),
        "R": ("rate_ramp_deg_per_h_per_h", units.DEG / units.HOUR**2, "deg/h/h"),
    },
    "accelerometer": {
        "Q": ("quantization_m_per_s", 1.0 / _SQRT12, "m/s (LSB)"),
        "N": ("vrw_m_per_s_per_sqrt_h", float(units.vrw_to_si(1.0)), "m/s/√h"),
        "B": ("bias_instability_micro_g", float(units.micro_g_to_si(1.0)), "µg"),
        "K": ("bias_rw_micro_g_per_sqrt_h", float(units.micro_g_per_sqrt_h_to_si(1.0)), "µg/√h"),
        "R": ("rate_ramp_micro_g_per_h", float(units.micro_g_to_si(1.0)) / units.HOUR, "µg/h"),
    },
}
_SCHEMA = {"gyro": GYRO_ERRORS, "accelerometer": ACCELEROMETER_ERRORS}


def sensor_figures(fits):
    """{sensor: {term: {"value", "sigma", "upper_bound", "axis", "key", "unit"}}} in the keys' units: the worst axis
    of each sensor in ``fits`` ({axis: AxisFit}); with ``bias_correlation_s`` when B is resolved."""
    out = {}
    for sensor, names in AXES.items():
        present = [name for name in names if name in fits]
        if not present:
            continue
        figures = {}
        for term, (key, size, unit) in KEYS[sensor].items():
            resolved = [(fits[a].fit.terms[term].value / size, fits[a].fit.terms[term].sigma / size, a)
                        for a in present if fits[a].fit.terms[term].resolved]
            bounds = [fits[a].fit.terms[term].upper_bound / size for a in present if not fits[a].fit.terms[term].resolved]
            value, sigma, axis = max(resolved) if resolved else (None, None, None)
            figures[term] = {"key": key, "unit": unit, "value": value, "sigma": _finite(sigma), "axis": axis,
                             "upper_bound": _finite(max(bounds)) if bounds and not resolved else None}
        if figures["B"]["value"] is not None:
            axis = fits[figures["B"]["axis"]]
            tau_min = axis.tau[int(np.argmin(axis.fit.avar(axis.tau)))]
            figures["bias_correlation_s"] = float(tau_min / GAUSS_MARKOV_PEAK_TAU)
        out[sensor] = figures
    return out


def imu_block(figures, rate_hz, source):
    """The TOML text of the ``[imu]`` block of ``figures`` (:func:`sensor_figures`) at ``rate_hz``, from ``source``."""
    lines = [f"# navsim imu fit of {source}: the worst axis of each sensor (a datasheet's figure); terms the log",
             "# does not resolve are 0 with their upper bound beside; a static log cannot tell the turn-on bias,",
             "# scale factor or misalignment (left at 0).", "[imu]", f"rate_hz = {rate_hz:.6g}"]
    for sensor, terms in figures.items():
        fields, notes = [], []
        for term in ("N", "K", "B", "Q"):
            figure = terms[term]
            fields.append(f"{figure['key']} = {_number(figure['value'] or 0.0)}")
            if figure["value"] is None:
                notes.append(f"{figure['key']} < {_number(figure['upper_bound'])} (not resolved)")
            else:
                notes.append(f"{figure['key']} ± {_number(figure['sigma'])} (1σ, axis {figure['axis']})")
        if "bias_correlation_s" in terms:
            fields.append(f"bias_correlation_s = {_number(terms['bias_correlation_s'])}")
        ramp = terms["R"]
        notes.append(f"rate ramp {'< ' + _number(ramp['upper_bound']) if ramp['value'] is None else _number(ramp['value'])} "
                     f"{ramp['unit']} (the models have no ramp: not in the block)")
        for key, value in (f.split(" = ") for f in fields):
            _SCHEMA[sensor][key].check(f"imu.{sensor}.{key}", float(value))
        lines += [f"# {sensor}: {note}" for note in notes]
        lines.append(f"{sensor} = {{ {', '.join(fields)} }}")
    return "\n".join(lines) + "\n"


def _number(value):
    return f"{value:.4g}" if value is not None else "inf"


def _finite(value):
    """``value``, or None when it is not a finite number (a bound the log cannot set: strict JSON has no inf)."""
    return value if value is not None and np.isfinite(value) else None


def summary(log, fits, figures, source, block):
    """The JSON summary (``FORMAT``): the log, each axis's curve, interval, EDF and terms (SI), the sensors'
    figures (the keys' units) and the block."""
    axes = {}
    for name, axis in fits.items():
        axes[name] = {
            "tau_s": axis.tau.tolist(), "adev": axis.adev.tolist(), "adev_low": axis.low.tolist(),
            "adev_high": axis.high.tolist(), "dof": axis.fit.dof.tolist(), "fit_adev": np.sqrt(axis.fit.avar(axis.tau)).tolist(),
            "chi_square": axis.fit.chi_square, "fit_dof": axis.fit.fit_dof,
            "terms_si": {term: {"value": t.value, "sigma": _finite(t.sigma), "upper_bound": _finite(t.upper_bound)}
                         for term, t in axis.fit.terms.items()},
        }
    return {"format": FORMAT, "log": {"source": str(source), "rate_hz": log.rate_hz, "samples": log.samples,
                                      "duration_s": log.samples / log.rate_hz},
            "confidence": CONFIDENCE, "axes": axes, "sensors": figures, "imu_block": block}
