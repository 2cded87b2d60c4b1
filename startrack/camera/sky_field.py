"""The field of a solved frame as plate solvers report it (astrometry.net's solve-field): the image centre with
its sigma, the field's size, the pixel scale, the orientation and the parity.

* **centre**: the direction of the centre pixel ((W-1)/2, (H-1)/2), astrometry.net's ``sip_get_radec_center``,
  d = R_IS exp([dtheta x]) c(f, cx, cy, k1, k2) with c the camera model's ray of that pixel; its covariance
  J C J^T with J = (-R_IS [c x], R_IS dc/dp) (dc/dp by central differences) and C the covariance of
  (dtheta, f, cx, cy, k1, k2) (:data:`startrack.camera.fit.PARAMETERS`; the attitude's alone for a given
  camera), read along the local east and north [arcsec];
* **size**: the angles the image subtends through its middle row and its middle column, from the outer edge
  of the first pixel to that of the last (astrometry.net's ``sip_get_field_size``;
  :func:`startrack.camera.model.width_angle`);
* **scale, orientation, parity**: astrometry.net's of the CD matrix of a WCS whose reference pixel is the image
  centre (solve-field ``--crpix-center``; :mod:`startrack.camera.wcs`), the local map there from pixels to the
  tangent plane's east and north, by central differences of the camera model over 0.01 px: 3600 sqrt|det CD|
  arcsec/px; "up is theta E of N", the position angle of the +y axis of FITS pixels (rows increasing: the top
  of a FITS viewer's display, which puts row 1 at the bottom; the bottom of a PNG or JPEG shown as stored, top
  row first); parity "pos" for det CD < 0 (east left of north with +y up, the sky as seen), else "neg".  The
  WCS that ``startrack solve --wcs`` writes has its reference pixel at the principal point, where the angle
  differs by the meridians' convergence over the offset, about (offset) tan(Dec).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from startrack.base.units import ARCSEC, dec_dms, ra_hms
from startrack.camera.model import width_angle
from startrack.camera.wcs import orientation_deg, parity, pixel_scale_arcsec
from startrack.geometry.rotation import skew, to_matrix
from startrack.geometry.sphere import local_frame, vector_to_radec

#: Central-difference steps of the intrinsics (f, cx, cy [px], k1, k2): far below any of their sigmas, far
#: above rounding of the unit vectors (1e-16 / 1e-3 px of the ray's ~1/f per px).
_STEPS = (1e-3, 1e-3, 1e-3, 1e-6, 1e-6)
_INTRINSICS = ("focal_px", "cx", "cy", "k1", "k2")
#: Pixel step [px] of the local CD matrix's central differences.
_PIXEL_STEP = 0.01


@dataclass(frozen=True)
class SkyField:
    """The image centre ``ra_deg``, ``dec_deg`` with its 1-sigma ``sigma_east_arcsec``, ``sigma_north_arcsec``;
    ``width_deg`` x ``height_deg``; ``scale_arcsec`` per pixel; ``orientation_deg`` (up is it E of N) and
    ``parity`` ("pos" or "neg"), module text."""

    ra_deg: float
    dec_deg: float
    sigma_east_arcsec: float
    sigma_north_arcsec: float
    width_deg: float
    height_deg: float
    scale_arcsec: float
    orientation_deg: float
    parity: str

    @property
    def sexagesimal(self):
        """("HH:MM:SS.sss", "+DD:MM:SS.ss") of the centre."""
        return ra_hms(self.ra_deg), dec_dms(self.dec_deg)

    def to_dict(self) -> dict:
        """The ``field`` entry of ``startrack solve --json``."""
        return {"width_deg": self.width_deg, "height_deg": self.height_deg, "pixel_scale_arcsec": self.scale_arcsec,
                "orientation_deg": self.orientation_deg, "parity": self.parity}


def sky_field(camera, q_IS, covariance) -> SkyField:
    """The :class:`SkyField` of ``camera`` (:class:`startrack.camera.model.Camera`) at ``q_IS``; ``covariance``
    (3, 3) of the attitude error dtheta [rad^2], or (8, 8) with the intrinsics (module text)."""
    centre = [[(camera.width - 1) / 2.0, (camera.height - 1) / 2.0]]
    R = to_matrix(np.asarray(q_IS, dtype=float))
    ray = camera.unproject(centre)[0]
    direction = R @ ray
    ra, dec = vector_to_radec(direction)
    covariance = np.asarray(covariance, dtype=float)
    columns = [-R @ skew(ray)]
    if covariance.shape[0] > 3:
        columns.append(R @ _ray_derivatives(camera, centre))
    J = np.hstack(columns)
    _, east, north = local_frame(ra, dec)
    axes = np.stack([east, north]) @ J
    sigma = np.sqrt(np.clip(np.einsum("ij,jk,ik->i", axes, covariance, axes), 0.0, None)) / ARCSEC
    cd = np.degrees(np.stack([east, north]) @ R @ _ray_gradient(camera, centre))
    width = width_angle(camera.focal_px, camera.cx, camera.cy, camera.k1, camera.k2, camera.width, camera.height,
                        camera.projection)
    height = width_angle(camera.focal_px, camera.cy, camera.cx, camera.k1, camera.k2, camera.height, camera.width,
                         camera.projection)  # x and y swapped: the middle column
    return SkyField(math.degrees(ra), math.degrees(dec), float(sigma[0]), float(sigma[1]), math.degrees(width),
                    math.degrees(height), pixel_scale_arcsec(cd), orientation_deg(cd), parity(cd))


def _ray_gradient(camera, pixel):
    """(3, 2) derivatives [rad/px] of the camera's ray through ``pixel`` [[u, v]] by u and v (central differences
    over :data:`_PIXEL_STEP`)."""
    steps = np.array([[_PIXEL_STEP, 0.0], [0.0, _PIXEL_STEP]])
    rays = camera.unproject(np.concatenate([pixel + steps, pixel - steps]))
    return ((rays[:2] - rays[2:]) / (2.0 * _PIXEL_STEP)).T


def _ray_derivatives(camera, pixel):
    """(3, 5) derivatives of the camera's ray through ``pixel`` [[u, v]] by f, cx, cy, k1, k2 (central differences)."""
    columns = []
    for name, step in zip(_INTRINSICS, _STEPS):
        value = getattr(camera, name)
        up = dataclasses.replace(camera, **{name: value + step}).unproject(pixel)[0]
        down = dataclasses.replace(camera, **{name: value - step}).unproject(pixel)[0]
        columns.append((up - down) / (2.0 * step))
    return np.stack(columns, axis=1)
