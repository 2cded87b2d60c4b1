"""Star-identification benchmark frames (benchmarks/star_id_frames.py) and the harness's scoring.

Checked against independent truth: the catalogue projected by brute force, the set's ranges, the
0.1 px noise statistics, the Cramer-Rao closed form near the boresight, and the peers' own file
layouts as their loaders read them.  The peer runners themselves are not run here.
"""

import struct
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

import star_id  # noqa: E402
import star_id_frames as sif  # noqa: E402

from startrack.attitude.solvers import cramer_rao_covariance  # noqa: E402

ARCSEC = np.pi / (180.0 * 3600.0)


@pytest.fixture(scope="module")
def stars():
    return sif.benchmark_stars()


@pytest.fixture(scope="module")
def camera():
    return sif.benchmark_camera()


@pytest.fixture(scope="module")
def stress(stars, camera):
    return sif.generate_frames("stress", 60, seed=11, stars=stars, camera=camera)


def test_frames_are_seeded_and_independent_of_the_frame_count(stars, camera):
    first = sif.generate_frames("main", 6, seed=5, stars=stars, camera=camera)
    assert sif.generate_frames("main", 6, seed=5, stars=stars, camera=camera) == first
    assert sif.generate_frames("main", 3, seed=5, stars=stars, camera=camera) == first[:3]
    other = sif.generate_frames("main", 3, seed=6, stars=stars, camera=camera)
    assert all(a["q_IS"] != b["q_IS"] for a, b in zip(first, other))
    clean = sif.generate_frames("clean", 3, seed=5, stars=stars, camera=camera)
    assert all(a["q_IS"] != b["q_IS"] for a, b in zip(first, clean))


def test_truth_hips_project_onto_their_centroids(stress, stars, camera):
    vector_of = dict(zip(stars.hip.tolist(), stars.vectors))
    residuals = []
    for frame in stress:
        blended = {i for i, _ in frame["blend_hip"]}
        for i, ((u, v, _), hip) in enumerate(zip(frame["centroids"], frame["hip"])):
            if hip < 0:
                continue
            uv, visible = camera.project(frame["q_IS"], vector_of[hip][None, :])
            assert visible[0]
            offset = np.array([u, v]) - uv[0]
            if i in blended:  # flux-weighted mean of members closer than the blend radius
                assert np.hypot(*offset) < sif.BLEND_RADIUS_PX + 0.6
            else:
                residuals.append(offset)
    residuals = np.array(residuals)
    assert len(residuals) > 1000
    assert np.max(np.hypot(residuals[:, 0], residuals[:, 1])) < 0.6  # 6 sigma of 0.1 px
    assert np.std(residuals) == pytest.approx(sif.CENTROID_SIGMA_PX, rel=0.06)
    assert np.abs(np.mean(residuals, axis=0)).max() < 0.01


def test_false_and_missing_counts_stay_in_the_set_ranges(stars, camera):
    for name, frame_set in sif.FRAME_SETS.items():
        frames = sif.generate_frames(name, 40, seed=2, stars=stars, camera=camera)
        n_false = [f["n_false"] for f in frames]
        n_missing = [f["n_missing"] for f in frames]
        assert 0 <= min(n_false) and max(n_false) <= frame_set.max_false
        assert 0 <= min(n_missing) and max(n_missing) <= frame_set.max_missing
        if frame_set.max_false >= 3:  # 40 draws reach both ends of the range
            assert min(n_false) == 0 and max(n_false) == frame_set.max_false
        for frame in frames:
            hip = np.array(frame["hip"])
            assert np.sum(hip < 0) == frame["n_false"]
            assert frame["n_stars"] + frame["n_false"] == len(frame["centroids"])
            flux = np.array(frame["centroids"])[:, 2]
            assert np.all(np.diff(flux) <= 0.0)  # brightest first


def test_clean_frames_hold_every_star_on_the_sensor(stars, camera):
    for frame in sif.generate_frames("clean", 20, seed=4, stars=stars, camera=camera):
        uv, visible = camera.project(frame["q_IS"], stars.vectors)  # brute force over all V <= 6 stars
        inside = np.flatnonzero(visible)
        present = set(frame["hip"]) | {h for _, h in frame["blend_hip"]}
        assert present <= set(stars.hip[inside].tolist())
        for k in inside[~np.isin(stars.hip[inside], list(present))]:
            margin = min(uv[k, 0] + 0.5, camera.width - 0.5 - uv[k, 0], uv[k, 1] + 0.5, camera.height - 0.5 - uv[k, 1])
            assert margin < 0.6  # only noise can push a star off the sensor


def test_false_stars_keep_clear_of_every_star_image(stress, stars, camera):
    for frame in stress:
        uv_stars, visible = camera.project(frame["q_IS"], stars.vectors)
        uv_stars = uv_stars[visible]
        for (u, v, _), hip in zip(frame["centroids"], frame["hip"]):
            if hip < 0:
                assert np.min(np.hypot(uv_stars[:, 0] - u, uv_stars[:, 1] - v)) >= sif.FALSE_STAR_CLEARANCE_PX


def test_tracking_priors_are_off_by_the_stated_angle(stars, camera):
    frames = sif.generate_frames("main", 4, seed=1, stars=stars, camera=camera)
    tracking = sif.tracking_frames(frames, seed=1)
    assert len(tracking) == len(frames) * len(sif.TRACKING_PRIOR_ERRORS_DEG)
    for frame in tracking:
        angle = (Rotation.from_quat(frame["q_IS"]).inv() * Rotation.from_quat(frame["prior_q_IS"])).magnitude()
        assert np.degrees(angle) == pytest.approx(frame["prior_error_deg"], abs=1e-9)  # rounding level: composed
    assert sif.tracking_frames(frames, seed=1) == tracking


def test_pixel_crb_reduces_to_the_vector_bound_near_the_boresight():
    rng = np.random.default_rng(0)
    focal_px, sigma_px = 3000.0, 0.1
    xy = rng.uniform(-3.0, 3.0, size=(12, 2))  # within 0.06 deg of the boresight
    b = np.column_stack([xy, np.full(12, focal_px)])
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    P = star_id.pixel_crb(b, focal_px, sigma_px)
    reference = cramer_rao_covariance(b, sigma_px / focal_px)
    # The pinhole's pixel Jacobian departs from the tangent plane's by (1 + r²/f²) per axis, r <= 3√2 px here: the
    # information, hence P (normalised by its sigmas), by at most 2 r²/f² = 4e-6 (1.4e-6 seen). atol, not the
    # default rtol 1e-5 with atol 1e-8, which exceeded every cross-boresight entry (1e-10 rad²).
    scale = np.sqrt(np.outer(np.diag(reference), np.diag(reference)))
    departure = 2.0 * np.max(np.sum(xy**2, axis=1)) / focal_px**2
    assert np.allclose(P / scale, reference / scale, rtol=0, atol=departure)


def test_pixel_crb_matches_monte_carlo_least_squares(camera):
    # Linearised least squares of the error rotation from noisy pixels has covariance P exactly.
    rng = np.random.default_rng(1)
    uv = rng.uniform(0, 1023, size=(15, 2))
    b = camera.unproject(uv)
    P = star_id.pixel_crb(b, camera.focal_px, 0.1)
    eps = 1e-7
    jac = np.stack([(camera.project_body(Rotation.from_rotvec(-eps * e).apply(b))[0] - uv).ravel() / eps
                    for e in np.eye(3)], axis=1)
    noise = rng.normal(scale=0.1, size=(4000, jac.shape[0]))
    estimates = np.linalg.lstsq(jac, noise.T, rcond=None)[0].T
    assert np.sqrt(np.diag(np.cov(estimates.T))) == pytest.approx(np.sqrt(np.diag(P)), rel=0.05)


def test_scoring_separates_success_wrong_attitude_and_wrong_hip(stars, camera):
    frames = sif.generate_frames("main", 3, seed=8, stars=stars, camera=camera)
    truth = [{"id": f["id"], "status": "ok", "q_IS": f["q_IS"], "solve_ms": 1.0,
              "matches": [[i, h] for i, h in enumerate(f["hip"]) if h >= 0]} for f in frames]
    rng = np.random.default_rng(0)
    metrics = star_id.evaluate(frames, truth, stars, camera, rng)
    assert metrics["success_rate"] == 1.0 and metrics["false_count"] == 0
    assert metrics["cross_boresight_arcsec"]["p95"] == pytest.approx(0.0, abs=1e-6)  # rounding level: the truth

    turned = (Rotation.from_quat(frames[0]["q_IS"]) * Rotation.from_rotvec([0, 70 * ARCSEC, 0])).as_quat()
    slightly = (Rotation.from_quat(frames[1]["q_IS"]) * Rotation.from_rotvec([0, 0, 50 * ARCSEC])).as_quat()
    bad = [dict(truth[0], q_IS=turned.tolist()),
           dict(truth[1], q_IS=slightly.tolist()),
           dict(truth[2], matches=[[0, frames[2]["hip"][0] + 1]] + truth[2]["matches"][1:])]
    metrics = star_id.evaluate(frames, bad, stars, camera, rng)
    assert metrics["success_rate"] == pytest.approx(1 / 3)
    assert (metrics["false_attitude_count"], metrics["wrong_hip_only_count"]) == (1, 1)
    assert metrics["roll_arcsec"]["median"] == pytest.approx(50.0, rel=1e-6)  # rounding level: a composed 50" roll


def test_peer_catalog_files_read_back_as_the_peers_parse_them(tmp_path, stars):
    subset = stars.select(np.arange(0, len(stars), 500))
    star_id.write_hip_main(tmp_path / "hip_main.dat", subset)
    for line, hip, ra, dec, v in zip((tmp_path / "hip_main.dat").read_text().splitlines(), subset.hip,
                                     subset.ra, subset.dec, subset.v_mag):
        entry = line.split("|")  # cedar-solve's reader: csv with '|', fields 1, 5, 8, 9, 12, 13
        assert int(entry[1]) == hip and float(entry[5]) == pytest.approx(v, abs=0.005)
        assert float(entry[8]) == pytest.approx(np.degrees(ra), abs=1e-8)  # the file's 8 decimals (half: 5e-9)
        assert float(entry[9]) == pytest.approx(np.degrees(dec), abs=1e-8)
        assert float(entry[12]) == 0.0 and float(entry[13]) == 0.0
        assert line[41:46] == entry[5] and line[51:63] == entry[8]  # I/239 byte columns 42-46, 52-63
    star_id.write_gdr3_binary(tmp_path / "stars.bin", subset)
    raw = (tmp_path / "stars.bin").read_bytes()
    assert raw[:4] == b"GDR3" and struct.unpack("<IQ", raw[4:16]) == (1, len(subset))
    records = [struct.unpack("<qddfff", raw[16 + 36 * k: 16 + 36 * (k + 1)]) for k in range(len(subset))]
    assert [r[0] for r in records] == subset.hip.tolist()
    # doubles are written exactly (rounding level), magnitudes as float32: half an ulp below 16 mag is 4.8e-7
    # (rtol 0: the default 1e-5 would allow 3.6e-3 deg)
    assert np.allclose([r[1] for r in records], np.degrees(subset.ra), rtol=0, atol=1e-12)
    assert np.allclose([r[2] for r in records], np.degrees(subset.dec), rtol=0, atol=1e-12)
    assert np.allclose([r[3] for r in records], subset.v_mag, rtol=0, atol=1e-6)
