"""The camera file: a calibrated camera with its 1-sigma, small TOML, written by ``startrack solve
--write-camera FILE`` and read by :func:`read_camera_file` (and so by a scenario's
``star_sensor.image.camera_file``).

Layout (units in the key names, docs/design.md)::

    [camera]
    width_px = 1024          # required: image size
    height_px = 768
    focal_px = 5120.4        # required: focal length [px]
    cx_px = 515.2            # principal point [px] (default: the image centre)
    cy_px = 386.2
    k1 = 0.119               # radial distortion (default 0)
    k2 = 0.0
    projection = "pinhole"   # or "fisheye" (equidistant; :mod:`startrack.camera.model`), default pinhole
    fov_deg = 11.4206        # angle the width subtends through the middle row (written, not read)

    [sigma]                  # optional: 1-sigma of the same keys
    focal_px = 1.1
    ...

    [fit]                    # optional, written: where the calibration came from
    source = "frame.tiff"
    matched = 154
    rms_px = 0.15

Nothing else is read; an unknown key is an error (a misspelt key would otherwise be ignored).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from startrack.base.errors import InputError

#: Keys of [camera] and [sigma]: (name in the file, Camera field, required).
_CAMERA_KEYS = (("width_px", "width", True), ("height_px", "height", True), ("focal_px", "focal_px", True),
                ("cx_px", "cx", False), ("cy_px", "cy", False), ("k1", "k1", False), ("k2", "k2", False))
_WRITTEN_ONLY = ("fov_deg",)
#: The [camera] key that is text: the projection.
_PROJECTION = "projection"


@dataclass(frozen=True)
class CameraFile:
    """A camera file's content: ``camera`` (:class:`startrack.camera.model.Camera`), ``sigma`` {Camera field:
    1-sigma} for the keys the file gives, ``fit`` (provenance, as written)."""

    camera: object
    sigma: dict = field(default_factory=dict)
    fit: dict = field(default_factory=dict)


def _number(path, key, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"camera file {path}: {key} = {value!r} is not a finite number")
    return value


def read_camera_file(path) -> CameraFile:
    """The :class:`CameraFile` at ``path``; one :class:`InputError` naming the file and the key for any problem."""
    from startrack.camera.model import Camera

    path = Path(path)
    if not path.is_file():
        raise InputError(f"camera file {path} does not exist")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise InputError(f"camera file {path} is not valid TOML ({error})") from None
    unknown = set(data) - {"camera", "sigma", "fit"}
    if unknown or not isinstance(data.get("camera"), dict):
        raise InputError(f"camera file {path} needs a [camera] table and no other than [sigma], [fit]"
                         + (f" (unknown: {', '.join(sorted(unknown))})" if unknown else ""))
    names = {key for key, _, _ in _CAMERA_KEYS}
    for table in ("camera", "sigma"):
        extra = set(data.get(table, {})) - names - (set(_WRITTEN_ONLY) | {_PROJECTION} if table == "camera" else set())
        if extra:
            raise InputError(f"camera file {path}: unknown key(s) {', '.join(f'{table}.{k}' for k in sorted(extra))}")
    values = {}
    for key, name, required in _CAMERA_KEYS:
        if key in data["camera"]:
            values[name] = _number(path, f"camera.{key}", data["camera"][key])
        elif required:
            raise InputError(f"camera file {path}: camera.{key} is missing")
    if _PROJECTION in data["camera"]:
        values["projection"] = data["camera"][_PROJECTION]
        if not isinstance(values["projection"], str):
            raise InputError(f"camera file {path}: camera.projection = {values['projection']!r} is not text")
    sigma = {name: float(_number(path, f"sigma.{key}", data["sigma"][key])) for key, name, _ in _CAMERA_KEYS
             if key in data.get("sigma", {})}
    if any(value < 0.0 for value in sigma.values()):
        raise InputError(f"camera file {path}: a [sigma] value is negative")
    try:
        camera = Camera(**values)
    except InputError as error:
        raise InputError(f"camera file {path}: {error}") from None
    return CameraFile(camera, sigma, dict(data.get("fit", {})))


def write_camera_file(path, calibration, source: str) -> Path:
    """Write the camera of ``calibration`` (:class:`startrack.camera.fit.CameraCalibration`) and its sigma."""
    path = Path(path)
    cam, sigma = calibration.camera, calibration.sigma
    spread = {"width": None, "height": None, "focal_px": sigma["focal_px"], "cx": sigma["cx"], "cy": sigma["cy"],
              "k1": sigma["k1"], "k2": sigma["k2"]}
    lines = ["# startrack camera file: written by `startrack solve --write-camera` (docs/design.md)", "[camera]"]
    lines += [f"{key} = {getattr(cam, name)!r}" for key, name, _ in _CAMERA_KEYS]
    lines += [f"{_PROJECTION} = {_toml_string(cam.projection)}"]
    lines += [f"fov_deg = {math.degrees(cam.angular_width)!r}  # angle the width subtends through the middle row",
              "", "[sigma]"]
    lines += [f"{key} = {spread[name]!r}" for key, name, _ in _CAMERA_KEYS if spread[name] is not None]
    lines += ["", "[fit]", f"source = {_toml_string(source)}", f"matched = {calibration.matched}",
              f"rms_px = {calibration.rms_px!r}", f"reduced_chi2 = {calibration.reduced_chi2!r}", ""]
    try:
        path.write_text("\n".join(lines), encoding="utf-8")
    except OSError as error:
        raise InputError(f"camera file {path} cannot be written ({error})") from None
    return path


def _toml_string(text: str) -> str:
    """A TOML basic string of ``text`` (backslashes and quotes escaped)."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'
