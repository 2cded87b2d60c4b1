"""The FITS world coordinate system of a solved frame: gnomonic (TAN) with SIP distortion polynomials, or
for a fisheye camera the zenithal polynomial projection (ZPN).

A camera of :mod:`startrack.camera.model` at the attitude ``q_IS`` maps a pixel (u, v) (0-based, origin at the
centre of the first pixel) to a direction; the FITS WCS of that map (Calabretta & Greisen 2002, eqs. 54-55
for TAN with LONPOLE 180; the SIP convention of Shupe et al. 2005) is, with FITS pixels p = u + 1, q = v + 1
and the reference pixel CRPIX at the principal point (cx + 1, cy + 1):

* intermediate world coordinates [deg] (x, y) = CD (U + A(U, V), V + B(U, V)), U = p - CRPIX1,
  V = q - CRPIX2 -- the standard coordinates (xi, eta) of the star about CRVAL (xi towards east,
  eta towards north), tangent plane to the sphere at the boresight;
* the pinhole part is exact and linear: (xi, eta) = M (x_n, y_n), with M the sensor's x and y axes seen
  on the tangent plane's east and north axes, so CD = (180 / pi) M / f [deg/px];
* Brown's radial distortion is the polynomial A, B of order 2..N: U + A = f x_n(U, V) with x_n the
  undistorted coordinate (:meth:`startrack.camera.model.Camera.undistort`), fitted by least squares on a grid
  over the image; AP, BP the inverse, U = U' + AP(U', V') on the undistorted offsets U' = f x_n.

The order N is the smallest (0 for a pinhole, else 2..:data:`_MAX_ORDER`) whose fit misses the camera model
by at most ``tolerance_arcsec`` (0.02") everywhere on the grid, the inverse likewise; the header states what it
reached (``max_error_px``).

A fisheye camera (equidistant with radial terms, :mod:`startrack.camera.model`) has no tangent plane beyond 90 deg
from the axis, but it is exactly the zenithal polynomial projection ZPN (Calabretta & Greisen 2002, eq. 68):
R = (180 / pi) sum_m P_m theta^m with theta the angle from CRVAL [rad] and R = |CD (U, V)| [deg], so the same
CRPIX, CRVAL and CD with P_1 = 1, P_3 = k1, P_5 = k2 (PV2_1, PV2_3, PV2_5) reproduce it with no polynomial fit.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError
from startrack.base.units import ARCSEC
from startrack.geometry.rotation import to_matrix

#: Highest SIP order tried (the distortion of a fisheye's corners needs the most terms).
_MAX_ORDER = 9
#: Grid points per image side on which the polynomials are fitted and checked.
GRID = 41


@dataclass(frozen=True)
class FrameWcs:
    """A TAN(-SIP) or ZPN WCS: ``crpix`` (2,) FITS px, ``crval`` (2,) [deg], ``cd`` (2, 2) [deg/px], the forward
    SIP coefficients ``a``, ``b`` and the inverse ``ap``, ``bp`` as {(p, q): value} (empty for a pinhole or a
    fisheye), ``order``, ``max_error_px`` of forward and inverse on the grid, image ``width`` x ``height``;
    ``projection`` "TAN" or "ZPN" with its coefficients ``pv`` {m: P_m}."""

    crpix: np.ndarray
    crval: np.ndarray
    cd: np.ndarray
    a: dict
    b: dict
    ap: dict
    bp: dict
    order: int
    max_error_px: float
    width: int
    height: int
    projection: str = "TAN"
    pv: dict = dataclasses.field(default_factory=dict)

    def cards(self):
        """[(keyword, value, comment)] of the FITS header (module text); SIP keywords when ``order``, PV2_m
        of a ZPN."""
        sip = bool(self.order)
        suffix = "-SIP" if sip else ""
        name = {"TAN": "gnomonic projection", "ZPN": "zenithal polynomial (fisheye)"}[self.projection]
        cards = [("WCSAXES", 2, "2-D image"),
                 ("CTYPE1", f"RA---{self.projection}" + suffix, name + (", SIP distortion" if sip else "")),
                 ("CTYPE2", f"DEC--{self.projection}" + suffix, name + (", SIP distortion" if sip else "")),
                 ("CUNIT1", "deg", ""), ("CUNIT2", "deg", ""),
                 ("RADESYS", "ICRS", "astrometric directions of the catalog"),
                 ("CRPIX1", float(self.crpix[0]), "principal point, FITS pixels"),
                 ("CRPIX2", float(self.crpix[1]), "principal point, FITS pixels"),
                 ("CRVAL1", float(self.crval[0]), "RA of the principal point [deg]"),
                 ("CRVAL2", float(self.crval[1]), "Dec of the principal point [deg]"),
                 ("LONPOLE", 180.0, ""), ("LATPOLE", float(self.crval[1]), ""),
                 ("CD1_1", float(self.cd[0, 0]), ""), ("CD1_2", float(self.cd[0, 1]), ""),
                 ("CD2_1", float(self.cd[1, 0]), ""), ("CD2_2", float(self.cd[1, 1]), ""),
                 ("IMAGEW", self.width, "image width [px]"), ("IMAGEH", self.height, "image height [px]")]
        cards += [(f"PV2_{m}", float(value), "ZPN coefficient of theta^m") for m, value in sorted(self.pv.items())]
        if sip:
            for name, terms in (("A", self.a), ("B", self.b), ("AP", self.ap), ("BP", self.bp)):
                cards.append((f"{name}_ORDER", self.order, "SIP polynomial order"))
                cards += [(f"{name}_{p}_{q}", float(value), "") for (p, q), value in sorted(terms.items())]
        return cards


#: CRVAL1 [deg] of a reference point at a celestial pole, where the RA is undefined: the orientation
#: astrometry.net's TAN assumes there whatever CRVAL1 says, and wcslib's (astropy's) for this CRVAL1.
_POLE_RA_DEG = 270.0


def reference(boresight):
    """(RA, Dec) [deg] of the unit vector ``boresight`` and the (east, north) unit vectors (2, 3) of the tangent
    plane there; at a pole the limit along the meridian of :data:`_POLE_RA_DEG` (east along +x)."""
    z = np.asarray(boresight, dtype=float)
    east = np.cross([0.0, 0.0, 1.0], z)
    norm = np.linalg.norm(east)
    at_pole = norm <= 1e-15
    east = np.array([1.0, 0.0, 0.0]) if at_pole else east / norm
    ra = _POLE_RA_DEG if at_pole else math.degrees(math.atan2(z[1], z[0])) % 360.0
    return np.array([ra, math.degrees(math.asin(np.clip(z[2], -1.0, 1.0)))]), np.array([east, np.cross(z, east)])


def pixel_scale_arcsec(cd):
    """The pixel scale [arcsec/px] of a CD matrix [deg/px]: 3600 sqrt|det CD| (astrometry.net's
    ``sip_pixel_scale``)."""
    return 3600.0 * math.sqrt(abs(float(np.linalg.det(cd))))


def parity(cd):
    """astrometry.net's parity of a CD matrix: "pos" when det CD < 0 (the sky as seen, east left of north
    with +y up), else "neg" (solve-field's "Field parity")."""
    return "pos" if np.linalg.det(cd) < 0.0 else "neg"


def orientation_deg(cd):
    """astrometry.net's field rotation [deg] in (-180, 180] of a CD matrix (its ``tan_get_orientation``, solve-field's
    "up is ... degrees E of N"): with p = +1 for det CD >= 0, else -1, -atan2(p CD2_1 - CD1_2, p CD1_1 + CD2_2); for a
    conformal CD (square pixels, ours) the position angle, east of north, of the +y axis of FITS pixels (rows
    increasing), atan2(CD1_2, CD2_2)."""
    sign = 1.0 if np.linalg.det(cd) >= 0.0 else -1.0
    angle = -math.degrees(math.atan2(sign * cd[1, 0] - cd[0, 1], sign * cd[0, 0] + cd[1, 1]))
    return 180.0 if angle <= -180.0 else angle + 0.0  # + 0.0: no -0


def _terms(order):
    """(p, q) exponents of the SIP terms of total order 2..``order``."""
    return [(p, n - p) for n in range(2, order + 1) for p in range(n, -1, -1)]


def _fit(U, V, target, order, scale):
    """{(p, q): coefficient} of the least-squares polynomial of ``order`` in (U, V) [px] to ``target`` (N, 2),
    fitted on (U, V) / scale for conditioning; and the largest miss [px]."""
    if order == 0:
        return {}, {}, float(np.abs(target).max())
    terms = _terms(order)
    X = np.stack([(U / scale) ** p * (V / scale) ** q for p, q in terms], axis=1)
    coef, *_ = np.linalg.lstsq(X, target, rcond=None)
    miss = float(np.abs(X @ coef - target).max())
    unscale = np.array([scale ** -(p + q) for p, q in terms])[:, None]
    coef = coef * unscale
    return ({t: c for t, c in zip(terms, coef[:, 0])}, {t: c for t, c in zip(terms, coef[:, 1])}, miss)


def frame_wcs(camera, q_IS, tolerance_arcsec=0.02):
    """The :class:`FrameWcs` of ``camera`` (:class:`startrack.camera.model.Camera`) at attitude ``q_IS`` (S -> I,
    scalar last): CD exact; a fisheye's ZPN exact, a pinhole's SIP polynomials of the lowest order that
    reproduces the camera model within ``tolerance_arcsec`` (as pixels at the focal length) on a grid over
    the image (module text); raises InputError if no order up to :data:`_MAX_ORDER` does."""
    tolerance_px = tolerance_arcsec * ARCSEC * camera.focal_px
    R = to_matrix(np.asarray(q_IS, dtype=float))
    crval, axes = reference(R[:, 2])
    cd = np.degrees(axes @ R[:, :2]) / camera.focal_px  # the sensor's x and y axes on east and north, over f
    crpix = np.array([camera.cx + 1.0, camera.cy + 1.0])
    if camera.projection == "fisheye":
        return FrameWcs(crpix, crval, cd, {}, {}, {}, {}, 0, 0.0, camera.width, camera.height, "ZPN",
                        {1: 1.0, 3: camera.k1, 5: camera.k2})
    u, v = np.meshgrid(np.linspace(-0.5, camera.width - 0.5, GRID), np.linspace(-0.5, camera.height - 0.5, GRID))
    U, V = (u.ravel() - camera.cx), (v.ravel() - camera.cy)
    ideal = camera.focal_px * camera.undistort(np.stack([U, V], axis=1) / camera.focal_px)  # f x_n, f y_n
    scale = max(np.abs(U).max(), np.abs(V).max())
    pinhole = camera.k1 == 0.0 and camera.k2 == 0.0
    for order in [0] if pinhole else range(2, _MAX_ORDER + 1):
        a, b, forward = _fit(U, V, ideal - np.stack([U, V], axis=1), order, scale)
        ap, bp, inverse = _fit(ideal[:, 0], ideal[:, 1], np.stack([U, V], axis=1) - ideal, order, scale)
        if max(forward, inverse) <= tolerance_px:
            return FrameWcs(crpix, crval, cd, a, b, ap, bp, order, max(forward, inverse), camera.width, camera.height)
    raise InputError(f"the camera's distortion (k1 {camera.k1:+.4g}, k2 {camera.k2:+.4g}) is not reproduced by SIP "
                     f"polynomials up to order {_MAX_ORDER} within {tolerance_arcsec:g} arcsec (largest miss "
                     f"{max(forward, inverse):.3g} px)")
