"""``startrack solve``: centroid CSV (with and without header/flux), image, JSON Lines batch, bad input.

With ``--fov-deg`` and the frame size the camera is given (an ideal pinhole) and the frame is identified
as a star tracker does (``tests/startrack/test_solve_given_camera.py`` checks its accuracy).  With
``--fov-hint-deg`` the field of view is a hint and the camera is calibrated from the stars, so the
attitude checked against the truth is the pointing of the image centre (``center``), which the stars
fix; the sensor frame's +z runs through the fitted principal point, known only to its sigma.
"""

import json
import re

import numpy as np
import pytest

from startrack.camera.model import Camera
from startrack.catalog.hipparcos import load_star_catalog
from startrack.cli import main
from startrack.geometry.attitude_angles import matrix_from_radec_roll
from startrack.image.synthetic import centroid_frame, random_attitude

SIZE = ["--width", "1024", "--height", "1024"]
GEOMETRY = ["--fov-deg", "16", *SIZE]
HINT = ["--fov-hint-deg", "16", *SIZE]


@pytest.fixture(scope="module")
def frame():
    camera = Camera.from_fov(np.radians(16.0), 1024, 1024)
    stars = load_star_catalog(2000.0).brighter_than(6.0)
    rng = np.random.default_rng(77)
    return camera, centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, 0.1,
                                  n_false=2, n_missing=1)


def _run(capsys, argv):
    status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _center_error(record, camera, q_IS):
    """Angle [rad] between the reported image-centre attitude and the true one."""
    truth = camera.center_radec_roll(q_IS)
    center = record["center"]
    found = np.radians([center["ra_deg"], center["dec_deg"], center["roll_deg"]])
    R = matrix_from_radec_roll(*truth).T @ matrix_from_radec_roll(*found)
    return float(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))


def _check_identified(record, camera, frame, source):
    assert record["status"] == "ok" and record["camera"]["source"] == source
    assert record["method"] == ("lost_in_space" if source == "given" else "pattern")
    for pair in record["matches"]:
        assert frame.hip[pair[0]] == pair[1]
    assert _center_error(record, camera, frame.q_IS) < 1e-4
    assert abs(record["camera"]["fov_deg"] / 16.0 - 1.0) < 1e-3
    for key in ("q_IS", "ra_deg", "dec_deg", "roll_deg", "solve_ms", "false_match_probability", "id", "camera"):
        assert key in record


@pytest.mark.parametrize("geometry, source", [(GEOMETRY, "given"), (HINT, "fitted")])
def test_csv_with_header_and_flux(tmp_path, capsys, frame, geometry, source):
    camera, f = frame
    path = tmp_path / "frame.csv"
    np.savetxt(path, np.column_stack([f.uv, f.flux]), delimiter=",", header="u,v,flux", comments="")
    status, out, _ = _run(capsys, ["solve", str(path), *geometry, "--centroid-sigma-px", "0.1", "--json"])
    assert status == 0
    record = json.loads(out)
    assert record["id"] == str(path)
    _check_identified(record, camera, f, source)


def test_csv_without_header_or_flux_in_brightness_order(tmp_path, capsys, frame):
    _, f = frame
    path = tmp_path / "frame.csv"
    np.savetxt(path, f.uv, delimiter=",")
    status, out, _ = _run(capsys, ["solve", str(path), *GEOMETRY, "--boresight-deg", "10,20"])
    assert status == 0 and re.search(r": ok  \d+ stars matched  false-match probability", out) and "  sensor  RA " in out


def test_image_is_detected_then_identified(tmp_path, capsys, frame):
    camera, f = frame
    rows, cols = np.mgrid[0:1024, 0:1024]
    image = np.full((1024, 1024), 100.0)
    for (u, v), flux in zip(f.uv, f.flux):  # Gaussian star images, sigma 1 px, on a flat background
        if 3 < u < 1020 and 3 < v < 1020:
            r0, c0 = int(v), int(u)
            window = (slice(r0 - 4, r0 + 5), slice(c0 - 4, c0 + 5))
            peak = 3000.0 * np.sqrt(flux / f.flux.max())  # compressed range: every star well above noise
            image[window] += peak * np.exp(-((cols[window] - u) ** 2 + (rows[window] - v) ** 2) / 2.0)
    image += np.random.default_rng(1).normal(0.0, 2.0, image.shape)
    path = tmp_path / "frame.npy"
    np.save(path, image)
    status, out, _ = _run(capsys, ["solve", str(path), "--json"])  # no geometry: the size is the file's
    record = json.loads(out)
    assert status == 0 and record["status"] == "ok", record
    assert _center_error(record, camera, f.q_IS) < 1e-4
    assert record["detection"]["detections"] >= len(record["matches"])


@pytest.mark.parametrize("geometry, source", [(GEOMETRY, "given"), (HINT, "fitted")])
def test_batch_reports_every_frame_and_bad_lines(tmp_path, capsys, frame, geometry, source):
    camera, f = frame
    lines = [json.dumps({"id": "good", "centroids": np.column_stack([f.uv, f.flux]).tolist()}),
             json.dumps({"id": "nan", "centroids": [[1, 2, 1], [3, float("nan"), 1], [5, 6, 1]]}),
             json.dumps({"id": "two", "centroids": [[1, 2], [3, 4]]}),
             json.dumps({"id": "off", "centroids": [[-100, 2], [3000, 4], [5, -90]]}),
             json.dumps({"id": "text", "centroids": [[1, "x"]]}),
             json.dumps({"id": "extra", "centroids": [], "fov": 3}),
             "{broken", ""]
    path = tmp_path / "frames.jsonl"
    path.write_text("\n".join(lines) + "\n")
    status, out, err = _run(capsys, ["solve", "--batch", str(path), *geometry, "--centroid-sigma-px", "0.1",
                                     "--json"])
    records = [json.loads(line) for line in out.splitlines()]
    assert status == 1 and err == ""
    assert [r["status"] for r in records] == ["ok", "error", "too_few", "error", "error", "error", "error"]
    assert [r["id"] for r in records] == ["good", "nan", "two", "off", "text", "extra", 7]
    _check_identified(records[0], camera, f, source)
    for record in records[1:]:
        assert record["reason"]
    assert "unknown key(s) fov" in records[5]["reason"]


def test_refit_refines_the_given_camera_and_holds_the_rest(tmp_path, capsys, frame):
    camera, f = frame
    path = tmp_path / "frame.csv"
    np.savetxt(path, np.column_stack([f.uv, f.flux]), delimiter=",")
    for refit in ("centre,k1", "all"):
        status, out, _ = _run(capsys, ["solve", str(path), *GEOMETRY, "--refit", refit, "--centroid-sigma-px", "0.1",
                                       "--json"])
        record = json.loads(out)
        assert status == 0 and record["camera"]["source"] == "refined" and record["method"] == "pattern"
        assert _center_error(record, camera, f.q_IS) < 1e-4
        fitted = record["camera"]
        if refit == "all":  # fitted: within its sigma of the truth, not at the given value
            assert fitted["focal_px"] != camera.focal_px and fitted["k2"] != 0.0
            assert abs(fitted["focal_px"] - camera.focal_px) < 5.0 * fitted["sigma"]["focal_px"]
        else:  # held by a prior of 1e-9 of it (1e-8: ten prior sigmas); k2 held exactly
            assert abs(fitted["focal_px"] / camera.focal_px - 1.0) < 1e-8 and fitted["k2"] == 0.0
            assert fitted["sigma"]["cx"] > 0.0 and fitted["sigma"]["k2"] == 0.0


def test_a_frame_the_given_camera_cannot_identify_says_what_camera_it_shows(tmp_path, capsys, frame):
    _, f = frame
    path = tmp_path / "frame.csv"
    np.savetxt(path, np.column_stack([f.uv, f.flux]), delimiter=",")
    status, out, _ = _run(capsys, ["solve", str(path), "--fov-deg", "16.8", *SIZE, "--centroid-sigma-px", "0.1", "--json"])
    record = json.loads(out)
    assert status == 1 and record["status"] == "no_match" and "q_IS" not in record
    assert "with the given camera (FOV 16.8000 deg). Solved as an unknown camera, the frame shows" in record["reason"]
    shown = re.search(r"FOV (\d+\.\d+) deg \(given 16.8000\)", record["reason"])
    assert shown and abs(float(shown.group(1)) - 16.0) < 0.01


@pytest.mark.parametrize("argv, message", [
    (["solve", "missing.csv", *GEOMETRY], "does not exist"),
    (["solve", *GEOMETRY], "no input"),
    (["solve", "x.csv", "--batch", "y.jsonl", *GEOMETRY], "not both"),
    (["solve", "FILE", "--fov-deg", "nan", "--width", "1024", "--height", "1024"], "--fov-deg"),
    (["solve", "FILE", *GEOMETRY, "--boresight-deg", "12"], "--boresight-deg"),
    (["solve", "FILE", *GEOMETRY, "--boresight-deg", "12,95"], "DEC"),
    (["solve", "FILE", "--fov-deg", "16", "--width", "0", "--height", "1024"], "--width"),
    (["solve", "FILE", "--fov-range-deg", "20,10"], "--fov-range-deg"),
    (["solve", "FILE", "--camera", "no-such-camera.toml"], "does not exist"),
    (["solve", "FILE", "--time-budget-s", "-1"], "--time-budget-s"),
    (["solve", "FILE", "--mesh-px", "3"], "--mesh-px"),
    (["solve", "FILE", "--fov-hint-deg", "inf", *SIZE], "--fov-hint-deg"),
    (["solve", "FILE", *GEOMETRY, "--camera", "cam.toml"], "not both"),
    (["solve", "FILE", *GEOMETRY, "--fov-hint-deg", "16"], "--fov-hint-deg"),
    (["solve", "FILE", *GEOMETRY, "--fov-range-deg", "10,20"], "--fov-range-deg"),
    (["solve", "FILE", *HINT, "--refit", "focal"], "--refit refits a given camera"),
    (["solve", "FILE", *GEOMETRY, "--refit", "focal,zoom"], "--refit"),
    (["solve", "FILE", *GEOMETRY, "--write-camera", "out.toml"], "--write-camera"),
])
def test_bad_options_end_with_one_line(tmp_path, capsys, argv, message):
    path = tmp_path / "frame.csv"
    path.write_text("1,2\n3,4\n5,6\n")
    argv = [str(path) if a == "FILE" else a for a in argv]
    status, out, err = _run(capsys, argv)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


@pytest.mark.parametrize("text, message", [("u,v,w\n1,2,3\n", "header"), ("1,2\n3,x\n", "line 2"),
                                           ("1,2\n3,4,5\n", "columns")])
def test_malformed_csv(tmp_path, capsys, text, message):
    path = tmp_path / "frame.csv"
    path.write_text(text)
    status, _, err = _run(capsys, ["solve", str(path), *GEOMETRY])
    assert status == 2 and message in err


@pytest.mark.parametrize("argv, expected_deg", [
    (["--fov-hint-deg", "1.5"], (1.5 / 1.3, 160.0)),     # below the default range: searched down to it
    (["--fov-hint-deg", "3"], None),                     # inside it (2-160 deg): the default range
    (["--fov-range-deg", "2,20", "--fov-hint-deg", "3"], (2.0, 20.0))])
def test_a_narrow_hint_extends_the_search(argv, expected_deg):
    from startrack.base.units import DEG
    from startrack.commands import build_parser
    from startrack.commands.solve import _fov_range

    found = _fov_range(build_parser().parse_args(["solve", "frame.png", *argv]))
    assert found == expected_deg if expected_deg is None else np.allclose(np.array(found) / DEG, expected_deg)
