"""PDF reports of runs and Monte Carlo campaigns: valid PDF, the sections, the key numbers, bad input."""

import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pypdf
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

import navsim
from navsim import cli
from navsim.attitude.report_statistics import envelopes
from navsim.campaign.montecarlo import aggregate, run_campaign
from navsim.output import read_npz, write_json, write_npz, write_run
from navsim.pooling import averaged_nees
from navsim.report import write_report
from navsim.typeset import statistics
from navsim.typeset.inputs import RunData
from startrack.base.errors import InputError
from startrack.catalog import address
from startrack.catalog.hipparcos import load_star_catalog
from tests.support import pdf_text

DEMO = Path(__file__).resolve().parents[2] / "scenarios" / "paper000_high_dynamic.toml"  # vector fidelity
SHORT = {"duration_s": 20.0}  # 40 frames at 2 Hz


@pytest.fixture(scope="module")
def catalog():
    return load_star_catalog(epoch=2000.0)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory, catalog):
    result = navsim.run(DEMO, seed=4, overrides=SHORT, star_catalog=catalog)
    return write_run(tmp_path_factory.mktemp("run") / "demo", result)


@pytest.fixture(scope="module")
def campaign_dir(tmp_path_factory):
    """A real four-run campaign whose last run then failed (its result replaced by the error a
    failing run records), aggregated again."""
    root = tmp_path_factory.mktemp("campaign") / "mc"
    run_campaign(DEMO, runs=4, out=root, overrides=SHORT, workers=1, progress=False)
    failed = root / "runs" / "run_00003"
    shutil.rmtree(failed)
    failed.mkdir()
    write_json(failed / "error.json", {"seed": 14, "error": "FloatingPointError: covariance lost positive definiteness"})
    write_json(root / "summary.json", aggregate(root).to_json())
    return root


def test_run_report_has_sections_and_key_numbers(run_dir, tmp_path):
    pdf = write_report(run_dir, tmp_path / "run.pdf")
    assert write_report(run_dir, tmp_path / "again.pdf").read_bytes() == pdf.read_bytes()  # reproducible
    text, pages = pdf_text(pdf)
    summary = json.loads((run_dir / "summary.json").read_text())
    for heading in ("Simulation run report: paper000_high_dynamic", "Key results", "Scenario parameters", "Attitude estimation error",
                    "Gyro bias estimate", "Filter consistency", "Not logged in this run"):
        assert heading in text
    assert pages >= 3
    assert f"cross-boresight attitude error RMS is {summary['cross_boresight_rms_arcsec']:.2f} arcsec" in text
    assert f"{summary['roll_rms_arcsec']:.2f} arcsec" in text
    rms = summary["attitude_error_rms_arcsec"]
    assert f"x {rms['x']:.2f}, y {rms['y']:.2f}, z {rms['z']:.2f} arcsec" in text
    assert f"The NEES (6 dof) averages {summary['nees']['mean']:.2f}" in text
    assert f"{100 * summary['nees']['fraction_in_band']:.1f} %" in text
    # A vector-fidelity run logs no image chain: those sections are left out, not drawn empty.
    assert "Boresight track" not in text and "A rendered frame" not in text
    # Scenario parameters come from scenario.json with units in the key names.
    assert "star_sensor.fov_deg 16" in text


def add_image_chain(directory, n_d=53):
    """Give a run directory the optional arrays of the image-fidelity closed loop (with known values)."""
    series = read_npz(directory / "timeseries.npz")
    frames = series["t"].size
    mode = np.full(frames, 2)
    mode[:2], mode[2:4], mode[30:33] = 0, 1, 3
    boresight = Rotation.from_quat(series["q_est"]).apply([0.0, 0.0, 1.0])
    ra = np.mod(np.arctan2(boresight[:, 1], boresight[:, 0]), 2 * np.pi)
    dec = np.arcsin(boresight[:, 2])
    l_d, l_ra = address.address(ra, dec, n_d)
    series.update(
        mode=mode, n_detected=np.full(frames, 9), n_identified=np.where(mode == 3, 0, 7), n_stacked=np.zeros(frames),
        id_ms=np.where(mode == 0, 40.0, np.where(mode == 1, 4.0, 0.2)), boresight_radec=np.stack([ra, dec], axis=1),
        subcatalog_index=address.base_index(l_d, l_ra, n_d), subcatalog_address=np.stack([l_d, l_ra], axis=1),
    )
    write_npz(directory / "timeseries.npz", series)
    summary = json.loads((directory / "summary.json").read_text())
    summary["modes"] = ["full-sky", "sub-catalog", "tracking", "outage"]
    summary["paper_comparison"] = [
        {"quantity": "recognition rate full-sky [%]", "ours": 99.25, "paper": 98.6, "source": "000 Table 3"}]
    write_json(directory / "summary.json", summary)
    frame = np.full((64, 80), 10.0)
    frame[20, 30] = frame[40, 50] = 500.0
    np.save(directory / "frame.npy", frame)
    (directory / "frame_detections.json").write_text(
        json.dumps([{"u": 30.0, "v": 20.0, "hip": 32349}, {"u": 50.0, "v": 40.0, "hip": None}]))
    return series


def test_run_report_with_image_chain_quantities(run_dir, tmp_path):
    directory = tmp_path / "image"
    shutil.copytree(run_dir, directory)
    series = add_image_chain(directory)
    run = RunData(directory, json.loads((directory / "summary.json").read_text()), series)
    assert statistics.declination_divisions(run) == 53  # inferred from the logged addresses alone
    text, _ = pdf_text(write_report(directory, tmp_path / "image.pdf"))
    for heading in ("Star sensor: modes, stars and identification time", "Boresight track and sub-catalog addresses",
                    "A rendered frame", "Comparison with the source documents"):
        assert heading in text
    assert "Not logged in this run" not in text
    distinct = np.unique(series["subcatalog_index"]).size
    assert "n_d = 53 declination divisions" in text
    assert f"used {distinct} distinct sub-catalogs" in text
    assert "The sensor changed mode 4 times" in text
    assert f"tracking {np.count_nonzero(series['mode'] == 2)}" in text  # mode table row: name, frames
    assert "recognition rate full-sky [%] 99.25 98.6 000 Table 3" in text
    assert "2 detections, 1 identified" in text


def test_declination_divisions_from_other_grid():
    n_d = 40
    ra, dec = np.radians([10.0, 200.0, 359.0]), np.radians([-60.0, 5.0, 80.0])
    l_d, l_ra = address.address(ra, dec, n_d)
    series = {"subcatalog_address": np.stack([l_d, l_ra], 1), "subcatalog_index": address.base_index(l_d, l_ra, n_d)}
    assert statistics.declination_divisions(RunData(Path("."), {}, series)) == n_d
    assert statistics.declination_divisions(RunData(Path("."), {}, series, {"star_sensor": {"image": {"catalog_nd": 53}}})) == 53


def test_campaign_report_has_sections_and_statistics(campaign_dir, tmp_path):
    text, _ = pdf_text(write_report(campaign_dir, tmp_path / "campaign.pdf"))
    for heading in ("Monte Carlo campaign report: paper000_high_dynamic", "Statistics across runs", "Attitude error envelopes",
                    "Filter consistency over runs", "Final errors", "Identification success per mode",
                    "Aggregate summary", "Failed runs", "Scenario parameters"):
        assert heading in text
    summaries = [json.loads(p.read_text()) for p in sorted(campaign_dir.glob("runs/run_*/summary.json"))]
    cross = [s["cross_boresight_rms_arcsec"] for s in summaries]
    assert "3 finished runs, 1 failed, 4 requested" in text
    assert f"cross-boresight RMS error is {np.mean(cross):.2f} arcsec on average" in text
    assert f"worst {max(cross):.2f} arcsec" in text
    lo, hi = chi2.ppf([0.025, 0.975], 18) / 3  # average of 3 runs of 6 dof
    assert f"[{lo:.2f}, {hi:.2f}] for 3 runs of 6 dof" in text
    assert "covariance lost positive definiteness" in text
    # Final errors: the RMS over runs of the last frame's error, independently from the arrays.
    last = np.array([read_npz(p)["attitude_error"][-1] for p in sorted(campaign_dir.glob("runs/run_*/timeseries.npz"))])
    rms = np.degrees(np.sqrt(np.mean(last**2, axis=0))) * 3600
    assert f"final error is x {rms[0]:.2f}, y {rms[1]:.2f}, z {rms[2]:.2f} arcsec" in text


def fake_campaign(nees_runs, P_runs=None):
    t = np.arange(nees_runs.shape[1]) * 0.1
    runs = []
    for k, nees in enumerate(nees_runs):
        series = {"t": t, "attitude_error": np.zeros((t.size, 3)), "nees": nees}
        if P_runs is not None:
            series["P_diag"] = P_runs[k]
        runs.append(RunData(Path(f"run_{k}"), {"settle_s": 0.0, "nees": {"dof": 6}}, series))
    return SimpleNamespace(runs=runs, summary=None)


def test_averaged_nees_band_holds_95_percent_for_a_consistent_filter():
    rng = np.random.default_rng(5)
    m, frames = 25, 4000

    def finished(nees_runs):
        return [(k, run.summary, run.series) for k, run in enumerate(fake_campaign(nees_runs).runs)]

    avg = averaged_nees(finished(rng.chisquare(6, size=(m, frames))), 0.0)
    assert avg["band_95"] == pytest.approx(list(chi2.ppf([0.025, 0.975], 6 * m) / m))  # rounding level: the same ppf
    assert avg["fraction_in_band"] == pytest.approx(0.95, abs=0.015)  # binomial σ over 4000 frames: 0.0034
    inflated = averaged_nees(finished(1.5 * rng.chisquare(6, size=(m, frames))), 0.0)
    assert inflated["fraction_in_band"] < 0.5


def test_filter_sigma_envelope_averages_the_covariance_not_the_sigma():
    P = np.stack([np.full((5, 6), 1.0), np.full((5, 6), 9.0)]) * (np.pi / 180 / 3600) ** 2  # (1")², (3")²
    env = envelopes(fake_campaign(np.ones((2, 5)), P))  # rounding level below: closed forms
    assert env.final_sigma_filter == pytest.approx(np.full(3, np.sqrt(5.0)))
    assert env.sigma3_filter[0] == pytest.approx(np.full(3, 3 * np.sqrt(5.0)))


def test_identification_success_pools_frames_per_mode():
    mode = np.array([0, 0, 2, 2, 2, 3])
    runs = [RunData(Path(f"run_{k}"), {"modes": ["full-sky", "sub-catalog", "tracking", "outage"]},
                    {"t": np.arange(6.0), "mode": mode, "n_identified": np.array([0, 3, 5, 1, 2, 0]) + k})
            for k in range(2)]
    rows, criterion = statistics.identification_success(SimpleNamespace(runs=runs, summary=None))
    assert criterion == "frames with at least 2 identified stars"
    pooled = [(r.name, r.identified, r.frames) for r in rows]
    assert pooled == [("full-sky", 2, 4), ("tracking", 5, 6), ("outage", 0, 2)]


def test_cli_report_and_run_with_report(run_dir, tmp_path, capsys):
    assert cli.main(["report", str(run_dir), "-o", str(tmp_path / "cli.pdf")]) == 0
    assert len(pypdf.PdfReader(tmp_path / "cli.pdf").pages) >= 3
    out = tmp_path / "run"
    assert cli.main(["run", str(DEMO), "--out", str(out), "--set", "duration_s=3",
                     "--set", "star_sensor.measurement=attitude", "--report"]) == 0
    text, _ = pdf_text(out / "report.pdf")
    summary = json.loads((out / "summary.json").read_text())
    assert f"cross-boresight attitude error RMS is {summary['cross_boresight_rms_arcsec']:.2f} arcsec" in text


def test_bad_input_is_one_clear_error(run_dir, tmp_path, capsys):
    with pytest.raises(InputError, match="no such directory"):
        write_report(tmp_path / "missing", tmp_path / "a.pdf")
    with pytest.raises(InputError, match="neither a run directory"):
        write_report(tmp_path, tmp_path / "a.pdf")
    with pytest.raises(InputError, match="must end in .pdf"):
        write_report(run_dir, tmp_path / "a.txt")
    broken = tmp_path / "broken"
    shutil.copytree(run_dir, broken)
    (broken / "timeseries.npz").write_bytes(b"not an archive")
    with pytest.raises(InputError, match=r"timeseries.npz: not an .npz"):
        write_report(broken, tmp_path / "a.pdf")
    series = read_npz(run_dir / "timeseries.npz")
    write_npz(broken / "timeseries.npz", {**series, "attitude_error": series["attitude_error"][:, :2]})
    with pytest.raises(InputError, match="'attitude_error' has shape"):
        write_report(broken, tmp_path / "a.pdf")
    del series["t"]
    write_npz(broken / "timeseries.npz", series)
    with pytest.raises(InputError, match="'t' is missing"):
        write_report(broken, tmp_path / "a.pdf")
    empty = tmp_path / "empty_campaign"
    empty.mkdir()
    write_json(empty / "campaign.json", {"scenario": "demo", "runs": 2})
    with pytest.raises(InputError, match="no finished runs"):
        write_report(empty, tmp_path / "a.pdf")
    assert cli.main(["report", str(tmp_path / "missing"), "-o", str(tmp_path / "a.pdf")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("navsim: error: ") and "no such directory" in err
