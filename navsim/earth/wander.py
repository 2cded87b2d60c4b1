"""The wander-azimuth frame w of the INS (issue 31): local level like NED (z down along the ellipsoid's
normal), its x axis turned from north towards east by the wander angle α, and no rotation about the
vertical relative to the Earth (ω_ew^w has no z component). The position is C_ew (the quaternion q_ew) and the
height h: no latitude, longitude or heading anywhere in it, so it is regular at the poles (Titterton & Weston,
2nd ed., §3.7.1; Groves, 2nd ed., §5.3.5 and §2.4.3; Savage 2000, ch. 4).

With s = sin L = −C_ew[2, 2] and c = (C_ew[2, 0], C_ew[2, 1]) = cos L · (north in w axes):

    ω_ie^w = ω_ie C_ew[2, :]ᵀ                                       (the Earth's axis in w)           (1)
    ω_ew^w = [g_y, −g_x, 0],  g = D v_h,  D = I/(R_N + h) + k c cᵀ,   k = R_N e² / ((1 − e² s²)(R_M+h)(R_N+h))
                                                                   (= (1/(R_M+h) − 1/(R_N+h)) / cos²L)   (2)

D is the curvature of the ellipsoid's parallel surface in w axes, diag(1/(R_M+h), 1/(R_N+h)) turned by α (k is
finite at the poles, where D is isotropic), and (2) is the NED transport rate's horizontal part turned by α.
C_nw = R_z(α) turns w into NED where NED is defined (|L| < 90°); ``geodetic`` gives (L, λ, α) from C_ew (at a
pole λ is the meridian the frame's numbers happen to give, and α follows it, so C_en(L, λ) C_nw = C_ew always).
"""

import numpy as np

from navsim.earth.frames import OMEGA_IE, c_en, q_en
from navsim.earth.wgs84 import E2, A, radii
from startrack import njit
from startrack import rotation as rot
from startrack import rotation_kernels as rk


@njit
def radii_of_sine(s):
    """(R_M, R_N) [m] at sin L = ``s`` (:func:`navsim.earth.wgs84.radii`) and their derivatives d/ds."""
    w = 1.0 - E2 * s * s
    r_n = A / np.sqrt(w)
    r_m = r_n * (1.0 - E2) / w
    return r_m, r_n, 3.0 * r_m * E2 * s / w, r_n * E2 * s / w


@njit
def parallel_curvature(s, h):
    """(1/(R_N + h), k) [1/m] of eq. 2 at sin L = ``s`` and h [m]: D = I/(R_N + h) + k c cᵀ."""
    r_m, r_n, _, _ = radii_of_sine(s)
    return 1.0 / (r_n + h), r_n * E2 / ((1.0 - E2 * s * s) * (r_m + h) * (r_n + h))


@njit
def curvature(C, h):
    """(D (2, 2) [1/m], k [1/m], s, c (2,)) of eq. 2 at the position C_ew (3, 3), h [m]."""
    s = -C[2, 2]
    c = np.array([C[2, 0], C[2, 1]])
    iso, k = parallel_curvature(s, h)
    D = np.empty((2, 2))
    for i in range(2):
        for j in range(2):
            D[i, j] = k * c[i] * c[j] + (iso if i == j else 0.0)
    return D, k, s, c


@njit
def axis_of(q):
    """(c0, c1, c2) = C_ew[2, :], the Earth's axis in w (eq. 1: ω_ie^w = ω_ie C_ew[2, :]ᵀ; c0, c1 the c of eq. 2 and
    c2 = −sin L), of the unit quaternion q_ew (4,) or 4-tuple, as scalars (the third row of
    :func:`startrack.geometry.rotation_kernels.quat_to_matrix`, without allocating it)."""
    x, y, z, w = q[0], q[1], q[2], q[3]
    return 2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)


@njit
def transport_of_axis(c0, c1, c2, h, v0, v1):
    """(g_y, −g_x) [rad/s], the horizontal part of ω_ew^w (eq. 2; g = D v_h = v_h/(R_N + h) + k c (c · v_h)), at the
    axis (c0, c1, c2) of :func:`axis_of`, h [m] and the horizontal ground velocity (v0, v1) [m/s] in w (scalars: no
    allocation)."""
    iso, k = parallel_curvature(-c2, h)
    projection = k * (c0 * v0 + c1 * v1)
    return iso * v1 + projection * c1, -(iso * v0 + projection * c0)


@njit
def earth_rate_w(C):
    """ω_ie^w (3,) [rad/s] (eq. 1)."""
    return np.array([OMEGA_IE * C[2, 0], OMEGA_IE * C[2, 1], OMEGA_IE * C[2, 2]])


@njit
def transport_rate_w(C, h, v):
    """ω_ew^w (3,) [rad/s] at C_ew, h [m] for the ground velocity v (3,) [m/s] in w (eq. 2; :func:`transport_of_axis`)."""
    x, y = transport_of_axis(C[2, 0], C[2, 1], C[2, 2], h, v[0], v[1])
    return np.array([x, y, 0.0])


def q_ew(lat, lon, alpha=0.0):
    """q_ew (..., 4) of the w frame at (L, λ) [rad] with wander angle α [rad]: q_en ⊗ q_z(α)."""
    lat, lon, alpha = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (lat, lon, alpha)))
    zero = np.zeros_like(alpha)
    return rot.multiply(np.stack(q_en(lat, lon), axis=-1), rot.from_rotation_vector(np.stack([zero, zero, alpha], -1)))


@njit
def frame_angles(C):
    """(L, λ, α) [rad] of one w frame C_ew (3, 3): L = atan2(s, |c|), λ from the normal, α the angle from the north
    of (L, λ) to the x axis of w towards east."""
    lat = np.arctan2(-C[2, 2], np.hypot(C[2, 0], C[2, 1]))
    lon = np.arctan2(-C[1, 2], -C[0, 2])
    sl, so, co = np.sin(lat), np.sin(lon), np.cos(lon)
    north = C[0, 0] * (-sl * co) + C[1, 0] * (-sl * so) + C[2, 0] * np.cos(lat)
    east = -C[0, 0] * so + C[1, 0] * co
    return lat, lon, np.arctan2(east, north)


@njit
def _angles_of_rows(q):
    out = np.empty((q.shape[0], 3))
    for i in range(q.shape[0]):
        out[i] = frame_angles(rk.quat_to_matrix(q[i]))
    return out


def geodetic(q):
    """(L, λ, α) [rad] (...,) of the w frames q_ew (..., 4) (:func:`frame_angles`)."""
    q = np.asarray(q, dtype=float)
    out = _angles_of_rows(np.ascontiguousarray(q.reshape(-1, 4))).reshape(q.shape[:-1] + (3,))
    return out[..., 0], out[..., 1], out[..., 2]


@njit
def _ned_rows(q, v_w, q_wb):
    """[L, λ [rad], v_n (3), q_nb (4)] (K, 9) of the rows q_ew (K, 4), v_w (K, 3), q_wb (K, 4) (:func:`to_ned`)."""
    out = np.empty((q.shape[0], 9))
    for i in range(q.shape[0]):
        out[i, 0], out[i, 1], alpha = frame_angles(rk.quat_to_matrix(q[i]))
        q_nw = rk.quat_from_rotation_vector(np.array([0.0, 0.0, alpha]))
        C_nw = rk.quat_to_matrix(q_nw)
        for r in range(3):
            out[i, 2 + r] = C_nw[r, 0] * v_w[i, 0] + C_nw[r, 1] * v_w[i, 1] + C_nw[r, 2] * v_w[i, 2]
        out[i, 5:9] = rk.quat_multiply(q_nw, q_wb[i])
    return out


def to_ned(q, v_w, q_wb):
    """(L, λ, v_n, q_nb) of the w-frame solution q_ew (..., 4), v_w (..., 3), q_wb (..., 4): L, λ and α of
    :func:`frame_angles`, v_n = C_nw v_w, q_nb = q_z(α) ⊗ q_wb (one compiled pass over the rows)."""
    q = np.ascontiguousarray(q, dtype=float)
    shape = q.shape[:-1]
    out = _ned_rows(q.reshape(-1, 4), np.ascontiguousarray(v_w, dtype=float).reshape(-1, 3),
                    np.ascontiguousarray(q_wb, dtype=float).reshape(-1, 4))
    out = out.reshape(shape + (9,))
    return out[..., 0], out[..., 1], out[..., 2:5], out[..., 5:9]


def normal(lat, lon):
    """The ellipsoid's outward normal (..., 3) in e at geodetic (L, λ) [rad]."""
    return -c_en(lat, lon)[..., 2]


def normal_turn(up_from, up_to):
    """δθ_e (..., 3) [rad, e axes]: the least rotation (axis ⟂ both) that turns the unit normal ``up_from`` into
    ``up_to``; the turn of one position's local-level frame into another's (C_ew,to = exp([δθ_e×]) C_ew,from)."""
    axis = np.cross(up_from, up_to)
    sine = np.linalg.norm(axis, axis=-1)
    angle = np.arctan2(sine, np.sum(up_from * up_to, axis=-1))
    return axis * np.where(sine > 0.0, angle / np.where(sine > 0.0, sine, 1.0), 1.0)[..., None]


def carried_ned(lat_from, lon_from, lat_to, lon_to):
    """C_n'n (..., 3, 3): NED vectors at (L, λ) carried to the NED at (L', λ') [rad] by the least turn of the normal
    (:func:`normal_turn`): C_n'e exp([δθ_e×]) C_en. Near each other it is a rotation about the vertical by the
    meridians' convergence (δλ sin L to first order, any angle at a pole: there NED is along λ)."""
    turn = rot.to_matrix(rot.from_rotation_vector(normal_turn(normal(lat_from, lon_from), normal(lat_to, lon_to))))
    return np.swapaxes(c_en(lat_to, lon_to), -1, -2) @ turn @ c_en(lat_from, lon_from)


def ned_offset(lat, lon, h, lat_ref, lon_ref, h_ref):
    """(north, east, down) [m] (..., 3) of positions (L, λ, h) from reference ones in the reference's NED: the
    turn δθ_n of the reference's normal into the other's (:func:`normal_turn`, C_en = C_en,ref (I + [δθ_n×]) to
    first order), then δN = −(R_M + h) δθ_y, δE = (R_N + h) δθ_x (δθ_n = [δλ cos L, −δL, ·]), δD = −δh. Defined
    wherever the reference's NED is (at a pole, along its meridian λ_ref): no cos L divides anything."""
    C_ne = np.swapaxes(c_en(lat_ref, lon_ref), -1, -2)
    theta_n = np.einsum("...ij,...j->...i", C_ne, normal_turn(normal(lat_ref, lon_ref), normal(lat, lon)))
    r_m, r_n = radii(lat_ref)
    return np.stack([-(r_m + h_ref) * theta_n[..., 1], (r_n + h_ref) * theta_n[..., 0],
                     -(np.asarray(h) - h_ref)], axis=-1)


def displaced(lat, lon, h, north, east):
    """(L, λ) [rad] (arrays of the inputs' broadcast shape) of the points ``north``, ``east`` [m] from (L, λ, h) along
    their NED axes: the normal turned by C_en [δE/(R_N + h), −δN/(R_M + h), 0] (the inverse of :func:`ned_offset` to
    first order; at a pole, NED along λ: no cos L divides anything)."""
    r_m, r_n = radii(lat)
    east, north = np.broadcast_arrays(east / (r_n + h), -north / (r_m + h))
    turn = np.einsum("...ij,...j->...i", c_en(lat, lon), np.stack([east, north, np.zeros_like(east)], axis=-1))
    up = rot.rotate(rot.from_rotation_vector(turn), normal(lat, lon))
    return np.arctan2(up[..., 2], np.hypot(up[..., 0], up[..., 1])), np.arctan2(up[..., 1], up[..., 0])
