"""FITS in, WCS out (issue 32): the TAN-SIP header of a solution read back by astropy.wcs, independent
software, against startrack's own camera model; ``startrack solve`` on FITS frames (rendered, and the real
frames of tests/data/realsky converted to FITS) with ``--wcs``, ``--new-fits`` and ``--corr``; the
observation's epoch from DATE-OBS; pixels without data; bad FITS input.

Tolerances: the SIP polynomials are fitted to 0.02" of the camera model (startrack.camera.wcs), so astropy's
pixel-to-sky map must agree with the model within 0.1" anywhere on the image (the issue's figure) and each
matched star's residual through the WCS with the solver's own residual within the same 0.1".
"""

import datetime
import json
import math
from pathlib import Path

import numpy as np
import pytest
from astropy.io import fits
from astropy.wcs import WCS

from startrack.base.units import ARCSEC, DEG
from startrack.camera.model import Camera
from startrack.camera.wcs import frame_wcs
from startrack.cli import main
from startrack.geometry.rotation import from_rotation_vector, to_matrix
from startrack.geometry.sphere import radec_to_vector
from startrack.image.files import read_frame
from tests.support import run_cli

#: astropy notes that a .wcs file (a header without data, as astrometry.net writes them) has no image axes.
pytestmark = pytest.mark.filterwarnings("ignore:The WCS transformation has more axes")

REALSKY = Path(__file__).resolve().parents[1] / "data" / "realsky"
REFERENCE = json.loads((REALSKY / "reference.json").read_text())

CAMERAS = {  # (fov [deg], width, height, cx, cy, k1, k2)
    "pinhole": (12.0, 1024, 768, None, None, 0.0, 0.0),
    "barrel": (20.0, 1600, 1200, 810.3, 590.7, -0.1, 0.01),
    "pincushion": (20.0, 1280, 960, 630.0, 470.0, 0.05, 0.0),
    "wide": (40.0, 2000, 1500, 1003.0, 748.0, -0.2, 0.02),
}
ATTITUDES = {"mid": [0.3, -1.1, 0.7], "north pole": [0.0, 0.0, 0.0], "south pole": [math.pi, 0.0, 0.0],
             "ra0": [1.5, 2.0, -0.2]}


def _camera(name):
    fov, width, height, cx, cy, k1, k2 = CAMERAS[name]
    return Camera.from_fov(fov * DEG, width, height, cx=cx, cy=cy, k1=k1, k2=k2)


def _angle(a, b):
    """Angles [rad] between rows of a and b (atan2: exact for small angles)."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))


def _wcs(solution):
    return WCS(fits.Header(solution.cards()))


@pytest.mark.parametrize("attitude", ATTITUDES)
@pytest.mark.parametrize("name", CAMERAS)
def test_astropy_reads_the_wcs_as_the_camera_model(name, attitude):
    """astropy.wcs maps every pixel of a grid over the image (edges included) to the camera model's direction
    within 0.1", and the directions back to their pixels within 0.01 px through the inverse polynomials."""
    camera = _camera(name)
    q = from_rotation_vector(np.array(ATTITUDES[attitude]))
    wcs = _wcs(frame_wcs(camera, q))
    u, v = np.meshgrid(np.linspace(-0.5, camera.width - 0.5, 33), np.linspace(-0.5, camera.height - 0.5, 25))
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    ra, dec = wcs.all_pix2world(uv[:, 0] + 1.0, uv[:, 1] + 1.0, 1)
    model = camera.unproject(uv) @ to_matrix(q).T
    assert _angle(radec_to_vector(ra * DEG, dec * DEG), model).max() < 0.1 * ARCSEC
    focal = np.stack(wcs.wcs_world2pix(ra, dec, 1), axis=1)  # the undistorted pixel, then AP/BP about CRPIX
    back = wcs.sip_foc2pix(focal - wcs.wcs.crpix, 1) if wcs.sip is not None else focal
    assert np.abs(back - (uv + 1.0)).max() < 0.01


def test_a_pinhole_is_plain_tan_and_its_cd_is_the_pixel_scale():
    camera = _camera("pinhole")
    solution = frame_wcs(camera, from_rotation_vector(np.array(ATTITUDES["mid"])))
    header = dict((k, v) for k, v, _ in solution.cards())
    assert header["CTYPE1"] == "RA---TAN" and "A_ORDER" not in header
    scale = math.sqrt(abs(np.linalg.det(solution.cd)))
    assert scale == pytest.approx(math.degrees(1.0 / camera.focal_px), rel=1e-12)


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """A rendered 20 deg frame written as FITS with DATE-OBS and EXPTIME."""
    folder = tmp_path_factory.mktemp("fits")
    png = folder / "orion.png"
    assert main(["render", "--ra-deg", "83.8", "--dec-deg", "-5.4", "--roll-deg", "30", "--fov-deg", "20",
                 "--width", "1280", "--height", "960", "-o", str(png)]) == 0
    image = read_frame(png).image
    header = fits.Header([("DATE-OBS", "2024-01-15T06:00:00"), ("EXPTIME", 60.0)])
    path = folder / "orion.fits"
    fits.PrimaryHDU(image, header=header).writeto(path)
    return path


def _solve(capsys, *argv):
    """(exit status, stderr, the JSON records) of ``startrack solve ARGV --json``."""
    status = main([str(a) for a in ("solve", *argv, "--json")])
    captured = capsys.readouterr()
    return status, captured.err, [json.loads(line) for line in captured.out.splitlines() if line.startswith("{")]


def test_solve_a_fits_frame_and_write_its_wcs_image_and_matches(rendered, tmp_path, capsys):
    out = {k: tmp_path / f"orion.{k}" for k in ("wcs", "new", "corr")}
    status, err, records = _solve(capsys, rendered, "--wcs", out["wcs"], "--new-fits", out["new"], "--corr", out["corr"])
    assert status == 0, err
    record = records[0]
    middle = datetime.datetime(2024, 1, 15, 6, 0, 30) - datetime.datetime(2000, 1, 1, 12)  # DATE-OBS + EXPTIME / 2
    assert abs(record["epoch"] - (2000.0 + middle / datetime.timedelta(days=365.25))) <= 0.0005 + 1e-9
    wcs = WCS(fits.getheader(out["wcs"]))
    corr = fits.getdata(out["corr"], 1)
    assert len(corr) == len(record["matches"])
    assert [int(i) for i in corr["index_id"]] == [h for _, h in record["matches"]]
    ra, dec = wcs.all_pix2world(corr["field_x"], corr["field_y"], 1)
    through_wcs = _angle(radec_to_vector(ra * DEG, dec * DEG), radec_to_vector(corr["index_ra"] * DEG,
                                                                                corr["index_dec"] * DEG))
    assert np.abs(through_wcs / ARCSEC - np.array(record["residuals_arcsec"])).max() < 0.1
    with fits.open(out["new"]) as new:
        assert np.array_equal(new[0].data, fits.getdata(rendered))
        assert new[0].header["DATE-OBS"] == "2024-01-15T06:00:00"
        assert WCS(new[0].header).wcs.ctype[0].startswith("RA---TAN")


def test_the_epoch_is_the_given_one_over_the_frames(rendered, capsys):
    status, err, records = _solve(capsys, rendered, "--epoch", "2010.5")
    assert status == 0, err
    assert records[0]["epoch"] == 2010.5


def test_pixels_without_data_are_masked(rendered, tmp_path, capsys):
    """A block of NaN pixels (a cut edge at its border) yields no detection near it; the frame still solves."""
    image = fits.getdata(rendered).astype(np.float32)
    image[300:500, 200:700] = np.nan
    path = tmp_path / "holes.fits"
    fits.PrimaryHDU(image).writeto(path)
    assert main(["detect", str(path), "--json"]) == 0
    stars = json.loads(capsys.readouterr().out)["stars"]
    assert stars and not any(297 <= s["v"] <= 502 and 197 <= s["u"] <= 702 for s in stars)
    status, err, records = _solve(capsys, path)
    assert status == 0 and records[0]["status"] == "ok", err


def test_gzipped_and_tile_compressed_fits_read_as_the_plain_file(rendered, tmp_path, capsys):
    """m42.fits.gz (gzip) and m42.fits.fz (fpack's lossless Rice tiles in HDU 1) give the plain file's detections;
    --wcs with {stem} names the outputs without the suffixes."""
    image = fits.getdata(rendered)
    fits.PrimaryHDU(image).writeto(tmp_path / "m42.fits.gz")
    fits.HDUList([fits.PrimaryHDU(), fits.CompImageHDU(image)]).writeto(tmp_path / "m43.fits.fz")
    stars = []
    for path in (rendered, tmp_path / "m42.fits.gz", tmp_path / "m43.fits.fz"):
        assert main(["detect", str(path), "--json"]) == 0
        stars.append(json.loads(capsys.readouterr().out)["stars"])
    assert stars[1] == stars[0] and stars[2] == stars[0]
    status, err, records = _solve(capsys, tmp_path / "m42.fits.gz", tmp_path / "m43.fits.fz", "--wcs",
                                  tmp_path / "{stem}.wcs")
    assert status == 0, err
    assert (tmp_path / "m42.wcs").is_file() and (tmp_path / "m43.wcs").is_file()


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_real_frames_as_fits_solve_to_the_reference(name, tmp_path, capsys):
    """The real frames converted to FITS (16-bit, a second HDU selected by --hdu) solve to the same image centre
    as the TIFF within 15" (the acceptance of test_plate_solver_real), and the WCS puts the centre pixel there."""
    reference = REFERENCE[name]
    image = read_frame(REALSKY / f"{name}.tiff").image
    path = tmp_path / f"{name}.fits"
    fits.HDUList([fits.PrimaryHDU(), fits.ImageHDU(image)]).writeto(path)
    wcs_path = tmp_path / "frame.wcs"
    status, err, records = _solve(capsys, path, "--hdu", "1", "--wcs", wcs_path)
    assert status == 0, err
    centre = records[0]["center"]
    wcs = WCS(fits.getheader(wcs_path))
    ra, dec = wcs.all_pix2world([(reference["width"] + 1) / 2.0], [(reference["height"] + 1) / 2.0], 1)
    ours = radec_to_vector(np.radians(ra), np.radians(dec))
    assert _angle(ours, radec_to_vector(math.radians(centre["ra_deg"]), math.radians(centre["dec_deg"]))[None])[0] < 0.1 * ARCSEC
    if name != "2019-07-29T204726_Alt40_Azi45_Try1":  # cedar-solve's own attitude is 90" off there
        truth = radec_to_vector(math.radians(reference["ra_deg"]), math.radians(reference["dec_deg"]))
        assert _angle(ours, truth[None])[0] < 15.0 * ARCSEC


def _no_image(path):
    fits.HDUList([fits.PrimaryHDU(), fits.BinTableHDU.from_columns([fits.Column("x", "D", array=[1.0])])]).writeto(path)


def _cube(path):
    fits.PrimaryHDU(np.zeros((3, 64, 64), np.float32)).writeto(path)


def _all_nan(path):
    fits.PrimaryHDU(np.full((64, 64), np.nan, np.float32)).writeto(path)


def _corrupt_header(path):
    path.write_bytes(b"SIMPLE  =                    T / not really" + b"\x00\xff" * 1500)


def _bad_date(path):
    fits.PrimaryHDU(np.zeros((64, 64), np.uint16), header=fits.Header([("DATE-OBS", "15/01/24")])).writeto(path)


BAD_FITS = {"no image HDU": (_no_image, "holds no image HDU"), "3-D cube": (_cube, "3-D array"),
            "all NaN": (_all_nan, "no finite pixel"), "corrupt header": (_corrupt_header, "not a readable FITS file"),
            "bad DATE-OBS": (_bad_date, "DATE-OBS")}


@pytest.mark.parametrize("case", BAD_FITS)
def test_a_bad_fits_file_is_one_clear_line(case, tmp_path, capsys):
    make, words = BAD_FITS[case]
    path = tmp_path / "bad.fits"
    make(path)
    status, err = run_cli(main, ["solve", path, "--wcs", tmp_path / "out.wcs"], capsys)
    assert status == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == [path]  # nothing written, half or whole


@pytest.mark.parametrize("argv, words", [
    (["--wcs", "/proc/forbidden/x.wcs"], "--wcs /proc/forbidden/x.wcs"),
    (["--corr", "{folder}/x.txt"], "must end in"),
    (["--hdu", "3"], "--hdu 3"),
])
def test_bad_output_options_are_one_clear_line(rendered, tmp_path, capsys, argv, words):
    argv = [a.replace("{folder}", str(tmp_path)) for a in argv]
    status, err = run_cli(main, ["solve", rendered, *argv], capsys)
    assert status == 2 and words in err and len(err.strip().splitlines()) == 1, err


def test_several_frames_need_a_stem(rendered, tmp_path, capsys):
    status, err = run_cli(main, ["solve", rendered, rendered, "--wcs", tmp_path / "one.wcs"], capsys)
    assert status == 2 and "{stem}" in err
