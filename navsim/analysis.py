"""The result of a linear covariance analysis, whatever the run kind (:mod:`navsim.estimation.lincov`; each kind's
``covariance_analysis`` builds it): the true RMS of the summary quantities and of every error state over time
beside the filter's own σ, each error source's share (the budget), the comparison with Monte Carlo runs of the
same scenario and the metric of a sweep point.

A kind describes its summary quantities as :class:`Quantity` (a unit and the rows that take the leading block of
the error state to the quantity's components at each kept frame, SI) and its states' edge units; the mean
square of a quantity is tr(J P Jᵀ) + |J m|², m the mean error of the fixed truth errors.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from navsim.estimation.consistency import mean_square_band
from startrack import InputError

#: The format of a covariance analysis's ``summary.json`` and of a covariance budget's ``budget.json``.
SUMMARY_FORMAT = "navsim.covariance-summary/1"
BUDGET_FORMAT = "navsim.covariance-budget/1"
#: How many times along the run a comparison with Monte Carlo checks.
COMPARE_TIMES = 10
#: The linearisation's allowance in a comparison with runs, as a fraction of the filter's own σ: an RMS of the runs
#: within this much of its sampling band agrees. The analysis propagates along the nominal on the coarsened grid and
#: leaves out the second-order terms of the errors, which the runs' filter has, and the refraction correction's
#: dependence on the INS's own vertical (the processing refracts about it: ∂ΔZ/∂(vertical) = A sec²Z, 1e-4 to 6e-4
#: of the position coupling, left out of the filter's H). Measured where the runs have no spread, a fixed deflection
#: and an uncorrected aberration alone: up to 2e-3 of the filter's σ without refraction, 1.1e-2 and 2.2e-2 with it
#: near the zeros of the Schuler velocity (tests/navsim/test_sins_cns_report.py). Three hundredths of σ are half the
#: sampling noise of a 500-run RMS at the filter's σ (±6 % at 95 %).
LINEARISATION = 3e-2
#: Relative tolerance of a common frame time of the runs and the analysis.
TIME_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Quantity:
    """A summary quantity: its edge ``unit``, that unit's ``size`` in SI, and ``rows`` (K, r, B) that take the
    leading B x B block of the error state to its r components at each kept frame [SI]."""

    unit: str
    size: float
    rows: np.ndarray


@dataclass(frozen=True)
class Analysis:
    """The result of a pass: at the kept frames ``t`` (K,) [s], per source of ``sources`` (one, "total", unless
    split) the mean error ``mean`` (S, K, n_t), the diagonal of its covariance in the truth's (``diag_t``) and the
    filter's coordinates (``diag_f`` (S, K, n_f), T P Tᵀ) and its leading B x B ``block`` (S, K, B, B); the
    filter's own ``filter_diag`` (K, n_f) and ``filter_block``; its expected NEES over its first ``nees_dof``
    states (K,); the truth's and the filter's state names with each state's edge unit and its SI size at each
    kept frame (``units_t``, ``scale_t`` (K, n_t); ``units_f``, ``scale_f``); the summary ``quantities``
    ({name: :class:`Quantity`}); ``run_errors`` the kind's function of a run series -> ({quantity: (F, r)},
    errors (F, m) of the filter's first m states) [SI]; ``notes``."""

    t: np.ndarray
    sources: tuple
    truth_names: tuple
    filter_names: tuple
    mean: np.ndarray
    diag_t: np.ndarray
    diag_f: np.ndarray
    block: np.ndarray
    filter_diag: np.ndarray
    filter_block: np.ndarray
    nees: np.ndarray
    nees_dof: int
    T: np.ndarray
    quantities: dict
    units_t: tuple
    scale_t: np.ndarray
    units_f: tuple
    scale_f: np.ndarray
    run_errors: object
    notes: tuple
    wall_seconds: float

    def _projected_mean(self, q):
        """(S, K, r) each source's mean error in the components of quantity ``q``."""
        B = q.rows.shape[2]
        return np.einsum("kri,ski->skr", q.rows, self.mean[:, :, :B])

    def _variance(self, q):
        """tr(J P_s Jᵀ) (S, K) [SI²]; a zero one propagated through the turns of the wander-azimuth frame can come out a
        rounding below zero (−2e-31 seen against 5e-8), held at zero."""
        return np.maximum(np.einsum("kri,skij,krj->sk", q.rows, self.block, q.rows), 0.0)

    def mean_square(self):
        """{quantity: (S, K)} each source's share of the true mean square [SI²]: tr(J P_s Jᵀ) + (J m_s)·(J m),
        m the total mean; the shares add up to the total exactly."""
        out = {}
        for name, q in self.quantities.items():
            projected = self._projected_mean(q)
            out[name] = self._variance(q) + np.einsum("skr,kr->sk", projected, projected.sum(axis=0))
        return out

    def alone_mean_square(self):
        """{quantity: (S, K)} the true mean square each source leaves alone, tr(J P_s Jᵀ) + |J m_s|² [SI²]: what a
        run with only that source in its truth averages to (``navsim budget --method montecarlo``'s parts)."""
        return {name: self._variance(q) + np.sum(self._projected_mean(q) ** 2, axis=2) for name, q in self.quantities.items()}

    def only(self, source):
        """The analysis of ``source`` alone (one of ``sources``): what runs with only that source in their truth,
        under the same filter, give (a part of ``navsim budget --method montecarlo``)."""
        i = self.sources.index(source)
        one = slice(i, i + 1)
        return dataclasses.replace(self, sources=(source,), mean=self.mean[one], diag_t=self.diag_t[one],
                                   diag_f=self.diag_f[one], block=self.block[one])

    def filter_variance(self):
        """{quantity: (K,)} the filter's own variance of each summary quantity [SI²]."""
        return {name: np.einsum("kri,kij,krj->k", q.rows, self.filter_block, q.rows) for name, q in self.quantities.items()}

    def series(self):
        """The arrays of ``timeseries.npz`` (:func:`series`)."""
        return series(self)

    def summary(self, scenario):
        """The content of ``summary.json`` (:func:`summary`)."""
        return summary(self, scenario)

    def compare(self, runs):
        """The analysis against Monte Carlo run series (:func:`compare`)."""
        return compare(self, runs)


def series(analysis):
    """The arrays of ``timeseries.npz`` (edge units): ``t``; per summary quantity its true RMS ``<q>_rms``, its mean
    error's size ``<q>_mean`` and the filter's σ ``<q>_sigma_filter``; the filter's states (``state_names``,
    ``state_units``): true RMS ``state_rms``, mean ``state_mean``, filter σ ``state_sigma``; the truth's
    (``truth_state_names``, ``truth_state_units``): ``truth_state_rms``, ``truth_state_mean``; ``nees_expected``;
    with the sources apart, ``sources`` and each quantity's share of the mean square ``<q>_share`` (S, K) [unit²]."""
    a = analysis
    total_mean = a.mean.sum(axis=0)
    ms, fv = a.mean_square(), a.filter_variance()
    out = {"t": a.t, "nees_expected": a.nees, "state_names": np.array(a.filter_names), "state_units": np.array(a.units_f),
           "truth_state_names": np.array(a.truth_names), "truth_state_units": np.array(a.units_t),
           "sources": np.array(a.sources)}
    for name, q in a.quantities.items():
        out[f"{name}_rms"] = np.sqrt(np.maximum(ms[name].sum(axis=0), 0.0)) / q.size
        out[f"{name}_mean"] = np.linalg.norm(a._projected_mean(q).sum(axis=0), axis=1) / q.size
        out[f"{name}_sigma_filter"] = np.sqrt(fv[name]) / q.size
        if len(a.sources) > 1:
            out[f"{name}_share"] = ms[name] / q.size**2
    mean_f = total_mean @ a.T.T
    out["state_rms"] = np.sqrt(a.diag_f.sum(axis=0) + mean_f**2) / a.scale_f
    out["state_mean"] = mean_f / a.scale_f
    out["state_sigma"] = np.sqrt(a.filter_diag) / a.scale_f
    out["truth_state_rms"] = np.sqrt(a.diag_t.sum(axis=0) + total_mean**2) / a.scale_t
    out["truth_state_mean"] = total_mean / a.scale_t
    return out


def _steady(t, scenario):
    steady = t >= scenario["settle_s"]
    return steady if steady.any() else np.ones_like(steady)


def summary(analysis, scenario):
    """The analysis's ``summary.json`` (:data:`SUMMARY_FORMAT`): per summary quantity its true RMS at the end
    (``final``), over the frames after ``settle_s`` (``rms``, √ of the mean square) and its largest (``max``), the
    mean error's size at the end and the filter's own σ at the end beside their ratio; per filter state at the end
    its true RMS, mean and the filter's σ; the filter's expected NEES after ``settle_s`` against its dof; with the
    sources apart each quantity's shares at the end and over the steady frames."""
    s = series(analysis)
    steady = _steady(s["t"], scenario)
    quantities = {}
    for name, q in analysis.quantities.items():
        rms, sigma = s[f"{name}_rms"], s[f"{name}_sigma_filter"]
        quantities[name] = {"unit": q.unit, "final": float(rms[-1]), "rms": float(np.sqrt(np.mean(rms[steady] ** 2))),
                            "max": float(rms[steady].max()), "mean_final": float(s[f"{name}_mean"][-1]),
                            "filter_sigma_final": float(sigma[-1]),
                            "true_over_filter_final": float(rms[-1] / sigma[-1]) if sigma[-1] > 0 else None}
    states = {name: {"unit": analysis.units_f[j], "rms_final": float(s["state_rms"][-1, j]),
                     "mean_final": float(s["state_mean"][-1, j]), "filter_sigma_final": float(s["state_sigma"][-1, j])}
              for j, name in enumerate(analysis.filter_names)}
    out = {"format": SUMMARY_FORMAT, "scenario": scenario.name, "kind": scenario.kind,
           "method": "linear covariance analysis", "duration_s": float(s["t"][-1]), "rows": int(s["t"].size),
           "settle_s": float(scenario["settle_s"]), "quantities": quantities, "states": states,
           "truth_states": list(analysis.truth_names), "filter_states": list(analysis.filter_names),
           "nees_expected": {"dof": int(analysis.nees_dof), "mean": float(np.mean(s["nees_expected"][steady])),
                             "final": float(s["nees_expected"][-1])},
           "notes": list(analysis.notes), "timing": {"wall_seconds": round(analysis.wall_seconds, 4)}}
    if len(analysis.sources) > 1:
        out["budget"] = {name: {source: {"final": float(s[f"{name}_share"][i, -1]),
                                         "steady": float(np.mean(s[f"{name}_share"][i, steady]))}
                                for i, source in enumerate(analysis.sources)} for name in analysis.quantities}
    return out


def lines(summary):
    """What the command line prints of a covariance analysis's summary."""
    out = [f"{'quantity':<20}{'true RMS end':>14}{'filter σ end':>14}{'true/filter':>12}{'RMS steady':>12}  unit"]
    for name, q in summary["quantities"].items():
        ratio = "-" if q["true_over_filter_final"] is None else f"{q['true_over_filter_final']:.3f}"
        out.append(f"{name.replace('_', ' '):<20}{q['final']:>14.4g}{q['filter_sigma_final']:>14.4g}{ratio:>12}"
                   f"{q['rms']:>12.4g}  {q['unit']}")
    nees = summary["nees_expected"]
    out.append(f"expected NEES       {nees['mean']:.2f} after settling for {nees['dof']} dof (consistent: = dof)")
    out += [f"note                {note}" for note in summary["notes"]]
    return out


def compare(analysis, runs, times=COMPARE_TIMES, probability=0.95):
    """The analysis against Monte Carlo runs (a list of run series): at ``times`` instants evenly along the run,
    each summary quantity's and compared filter state's RMS over the runs beside the analysis's and the
    ``probability`` sampling band of an N-run RMS (:func:`navsim.estimation.consistency.mean_square_band`); the
    family-wise band holds all the checks at once at ``probability`` (Šidák). Returns a JSON-able dict."""
    a, N = analysis, len(runs)
    rows, frames = _common_times(a.t, runs[0]["t"], times)
    errors = [a.run_errors(run) for run in runs]
    compared = errors[0][1].shape[1]
    checks = (len(a.quantities) + compared) * times
    family = probability ** (1.0 / checks)
    out = {"runs": N, "probability": probability, "family_probability": probability, "checks": checks,
           "quantities": {}, "states": {}}

    def entry(expected, variance, samples, size, filter_variance):
        # the band of the runs' RMS, widened by the linearisation's allowance (a fixed error alone has no spread); a
        # source that does not reach a state leaves it a variance of rounding size and either sign
        expected, variance = max(expected, 0.0), max(variance, 0.0)
        allowance = LINEARISATION * np.sqrt(filter_variance)
        lo, hi = (np.sqrt(v) for v in mean_square_band(expected, variance, N, probability))
        flo, fhi = (np.sqrt(v) for v in mean_square_band(expected, variance, N, family))
        lo, flo, hi, fhi = max(lo - allowance, 0.0), max(flo - allowance, 0.0), hi + allowance, fhi + allowance
        mc = float(np.sqrt(np.mean(samples)))
        return {"analysis": float(np.sqrt(expected)) / size, "montecarlo": mc / size,
                "band": [float(lo) / size, float(hi) / size], "inside": bool(lo <= mc <= hi),
                "family_band": [float(flo) / size, float(fhi) / size], "inside_family": bool(flo <= mc <= fhi)}

    block, total = a.block.sum(axis=0), a.mean.sum(axis=0)
    for name, q in a.quantities.items():
        B = q.rows.shape[2]
        rows_out = []
        for r, f in zip(rows, frames):
            J = q.rows[r]
            C, m = J @ block[r] @ J.T, J @ total[r, :B]
            expected, variance = np.trace(C) + m @ m, 2.0 * np.trace(C @ C) + 4.0 * m @ C @ m
            samples = [np.sum(err[0][name][f] ** 2) for err in errors]
            rows_out.append({"t": float(a.t[r]), **entry(expected, variance, samples, q.size, np.trace(J @ a.filter_block[r] @ J.T))})
        out["quantities"][name] = {"unit": q.unit, "rows": rows_out}
    mean_f, var_f = total @ a.T.T, a.diag_f.sum(axis=0)
    for j, name in enumerate(a.filter_names[:compared]):
        rows_out = []
        for r, f in zip(rows, frames):
            expected = var_f[r, j] + mean_f[r, j] ** 2
            variance = 2.0 * var_f[r, j] ** 2 + 4.0 * mean_f[r, j] ** 2 * var_f[r, j]
            samples = [err[1][f, j] ** 2 for err in errors]
            rows_out.append({"t": float(a.t[r]), **entry(expected, variance, samples, a.scale_f[r, j], a.filter_diag[r, j])})
        out["states"][name] = {"unit": a.units_f[j], "rows": rows_out}
    every = [row for group in ("quantities", "states") for item in out[group].values() for row in item["rows"]]
    out["inside"] = sum(row["inside"] for row in every)
    out["inside_family"] = sum(row["inside_family"] for row in every)
    return out


def _common_times(t, t_run, times):
    """(rows of ``t``, frames of ``t_run``) at ``times`` instants evenly along the run, each a kept row of the
    analysis that is also a frame of the runs (the analysis keeps frames at a stride, the runs every frame)."""
    nearest = np.clip(np.searchsorted(t_run, t), 1, t_run.size - 1)
    nearest -= np.abs(t_run[nearest - 1] - t) < np.abs(t_run[nearest] - t)
    common = np.flatnonzero(np.abs(t_run[nearest] - t) <= TIME_TOLERANCE * np.maximum(1.0, t))
    if common.size == 0:
        raise InputError("the runs and the analysis share no frame time (another frame rate?)")
    wanted = t[-1] * (np.arange(times) + 1) / times
    rows = [int(common[np.argmin(np.abs(t[common] - w))]) for w in wanted]
    return rows, [int(nearest[r]) for r in rows]


def budget(scenario, analysis, labels):
    """The error budget of ``scenario`` from its analysis with the sources apart (the content of ``budget.json``,
    :data:`BUDGET_FORMAT`; ``labels`` {source: label}): per summary quantity and source, the RMS the source leaves
    alone (what a run with only that source averages to) and its share of the total mean square (tr(J P_s Jᵀ) +
    (J m_s)·(J m): the shares add up to the total's square exactly), at the end and over the frames after
    ``settle_s``."""
    t = analysis.t
    steady = _steady(t, scenario)
    share, alone = analysis.mean_square(), analysis.alone_mean_square()
    quantities = {}
    for name, q in analysis.quantities.items():
        total = share[name].sum(axis=0)
        rows = {key: {"label": labels[key], "alone_final": float(np.sqrt(alone[name][i, -1])) / q.size,
                      "alone_rms": float(np.sqrt(np.mean(alone[name][i, steady]))) / q.size,
                      "share_final": float(share[name][i, -1]) / q.size**2,
                      "share_steady": float(np.mean(share[name][i, steady])) / q.size**2}
                for i, key in enumerate(analysis.sources)}
        quantities[name] = {"unit": q.unit, "total_final": float(np.sqrt(total[-1])) / q.size,
                            "total_rms": float(np.sqrt(np.mean(total[steady]))) / q.size, "sources": rows}
    return {"format": BUDGET_FORMAT, "method": "covariance", "scenario": scenario.name, "source": scenario.source,
            "settle_s": float(scenario["settle_s"]), "duration_s": float(t[-1]), "sources": list(analysis.sources),
            "headline": next(iter(analysis.quantities)), "quantities": quantities, "notes": list(analysis.notes)}


def budget_text(budget):
    """The covariance budget as lines of text: per source the headline quantity's error it leaves alone and its
    share of the total's mean square, at the end."""
    name = budget["headline"]
    q = budget["quantities"][name]
    unit = q["unit"]
    out = [f"error budget        {budget['scenario']}: linear covariance analysis, {name.replace('_', ' ')} at the end "
           f"({budget['duration_s']:.0f} s)",
           f"{'source':<36} {f'alone [{unit}]':>14} {f'share [{unit}²]':>16} {'share %':>8}"]
    total2 = q["total_final"] ** 2
    for row in q["sources"].values():
        out.append(f"{row['label']:<36} {row['alone_final']:14.4g} {row['share_final']:16.4g} "
                   f"{100 * row['share_final'] / total2 if total2 else 0.0:8.1f}")
    out.append(f"{'total (√ of the summed shares)':<36} {q['total_final']:14.4g} {total2:16.4g} {100.0:8.1f}")
    return out


def check_metric(scenario, name, time_s, quantities):
    """An InputError unless ``name`` is one of the kind's summary ``quantities`` and ``time_s`` [s] (None: the end)
    lies in the run."""
    if name not in quantities:
        raise InputError(f"--metric {name}: unknown; choose one of {', '.join(quantities)}")
    if time_s is not None and not 0.0 < time_s <= scenario["duration_s"]:
        raise InputError(f"--metric {name}@{time_s:g}s: the time must be inside the run (0, {scenario['duration_s']:g}] s")


def _row(t, time_s):
    return t.size - 1 if time_s is None else int(np.argmin(np.abs(t - time_s)))


def covariance_metric(analysis, name, time_s):
    """{value, filter_sigma, t}: the summary quantity ``name``'s true RMS and the filter's σ at the kept frame
    nearest ``time_s`` [s] (None: the end), in its edge unit."""
    s = analysis.series()
    r = _row(s["t"], time_s)
    return {"value": float(s[f"{name}_rms"][r]), "filter_sigma": float(s[f"{name}_sigma_filter"][r]), "t": float(s["t"][r])}


def montecarlo_metric(runs, name, time_s, run_errors, size):
    """{value, t, runs}: the RMS over the run series ``runs`` of the summary quantity ``name`` (its errors from the
    kind's ``run_errors``, SI; ``size`` its edge unit in SI) at the frame nearest ``time_s`` [s] (None: the end)."""
    t = runs[0]["t"]
    f = _row(t, time_s)
    squares = [np.sum(run_errors(run)[0][name][f] ** 2) for run in runs]
    return {"value": float(np.sqrt(np.mean(squares))) / size, "t": float(t[f]), "runs": len(runs)}
