"""The figure of a fit: each axis's Allan deviation with its confidence band, the fitted curve and each resolved
term's asymptote (gyro in deg/h, accelerometer in µg)."""

import numpy as np

from navsim.inertial_log.noise_fit import TERMS
from navsim.inertial_log.reading import AXES
from startrack import units

_DISPLAY = {"gyro": (float(units.deg_per_h_to_rad_per_s(1.0)), "deg/h"),
            "accelerometer": (float(units.micro_g_to_si(1.0)), "µg")}
_LABELS = {"Q": "quantisation", "N": "white noise", "B": "bias instability", "K": "rate random walk", "R": "rate ramp"}


def write_plot(path, fits, title):
    """Draw ``fits`` ({axis: AxisFit}) into ``path`` (.pdf or .png)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    sensors = [(sensor, [a for a in names if a in fits]) for sensor, names in AXES.items()]
    sensors = [(sensor, axes) for sensor, axes in sensors if axes]
    figure, panels = pyplot.subplots(len(sensors), 3, figsize=(13, 4 * len(sensors)), squeeze=False)
    for row, (sensor, axes) in zip(panels, sensors):
        size, unit = _DISPLAY[sensor]
        for panel, name in zip(row, axes):
            _panel(panel, fits[name], name, size, unit)
        for panel in row[len(axes):]:
            panel.set_visible(False)
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path)
    pyplot.close(figure)


def _panel(panel, axis, name, size, unit):
    tau = axis.tau
    dense = np.geomspace(tau[0], tau[-1], 200)
    panel.fill_between(tau, axis.low / size, axis.high / size, color="C0", alpha=0.25, label="95 % interval")
    panel.loglog(tau, axis.adev / size, "o", color="C0", markersize=3, label="Allan deviation")
    panel.loglog(dense, np.sqrt(axis.fit.avar(dense)) / size, "-", color="k", label="fit")
    terms = axis.fit.term_avar(dense)
    for k, term in enumerate(TERMS):
        if axis.fit.terms[term].resolved:
            panel.loglog(dense, np.sqrt(terms[:, k]) / size, "--", linewidth=1, label=_LABELS[term])
    panel.set_ylim(0.3 * np.min(axis.low) / size, 3.0 * np.max(axis.high) / size)
    panel.set_xlabel("τ [s]")
    panel.set_ylabel(f"σ(τ) [{unit}]")
    panel.set_title(name)
    panel.grid(True, which="both", alpha=0.3)
    panel.legend(fontsize=7)
