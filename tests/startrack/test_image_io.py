"""Frame files (PNG/TIFF/NPY) and the ``startrack render`` / ``startrack detect`` commands."""

import json

import numpy as np
import pytest
from PIL import Image
from scipy.spatial import cKDTree

from startrack.base.errors import InputError
from startrack.cli import main
from startrack.image.files import full_scale, read_frame, read_image, write_image


def _frame():
    return (np.arange(48 * 64).reshape(48, 64) * 7 % 4096).astype(np.uint16)


@pytest.mark.parametrize("name", ["f.png", "f.npy"])
def test_write_read_round_trip(tmp_path, name):
    frame = _frame()
    read = read_image(write_image(tmp_path / name, frame))
    assert read.dtype == np.uint16
    np.testing.assert_array_equal(read, frame)


def test_png_is_16_bit_and_tiff_and_float_npy_read(tmp_path):
    frame = _frame()
    write_image(tmp_path / "f.png", frame)
    with Image.open(tmp_path / "f.png") as image:
        assert image.mode.startswith("I")
    Image.fromarray(frame).save(tmp_path / "f.tif")
    np.testing.assert_array_equal(read_image(tmp_path / "f.tif"), frame)
    np.save(tmp_path / "g.npy", frame.astype(float) + 0.25)
    read = read_image(tmp_path / "g.npy")
    assert read.dtype == np.float64 and read[0, 1] == 7.25


def test_bad_image_files(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read_image(tmp_path / "missing.png")
    (tmp_path / "junk.png").write_text("not a png")
    with pytest.raises(InputError, match="could not be read"):
        read_image(tmp_path / "junk.png")
    np.save(tmp_path / "cube.npy", np.zeros((2, 3, 4)))
    with pytest.raises(InputError, match="2-D"):
        read_image(tmp_path / "cube.npy")
    bad = np.zeros((4, 4))
    bad[1, 1] = np.nan
    np.save(tmp_path / "nan.npy", bad)
    with pytest.raises(InputError, match="NaN"):
        read_image(tmp_path / "nan.npy")
    np.save(tmp_path / "obj.npy", np.array([{"a": 1}], dtype=object))
    with pytest.raises(InputError, match="not a readable"):
        read_image(tmp_path / "obj.npy")
    (tmp_path / "f.jpg").write_text("x")
    with pytest.raises(InputError, match="could not be read"):
        read_image(tmp_path / "f.jpg")
    (tmp_path / "f.bmp").write_text("x")
    with pytest.raises(InputError, match="suffix"):
        read_image(tmp_path / "f.bmp")
    with pytest.raises(InputError, match=".png"):
        write_image(tmp_path / "f.bmp", _frame())


def test_render_then_detect_command_line(tmp_path, capsys):
    out = tmp_path / "frame.png"
    assert main(["render", "--ra-deg", "195", "--dec-deg", "0", "--fov-deg", "20", "--width", "512",
                 "--height", "512", "--seed", "3", "--json", "-o", str(out)]) == 0
    rendered = json.loads(capsys.readouterr().out)
    assert rendered["stars_in_image"] >= 5
    assert main(["detect", str(out), "--json"]) == 0
    found = json.loads(capsys.readouterr().out)
    uv = np.array([[s["u"], s["v"]] for s in found["stars"]])
    truth = np.array(rendered["uv_true"])
    dist, _ = cKDTree(uv).query(truth)
    assert np.sum(dist < 0.3) >= 0.8 * len(truth)
    assert main(["detect", str(out)]) == 0
    assert "V_th" in capsys.readouterr().out
    again = tmp_path / "again.npy"
    main(["render", "--ra-deg", "195", "--dec-deg", "0", "--fov-deg", "20", "--width", "512",
          "--height", "512", "--seed", "3", "-o", str(again)])
    np.testing.assert_array_equal(read_image(again), read_image(out))


def test_command_line_bad_input_exits_2(tmp_path, capsys):
    assert main(["detect", str(tmp_path / "none.png")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert main(["render", "--ra-deg", "nan", "--dec-deg", "0", "-o", str(tmp_path / "x.png")]) == 2
    assert "--ra-deg" in capsys.readouterr().err
    assert main(["render", "--ra-deg", "10", "--dec-deg", "0", "-o", str(tmp_path / "x.bmp")]) == 2
    assert ".jpg" in capsys.readouterr().err  # a JPEG is written (8-bit, tests/startrack/test_solve_answer.py)
    assert main(["render", "--ra-deg", "10", "--dec-deg", "0", "--rate-deg-s", "1,2", "-o",
                 str(tmp_path / "x.png")]) == 2
    assert "--rate-deg-s" in capsys.readouterr().err


def test_colour_and_jpeg_frames_are_read_as_luminance(tmp_path):
    rng = np.random.default_rng(21)
    rgb = rng.integers(0, 256, (24, 32, 3), dtype=np.uint8)
    Image.fromarray(rgb).save(tmp_path / "c.png")
    frame = read_frame(tmp_path / "c.png")
    expected = rgb.astype(float) @ [0.299, 0.587, 0.114]  # ITU-R BT.601 luma
    np.testing.assert_allclose(frame.image, expected, atol=1e-9)  # rounding level: the same weighted sum
    assert frame.full_scale == 255.0
    grey = np.full((40, 48), 30, np.uint8)
    grey[20, 24] = 250
    Image.fromarray(grey).save(tmp_path / "g.jpg", quality=95)
    jpeg = read_frame(tmp_path / "g.jpg")
    assert jpeg.image.shape == (40, 48) and jpeg.full_scale == 255.0
    assert np.unravel_index(np.argmax(jpeg.image), jpeg.image.shape) == (20, 24)
    Image.fromarray(rgb).save(tmp_path / "c.jpg", quality=90)
    assert read_frame(tmp_path / "c.jpg").image.dtype == np.float64


@pytest.mark.parametrize("values, scale", [
    ([0, 17, 4095], 4095.0),                       # 12-bit
    ([0, 16 * 3, 16 * 4095, 65535], 65520.0),      # 12-bit data scaled by 16, a clipped 65535
    ([1, 255], 255.0),                             # 8-bit widened
    ([3, 40000], 65535.0),                         # 16-bit
    ([5, 1000], 1023.0),                           # 10-bit
])
def test_full_scale_from_the_bit_depth(values, scale):
    assert full_scale(np.array(values, dtype=np.uint16).reshape(1, -1)) == scale
    assert full_scale(np.array([[0.5, 2.0]])) is None
