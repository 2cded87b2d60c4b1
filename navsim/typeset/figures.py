"""Report figures every kind of run shares (matplotlib, no pyplot: each function returns a Figure, or
None when the run did not log the quantity it draws): the style, NEES and NIS with their bands, error
envelopes across a campaign, and the image-fidelity star sensor's modes, stars, identification times,
boresight track and a rendered frame. Units at this edge: arcsec, degrees, milliseconds.
"""

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from navsim.estimation.consistency import chi2_band
from navsim.estimation.intervals import interval_text
from navsim.typeset import statistics as stats
from startrack import address

WIDTH_IN = 6.5
AXES = "xyz"
COLORS = ("tab:blue", "tab:orange", "tab:green")
STYLE = {
    "font.size": 8,
    "axes.titlesize": 8,
    "axes.labelsize": 8,
    "legend.fontsize": 7,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "svg.hashsalt": "navsim-report",
}


def new_figure(height_in, rows=1, cols=1, sharex=True):
    fig = Figure(figsize=(WIDTH_IN, height_in), layout="constrained")
    axes = fig.subplots(rows, cols, sharex=sharex, squeeze=False)
    return fig, axes


def log_y(ax):
    """Log y axis labelled at 1, 2 and 5 times the powers of ten only."""
    ax.set_yscale("log")
    ax.yaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
    ax.yaxis.set_minor_formatter(NullFormatter())


def save(fig, path):
    """Write ``fig`` as SVG (text as paths, no date, fixed ids: the same data gives the same bytes)."""
    fig.savefig(path, format="svg", metadata={"Date": None})


# ------------------------------------------------------------------------------- one run


def clip_to(ax, *curves):
    """Symmetric y axis scaled to the steady part: the largest |value| of the curves after 10 % of the run."""
    finite = np.concatenate([np.abs(c[c.size // 10:]) for c in curves])
    finite = finite[np.isfinite(finite)]
    if finite.size:
        lim = 1.15 * float(finite.max())
        if lim > 0:
            ax.set_ylim(-lim, lim)


def consistency(run):
    """NEES (attitude and bias, 6 dof) and NIS per degree of freedom with their 95 % chi-square bands."""
    s = run.series
    has_nees, has_nis = "nees" in s, "nis" in s and "nis_dof" in s
    if not (has_nees or has_nis):
        return None
    fig, axes = new_figure(3.6, has_nees + has_nis, 1)
    t = s["t"]
    row = 0
    if has_nees:
        ax = axes[row, 0]
        dof = int(run.summary["nees"]["dof"])
        lo, hi = chi2_band(dof)
        ax.plot(t, s["nees"], lw=0.7, color="tab:blue", label=f"NEES ({dof} dof)")
        log_y(ax)
        ax.axhline(dof, color="k", lw=0.8, label="expected")
        ax.axhspan(lo, hi, color="tab:green", alpha=0.15, label="95 % χ² band")
        ax.set_ylabel("NEES")
        ax.legend(loc="upper right", ncols=3)
        row += 1
    if has_nis:
        ax = axes[row, 0]
        dof = s["nis_dof"]
        ok = dof > 0
        ratio = np.full(t.size, np.nan)
        ratio[ok] = s["nis"][ok] / dof[ok]
        lo = np.full(t.size, np.nan)
        hi = np.full(t.size, np.nan)
        if ok.any():
            lo[ok], hi[ok] = chi2_band(dof[ok])
            lo[ok], hi[ok] = lo[ok] / dof[ok], hi[ok] / dof[ok]
        ax.plot(t, ratio, ".", ms=1.5, color="tab:purple", label="NIS / dof")
        log_y(ax)
        ax.fill_between(t, lo, hi, step="mid", color="tab:green", alpha=0.15, lw=0, label="95 % χ² band")
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_ylabel("NIS / dof")
        ax.legend(loc="upper right", ncols=2)
    axes[-1, 0].set_xlabel("time [s]")
    return fig


def mode_timeline(run):
    """Sensor mode against time, one row per mode."""
    s = run.series
    if "mode" not in s:
        return None
    names = stats.mode_names(run.summary, s["mode"])
    codes = sorted(names)
    fig, axes = new_figure(0.6 + 0.3 * len(codes))
    ax = axes[0, 0]
    cmap = [f"C{i % 10}" for i in range(len(codes))]
    for code, start, end in stats.mode_segments(s["t"], s["mode"]):
        row = codes.index(code)
        ax.broken_barh([(start, end - start)], (row - 0.4, 0.8), color=cmap[row])
    ax.set_yticks(range(len(codes)), [names[c] for c in codes])
    ax.set_ylim(-0.6, len(codes) - 0.4)
    ax.set_xlim(s["t"][0] - 0.5 * _period(s["t"]), s["t"][-1] + 0.5 * _period(s["t"]))
    ax.set_xlabel("time [s]")
    ax.grid(axis="y", visible=False)
    return fig


def _period(t):
    return float(np.median(np.diff(t))) if t.size > 1 else 1.0


def star_counts(run):
    """Stars per frame: detected, identified, stacked, and measurements offered/accepted by the filter."""
    s = run.series
    curves = [(k, label) for k, label in (
        ("n_detected", "detected"), ("n_identified", "identified"), ("n_stacked", "stacked (dim)"),
        ("n_measurements", "offered to the filter"), ("n_accepted", "accepted by the gate"),
    ) if k in s]
    if not curves:
        return None
    fig, axes = new_figure(2.4)
    ax = axes[0, 0]
    for i, (key, label) in enumerate(curves):
        ax.step(s["t"], s[key], where="mid", lw=0.8, color=f"C{i}", label=label,
                ls="--" if key == "n_accepted" else "-")
    ax.set_ylabel("stars per frame")
    ax.set_xlabel("time [s]")
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper right", ncols=3)
    return fig


def identification_time(run):
    """Distribution of the identification time [ms] in each mode (box: quartiles; whiskers: 5-95 %)."""
    s = run.series
    if "id_ms" not in s:
        return None
    ms = s["id_ms"]
    if "mode" in s:
        names = stats.mode_names(run.summary, s["mode"])
        groups = [(names[c], ms[(s["mode"] == c) & np.isfinite(ms)]) for c in sorted(names)]
    else:
        groups = [("all frames", ms[np.isfinite(ms)])]
    groups = [(name, v) for name, v in groups if v.size]
    if not groups:
        return None
    fig, axes = new_figure(2.4)
    ax = axes[0, 0]
    ax.boxplot([v for _, v in groups], tick_labels=[f"{n}\n({v.size} frames)" for n, v in groups],
               whis=(5, 95), showfliers=True, flierprops={"markersize": 2})
    ax.set_ylabel("identification time [ms]")
    if max(float(v.max()) for _, v in groups) > 20 * min(float(np.median(v)) for _, v in groups):
        log_y(ax)
    return fig


def boresight_track(run, n_d):
    """Boresight RA/Dec over the base-point grid (eq. 1-2 of 000), with the addresses (eq. 7-8) used.

    Without a known ``n_d`` the track is drawn alone. The sub-catalogs used are the logged flat
    indices, else the logged addresses, else eq. 7-8 applied to the logged boresight.
    """
    s = run.series
    if "boresight_radec" not in s:
        return None
    ra_b, dec_b = np.degrees(s["boresight_radec"][:, 0]), np.degrees(s["boresight_radec"][:, 1])
    fig, axes = new_figure(3.4, 1, 2, sharex=False)
    overview, zoom = axes[0]
    # Zoom: RA unwrapped about the track's circular mean so a track across RA = 0 stays in one piece.
    centre = np.degrees(np.angle(np.mean(np.exp(1j * np.radians(ra_b)))))

    def unwrap(ra):
        return centre + (ra - centre + 180.0) % 360.0 - 180.0

    ra_t = unwrap(ra_b)
    pad = max(5.0, 0.15 * max(np.ptp(ra_t), np.ptp(dec_b)))
    box = (ra_t.min() - pad, ra_t.max() + pad, max(dec_b.min() - pad, -90.0), min(dec_b.max() + pad, 90.0))
    title = "whole sky"
    if n_d is not None:
        ra_g, dec_g = (np.degrees(a) for a in address.base_points_radec(n_d))
        overview.scatter(ra_g, dec_g, s=0.3, color="0.6", lw=0)
        title += f", n_d = {n_d} ({address.base_point_count(n_d)} base points)"
        ra_gz = unwrap(ra_g)
        near = (ra_gz >= box[0]) & (ra_gz <= box[1]) & (dec_g >= box[2]) & (dec_g <= box[3])
        zoom.scatter(ra_gz[near], dec_g[near], s=4, color="0.6", lw=0, label="base points")
        used = np.unique(stats.sub_catalog_indices(s, n_d))
        zoom.scatter(ra_gz[used], dec_g[used], s=14, facecolor="none", edgecolor="tab:blue", lw=0.8,
                     label=f"sub-catalogs used ({used.size})")
        if used.size <= 40:
            l_d, l_ra = address.address_of_index(used, n_d)
            for x, y, a, b in zip(ra_gz[used], dec_g[used], l_d, l_ra):
                zoom.annotate(f"({a},{b})", (x, y), xytext=(3, 3), textcoords="offset points", fontsize=5,
                              color="tab:blue")
    overview.plot(ra_b, dec_b, ".", ms=1.5, color="tab:red")
    overview.set(xlim=(360, 0), ylim=(-90, 90), xlabel="RA [deg]", ylabel="Dec [deg]", title=title)
    zoom.plot(ra_t, dec_b, "-", lw=0.8, color="tab:red", label="boresight")
    zoom.set(xlim=(box[1], box[0]), ylim=(box[2], box[3]), xlabel="RA [deg]", ylabel="Dec [deg]",
             title="track" + (", with addresses (l_d, l_ra)" if n_d is not None else ""))
    zoom.legend(loc="lower left", fontsize=6)
    return fig


def rendered_frame(run):
    """The rendered frame (asinh stretch) with the detections; identified stars are labelled HIP n."""
    if run.frame is None:
        return None
    img = np.asarray(run.frame, dtype=float)
    h, w = img.shape
    fig = Figure(figsize=(WIDTH_IN, WIDTH_IN * min(h / w, 1.2) * 0.85), layout="constrained")
    ax = fig.subplots()
    low, high = np.percentile(img, [50, 99.95])
    stretched = np.arcsinh(np.clip(img - low, 0, None) / max(high - low, 1e-12) * 20.0)
    # Pixel centres at integer (u, v), origin at the top-left pixel (docs/design.md image coordinates).
    ax.imshow(stretched, cmap="gray", origin="upper", extent=(-0.5, w - 0.5, h - 0.5, -0.5),
              interpolation="nearest")
    ax.grid(False)
    radius = max(w, h) / 80.0
    for u, v, hip in run.detections or []:
        color = "tab:green" if hip is not None else "tab:red"
        ax.add_patch(Circle((u, v), radius, fill=False, color=color, lw=0.8))
        if hip is not None:
            ax.annotate(f"HIP {hip}", (u, v), xytext=(radius + 2, -radius - 2), textcoords="offset points",
                        color=color, fontsize=6)
    ax.set(xlabel="u [px]", ylabel="v [px]", xlim=(-0.5, w - 0.5), ylim=(h - 0.5, -0.5))
    return fig


# ----------------------------------------------------------------------------- campaigns


def error_envelopes(env, labels=tuple(f"δθ{axis} [arcsec]" for axis in AXES), xlabel="time [s]", t_scale=1.0):
    """Across-run mean ± σ and 5-95 % envelope of the error per axis (``labels``), with the filter's
    average ±3σ; time divided by ``t_scale`` for the x axis."""
    fig, axes = new_figure(4.6, 3, 1)
    t = env.t / t_scale
    for i, ax in enumerate(axes[:, 0]):
        ax.fill_between(t, env.p05[:, i], env.p95[:, i], color=COLORS[i], alpha=0.15, lw=0, label="5-95 %")
        ax.fill_between(t, env.mean[:, i] - env.std[:, i], env.mean[:, i] + env.std[:, i], color=COLORS[i],
                        alpha=0.35, lw=0, label="mean ± σ")
        ax.plot(t, env.mean[:, i], color=COLORS[i], lw=0.8, label="mean")
        ax.plot(t, env.rms[:, i], color="k", lw=0.7, ls=":", label="RMS across runs")
        bound = env.sigma3_filter[:, i] if env.sigma3_filter is not None else np.abs(env.p95[:, i])
        if env.sigma3_filter is not None:
            ax.plot(t, env.sigma3_filter[:, i], "k--", lw=0.7, label="filter ±3σ (mean P)")
            ax.plot(t, -env.sigma3_filter[:, i], "k--", lw=0.7)
        clip_to(ax, env.p05[:, i], env.p95[:, i], bound)
        ax.set_ylabel(labels[i])
        ax.legend(loc="upper right", ncols=5)
    axes[0, 0].set_title(f"{env.runs} runs")
    axes[-1, 0].set_xlabel(xlabel)
    return fig


def nees_band(avg):
    """NEES averaged over M runs with the chi-square band of M runs, and its mean after the settling time with
    the 95 % interval of that mean (unbounded for one run: said in the legend)."""
    fig, axes = new_figure(2.4)
    ax = axes[0, 0]
    ax.plot(avg.t, avg.mean, lw=0.8, color="tab:blue", label=f"NEES averaged over {avg.runs} runs")
    log_y(ax)
    ax.axhline(avg.dof, color="k", lw=0.8, label=f"expected ({avg.dof})")
    ax.axhspan(*avg.band, color="tab:green", alpha=0.2, label=f"95 % band for {avg.runs} runs")
    lo, hi = avg.mean_interval
    steady, mean = avg.t[avg.t >= avg.settle_s], avg.mean_after_settle
    label = f"mean {mean:.2f}, 95 % interval {interval_text(avg.mean_interval)}"
    ax.plot(steady[[0, -1]], [mean, mean], color="tab:purple", lw=0.8, ls="--", label=label)
    if lo > 0.0 and hi is not None:  # a log axis: an interval from 0 is in the legend only
        ax.errorbar(steady[0], mean, yerr=[[mean - lo], [hi - mean]], color="tab:purple", capsize=3, lw=0.9)
    if avg.settle_s > avg.t[0]:
        ax.axvline(avg.settle_s, color="0.4", lw=0.7, ls=":", label="settle time")
    ax.set(xlabel="time [s]", ylabel="average NEES")
    ax.legend(loc="upper right", ncols=2)
    return fig


def identification_success(rows, criterion):
    """Pooled fraction of identified frames per mode (None for fewer than two modes: the table says it all)."""
    if len(rows) < 2:
        return None
    fig, axes = new_figure(2.2)
    ax = axes[0, 0]
    fractions = [100.0 * r.fraction for r in rows]
    bars = ax.bar(range(len(rows)), fractions, color=[f"C{i % 10}" for i in range(len(rows))])
    ax.set_xticks(range(len(rows)), [r.name for r in rows])
    for bar, r in zip(bars, rows):
        ax.annotate(f"{r.identified}/{r.frames}", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                    xytext=(0, 2), textcoords="offset points", ha="center", fontsize=6)
    ax.set(ylim=(0, 110), ylabel="success [%]", title=criterion)
    return fig
