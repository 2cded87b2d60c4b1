"""Static studies (003 §3 attitude precision, 001 star maps): scenario files, numbers against
independent references (Cramér-Rao bound, the algorithms' own first-order covariance, 003/001's
printed figures), reproducibility, the command line and the PDF report."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pypdf
import pytest

import navsim
from navsim import studies
from navsim.kinds import load_scenario, scenario_from_dict
from navsim.output import write_study
from navsim.report import write_report
from startrack.base.errors import InputError
from tests.support import HANG_S

ROOT = Path(__file__).resolve().parents[2]
PRECISION = ROOT / "scenarios" / "paper003_precision.toml"
CONTEST = ROOT / "scenarios" / "contest_starmap.toml"
SMALL_PRECISION = {"study.attitude_precision.trials": 200, "study.attitude_precision.stars": [3, 9, 21],
                   "study.attitude_precision.sigma_sweep_arcsec": [0.5, 1.0, 2.0],
                   "study.attitude_precision.fov_sweep_deg": [4.0], "study.attitude_precision.fov_sweep_stars": [3],
                   "study.attitude_precision.distributions": ["line", "uniform"],
                   "study.attitude_precision.tail_batches": 4}
SMALL_CONTEST = {"study.contest_starmap.maps": 120, "study.contest_starmap.casadi_maps": 10,
                 "study.contest_starmap.identification_maps": 40}


def navsim_cli(*args):
    return subprocess.run([sys.executable, "-m", "navsim.cli", *map(str, args)], capture_output=True,
                          text=True, cwd=ROOT, timeout=HANG_S)


@pytest.fixture(scope="module")
def precision():
    return navsim.run_study(PRECISION, overrides=SMALL_PRECISION)


@pytest.fixture(scope="module")
def contest():
    return navsim.run_study(CONTEST, overrides=SMALL_CONTEST)


# ------------------------------------------------------------------------------ scenario files

def test_study_files_load_with_the_papers_settings():
    p = load_scenario(PRECISION)
    assert p.kind == "study" and p["study"]["kind"] == "attitude_precision"
    assert studies.parameters(p)["trials"] == 300 and studies.parameters(p)["stars"] == list(range(3, 22))
    c = load_scenario(CONTEST)
    assert studies.parameters(c)["maps"] == 1000 and studies.parameters(c)["gate_sigmas"] == [3.0, 1.0]


def test_a_study_table_may_be_left_out_and_takes_the_defaults():
    s = scenario_from_dict({"name": "x", "study": {"kind": "attitude_precision"}})
    assert studies.parameters(s)["fov_deg"] == 16.0 and studies.parameters(s)["distribution"] == "radec_window"


@pytest.mark.parametrize("overrides, message", [
    ({"study.attitude_precision.colour": 1}, "study.attitude_precision.colour: unknown key"),
    ({"study.attitude_precision.stars": [3, 2]}, "study.attitude_precision.stars: must be >= 3"),
    ({"study.attitude_precision.stars": [3.5]}, "study.attitude_precision.stars: must be a list of integers"),
    ({"study.attitude_precision.distributions": ["spiral"]}, "'spiral' is not one of"),
    ({"study.attitude_precision.trials": 1}, "study.attitude_precision.trials: must be >= 2"),
    ({"study.kind": "horoscope"}, "study.kind: must be one of"),
    ({"study.contest_starmap.maps": 3}, "study.contest_starmap: given, but study.kind is 'attitude_precision'"),
    ({"study.attitude_precision.sigma_sweep_arcsec": [1.0]}, "needs at least 2 entries"),
])
def test_bad_study_input_names_file_and_key(overrides, message):
    with pytest.raises(InputError, match="paper003_precision.toml: ") as error:
        load_scenario(PRECISION, overrides)
    assert message in str(error.value)


def test_a_study_is_not_a_simulation():
    with pytest.raises(InputError, match="static study .* cannot be used for a simulation run"):
        navsim.run(PRECISION)
    with pytest.raises(InputError, match="not a static study"):
        navsim.run_study(ROOT / "scenarios" / "paper000_high_dynamic.toml")


# ---------------------------------------------------------------------------------- 003 §3

def test_optimal_solution_attains_the_cramer_rao_bound(precision):
    """SVD Monte Carlo RMS vs the CRB: 200 trials give a ~5 % standard error per angle."""
    for row in precision.summary["points"]["error_vs_stars"]:
        ours, bound = np.array(row["svd"]["rms_arcsec"]), np.array(row["crb_rms_arcsec"])
        assert np.all(np.abs(ours / bound - 1.0) < 0.2), (row["stars"], ours, bound)


def test_003_algorithm_follows_its_first_order_covariance_and_is_not_efficient(precision):
    for row in precision.summary["points"]["error_vs_stars"]:
        if row["stars"] < 9:  # the three-star RMS has no finite variance (see the study's notes)
            continue
        mc, predicted = np.array(row["multi_vector"]["rms_arcsec"]), np.array(row["multi_vector"]["predicted_rms_arcsec"])
        assert np.all(np.abs(mc / predicted - 1.0) < 0.2), (row["stars"], mc, predicted)
        assert np.all(predicted >= 0.99 * np.array(row["crb_rms_arcsec"]))


def test_003_figures_reproduced_at_9_and_21_stars(precision):
    """003 Fig. 6 (printed): (0.56, 0.49, 4.08)" at N = 9 and (0.34, 0.28, 2.47)" at N = 21, within 25 %
    (2.5 standard errors of a 200-trial RMS)."""
    rows = {r["stars"]: r for r in precision.summary["points"]["error_vs_stars"]}
    for n, paper in ((9, (0.56, 0.49, 4.08)), (21, (0.34, 0.28, 2.47))):
        assert np.allclose(rows[n]["multi_vector"]["rms_arcsec"], paper, rtol=0.25), (n, rows[n]["multi_vector"])
    quantities = [row["quantity"] for row in precision.summary["paper_comparison"]]
    assert any("N = 9" in q for q in quantities) and any("A = 4 deg" in q for q in quantities)


def test_algorithm_error_is_at_rounding_and_errors_are_linear_in_sigma(precision):
    worst = max(max(r["multi_vector"]["max_abs_arcsec"]) for r in precision.summary["points"]["algorithm_error"])
    assert worst < 1e-6  # arcsec; 003 reports 3.7e-4" for its iterative inverse square root
    slopes = precision.summary["slopes_arcsec_per_arcsec"]
    assert np.allclose(slopes["svd"], slopes["crb"], rtol=0.25)
    assert precision.summary["linearity_residual_percent"] < 15.0


def test_line_distribution_loses_the_declination_and_roll(precision):
    """003 Table 1: stars on one declination circle leave rotation about that circle's pole weakly
    observed by 003's algorithm; the optimal solution and the bound do not care."""
    rows = {r["distribution"]: r for r in precision.summary["points"]["distributions"]}
    assert rows["line"]["multi_vector"]["rms_arcsec"][1] > 5 * rows["uniform"]["multi_vector"]["rms_arcsec"][1]
    assert rows["line"]["svd"]["rms_arcsec"][1] < 2 * rows["uniform"]["svd"]["rms_arcsec"][1]


def test_a_changed_setup_drops_the_papers_figures():
    result = navsim.run_study(PRECISION, overrides=SMALL_PRECISION | {"study.attitude_precision.trials": 5,
                                                                      "study.attitude_precision.fov_deg": 12.0})
    assert result.summary["paper_comparison"] == []
    assert "differs from 003's" in result.summary["notes"][0]


def test_same_seed_same_numbers():
    small = SMALL_PRECISION | {"study.attitude_precision.trials": 10}
    a, b = (navsim.run_study(PRECISION, overrides=small).summary for _ in range(2))
    c = navsim.run_study(PRECISION, seed=4, overrides=small).summary
    for s in (a, b, c):
        s.pop("wall_seconds")
    assert a == b and a != c


# ----------------------------------------------------------------------------------- 001

def test_contest_all_star_solves_against_the_bound(contest):
    optical = contest.summary["optical_axis"]
    bound = optical["crb_rms_arcsec"]["crb_vector"]
    assert abs(optical["rms_arcsec"]["vector_all_procrustes"] / bound - 1.0) < 0.2
    assert optical["rms_arcsec"]["vector_all_ols"] > 0.95 * bound
    assert optical["rms_arcsec"]["scalar_all_ols"] > 0.95 * optical["crb_rms_arcsec"]["crb_scalar"]
    ranks = optical["rank_beats_percent"]
    for model in ("scalar_known_f", "vector_known_f"):
        assert 60.0 < ranks[model]["best_triple"] < ranks[model]["ols"]  # 001: 86/97 and 81/90 %


def test_contest_maps_are_all_recognised_without_false_matches(contest):
    for summary in contest.summary["identification"].values():
        assert summary["recognised_percent"] == 100.0 and summary["false_matches"] == 0
        assert summary["cross_boresight_rms_arcsec"] < 1.5 * summary["cross_boresight_crb_rms_arcsec"]
    assert contest.arrays["id_gate_3_sigma_ok"].shape == (40,)
    assert contest.arrays["optical_vector_all_ols"].shape == (120,)


# ----------------------------------------------------------------------- command line, report

def test_cli_runs_a_study_prints_the_comparison_and_writes_a_report(tmp_path):
    out = tmp_path / "p3"
    sets = [a for key, value in SMALL_PRECISION.items() for a in ("--set", f"{key}={json.dumps(value)}")]
    done = navsim_cli("run", PRECISION, "--out", out, *sets, "--set", "study.attitude_precision.trials=30", "--report")
    assert done.returncode == 0, done.stderr
    assert "003 printed" in done.stdout and "(0.56, 0.49, 4.08)" in done.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["study"] == "attitude_precision" and (out / "study.npz").is_file()
    text = "\n".join(page.extract_text() for page in pypdf.PdfReader(out / "report.pdf").pages)
    for needle in ("Static study report", "Comparison with the source documents", "What the comparison shows",
                   "003 Fig. 6", "(0.56, 0.49, 4.08)"):
        assert needle in text, needle
    row = summary["points"]["error_vs_stars"][1]
    assert f"{row['multi_vector']['rms_arcsec'][0]:.2f}" in text


def test_contest_report_has_its_figures_and_numbers(tmp_path, contest):
    write_study(tmp_path / "c", contest)
    pdf = write_report(tmp_path / "c", tmp_path / "c.pdf")
    text = "\n".join(page.extract_text() for page in pypdf.PdfReader(pdf).pages)
    for needle in ("001 Fig. 2.6/3.5", "001 §5.4", "maps recognised"):
        assert needle in text, needle
    assert f"{contest.summary['optical_axis']['rms_arcsec']['vector_all_ols']:.3f}" in text


def test_montecarlo_and_tune_refuse_a_study(tmp_path):
    for args in (("montecarlo", PRECISION, "--runs", "2", "--out", tmp_path / "mc"), ("tune", PRECISION)):
        done = navsim_cli(*args)
        assert done.returncode == 2 and "Traceback" not in done.stderr
        assert "static study" in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "mc").exists()


def test_report_of_a_broken_study_directory_is_one_clear_error(tmp_path):
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "summary.json").write_text(json.dumps({"study": "attitude_precision"}))
    (tmp_path / "s" / "study.npz").write_bytes(b"not a zip")
    (tmp_path / "s" / "scenario.json").write_text(json.dumps({"study": {"kind": "attitude_precision",
                                                                        "attitude_precision": {}}}))
    with pytest.raises(InputError, match="study.npz: not an .npz"):
        write_report(tmp_path / "s", tmp_path / "s.pdf")
