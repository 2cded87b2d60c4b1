"""The result record of a star identification (one per frame).

Angles are radians inside (``ra``, ``dec``, ``roll``, ``residuals``, ``covariance``); :meth:`to_dict`
gives the JSON form of the ``startrack solve`` contract (docs/design.md) with degrees and arcseconds.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from startrack.attitude.solvers import cramer_rao_covariance
from startrack.base.units import ARCSEC
from startrack.camera.sky_field import sky_field
from startrack.geometry.attitude_angles import radec_roll_from_quaternion
from startrack.geometry.rotation import to_matrix

#: Status values: identified; searched without an accepted hypothesis; too few usable centroids;
#: a frame that cannot be solved as given (NaN, outside the sensor, wrong shape).
_STATUSES = ("ok", "no_match", "too_few", "error")
#: Where the camera of an answer came from: given (a calibrated camera: a camera file, or a field of view
#: and the frame size), fitted from the stars alone, or refined from a given camera (``--refit``).
_CAMERA_SOURCES = ("given", "fitted", "refined")


@dataclass(frozen=True, eq=False)
class IdentificationResult:
    """Outcome of one identification.

    status: one of :data:`_STATUSES`; reason: one sentence when status is not "ok" ("" otherwise).
    q_IS: (4,) scalar-last quaternion rotating sensor-frame vectors into the inertial frame (NaN unless ok);
        :attr:`ra`, :attr:`dec`, :attr:`roll` are the boresight angles (003 §1.1) [rad] derived from it.
    matches: (M, 2) int64 rows (centroid index in the caller's order, HIP number -- or, from a plate
        solver using the Gaia DR3 stars, the Gaia source_id of a star Hipparcos-2 lacks: an id above
        :data:`startrack.catalog.hipparcos.HIP_MAX`), by centroid index.
    obs_S, ref_I: (M, 3) the matched centroid directions in S and their catalog directions in I (the
        measurements a filter uses); sigma: their per-axis angular noise [rad], scalar or (M,).
        :attr:`residuals` and :attr:`covariance` are derived from them when asked.
    false_match_probability: chance that a wrong attitude hypothesis explains as many centroids
        (:func:`startrack.identify.verify.false_match_probability`); NaN when nothing was verified.
    method: strategy that produced the answer ("tracking", "subcatalog", "lost_in_space"; "pattern" for the
        plate solver's search without a calibrated camera) or "" if none.
    solve_ms: wall-clock time of the whole call [ms].
    lost_hip / entered_hip: tracking only -- previously tracked stars predicted inside the field but not
        found, and stars identified now that were not tracked before (HIP numbers).
    calibration: the camera the frame calibrated (:class:`startrack.camera.fit.CameraCalibration`), when
        the camera was fitted or refined (:class:`startrack.identify.plate_solver.PlateSolver`); then
        :attr:`covariance` is the fit's, which includes the intrinsics' uncertainty.
    camera: the :class:`startrack.camera.model.Camera` whose frame S ``q_IS`` is the attitude of (None when not
        ok); camera_source: where it came from, one of :data:`_CAMERA_SOURCES` ("" when not ok).
    """

    status: str
    reason: str = ""
    q_IS: np.ndarray = field(default_factory=lambda: np.full(4, np.nan))
    matches: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    obs_S: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    ref_I: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    sigma: float = math.nan
    false_match_probability: float = math.nan
    method: str = ""
    solve_ms: float = math.nan
    lost_hip: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    entered_hip: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    calibration: object = None
    camera: object = None
    camera_source: str = ""

    def __post_init__(self):
        if self.status not in _STATUSES:
            raise ValueError(f"identification status {self.status!r} is not one of {_STATUSES}")
        if self.camera_source not in _CAMERA_SOURCES + ("",):
            raise ValueError(f"camera source {self.camera_source!r} is not one of {_CAMERA_SOURCES}")

    @property
    def ok(self) -> bool:
        """True when the frame was identified."""
        return self.status == "ok"

    @functools.cached_property
    def _radec_roll(self):
        return tuple(float(x) for x in radec_roll_from_quaternion(self.q_IS))

    @property
    def ra(self) -> float:
        """Boresight right ascension [rad] in [0, 2 pi) (NaN unless ok)."""
        return self._radec_roll[0]

    @property
    def dec(self) -> float:
        """Boresight declination [rad] (NaN unless ok)."""
        return self._radec_roll[1]

    @property
    def roll(self) -> float:
        """Roll about the boresight [rad] in [-pi, pi), 003 §1.1 (NaN unless ok)."""
        return self._radec_roll[2]

    @functools.cached_property
    def residuals(self) -> np.ndarray:
        """(M,) angle [rad] between each matched direction and its prediction R_IS^T ref_I."""
        if not self.ok:
            return np.zeros(0)
        chord = self.obs_S - self.ref_I @ to_matrix(self.q_IS)
        return 2.0 * np.arcsin(np.minimum(0.5 * np.sqrt(np.einsum("ij,ij->i", chord, chord)), 1.0))

    @functools.cached_property
    def covariance(self) -> np.ndarray:
        """(3, 3) attitude-error covariance in sensor axes [rad^2] (x, y cross-boresight, z roll).

        The Cramer-Rao bound of the matched stars, which the SVD solution of Wahba's problem attains
        (:func:`startrack.attitude.solvers.cramer_rao_covariance`), or the calibration fit's; NaN unless ok.
        """
        if not self.ok:
            return np.full((3, 3), np.nan)
        if self.calibration is not None:
            return self.calibration.covariance[:3, :3].copy()
        return cramer_rao_covariance(self.obs_S, self.sigma)

    @functools.cached_property
    def sky_field(self):
        """The field as plate solvers report it (:class:`startrack.camera.sky_field.SkyField`: the image centre
        with its sigma, size, scale, orientation, parity); None unless ok with a camera."""
        if not self.ok or self.camera is None:
            return None
        return sky_field(self.camera, self.q_IS,
                         self.covariance if self.calibration is None else self.calibration.covariance)

    @property
    def matched_hip(self) -> np.ndarray:
        """HIP numbers (or Gaia DR3 source_ids, :attr:`matches`) of the matched stars, in the order of :attr:`matches`."""
        return self.matches[:, 1]

    def to_dict(self, frame_id=None) -> dict:
        """JSON-ready dict of the ``startrack solve --json`` contract (degrees, arcseconds)."""
        out = {"id": frame_id, "status": self.status}
        if self.reason:
            out["reason"] = self.reason
        if self.ok:
            sigma = np.sqrt(np.clip(np.diag(self.covariance), 0.0, None)) / ARCSEC
            out.update(
                q_IS=[float(x) for x in self.q_IS],
                ra_deg=math.degrees(self.ra),
                dec_deg=math.degrees(self.dec),
                roll_deg=math.degrees(self.roll),
                matches=self.matches.tolist(),
                residuals_arcsec=np.round(self.residuals / ARCSEC, 4).tolist(),
                sigma_arcsec=sigma.tolist(),
                false_match_probability=float(self.false_match_probability),
            )
            out["stars_matched"] = len(self.matches)
            if self.camera is not None:
                roll = math.degrees(float(self.camera.center_radec_roll(self.q_IS)[2]))
                field = self.sky_field
                out["center"] = {"ra_deg": field.ra_deg, "dec_deg": field.dec_deg, "roll_deg": roll,
                                 "ra_hms": field.sexagesimal[0],
                                 "dec_dms": field.sexagesimal[1],
                                 "sigma_arcsec": [field.sigma_east_arcsec, field.sigma_north_arcsec]}
                out["field"] = field.to_dict()
                out["camera"] = {"source": self.camera_source, **_camera_dict(self.camera),
                                 **({} if self.calibration is None else self.calibration.to_dict())}
            if self.method == "tracking":
                out["lost_hip"] = [int(h) for h in self.lost_hip]
                out["entered_hip"] = [int(h) for h in self.entered_hip]
        out["method"] = self.method
        out["solve_ms"] = round(float(self.solve_ms), 4)
        return out


def _camera_dict(camera) -> dict:
    """The geometry of ``camera`` as the ``camera`` entry of ``startrack solve --json`` gives it."""
    return {"width": camera.width, "height": camera.height, "fov_deg": math.degrees(camera.angular_width),
            "focal_px": camera.focal_px, "cx": camera.cx, "cy": camera.cy, "k1": camera.k1, "k2": camera.k2,
            "projection": camera.projection}
