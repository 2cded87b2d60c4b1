"""How ``startrack solve`` identifies a frame: with the camera it is given, or with the camera it fits.

* **given camera** (``--camera FILE``, or ``--fov-deg F`` with the frame's size: an ideal pinhole, principal
  point at the centre of the pixel grid, no distortion): a star tracker's identification
  (:class:`startrack.identify.calibrated.CalibratedSolver`, one per camera); the attitude is that camera's.
  A frame it cannot identify is solved once more as from an unknown camera, and its reason gives the
  camera the stars show beside the given one (it stays ``no_match``: refitting is asked for with
  ``--refit``);
* **refined camera** (a given camera and ``--refit focal,centre,k1,k2``): the plate solver from the given
  camera, the intrinsics named refitted per frame, the others held;
* **fitted camera** (no geometry): the plate solver (:class:`startrack.identify.plate_solver.PlateSolver`),
  with ``--fov-hint-deg`` / ``--fov-range-deg``.

Every solver is built on first use, so a single bad INPUT fails before the catalogs are loaded.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from startrack.base.errors import InputError

#: Centroid sigma [px] of centroid lists and of a given camera's gates when neither the option nor the
#: camera file's fit gives one.
_DEFAULT_CENTROID_SIGMA_PX = 0.3
#: A frame's own epoch is rounded to this step [Julian years] (8.8 h: 0.005" of the fastest proper motion,
#: 10"/yr), so that the frames of a night share one solver.
_EPOCH_STEP_YEARS = 0.001


def parse_refit(text):
    """The intrinsics of ``--refit`` (comma-separated names of :data:`REFIT`, or ``all``)."""
    from startrack.identify.plate_solver import REFIT

    names = tuple(REFIT) if text.strip() == "all" else tuple(n.strip() for n in text.split(","))
    unknown = [n for n in names if n not in REFIT]
    if unknown or not names:
        raise InputError(f"option --refit = {text!r}: give some of {','.join(REFIT)} (comma-separated) or all.")
    return names


def centroid_sigma(option, camera_file):
    """The centroid sigma [px]: the option's, else the camera file's fit RMS, else the default."""
    if option is not None:
        return option
    rms = None if camera_file is None else camera_file.fit.get("rms_px")
    if isinstance(rms, (int, float)) and not isinstance(rms, bool) and 0.0 < rms <= 100.0:
        return float(rms)
    return _DEFAULT_CENTROID_SIGMA_PX


class FrameSolver:
    """The solve of every frame of one ``startrack solve`` run.

    camera_file: a :class:`startrack.camera.file.CameraFile` or None; fov: the field of view [rad] of an
    ideal pinhole of the frame's size, or None; refit: intrinsics refitted (None: the camera is used as
    given); sigma_px: centroid sigma of centroid lists and of the given camera's gates [px]; plate:
    keyword arguments of the plate solver (but the epoch); fov_hint [rad] or None; mag_limit, threshold as
    the solvers take them; epoch [Julian year] of the star positions, or None: each frame's own
    (:meth:`epoch_of`).
    """

    def __init__(self, camera_file, fov, refit, sigma_px, plate, fov_hint, mag_limit, epoch, threshold):
        self.camera_file, self.fov, self.refit, self.sigma_px = camera_file, fov, refit, sigma_px
        self.plate_options, self.fov_hint = plate, fov_hint
        self.mag_limit, self.epoch, self.threshold = mag_limit, epoch, threshold
        self._plates, self._calibrated = {}, {}

    @property
    def given(self):
        """True when the frames come with their camera."""
        return self.camera_file is not None or self.fov is not None

    def prepare(self):
        """Build the solver of the frames to come now (catalogs, compiled kernels), for a stream whose first
        frame must not wait for them: the epoch given or J2000 (a frame of another epoch builds its own)."""
        epoch = 2000.0 if self.epoch is None else self.epoch
        if not self.given or self.refit is not None:
            self.plate(epoch)
        elif self.camera_file is not None:
            self._calibrated_solver(self.camera_file.camera, epoch)

    def epoch_of(self, frame):
        """The epoch of a frame's star positions [Julian year]: the given one, else the frame's observation's
        to :data:`_EPOCH_STEP_YEARS` (one solver per step), else J2000."""
        if self.epoch is not None:
            return self.epoch
        if frame.epoch is None:
            return 2000.0
        return round(frame.epoch / _EPOCH_STEP_YEARS) * _EPOCH_STEP_YEARS

    def solve(self, frame, boresight):
        """The :class:`startrack.identify.result.IdentificationResult` of a readable ``SolveFrame``."""
        sigma = frame.sigma if frame.sigma is not None else np.full(len(frame.uv), self.sigma_px)
        epoch = self.epoch_of(frame)
        if not self.given:
            return self.plate(epoch).solve(frame.uv, frame.width, frame.height, frame.flux, sigma, fov_hint=self.fov_hint,
                                    boresight=boresight)
        known = self._camera_file(frame.width, frame.height)
        if self.refit is not None:
            return self.plate(epoch).solve(frame.uv, frame.width, frame.height, frame.flux, sigma, camera=known,
                                    refit=self.refit, boresight=boresight)
        weights = None  # centroid lists: the stated sigma of the identifier's gates
        if frame.sigma is not None:  # a detection's sigma leaves out the PSF's and pixels' own errors
            from startrack.identify.plate_solver import SIGMA_FLOOR_PX

            weights = np.hypot(frame.sigma, SIGMA_FLOOR_PX)
        result = self._calibrated_solver(known.camera, epoch).solve(frame.uv, frame.width, frame.height, frame.flux, weights,
                                                              boresight=boresight)
        return self._diagnosed(result, frame, known, sigma, boresight, epoch) if result.status == "no_match" else result

    # ------------------------------------------------------------------ internals
    def plate(self, epoch, search=None):
        """The plate solver of the star positions at ``epoch``, of the options' field-of-view range or of
        ``search`` (a range [rad], or "default": the plate solver's whole default range)."""
        options = self.plate_options if search is None else\
            {**self.plate_options, "fov_range": None if search == "default" else search}
        key = (epoch, options["fov_range"])
        if key not in self._plates:
            from startrack.identify.plate_solver import PlateSolver

            self._plates[key] = PlateSolver(**options, epoch=epoch)
        return self._plates[key]

    def _camera_file(self, width, height):
        if self.camera_file is not None:
            return self.camera_file
        from startrack.camera.file import CameraFile
        from startrack.camera.model import Camera

        return CameraFile(Camera.from_fov(self.fov, width, height))

    def _calibrated_solver(self, camera, epoch):
        key = (camera.width, camera.height, epoch)
        if key not in self._calibrated:
            from startrack.identify.calibrated import CalibratedSolver

            self._calibrated[key] = CalibratedSolver(camera, self.mag_limit, epoch, self.sigma_px, self.threshold,
                                                     progress=True)
        return self._calibrated[key]

    def _diagnosed(self, result, frame, known, sigma, boresight, epoch):
        """``result`` (no_match with the given camera) with what a solve as an unknown camera over the plate
        solver's whole default range (the given field searched first) finds, or that it finds nothing either."""
        from startrack.identify.plate_solver import DEFAULT_FOV_RANGE

        unknown = self.plate(epoch, "default").solve(frame.uv, frame.width, frame.height, frame.flux, sigma,
                                                     fov_hint=known.camera.angular_width, boresight=boresight)
        given = f"{result.reason.rstrip('.')} with the given camera (FOV {math.degrees(known.camera.angular_width):.4f} deg)."
        if not unknown.ok:
            low, high = (math.degrees(x) for x in DEFAULT_FOV_RANGE)
            reason = f"{given} Solved as an unknown camera ({low:g}-{high:g} deg) it is not identified either: {unknown.reason}"
        else:
            reason = (f"{given} Solved as an unknown camera, the frame shows {_camera_change(known.camera, unknown.camera)}"
                      f": the given camera does not fit it (--refit refines it per frame if it is near; give the "
                      f"shown camera, e.g. --fov-deg {math.degrees(unknown.camera.angular_width):.4f}, or no geometry "
                      f"to fit one from the stars).")
        return dataclasses.replace(result, reason=reason)


def _camera_change(given, fitted):
    """The fitted camera beside the given one, in words."""
    return (f"FOV {math.degrees(fitted.angular_width):.4f} deg (given {math.degrees(given.angular_width):.4f}), scale "
            f"{math.degrees(3600.0 / fitted.focal_px):.4f} arcsec/px (given {math.degrees(3600.0 / given.focal_px):.4f}), "
            f"focal {fitted.focal_px:.2f} px (given {given.focal_px:.2f}), centre ({fitted.cx:.1f}, {fitted.cy:.1f}) px (given "
            f"({given.cx:.1f}, {given.cy:.1f})), k1 {fitted.k1:+.4f} (given {given.k1:+.4f})")
