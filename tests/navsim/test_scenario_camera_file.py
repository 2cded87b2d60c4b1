"""``star_sensor.image.camera_file``: a calibrated camera (``startrack solve --write-camera``) in a scenario."""

from pathlib import Path

import pytest

from navsim.build.star_sensor import image_star_sensor
from navsim.kinds import load_scenario
from startrack.base.errors import InputError
from startrack.catalog.hipparcos import load_star_catalog

CAMERA = """[camera]
width_px = 640
height_px = 480
focal_px = 2600.5
cx_px = 322.25
cy_px = 236.75
k1 = -0.08
k2 = 0.0
fov_deg = 14.0

[sigma]
focal_px = 0.4
"""


DEMO = Path(__file__).resolve().parents[2] / "scenarios" / "demo.toml"


def _scenario_file(folder, camera_file):
    """The demo scenario (image fidelity) in ``folder`` with ``camera_file`` (a path relative to it)."""
    text = DEMO.read_text(encoding="utf-8").replace("[star_sensor.image]",
                                                    f'[star_sensor.image]\ncamera_file = "{camera_file}"')
    path = folder / "scenario.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_camera_file_sets_the_image_sensor_camera(tmp_path):
    (tmp_path / "cameras").mkdir()
    (tmp_path / "cameras" / "mine.toml").write_text(CAMERA, encoding="utf-8")
    path = _scenario_file(tmp_path, "cameras/mine.toml")
    scenario = load_scenario(path)
    image = scenario["star_sensor"]["image"]
    assert (image["width_px"], image["height_px"]) == (640, 480)
    sensor = image_star_sensor(scenario, load_star_catalog(2000.0), [0.0, 0.0, 0.0, 1.0], None, 2000.0)
    camera = sensor.camera
    assert (camera.width, camera.height, camera.focal_px, camera.cx, camera.cy, camera.k1) == (
        640, 480, 2600.5, 322.25, 236.75, -0.08)
    assert camera.circular_fov  # the scenario's field shape is kept


@pytest.mark.parametrize("content, message", [
    (None, "does not exist"),
    ("[camera]\nwidth_px = 640\n", "camera.height_px is missing"),
    ("[camera\n", "not valid TOML"),
    (CAMERA.replace("k1 = -0.08", "k1 = nan"), "camera.k1"),
    (CAMERA + "\n[lens]\nmodel = 1\n", "unknown"),
])
def test_missing_or_bad_camera_file_is_one_input_error(tmp_path, content, message):
    if content is not None:
        (tmp_path / "camera.toml").write_text(content, encoding="utf-8")
    path = _scenario_file(tmp_path, "camera.toml")
    with pytest.raises(InputError) as error:
        load_scenario(path)
    text = str(error.value)
    assert "star_sensor.image.camera_file" in text and message in text and "\n" not in text
