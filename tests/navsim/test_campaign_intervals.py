"""A campaign's statistics with their uncertainty: CEP50/CEP95 with the order-statistic interval of the runs and
the NEES mean with Student's t over the runs' means, in summary.json, on the console and in the report, and the
"too few runs" caveat where 4 runs cannot bound them (navsim.estimation.intervals)."""

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from navsim import cli
from tests.support import pdf_text

BASE = Path(__file__).resolve().parent / "data" / "base_navigation.toml"


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """A 4-run navigation campaign, its console output and its report's text."""
    out = tmp_path_factory.mktemp("intervals") / "mc"
    console = io.StringIO()  # capsys is function-scoped; the campaign is the module's
    with contextlib.redirect_stdout(console):
        assert cli.main(["montecarlo", str(BASE), "--runs", "4", "--workers", "1", "--out", str(out)]) == 0
        assert cli.main(["report", str(out), "-o", str(out.parent / "mc.pdf")]) == 0
    return out, console.getvalue(), pdf_text(out.parent / "mc.pdf")[0]


def run_files(out):
    return [(json.loads((d / "summary.json").read_text()), np.load(d / "timeseries.npz"))
            for d in sorted((out / "runs").glob("run_*"))]


def test_cep_intervals_are_the_order_statistics_of_the_runs(campaign):
    """4 runs: CEP95's interval starts at the 3rd smallest final error (B ~ Bin(4, 0.95): P(B ≤ 2) = 1.4 % ≤ 2.5 %,
    P(B ≤ 3) = 18.5 %) and has no upper end (0.95⁴ = 81 % > 2.5 %); CEP50's has neither (0.5⁴ = 6.25 %): 0 below."""
    out, _, _ = campaign
    summary = json.loads((out / "summary.json").read_text())
    finals = sorted(s["position_error_m"]["horizontal"]["final"] for s, _ in run_files(out))
    horizontal = summary["position_error_m"]["horizontal"]
    assert horizontal["interval_95"] == {"cep50": [0.0, None], "cep95": [pytest.approx(finals[2], rel=1e-15), None]}
    assert horizontal["runs_to_bound"] == {"cep50": 6, "cep95": 72}
    assert summary["position_error_nmi"]["horizontal"]["interval_95"]["cep95"][0] == pytest.approx(finals[2] / 1852.0)
    assert summary["position_error_m"]["vertical"]["interval_95"]["p95"][1] is None


def test_the_nees_mean_interval_is_students_t_over_the_runs_steady_means(campaign):
    out, _, _ = campaign
    summary = json.loads((out / "summary.json").read_text())
    settle = json.loads((out / "campaign.json").read_text())["scenario_data"]["settle_s"]
    means = [float(np.mean(series["nees"][series["t"] >= settle])) for _, series in run_files(out)]
    nees = summary["nees"]
    assert nees["mean"] == pytest.approx(np.mean(means), rel=1e-12)
    expected = stats.t.interval(0.95, 3, loc=np.mean(means), scale=stats.sem(means))
    assert nees["mean_interval_95"] == pytest.approx([max(expected[0], 0.0), expected[1]], rel=1e-12)


def test_the_console_and_the_report_give_the_intervals_and_say_the_runs_are_too_few(campaign):
    out, console, text = campaign
    summary = json.loads((out / "summary.json").read_text())
    lo95 = summary["position_error_m"]["horizontal"]["interval_95"]["cep95"][0]
    lo, hi = summary["nees"]["mean_interval_95"]
    assert f"CEP95 [{lo95:.2f}, unbounded] m" in console
    assert "too few runs        4 runs leave these 95 % intervals unbounded above: CEP50 (6 runs bound it), CEP95 (72)" in console
    assert f"95 % interval of the mean [{lo:.2f}, {hi:.2f}] over 4 runs" in console
    assert f"CEP95 [{lo95:.2f}, unbounded] m; 4 runs are too few to bound CEP50 and CEP95 above" in text
    assert f"95 % interval of the mean [{lo:.2f}, {hi:.2f}]" in text
