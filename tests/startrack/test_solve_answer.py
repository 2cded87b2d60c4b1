"""``startrack solve``'s answer as astronomers read it (issue 64 item 5): the centre, field, scale, orientation and
parity of a rendered frame of known attitude and of a real frame, checked against the truth, the reference
solution and astropy.wcs on the WCS the solve wrote; ``--annotate``'s PNG, each matched star drawn within 1 px of
where astropy puts its catalog position; 8-bit pictures from ``startrack render``; a stretched JPEG whose 5 sigma
threshold lies above 255; a frame the given camera cannot identify.

Tolerances come from the answer's own sigmas (4 sigma) or from the WCS's 0.02" fidelity (startrack.camera.wcs).
"""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from astropy.coordinates import SkyCoord
from astropy.io import fits
from astropy.wcs import WCS
from PIL import Image

from startrack.base.units import DEG
from startrack.camera.model import Camera
from startrack.cli import main
from startrack.commands import solve_annotate
from startrack.image.files import read_image, stretch_to_8_bit
from startrack.image.render import SensorModel

pytestmark = pytest.mark.filterwarnings("ignore:The WCS transformation has more axes")

REALSKY = Path(__file__).resolve().parents[1] / "data" / "realsky"
REFERENCE = json.loads((REALSKY / "reference.json").read_text())
REAL = "2019-07-29T204726_Alt40_Azi-45_Try1"
#: The rendered field: Orion's belt, 10 deg across 1024 x 768 px, roll 30 deg (up is -30 deg E of N).
RA, DEC, ROLL, FOV = 83.8, -5.4, 30.0, 10.0
RENDER = ["render", "--ra-deg", str(RA), "--dec-deg", str(DEC), "--roll-deg", str(ROLL), "--fov-deg", str(FOV),
          "--width", "1024", "--height", "768", "--seed", "5"]


def _run(capsys, argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    path = tmp_path_factory.mktemp("answer") / "orion.png"
    assert main([*RENDER, "-o", str(path)]) == 0
    return path


def _numbers(pattern, text):
    match = re.search(pattern, text)
    assert match, f"{pattern!r} not in {text!r}"
    return [float(x) for x in match.groups()]


def test_a_rendered_frame_answers_its_attitude_as_astronomers_read_it(rendered, tmp_path, capsys):
    status, out, _ = _run(capsys, ["solve", rendered])
    assert status == 0
    ra, dec, east, north = _numbers(r"centre  RA (\S+) deg  Dec (\S+) deg  \(05:35:1\d\.\d{3}, -05:2\d:\d\d\.\d\d\)  sigma "
                                    r"(\S+)\" E, (\S+)\" N", out)
    offset = SkyCoord(RA, DEC, unit="deg").spherical_offsets_to(SkyCoord(ra, dec, unit="deg"))
    assert abs(offset[0].arcsec) < 4.0 * east and abs(offset[1].arcsec) < 4.0 * north and max(east, north) < 2.0
    width, height, scale, up = _numbers(r"field   (\S+) x (\S+) deg  scale (\S+) arcsec/px  up is (\S+) deg E of N  parity neg",
                                        out)
    camera = Camera.from_fov(FOV * DEG, 1024, 768)
    assert width == pytest.approx(FOV, abs=0.005) and height == pytest.approx(math.degrees(camera.fov_y), abs=0.005)
    assert scale == pytest.approx(1.0 / camera.focal_px / DEG * 3600.0, rel=7e-4)  # f's sigma 1.5e-4
    assert up == pytest.approx(-ROLL, abs=0.02)  # the roll's sigma 13" = 0.004 deg
    assert "top row first, its top is 150.00 deg E of N" in out and re.search(r"ok  \d+ stars matched  false-match", out)
    status, out, _ = _run(capsys, ["solve", rendered, "--json"])
    record = json.loads(out)
    field, centre = record["field"], record["center"]
    assert (centre["ra_deg"], centre["dec_deg"]) == pytest.approx((ra, dec), abs=1e-6)
    for value, printed, decimals in zip((field["width_deg"], field["height_deg"], field["pixel_scale_arcsec"],
                                         field["orientation_deg"]), (width, height, scale, up), (4, 4, 4, 2)):
        assert value == pytest.approx(printed, abs=0.51 * 10.0**-decimals)  # the text's rounding
    assert field["parity"] == "neg" and record["stars_matched"] == len(record["matches"])
    assert centre["ra_hms"].startswith("05:35:1") and centre["dec_dms"].startswith("-05:2")


def _astropy_field(wcs, width, height):
    """(centre SkyCoord, position angle of +y [deg], scale [arcsec/px]) of a WCS at the image centre, by astropy."""
    cu, cv = (width - 1) / 2.0, (height - 1) / 2.0

    def sky(u, v):
        return SkyCoord(*wcs.all_pix2world([u], [v], 0), unit="deg")

    up = sky(cu, cv).position_angle(sky(cu, cv + 0.5)).deg[0]
    scale = math.sqrt(sky(cu - 0.5, cv).separation(sky(cu + 0.5, cv)).arcsec[0]
                      * sky(cu, cv - 0.5).separation(sky(cu, cv + 0.5)).arcsec[0])
    return sky(cu, cv), (up + 180.0) % 360.0 - 180.0, scale


def test_a_real_frame_answers_what_astropy_reads_from_its_wcs_and_the_reference(tmp_path, capsys):
    """The real frame: centre, orientation and scale as astropy.wcs reads them from the written WCS (0.05", 0.005 deg,
    1e-5), and beside cedar-solve's reference (centre within 15", the acceptance of test_plate_solver_real; up
    is -roll within 0.05 deg: its roll at the image centre; FOV within 0.01 deg)."""
    reference = REFERENCE[REAL]
    wcs_path = tmp_path / "real.wcs"
    status, out, _ = _run(capsys, ["solve", REALSKY / f"{REAL}.tiff", "--wcs", wcs_path, "--json"])
    record = json.loads(out)
    assert status == 0
    field, centre = record["field"], record["center"]
    sky, up, scale = _astropy_field(WCS(fits.getheader(wcs_path)), 1024, 768)
    ours = SkyCoord(centre["ra_deg"], centre["dec_deg"], unit="deg")
    assert ours.separation(sky).arcsec[0] < 0.05
    assert field["orientation_deg"] == pytest.approx(up, abs=0.005)
    assert field["pixel_scale_arcsec"] == pytest.approx(scale, rel=1e-5)
    assert ours.separation(SkyCoord(reference["ra_deg"], reference["dec_deg"], unit="deg")).arcsec < 15.0
    assert field["orientation_deg"] == pytest.approx(-reference["roll_deg"], abs=0.05)
    assert field["width_deg"] == pytest.approx(reference["fov_deg"], abs=0.01) and field["parity"] == "neg"


def test_annotate_draws_every_matched_star_where_astropy_puts_it(tmp_path, capsys, monkeypatch):
    """Each matched star's circle lies within 1 px of astropy.wcs's world_to_pixel of its catalog RA/Dec (the
    --corr table's) through the written WCS (in fact within 0.01 px: the WCS's fidelity); the figure's data
    coordinates land on the PNG's pixels; names, detections and the grid are drawn."""
    drawn = {}

    def spy(*args):
        drawn["figure"], drawn["dpi"] = figure(*args)
        return drawn["figure"], drawn["dpi"]

    figure = solve_annotate.annotation_figure
    monkeypatch.setattr(solve_annotate, "annotation_figure", spy)
    png, wcs_path, corr = tmp_path / "real.png", tmp_path / "real.wcs", tmp_path / "real.corr"
    status, out, _ = _run(capsys, ["solve", REALSKY / f"{REAL}.tiff", "--annotate", png, "--wcs", wcs_path, "--corr",
                                   corr, "--json"])
    record = json.loads(out)
    assert status == 0
    ax = drawn["figure"].axes[0]
    artists = {c.get_gid(): c for c in ax.collections}
    circles = artists["matched"].get_offsets()
    table = fits.getdata(corr, 1)
    expected = np.stack(WCS(fits.getheader(wcs_path)).all_world2pix(table["index_ra"], table["index_dec"], 0), axis=1)
    assert len(circles) == len(record["matches"]) == len(table)
    assert np.hypot(*(circles - expected).T).max() < 1.0
    assert np.hypot(*(circles - expected).T).max() < 0.01
    names = [t for t in ax.texts if t.get_gid() == "names"]
    assert len(names) == len(circles) and all(re.match(r"(HIP|Gaia DR3) \d+ [A-Z][A-Za-z]{2} V -?\d", t.get_text())
                                              for t in names)
    assert np.allclose([t.xy for t in names], circles)
    assert {"HIP 54061 UMa V 1.8", "HIP 53910 UMa V 2.5"} <= {t.get_text() for t in names}  # Dubhe and Merak
    assert len(artists["detections"].get_offsets()) == record["detection"]["detections"]
    assert sum(line.get_gid() == "grid" for line in ax.lines) >= 4
    with Image.open(png) as image:
        assert image.size == (1024, 768)
    scale = drawn["dpi"] / 100.0  # data (u, v) -> PNG pixel centre (u + 0.5, v + 0.5) scaled
    display = ax.transData.transform(circles)
    png_xy = np.stack([display[:, 0], 768 * scale - display[:, 1]], axis=1)
    assert np.abs(png_xy - (circles + 0.5) * scale).max() < 0.01


def test_render_writes_8_bit_pictures_of_the_documented_stretch(tmp_path, capsys):
    """--bits 8 is the 16-bit frame (same seed) through level = round(255 (DN - BLACK) / (WHITE - BLACK)); the
    defaults are BLACK = b - 3 sigma_n, WHITE = BLACK + 255 sigma_n; a JPEG is written and read back as 8-bit."""
    counts, levels, jpeg = tmp_path / "c.png", tmp_path / "l.png", tmp_path / "l.jpg"
    small = ["render", "--ra-deg", "83.8", "--dec-deg", "-5.4", "--width", "256", "--height", "192", "--seed", "2"]
    assert _run(capsys, [*small, "-o", counts])[0] == 0
    status, out, _ = _run(capsys, [*small, "-o", levels, "--bits", "8", "--json"])
    summary = json.loads(out)
    sensor = SensorModel()
    black, white = sensor.background_dn - 3.0 * sensor.noise_dn, sensor.background_dn + 252.0 * sensor.noise_dn
    assert summary["stretch"] == pytest.approx({"black_dn": black, "white_dn": white})
    expected = np.clip(np.rint(255.0 * (read_image(counts).astype(float) - black) / (white - black)), 0, 255)
    assert np.array_equal(read_image(levels), expected)
    assert np.array_equal(expected, stretch_to_8_bit(read_image(counts), black, white))
    assert _run(capsys, [*small, "-o", jpeg])[0] == 0
    with Image.open(jpeg) as image:
        assert image.format == "JPEG" and image.mode == "L"


@pytest.mark.parametrize("argv, words", [
    (["-o", "{tmp}/x.npy", "--bits", "8"], "sets the bits of a .png"),
    (["-o", "{tmp}/x.jpg", "--bits", "16"], "a JPEG holds 8 bits"),
    (["-o", "{tmp}/x.png", "--white-dn", "300"], "8-bit picture"),
    (["-o", "{tmp}/x.jpg", "--black-dn", "300", "--white-dn", "200"], "must lie below"),
    (["-o", "{tmp}/x.jpg", "--black-dn", "nan"], "--black-dn"),
])
def test_bad_picture_options_are_one_line(tmp_path, capsys, argv, words):
    status, out, err = _run(capsys, ["render", "--ra-deg", "1", "--dec-deg", "2",
                                     *[a.replace("{tmp}", str(tmp_path)) for a in argv]])
    assert status == 2 and out == "" and err.count("\n") == 1 and words in err


def test_a_stretched_jpeg_whose_threshold_passes_255_solves(tmp_path, capsys):
    """The issue's picture: the rendered field as a JPEG stretched to a background of 155 and a noise of 32 of 255
    (b + 5 sigma_n = 315): detected at its clipped stars, it solves to the rendered attitude (4 sigma)."""
    sensor = SensorModel()
    gain = 32.0 / sensor.noise_dn  # levels per DN
    black = sensor.background_dn - 155.0 / gain
    path = tmp_path / "stretched.jpg"
    assert _run(capsys, [*RENDER, "-o", path, "--black-dn", black, "--white-dn", black + 255.0 / gain])[0] == 0
    image = read_image(path).astype(float)
    median = np.median(image)
    assert median == pytest.approx(155.0, abs=3.0) and 1.4826 * np.median(np.abs(image - median)) == pytest.approx(32.0, abs=3.0)
    status, out, _ = _run(capsys, ["solve", path, "--json"])
    record = json.loads(out)
    assert status == 0 and record["detection"]["clipped"] and record["detection"]["threshold_dn"] == 254.5
    centre = record["center"]
    offset = SkyCoord(RA, DEC, unit="deg").spherical_offsets_to(SkyCoord(centre["ra_deg"], centre["dec_deg"], unit="deg"))
    assert abs(offset[0].arcsec) < 4.0 * centre["sigma_arcsec"][0] and abs(offset[1].arcsec) < 4.0 * centre["sigma_arcsec"][1]
    assert record["field"]["orientation_deg"] == pytest.approx(-ROLL, abs=0.05)
    status, out, _ = _run(capsys, ["solve", path])
    assert "detection: b + a sigma_n lies above the full scale" in out


def test_a_frame_the_given_camera_cannot_identify_names_the_camera_its_stars_show(rendered, capsys):
    """A 10 deg frame solved with --fov-deg 16: no_match, and the reason gives the field and scale its stars show
    (a search of the whole default range) and the option that solves it."""
    status, out, _ = _run(capsys, ["solve", rendered, "--fov-deg", "16", "--json"])
    record = json.loads(out)
    assert status == 1 and record["status"] == "no_match"
    shown = _numbers(r"FOV (\d+\.\d+) deg \(given 16\.0000\), scale (\d+\.\d+) arcsec/px", record["reason"])
    scale = 1.0 / Camera.from_fov(FOV * DEG, 1024, 768).focal_px / DEG * 3600.0
    assert shown[0] == pytest.approx(FOV, abs=0.01) and shown[1] == pytest.approx(scale, rel=1e-3)
    option = _numbers(r"--fov-deg (\d+\.\d+)", record["reason"])[0]
    status, out, _ = _run(capsys, ["solve", rendered, "--fov-deg", str(option), "--json"])
    assert status == 0 and json.loads(out)["camera"]["source"] == "given"
