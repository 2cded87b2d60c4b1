"""The Earth of the strapdown INS: WGS-84 geometry (:mod:`navsim.earth.wgs84`), normal gravity and its
disturbance (:mod:`navsim.earth.gravity`), the frames n, e, i (:mod:`navsim.earth.frames`), the Earth's
orientation and an observer's barycentric velocity (:mod:`navsim.earth.orientation`), and the apparent
star directions such an observer sees (:mod:`navsim.earth.apparent`).

Conventions are those of docs/design.md: NED navigation frame, geodetic latitude L, longitude λ,
height h above the ellipsoid [rad, rad, m], gravity g_n = [0, 0, +g] (down positive).
"""
