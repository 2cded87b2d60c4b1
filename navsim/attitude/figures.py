"""The attitude run's and campaign's own figures (matplotlib, no pyplot: each function returns a Figure,
or None when the run did not log the quantity it draws): the attitude error and the gyro bias with the
filter's ±3σ, and the final errors across a campaign. Units at this edge: arcsec, deg/h."""

import numpy as np

from navsim.typeset.figures import AXES, COLORS, clip_to, new_figure
from startrack import units


def attitude_error(run):
    """Estimation error per body axis [arcsec] with the filter's ±3σ bounds."""
    s = run.series
    t, err = s["t"], units.rad_to_arcsec(s["attitude_error"])
    fig, axes = new_figure(4.2, 3, 1)
    for i, ax in enumerate(axes[:, 0]):
        ax.plot(t, err[:, i], color=COLORS[i], lw=0.8, label=f"error {AXES[i]}")
        if "P_diag" in s:
            bound = 3.0 * units.rad_to_arcsec(np.sqrt(s["P_diag"][:, i]))
            ax.plot(t, bound, "k--", lw=0.7, label="±3σ (filter)")
            ax.plot(t, -bound, "k--", lw=0.7)
            clip_to(ax, err[:, i], bound)
        ax.set_ylabel(f"δθ{AXES[i]} [arcsec]")
        ax.legend(loc="upper right", ncols=2)
    axes[-1, 0].set_xlabel("time [s]")
    return fig


def gyro_bias(run):
    """Gyro bias truth and estimate per axis [deg/h], with the estimate's ±3σ."""
    s = run.series
    if "bias_true" not in s or "bias_est" not in s:
        return None
    t = s["t"]
    true = units.rad_per_s_to_deg_per_h(s["bias_true"])
    est = units.rad_per_s_to_deg_per_h(s["bias_est"])
    fig, axes = new_figure(4.2, 3, 1)
    for i, ax in enumerate(axes[:, 0]):
        ax.plot(t, true[:, i], color="k", lw=1.0, label="truth")
        ax.plot(t, est[:, i], color=COLORS[i], lw=0.8, label="estimate")
        if "P_diag" in s:
            sig3 = 3.0 * units.rad_per_s_to_deg_per_h(np.sqrt(s["P_diag"][:, 3 + i]))
            ax.fill_between(t, est[:, i] - sig3, est[:, i] + sig3, color=COLORS[i], alpha=0.15, lw=0,
                            label="estimate ±3σ")
            span = np.concatenate([true[t.size // 10:, i], (est[:, i] - sig3)[t.size // 10:],
                                   (est[:, i] + sig3)[t.size // 10:]])
            lo, hi = float(span.min()), float(span.max())
            pad = 0.1 * max(hi - lo, 1e-6)
            ax.set_ylim(lo - pad, hi + pad)
        ax.set_ylabel(f"b{AXES[i]} [deg/h]")
        ax.legend(loc="upper right", ncols=3)
    axes[-1, 0].set_xlabel("time [s]")
    return fig


def final_error_histogram(env):
    """Final attitude error across runs per axis [arcsec], with the normal law of the filter's final σ."""
    fig, axes = new_figure(2.3, 1, 3, sharex=False)
    bins = int(np.clip(np.sqrt(env.runs) * 2, 5, 40))
    for i, ax in enumerate(axes[0]):
        x = env.final[:, i]
        ax.hist(x, bins=bins, density=True, color=COLORS[i], alpha=0.6, label="runs")
        if env.final_sigma_filter is not None:
            sig = env.final_sigma_filter[i]
            lim = max(4.0 * sig, float(np.abs(x).max()) * 1.05)
            grid = np.linspace(-lim, lim, 200)
            ax.plot(grid, np.exp(-0.5 * (grid / sig) ** 2) / (sig * np.sqrt(2 * np.pi)), "k", lw=0.8,
                    label="N(0, σ_filter²)")
        ax.set_xlabel(f"final δθ{AXES[i]} [arcsec]")
        ax.legend(loc="upper right", fontsize=6)
    axes[0, 0].set_ylabel("density")
    return fig
