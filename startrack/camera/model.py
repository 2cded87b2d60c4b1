"""Camera of the star sensor: a pinhole or a fisheye projection with radial distortion (k1, k2).

Frame convention (docs/design.md, binding):

* Sensor frame S: +z along the boresight (out of the lens, towards the sky),
  +x along the image columns u (to the right), +y along the image rows v
  (downwards); right-handed.
* Image coordinates (u, v) in pixels, origin at the *centre* of the top-left
  pixel, so pixel (row r, column c) covers u in [c - 1/2, c + 1/2] and v in
  [r - 1/2, r + 1/2]; the principal point defaults to ((W-1)/2, (H-1)/2).
* Projection: a direction at angle theta from the boresight and azimuth phi has the normalised ideal
  coordinates (x_n, y_n) = R(theta) (cos phi, sin phi), and u = cx + f x_n, v = cy + f y_n with f the
  focal length in pixels.  ``pinhole`` (gnomonic): R = tan theta, i.e. x_n = x/z, y_n = y/z (tangent-plane
  coordinates); ``fisheye`` (equidistant): R = theta, the model of Kannala & Brandt (2006) whose radial
  terms below also reach the equisolid (2 sin(theta/2) = theta (1 - theta^2/24 + ...)), stereographic
  and orthographic lenses; it images fields up to and beyond 180 deg.
* Radial distortion (Brown's polynomial, even terms; Brown 1971; Kannala & Brandt's for the fisheye):
  (x_d, y_d) = (x_n, y_n) (1 + k1 r^2 + k2 r^4), r^2 = x_n^2 + y_n^2, and
  u = cx + f x_d, v = cy + f y_d.  The inverse is solved for the radius by
  Newton's method to machine precision; the constructor refuses (k1, k2)
  whose distorted radius is not monotonic over the image, and a direction
  beyond the fold of the polynomial (where the distorted radius would fall
  again) is never visible: the polynomial would put it back in the image.
* Attitude: ``q_IS`` is the scalar-last quaternion (scipy convention) that
  rotates S-frame vectors into the inertial frame I: v_I = R_IS v_S
  (boresight RA/Dec/roll conversions in :mod:`startrack.geometry.attitude_angles`).
* Field of view: ``fov_x`` is the full angle across the image width,
  f = (W/2) / R(fov_x/2) (R = tan for the pinhole).  With ``circular_fov`` the field is the cone of
  half-angle fov_x/2 (the circle inscribed in the width, as in 000 and 004),
  intersected with the image; otherwise the image rectangle.
"""

import functools
import math
from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError
from startrack.geometry.attitude_angles import radec_roll_from_matrix
from startrack.geometry.rotation import from_rotation_vector, to_matrix
from startrack.geometry.sphere import angular_distance

#: Newton iterations of the distortion inverse (quadratic convergence; 8 are ample).
_NEWTON_ITERATIONS = 12
#: The projections, in the order of their code in the compiled kernels' camera arrays (index 8).
PROJECTIONS = ("pinhole", "fisheye")


def radius_of_angle(theta, projection="pinhole"):
    """Ideal normalised radius R(theta) of directions ``theta`` [rad] off the axis (module text)."""
    return np.tan(theta) if projection == "pinhole" else np.asarray(theta, dtype=float)


def _angle_of_radius(radius, projection="pinhole"):
    """Angle off the axis [rad] of ideal normalised radii (the inverse of :func:`radius_of_angle`)."""
    return np.arctan(radius) if projection == "pinhole" else np.asarray(radius, dtype=float)


def _ideal_coordinates(v_S, projection="pinhole"):
    """(x_n, y_n) (..., 2) of directions ``v_S`` (..., 3) in S and the mask of those the projection images
    (pinhole: z > 0; fisheye: all but the -z axis); NaN where it does not (module text)."""
    v_S = np.asarray(v_S, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        if projection == "pinhole":
            front = v_S[..., 2] > 0.0
            return v_S[..., :2] / np.where(front, v_S[..., 2], np.nan)[..., None], front
        rho = np.hypot(v_S[..., 0], v_S[..., 1])
        theta = np.arctan2(rho, v_S[..., 2])
        front = theta < np.pi
        scale = np.where(rho > 0.0, theta / np.where(rho > 0.0, rho, 1.0), 1.0 / np.abs(v_S[..., 2]))
        return v_S[..., :2] * np.where(front, scale, np.nan)[..., None], front


def ray(xy_n, projection="pinhole"):
    """Unit vectors (..., 3) in S of normalised ideal coordinates (..., 2) (inverse of :func:`_ideal_coordinates`)."""
    xy_n = np.asarray(xy_n, dtype=float)
    if projection == "pinhole":
        v = np.concatenate([xy_n, np.ones(xy_n.shape[:-1] + (1,))], axis=-1)
        return v / np.linalg.norm(v, axis=-1, keepdims=True)
    theta = np.hypot(xy_n[..., 0], xy_n[..., 1])
    sinc = np.where(theta > 0.0, np.sin(theta) / np.where(theta > 0.0, theta, 1.0), 1.0)
    return np.concatenate([xy_n * sinc[..., None], np.cos(theta)[..., None]], axis=-1)


def fold_radius_squared(k1, k2):
    """Smallest t = r^2 > 0 with d/dr [r (1 + k1 r^2 + k2 r^4)] = 1 + 3 k1 t + 5 k2 t^2 = 0, or inf: the
    ideal radius^2 beyond which the distorted radius decreases.  Plain arithmetic, so that the compiled
    kernels wrap this very function (:data:`startrack.camera.projection_kernels.fold_radius_squared_jit`)."""
    if k2 == 0.0:
        return -1.0 / (3.0 * k1) if k1 < 0.0 else math.inf
    disc = 9.0 * k1 * k1 - 20.0 * k2
    if disc < 0.0:
        return math.inf
    best = math.inf
    for t in ((-3.0 * k1 - math.sqrt(disc)) / (10.0 * k2), (-3.0 * k1 + math.sqrt(disc)) / (10.0 * k2)):
        if 0.0 < t < best:
            best = t
    return best


def _ideal_radius(rd, k1, k2):
    """Ideal normalised radius r of distorted radii ``rd``: r (1 + k1 r^2 + k2 r^4) = rd by Newton's method
    to machine precision (Brown 1971; broadcasts over rd, k1, k2)."""
    rd = np.asarray(rd, dtype=float)
    r = rd.copy()
    for _ in range(_NEWTON_ITERATIONS):
        r2 = r * r
        step = (r * (1.0 + k1 * r2 + k2 * r2 * r2) - rd) / (1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2)
        r = r - step
        if np.all(np.abs(step) <= 1e-16 * np.maximum(r, 1.0)):
            break
    return r


def _ideal_scale(rd, k1, k2):
    """r / r_d of distorted radii ``rd`` (1 at the centre)."""
    r = _ideal_radius(rd, k1, k2)
    return np.where(rd > 0.0, r / np.where(rd > 0.0, rd, 1.0), 1.0)


def width_angle(focal_px, cx, cy, k1, k2, width, height, projection="pinhole"):
    """Angle [rad] the image width subtends through its middle row, between the outer edges of its end
    pixels, distortion removed: the angles from each end to the row's point below the principal point, summed
    (the row is a great circle of a pinhole; a fisheye's field may pass 180 deg); broadcasts over the camera
    parameters: one call for many cameras."""
    cx, cy, focal_px = (np.asarray(value, float) for value in (cx, cy, focal_px))
    u = np.stack(np.broadcast_arrays(-0.5 + 0.0 * cx, cx, width - 0.5 + 0.0 * cx))  # the ends and the middle
    x_d, y_d = np.broadcast_arrays((u - cx) / focal_px, ((height - 1) / 2.0 - cy) / focal_px)
    scale = _ideal_scale(np.hypot(x_d, y_d), k1, k2)
    left, centre, right = ray(np.stack([x_d * scale, y_d * scale], axis=-1), projection)
    return angular_distance(left, centre) + angular_distance(centre, right)


@dataclass(frozen=True)
class Camera:
    """Camera: W x H pixels, focal length in pixels, principal point, k1, k2, ``projection`` (one of
    :data:`PROJECTIONS`)."""

    width: int
    height: int
    focal_px: float
    cx: float | None = None
    cy: float | None = None
    k1: float = 0.0
    k2: float = 0.0
    circular_fov: bool = False
    projection: str = "pinhole"

    def __post_init__(self):
        for name in ("width", "height"):
            value = getattr(self, name)
            if int(value) != value or value < 1:
                raise InputError(f"camera {name} must be a positive integer number of pixels, got {value!r}")
            object.__setattr__(self, name, int(value))
        if not np.isfinite(self.focal_px) or self.focal_px <= 0:
            raise InputError(f"camera focal_px must be a positive number of pixels, got {self.focal_px!r}")
        object.__setattr__(self, "focal_px", float(self.focal_px))
        object.__setattr__(self, "cx", (self.width - 1) / 2.0 if self.cx is None else float(self.cx))
        object.__setattr__(self, "cy", (self.height - 1) / 2.0 if self.cy is None else float(self.cy))
        for name in ("cx", "cy", "k1", "k2"):
            if not np.isfinite(getattr(self, name)):
                raise InputError(f"camera {name} must be finite, got {getattr(self, name)!r}")
        object.__setattr__(self, "k1", float(self.k1))
        object.__setattr__(self, "k2", float(self.k2))
        if self.projection not in PROJECTIONS:
            raise InputError(f"camera projection {self.projection!r} is not one of {', '.join(PROJECTIONS)}")
        self._check_distortion_monotonic()

    # ----------------------------------------------------------------- constructors
    @classmethod
    def from_fov(cls, fov_x_rad, width, height, projection="pinhole", **kw):
        """Camera whose full field across the width is ``fov_x_rad``: f = (W/2)/R(fov_x/2)."""
        top = np.pi if projection == "pinhole" else 2.0 * np.pi
        if not 0 < fov_x_rad < top:
            raise InputError(f"field of view must be in (0, {np.degrees(top):g}) deg for a {projection} camera, got "
                             f"{np.degrees(fov_x_rad)!r} deg")
        return cls(width, height, (width / 2.0) / radius_of_angle(fov_x_rad / 2.0, projection), projection=projection, **kw)

    @classmethod
    def from_pitch(cls, focal_length_m, pixel_pitch_m, width, height, **kw):
        """Camera from the focal length and the pixel pitch [m]: f_px = focal / pitch."""
        if not (focal_length_m > 0 and pixel_pitch_m > 0):
            raise InputError(
                f"focal length and pixel pitch must be positive, got {focal_length_m!r} m and {pixel_pitch_m!r} m"
            )
        return cls(width, height, focal_length_m / pixel_pitch_m, **kw)

    # ----------------------------------------------------------------- field
    @property
    def fov_x(self):
        """Full field angle across the width [rad] (undistorted)."""
        return 2.0 * float(_angle_of_radius(self.width / (2.0 * self.focal_px), self.projection))

    @property
    def fov_y(self):
        """Full field angle across the height [rad]."""
        return 2.0 * float(_angle_of_radius(self.height / (2.0 * self.focal_px), self.projection))

    @functools.cached_property
    def angular_width(self):
        """Angle [rad] the image width subtends through its middle row (outer pixel edges, distortion
        included): the field of view a plate solver measures; fov_x for an undistorted camera with its
        principal point at the centre (:func:`width_angle`)."""
        return float(width_angle(self.focal_px, self.cx, self.cy, self.k1, self.k2, self.width, self.height,
                                 self.projection))

    @property
    def fov_diagonal(self):
        """Full field angle across the diagonal [rad]."""
        return 2.0 * float(_angle_of_radius(np.hypot(self.width, self.height) / (2.0 * self.focal_px), self.projection))

    # ----------------------------------------------------------------- distortion
    def _radial_factor(self, r2):
        return 1.0 + self.k1 * r2 + self.k2 * r2 * r2

    def _max_distorted_radius(self):
        """Normalised distorted radius of the farthest image corner (pixel edges included)."""
        du = max(self.cx + 0.5, self.width - 0.5 - self.cx)
        dv = max(self.cy + 0.5, self.height - 0.5 - self.cy)
        return np.hypot(du, dv) / self.focal_px

    def _check_distortion_monotonic(self):
        """The distorted radius must grow out to the farthest corner (with 5 % margin): the corner lies
        below the distorted radius reached at the fold, r_f (1 + k1 r_f^2 + k2 r_f^4)."""
        if self.k1 == 0.0 and self.k2 == 0.0:
            return
        fold = fold_radius_squared(self.k1, self.k2)
        if math.isinf(fold):
            return
        r_fold = math.sqrt(fold)
        if r_fold * self._radial_factor(fold) <= 1.05 * self._max_distorted_radius():
            raise InputError(
                f"radial distortion k1={self.k1!r}, k2={self.k2!r} is not invertible over the image "
                "(distorted radius not monotonic out to the corners)"
            )

    def distort(self, xy_n):
        """Normalised ideal (x_n, y_n) (N,2) -> distorted (x_d, y_d) (Brown radial model)."""
        xy_n = np.asarray(xy_n, dtype=float)
        return xy_n * self._radial_factor(np.sum(xy_n * xy_n, axis=-1))[..., None]

    def undistort(self, xy_d):
        """Distorted normalised (x_d, y_d) -> ideal (x_n, y_n): each point scaled by r / r_d
        (:func:`_ideal_radius`)."""
        xy_d = np.asarray(xy_d, dtype=float)
        if self.k1 == 0.0 and self.k2 == 0.0:
            return xy_d.copy()
        return xy_d * _ideal_scale(np.sqrt(np.sum(xy_d * xy_d, axis=-1)), self.k1, self.k2)[..., None]

    # ----------------------------------------------------------------- projection
    def _project(self, v_S):
        """(uv, normalised ideal x_n y_n, imaged mask) of directions (N,3) in S; NaN where not imaged."""
        xy_n, front = _ideal_coordinates(v_S, self.projection)
        return self.focal_px * self.distort(xy_n) + np.array([self.cx, self.cy]), xy_n, front

    def project_body(self, vectors_S):
        """(uv (N,2) px, visible (N,) bool) of directions (N,3) given in S.

        visible: in front of the lens (z > 0), inside the image (pixel edges
        included) and, for a circular field, within fov_x/2 of the boresight.
        Points the projection does not image (behind a pinhole) get NaN coordinates.
        """
        v = np.atleast_2d(np.asarray(vectors_S, dtype=float))
        if v.ndim != 2 or v.shape[1] != 3:
            raise InputError(f"direction vectors must have shape (N, 3), got {np.shape(vectors_S)}")
        uv, xy_n, front = self._project(v)
        return uv, self._visible(uv, xy_n, front, 0.0)

    def project(self, q_IS, vectors_I):
        """(uv, visible) of inertial directions (N,3) for the attitude q_IS (S -> I)."""
        return self.project_body(self.to_sensor(q_IS, vectors_I))

    @staticmethod
    def to_sensor(q_IS, vectors_I):
        """Inertial directions (N,3) expressed in S: v_S = R_IS^T v_I."""
        q = np.asarray(q_IS, dtype=float)
        if q.shape != (4,) or not np.all(np.isfinite(q)) or np.linalg.norm(q) == 0:
            raise InputError(f"attitude quaternion q_IS must be 4 finite numbers, not all zero, got {q_IS!r}")
        return np.atleast_2d(np.asarray(vectors_I, dtype=float)) @ to_matrix(q)

    def unproject(self, uv):
        """Unit vectors (N,3) in S of image points (N,2) [px] (distortion removed)."""
        uv = np.atleast_2d(np.asarray(uv, dtype=float))
        if uv.ndim != 2 or uv.shape[1] != 2:
            raise InputError(f"image points must have shape (N, 2), got {uv.shape}")
        return ray(self.undistort((uv - np.array([self.cx, self.cy])) / self.focal_px), self.projection)

    def unproject_covariance(self, uv, cov_uv):
        """Covariances (N, 3, 3) in S of the unit vectors of image points ``uv`` (N, 2) [px] whose positions have
        covariances ``cov_uv`` (N, 2, 2) [px²]: J Σ Jᵀ with J = ∂ unproject / ∂(u, v) (N, 3, 2) by central
        differences of 0.01 px (truncation ~(0.01 px / f)² of J, rounding ~1e-16 / 0.01 of it: both far below
        any centroid's σ)."""
        uv = np.atleast_2d(np.asarray(uv, dtype=float))
        step = 0.01
        J = np.stack([(self.unproject(uv + d) - self.unproject(uv - d)) / (2.0 * step)
                      for d in (np.array([step, 0.0]), np.array([0.0, step]))], axis=-1)
        return J @ np.asarray(cov_uv, dtype=float) @ np.swapaxes(J, 1, 2)

    def center_radec_roll(self, q_IS):
        """(ra, dec, roll) [rad] of the image centre: the frame whose +z is the direction of the centre pixel
        ((W-1)/2, (H-1)/2) and whose axes follow S by the smallest rotation (what plate solvers report)."""
        c = self.unproject([[(self.width - 1) / 2.0, (self.height - 1) / 2.0]])[0]
        axis = np.cross([0.0, 0.0, 1.0], c)
        angle = math.atan2(np.linalg.norm(axis), c[2])
        turn = to_matrix(from_rotation_vector(axis / max(np.linalg.norm(axis), 1e-300) * angle))
        return radec_roll_from_matrix(to_matrix(q_IS) @ turn)

    def stars_in_field(self, q_IS, vectors_I, margin_px=0.0):
        """Indices of the directions inside the field grown by ``margin_px`` pixels."""
        uv, xy_n, front = self._project(self.to_sensor(q_IS, vectors_I))
        return np.flatnonzero(self._visible(uv, xy_n, front, float(margin_px)))

    @property
    def fold_radius(self):
        """Ideal normalised radius beyond which the distorted radius r (1 + k1 r^2 + k2 r^4) decreases
        again (inf if it never does): directions farther off axis fold back into the image under the
        polynomial but are not imaged by the lens, so they are never visible."""
        return math.sqrt(fold_radius_squared(self.k1, self.k2))

    def _visible(self, uv, xy_n, front, margin_px):
        with np.errstate(invalid="ignore"):
            inside = (
                front
                & (np.sum(xy_n * xy_n, axis=1) < self.fold_radius**2)
                & (uv[:, 0] >= -0.5 - margin_px)
                & (uv[:, 0] <= self.width - 0.5 + margin_px)
                & (uv[:, 1] >= -0.5 - margin_px)
                & (uv[:, 1] <= self.height - 0.5 + margin_px)
            )
            if self.circular_fov:
                radius = self.width / 2.0 + margin_px
                inside &= np.sum(xy_n * xy_n, axis=1) * self.focal_px**2 <= radius * radius
        return inside

    def angular_velocity_track(self, q_IS_mid, omega_S, times_s, vectors_I):
        """Image tracks (N, K, 2) of inertial directions at ``times_s`` (K,) from mid-exposure.

        Constant body rate omega_S [rad/s] in S: R_IS(t) = R_IS(0) exp([omega x] t),
        so v_S(t) = exp([omega x] t)^T v_S(0).
        """
        v_S0 = self.to_sensor(q_IS_mid, vectors_I)
        rotvecs = np.asarray(times_s, dtype=float)[:, None] * np.asarray(omega_S, dtype=float)[None, :]
        mats = to_matrix(from_rotation_vector(rotvecs))  # (K,3,3) S(t) -> S(0)
        v_S = np.einsum("nj,kji->nki", v_S0, mats)  # R^T v
        xy_n, _ = _ideal_coordinates(v_S, self.projection)
        return self.focal_px * self.distort(xy_n) + np.array([self.cx, self.cy])
