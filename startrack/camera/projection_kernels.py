"""The compiled projection kernels of the camera model, on the kernels' camera-parameter array.

The model of :mod:`startrack.camera.model` (docs/design.md), one direction at a time for the compiled
identification and fit: a direction v_S is seen at the ideal coordinates (x, y) of the camera's projection --
pinhole x = v_x / v_z, y = v_y / v_z; fisheye (equidistant, Kannala & Brandt 2006) (x, y) = theta (v_x, v_y) /
rho, rho = hypot(v_x, v_y), theta = atan2(rho, v_z) -- r^2 = x^2 + y^2, d = 1 + k1 r^2 + k2 r^4 and

    u = cx + f x d,   v = cy + f y d.

The camera-parameter array is (f, cx, cy, W, H, k1, k2, circular, projection) (:func:`camera_array`).
"""

from __future__ import annotations

import math

import numpy as np

from startrack.camera.model import PROJECTIONS, fold_radius_squared
from startrack.compiled.numba_setup import njit

#: Positions of the intrinsics (f, cx, cy, k1, k2) in a camera-parameter array (f, cx, cy, W, H, k1, k2,
#: circular, projection) -- the layout of :func:`camera_array`.
INTRINSICS = np.array([0, 1, 2, 5, 6], np.int64)
#: Code of the fisheye projection at index 8 of a camera-parameter array (0: pinhole;
#: :data:`startrack.camera.model.PROJECTIONS`).
FISHEYE = 1.0


def camera_array(camera) -> np.ndarray:
    """The compiled kernels' camera-parameter array (f, cx, cy, W, H, k1, k2, circular, projection) of a
    :class:`startrack.camera.model.Camera`."""
    return np.array([camera.focal_px, camera.cx, camera.cy, camera.width, camera.height, camera.k1, camera.k2,
                     float(camera.circular_fov), float(PROJECTIONS.index(camera.projection))])
#: Compiled twin of :func:`startrack.camera.model.fold_radius_squared` (the same function).
fold_radius_squared_jit = njit(fold_radius_squared)


@njit(_nrt=False)
def _ideal_xy(vx, vy, vz, projection):  # pragma: no cover  (compiled)
    """(imaged, x, y): the normalised ideal coordinates of the direction (vx, vy, vz) in S under the
    projection code (module text); imaged is False behind a pinhole and on the fisheye's -z axis."""
    if projection != FISHEYE:
        if vz <= 0.0:
            return False, 0.0, 0.0
        return True, vx / vz, vy / vz
    rho = math.sqrt(vx * vx + vy * vy)
    if rho <= 1e-12 * abs(vz):
        return vz > 0.0, vx / abs(vz), vy / abs(vz)
    s = math.atan2(rho, vz) / rho
    return True, s * vx, s * vy


@njit(_nrt=False)
def in_view(vx, vy, vz, camera_params, fold):  # pragma: no cover  (compiled)
    """(imaged within the fold radius^2 ``fold`` of the distortion, x, y) of a direction in S."""
    imaged, x, y = _ideal_xy(vx, vy, vz, camera_params[8])
    return imaged and x * x + y * y < fold, x, y


@njit(_nrt=False)
def folds_inside(camera_params):  # pragma: no cover  (compiled)
    """Whether the distorted radius stops growing before the farthest image corner (with the 5 % margin of
    :class:`startrack.camera.model.Camera`, which refuses such a camera)."""
    f, cx, cy, width, height, k1, k2 = camera_params[:7]
    fold = fold_radius_squared_jit(k1, k2)
    if math.isinf(fold):
        return False
    corner = math.hypot(max(cx + 0.5, width - 0.5 - cx), max(cy + 0.5, height - 0.5 - cy)) / f
    return math.sqrt(fold) * (1.0 + k1 * fold + k2 * fold * fold) <= 1.05 * corner


@njit(_nrt=False)
def image_point(x, y, camera_params):  # pragma: no cover  (compiled)
    """(u, v) [px] of normalised ideal coordinates (x, y): the radial polynomial and the intrinsics."""
    f, cx, cy, k1, k2 = camera_params[0], camera_params[1], camera_params[2], camera_params[5], camera_params[6]
    r2 = x * x + y * y
    d = 1.0 + k1 * r2 + k2 * r2 * r2
    return cx + f * x * d, cy + f * y * d


@njit(_nrt=False)
def project_one(vx, vy, vz, camera_params):  # pragma: no cover  (compiled)
    """(u, v) [px] of the direction (vx, vy, vz) in S (one the projection images): the module's model."""
    _, x, y = _ideal_xy(vx, vy, vz, camera_params[8])
    return image_point(x, y, camera_params)


@njit(_nrt=False)
def off_axis_angle(radius, projection):  # pragma: no cover  (compiled)
    """Angle off the axis [rad] of the ideal normalised radius ``radius`` (pinhole atan, fisheye itself)."""
    return radius if projection == FISHEYE else math.atan(radius)


@njit(_nrt=False)
def ray_one(x, y, projection):  # pragma: no cover  (compiled)
    """Unit vector in S of the normalised ideal coordinates (x, y) (the inverse of :func:`_ideal_xy`)."""
    if projection != FISHEYE:
        norm = math.sqrt(x * x + y * y + 1.0)
        return x / norm, y / norm, 1.0 / norm
    theta = math.sqrt(x * x + y * y)
    sinc = math.sin(theta) / theta if theta > 0.0 else 1.0
    return x * sinc, y * sinc, math.cos(theta)


@njit
def project(v_S, camera_params):  # pragma: no cover  (compiled)
    """(u, v) (m, 2) [px] of the directions v_S (m, 3) in S (in front of the lens)."""
    uv = np.empty((v_S.shape[0], 2))
    for i in range(v_S.shape[0]):
        uv[i, 0], uv[i, 1] = project_one(v_S[i, 0], v_S[i, 1], v_S[i, 2], camera_params)
    return uv
