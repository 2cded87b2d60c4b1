"""The Earth of the strapdown INS: WGS-84 geometry (:mod:`navsim.earth.wgs84`), normal gravity and its
disturbance (:mod:`navsim.earth.gravity`), and the frames n, e, i (:mod:`navsim.earth.frames`).

Conventions are those of docs/design.md: NED navigation frame, geodetic latitude L, longitude λ,
height h above the ellipsoid [rad, rad, m], gravity g_n = [0, 0, +g] (down positive).
"""
