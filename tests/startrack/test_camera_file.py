"""Camera files (startrack.camera.file): written from a calibration, read back, bad files refused."""

import math

import numpy as np
import pytest

from startrack.base.errors import InputError
from startrack.camera.file import read_camera_file, write_camera_file
from startrack.camera.fit import CameraCalibration
from startrack.camera.model import Camera


def test_written_camera_is_read_back_with_its_sigma(tmp_path):
    camera = Camera(1024, 768, 5114.25, cx=514.5, cy=386.25, k1=0.119, k2=0.0)
    covariance = np.diag([1e-9, 1e-9, 1e-9, 0.16, 4.0, 6.25, 1e-4, 0.0])
    path = write_camera_file(tmp_path / "cam.toml", CameraCalibration(camera, covariance, 1.2, 0.15, 150, 160, 8.0),
                             'frame "a".tiff')
    content = read_camera_file(path)
    assert content.camera == camera and read_camera_file(path).camera == camera
    # rounding level: square roots of the diagonal written above
    assert content.sigma == pytest.approx({"focal_px": 0.4, "cx": 2.0, "cy": 2.5, "k1": 0.01, "k2": 0.0})
    assert content.fit["source"] == 'frame "a".tiff' and content.fit["matched"] == 150
    assert f"fov_deg = {math.degrees(camera.angular_width)!r}" in path.read_text()


@pytest.mark.parametrize("text, message", [
    ("[camera]\nwidth_px = 64\nheight_px = 48\n", "camera.focal_px is missing"),
    ("[camera]\nwidth_px = 64\nheight_px = 48\nfocal_px = -5.0\n", "focal_px"),
    ("[camera]\nwidth_px = 64\nheight_px = 48\nfocal_px = 100.0\nzoom = 2\n", "camera.zoom"),
    ("[camera]\nwidth_px = 64\nheight_px = 48\nfocal_px = 100.0\n[sigma]\nk1 = -1.0\n", "negative"),
    ("[camera]\nwidth_px = 64.5\nheight_px = 48\nfocal_px = 100.0\n", "width"),
    ("[camera]\nwidth_px = 64\nheight_px = 48\nfocal_px = 10.0\nk1 = -5.0\n", "not invertible"),
    ("width_px = 64\n", "[camera]"),
    ("[camera\n", "not valid TOML"),
])
def test_bad_camera_files_are_one_input_error(tmp_path, text, message):
    path = tmp_path / "cam.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=message.replace("[", r"\[")) as error:
        read_camera_file(path)
    assert str(path) in str(error.value)


def test_missing_camera_file(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read_camera_file(tmp_path / "none.toml").camera
