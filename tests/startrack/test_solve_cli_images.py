"""``startrack solve`` on images: batches of folders and lists in one process, JPEG and colour input,
bad input (missing, corrupt, empty, all-dark, NaN frames; wrong options) answered with one line."""

import io
import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from PIL import Image

from startrack.cli import main
from startrack.identify import plate_solver
from startrack.image.files import read_image
from tests.support import SteppedClock

FRAMES = sorted((Path(__file__).resolve().parents[1] / "data" / "realsky").glob("*.tiff"))


def _run(capsys, argv):
    status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _as_8_bit(path):
    """The 16-bit (12-bit data scaled by 16) frame stretched to 8 bits between its 0.5 and 99.95 percentiles."""
    image = read_image(path).astype(float)
    low, high = np.percentile(image, [0.5, 99.95])
    return np.clip((image - low) / (high - low) * 255.0, 0, 255).astype(np.uint8)


def test_batch_folder_solves_every_image_and_reports_a_broken_one(tmp_path, capsys):
    folder = tmp_path / "night"
    folder.mkdir()
    for frame in FRAMES[:2]:
        shutil.copy(frame, folder / frame.name)
    (folder / "zz-broken.png").write_bytes(b"not an image")
    (folder / "notes.txt").write_text("not a frame")
    status, out, err = _run(capsys, ["solve", "--batch", str(folder), "--json"])
    records = [json.loads(line) for line in out.splitlines()]
    assert status == 1 and err == ""
    assert [r["status"] for r in records] == ["ok", "ok", "error"]
    assert "could not be read" in records[2]["reason"]
    assert all(r["camera"]["width"] == 1024 and r["detection"]["detections"] > 50 for r in records[:2])


def test_batch_list_of_images_and_several_inputs(tmp_path, capsys):
    listing = tmp_path / "frames.txt"
    listing.write_text("# two frames\n" + "\n".join(str(f) for f in FRAMES[:2]) + "\n")
    status, out, _ = _run(capsys, ["solve", "--batch", str(listing)])
    assert status == 0 and out.count(": ok  ") == 2 and out.count("  centre  RA ") == 2 and out.count("camera (fitted): FOV") == 2
    status, out, _ = _run(capsys, ["solve", str(FRAMES[0]), str(tmp_path / "missing.tiff"), "--json"])
    records = [json.loads(line) for line in out.splitlines()]
    assert status == 1 and [r["status"] for r in records] == ["ok", "error"]


def test_a_stream_on_standard_input_answers_each_line_as_it_comes(tmp_path, capsys, monkeypatch):
    """``--batch -``: image paths and JSON centroid records on stdin, one answer per line in order; a bad
    line is that frame's error, not the stream's end."""
    solved = json.loads(_run(capsys, ["solve", str(FRAMES[0]), "--json"])[1])
    detected = json.loads(_run(capsys, ["detect", str(FRAMES[1]), "--json"])[1])
    centroids = [[s["u"], s["v"], s["flux_dn"]] for s in detected["stars"]]
    lines = [str(FRAMES[0]), "", json.dumps({"id": "list", "centroids": centroids}), str(tmp_path / "gone.png"),
             "{not json"]
    monkeypatch.setattr("sys.stdin", io.StringIO("\n".join(lines) + "\n"))
    status, out, err = _run(capsys, ["solve", "--batch", "-", "--width", "1024", "--height", "768", "--json"])
    records = [json.loads(line) for line in out.splitlines()]
    assert status == 1 and err == ""
    assert [r["status"] for r in records] == ["ok", "ok", "error", "error"]
    assert records[0]["q_IS"] == solved["q_IS"] and records[1]["id"] == "list"
    assert "does not exist" in records[2]["reason"] and "standard input line 5" in records[3]["reason"]


@pytest.mark.parametrize("mode, quality", [("L", 90), ("RGB", 85)])
def test_jpeg_and_colour_frames_are_solved(tmp_path, capsys, mode, quality):
    grey = _as_8_bit(FRAMES[-1])
    picture = Image.fromarray(grey) if mode == "L" else Image.fromarray(np.dstack([grey, grey, grey]))
    path = tmp_path / "frame.jpg"
    picture.save(path, quality=quality)
    status, out, _ = _run(capsys, ["solve", str(path), "--json"])
    record = json.loads(out)
    assert status == 0 and record["status"] == "ok" and abs(record["camera"]["fov_deg"] - 11.42) < 0.02
    assert record["detection"]["full_scale_dn"] == 255.0


def test_all_dark_and_empty_frames_say_why(tmp_path, capsys):
    np.save(tmp_path / "dark.npy", np.zeros((480, 640), np.uint16))
    status, out, err = _run(capsys, ["solve", str(tmp_path / "dark.npy")])
    assert status == 1 and "too_few" in out and "0 detections" in out and "flat" in out and err == ""
    np.save(tmp_path / "empty.npy", np.zeros((0, 5)))
    status, out, err = _run(capsys, ["solve", str(tmp_path / "empty.npy")])
    assert status == 2 and out == "" and err.count("\n") == 1 and "empty" in err


@pytest.mark.parametrize("setup, argv_tail, message", [
    ("nan", [], "NaN"),
    ("corrupt", [], "could not be read"),
    ("missing", [], "does not exist"),
    ("good", ["--fov-range-deg", "5"], "--fov-range-deg"),
    ("good", ["--mag", "10.5"], "--mag"),
    ("good", ["--width", "1000"], "not the 1000 x"),
    ("good", ["--batch", "x"], "not both"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys, setup, argv_tail, message):
    path = tmp_path / ("frame.npy" if setup == "nan" else "frame.png")
    if setup == "nan":
        frame = np.ones((64, 64))
        frame[3, 3] = np.nan
        np.save(path, frame)
    elif setup == "corrupt":
        path.write_bytes(b"\x89PNG broken")
    elif setup == "good":
        path = FRAMES[0]
    status, out, err = _run(capsys, ["solve", str(path), *argv_tail])
    assert status == 2 and out == "" and err.count("\n") == 1 and message in err and "Traceback" not in err


def test_time_budget_ends_a_frame_of_noise_with_its_reason(tmp_path, capsys, monkeypatch):
    # the solver's clock advances 10 ms per look: the 0.05 s budget ends after 5 chunks on any machine
    monkeypatch.setattr(plate_solver, "time", SimpleNamespace(perf_counter=SteppedClock(0.01)))
    rng = np.random.default_rng(41)
    path = tmp_path / "noise.csv"
    np.savetxt(path, np.column_stack([rng.uniform(0, 1023, (400, 2)), rng.uniform(1, 2, 400)]), delimiter=",",
               header="u,v,flux", comments="")
    status, out, _ = _run(capsys, ["solve", str(path), "--width", "1024", "--height", "768", "--time-budget-s", "0.05"])
    assert status == 1 and "no_match" in out and "time budget of 0.05 s" in out


def test_a_fisheye_image_is_solved_as_one_and_its_wcs_is_zpn(tmp_path, capsys):
    """An equisolid fisheye frame of ~100 deg (16-bit PNG): fitted as a fisheye camera, written as a ZPN WCS
    that astropy maps back to the solved image centre, and as a camera file that keeps the projection."""
    from astropy.io import fits
    from astropy.wcs import WCS

    from startrack.base.units import DEG
    from startrack.camera.file import read_camera_file
    from startrack.camera.model import Camera
    from startrack.catalog.hipparcos import load_star_catalog
    from startrack.image.files import write_image
    from startrack.image.synthetic import rendered_sky

    focal = Camera.from_fov(100.0 * DEG, 1024, 768, projection="fisheye").focal_px
    camera = Camera(1024, 768, focal, k1=-1.0 / 24.0, k2=1.0 / 1920.0, projection="fisheye")
    sky = rendered_sky(camera, load_star_catalog(2000.0).brighter_than(8.5), np.random.default_rng(100))
    image = tmp_path / "allsky.png"
    write_image(image, np.round(sky.image / sky.full_scale * 65535.0))
    status, out, err = _run(capsys, ["solve", str(image), "--json", "--wcs", str(tmp_path / "allsky.wcs"),
                                     "--write-camera", str(tmp_path / "allsky.toml")])
    record = json.loads(out)
    assert status == 0 and err == "" and record["camera"]["projection"] == "fisheye"
    assert abs(record["camera"]["fov_deg"] / np.degrees(camera.angular_width) - 1.0) < 1e-3  # 103.5 deg: k1 < 0
    header = fits.getheader(tmp_path / "allsky.wcs")
    assert header["CTYPE1"] == "RA---ZPN" and header["PV2_3"] == pytest.approx(-1.0 / 24.0, abs=1e-3)
    ra, dec = WCS(header).all_pix2world([512.5], [384.5], 1)  # the image centre, FITS pixels
    centre = record["center"]
    assert abs(dec[0] - centre["dec_deg"]) < 1e-6 and abs((ra[0] - centre["ra_deg"] + 180.0) % 360.0 - 180.0) < 1e-6
    assert read_camera_file(tmp_path / "allsky.toml").camera.projection == "fisheye"
