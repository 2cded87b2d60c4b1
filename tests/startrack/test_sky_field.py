"""The field of a solved frame as plate solvers report it (startrack.camera.sky_field), against independent
computations: astropy.wcs on the frame's TAN-SIP header (the centre pixel's direction, the position angle of
the +y axis from two pixels by astropy's SkyCoord.position_angle, the local pixel scale, the field's width and
height through the middle row and column by SkyCoord.separation), the attitude a frame was rendered at (up is
-roll E of N: 003's roll puts the north pole at roll from +y towards +x), astropy's sexagesimal strings, and a
Monte Carlo of the centre's sigma.

Tolerances: the WCS reproduces the camera model within 0.02" (startrack.camera.wcs), so the centre agrees within
0.05"; the position angle over a 1 px baseline (35-300") is measured through the SIP polynomials, smooth on that
scale (their misfit varies over tens of pixels), to 0.002 deg; scale and size relative 1e-5 (0.02" over a
35" pixel is 6e-4 at worst, the polynomials' misfit a smooth fraction of that over one pixel).
"""

import math

import numpy as np
import pytest
from astropy.coordinates import Angle, SkyCoord
from astropy.io import fits
from astropy.wcs import WCS

from startrack.base.units import ARCSEC, DEG, dec_dms, ra_hms
from startrack.camera.model import Camera
from startrack.camera.sky_field import sky_field
from startrack.camera.wcs import frame_wcs, orientation_deg, parity
from startrack.geometry.attitude_angles import quaternion_from_radec_roll
from startrack.geometry.rotation import from_rotation_vector, multiply, to_matrix

#: astropy notes that a header without data has no image axes.
pytestmark = pytest.mark.filterwarnings("ignore:The WCS transformation has more axes")

CAMERAS = {  # (fov [deg], width, height, cx, cy, k1, k2, projection)
    "pinhole": (10.0, 1024, 768, None, None, 0.0, 0.0, "pinhole"),
    "real-like": (11.4, 1024, 768, 514.4, 390.1, 0.09, 0.0, "pinhole"),
    "barrel": (30.0, 1600, 1200, 790.3, 610.7, -0.1, 0.01, "pinhole"),
    "fisheye": (100.0, 1200, 1000, 603.0, 497.0, -0.02, 0.001, "fisheye"),
}
ATTITUDES = {"orion": (83.8, -5.4, 30.0), "near pole": (40.0, 87.5, -120.0), "ra 0": (359.9, 20.0, 175.0),
             "south": (250.0, -60.0, -10.0)}


def _camera(name):
    fov, width, height, cx, cy, k1, k2, projection = CAMERAS[name]
    return Camera.from_fov(fov * DEG, width, height, cx=cx, cy=cy, k1=k1, k2=k2, projection=projection)


def _sky(wcs, u, v):
    """SkyCoord of 0-based pixels through astropy.wcs."""
    ra, dec = wcs.all_pix2world(np.atleast_1d(u), np.atleast_1d(v), 0)
    return SkyCoord(ra, dec, unit="deg")


@pytest.mark.parametrize("attitude", ATTITUDES)
@pytest.mark.parametrize("name", CAMERAS)
def test_the_field_is_what_astropy_reads_from_the_wcs(name, attitude):
    camera = _camera(name)
    q = quaternion_from_radec_roll(*np.radians(ATTITUDES[attitude]))
    field = sky_field(camera, q, np.eye(3) * ARCSEC**2)
    wcs = WCS(fits.Header(frame_wcs(camera, q).cards()))
    cu, cv = (camera.width - 1) / 2.0, (camera.height - 1) / 2.0
    centre = _sky(wcs, cu, cv)
    assert centre.separation(SkyCoord(field.ra_deg, field.dec_deg, unit="deg")).arcsec[0] < 0.05
    pa = centre.position_angle(_sky(wcs, cu, cv + 0.5)).deg[0]  # of +y at the centre, E of N (a great circle)
    assert abs(((field.orientation_deg - pa) + 180.0) % 360.0 - 180.0) < 0.002
    ends = _sky(wcs, [cu - 0.5, cu, cu + 0.5], [cv, cv, cv])
    scale = math.sqrt(ends[0].separation(ends[2]).arcsec * _sky(wcs, cu, cv - 0.5).separation(_sky(wcs, cu, cv + 0.5)).arcsec[0])
    assert field.scale_arcsec == pytest.approx(scale, rel=1e-5)
    row = _sky(wcs, [-0.5, cu, camera.width - 0.5], [cv] * 3)
    column = _sky(wcs, [cu] * 3, [-0.5, cv, camera.height - 0.5])
    if camera.projection == "pinhole":  # a fisheye's ZPN through astropy is exact too, but its rows are not great circles
        assert field.width_deg == pytest.approx(row[0].separation(row[1]).deg + row[1].separation(row[2]).deg, rel=1e-5)
        assert field.height_deg == pytest.approx(column[0].separation(column[1]).deg + column[1].separation(column[2]).deg,
                                                 rel=1e-5)
    turn = (centre.position_angle(_sky(wcs, cu + 0.5, cv)).deg[0] - pa) % 360.0  # from +y to +x, E of N
    assert field.parity == ("neg" if abs(turn - 90.0) < 1.0 else "pos") and min(abs(turn - 90.0), abs(turn - 270.0)) < 1.0


@pytest.mark.parametrize("roll", [0.0, 30.0, -150.0, 179.9, 90.0])
def test_a_rendered_attitude_shows_up_at_minus_its_roll(roll):
    """003's roll puts the north pole at roll from +y towards +x, so +y (FITS up) is at -roll E of N; a camera
    with its principal point at the centre: the centre is the boresight, the scale 206264.8"/f."""
    camera = _camera("pinhole")
    q = quaternion_from_radec_roll(83.8 * DEG, -5.4 * DEG, roll * DEG)
    field = sky_field(camera, q, np.zeros((3, 3)))
    assert field.orientation_deg == pytest.approx(-roll, abs=1e-9)
    assert (field.ra_deg, field.dec_deg) == pytest.approx((83.8, -5.4), abs=1e-9)
    assert field.parity == "neg"
    assert field.scale_arcsec == pytest.approx(1.0 / camera.focal_px / ARCSEC, rel=1e-9)
    assert field.width_deg == pytest.approx(10.0, abs=1e-9)
    assert field.height_deg == pytest.approx(2.0 * math.degrees(math.atan(384.0 / camera.focal_px)), abs=1e-9)


def test_astrometry_nets_orientation_and_parity_of_cd_matrices():
    """tan_get_orientation of conformal CD matrices of both parities is the position angle of +y (the column
    (CD1_2, CD2_2) on east and north); det CD < 0 is astrometry.net's "pos" (north up, east left)."""
    for angle in (-179.0, -90.0, -10.0, 0.0, 45.0, 180.0):
        c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        normal = 1e-3 * np.array([[-c, s], [s, c]])  # +y at angle E of N, +x towards west: the sky as seen
        flipped = 1e-3 * np.array([[c, s], [-s, c]])
        assert orientation_deg(normal) == pytest.approx(angle if angle != -180.0 else 180.0, abs=1e-9)
        assert orientation_deg(flipped) == pytest.approx(angle, abs=1e-9)
        assert (parity(normal), parity(flipped)) == ("pos", "neg")


@pytest.mark.parametrize("value", [0.0, 83.82, 172.3687988, 359.99999999, 15.0 * 23.999999999])
def test_sexagesimal_is_astropys(value):
    assert ra_hms(value) == Angle(value % 360.0, "deg").wrap_at("360d").to_string("hourangle", sep=":", precision=3,
                                                                               pad=True).replace("24:00:00.000", "00:00:00.000")
    dec = value / 4.0 - 45.0
    assert dec_dms(dec) == Angle(dec, "deg").to_string(sep=":", precision=2, alwayssign=True, pad=True)


def test_the_centres_sigma_is_the_spread_of_the_centres_it_propagates():
    """The centre's east and north sigma from (dtheta, f, cx, cy, k1, k2) with correlations, against 4000
    draws of the attitude and the camera through the camera model: within 6 % (the sampling's 2.2 % sigma)."""
    camera = _camera("real-like")
    q = quaternion_from_radec_roll(172.37 * DEG, 57.65 * DEG, 123.4 * DEG)
    rng = np.random.default_rng(64)
    spread = np.array([180 * ARCSEC, 160 * ARCSEC, 15 * ARCSEC, 1.0, 4.0, 4.5, 0.03, 1e-3])
    correlation = np.eye(8)
    correlation[0, 5] = correlation[5, 0] = -0.95  # the principal point against the attitude, as fits have it
    correlation[1, 4] = correlation[4, 1] = 0.95
    covariance = correlation * np.outer(spread, spread)
    field = sky_field(camera, q, covariance)
    draws = rng.multivariate_normal(np.zeros(8), covariance, 4000)
    centre = [[(camera.width - 1) / 2.0, (camera.height - 1) / 2.0]]
    directions = []
    for d in draws:
        moved = Camera(camera.width, camera.height, camera.focal_px + d[3], camera.cx + d[4], camera.cy + d[5],
                       camera.k1 + d[6], camera.k2 + d[7])
        directions.append(to_matrix(multiply(q, from_rotation_vector(d[:3]))) @ moved.unproject(centre)[0])
    found = SkyCoord(*np.degrees(np.array([[math.atan2(y, x), math.asin(z)] for x, y, z in directions])).T, unit="deg")
    east, north = SkyCoord(field.ra_deg, field.dec_deg, unit="deg").spherical_offsets_to(found)
    assert np.std(east.arcsec) == pytest.approx(field.sigma_east_arcsec, rel=0.06)
    assert np.std(north.arcsec) == pytest.approx(field.sigma_north_arcsec, rel=0.06)
