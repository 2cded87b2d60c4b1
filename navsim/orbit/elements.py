"""Keplerian elements <-> Cartesian states, the Earth's constants of an orbit, and the closed forms of the J2
secular motion that the tests hold the numerical propagator to.

Elements: semi-major axis a [m], eccentricity e, inclination i, right ascension of the ascending node Ω,
argument of perigee ω and true anomaly ν [rad], in GCRS axes (Vallado, *Fundamentals of Astrodynamics and
Applications*, 4th ed., algorithms 9 RV2COE and 10 COE2RV). The Earth: GM and the equatorial radius of
WGS-84 (NIMA TR8350.2, the values :mod:`navsim.earth.wgs84` holds) and J2 = −√5 C̄20 of EGM2008
(C̄20 = −4.84165143790815e-4, Pavlis et al. 2012).
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.wgs84 import GM
from navsim.earth.wgs84 import A as R_EARTH
from startrack import InputError

#: J2 of EGM2008: −√5 C̄20 (the normalised coefficient, Pavlis et al. 2012).
J2 = -np.sqrt(5.0) * -4.84165143790815e-4
#: The Earth's mean motion about the Sun [rad/s] (360 deg per tropical year of 365.2421897 d): the node rate of
#: a sun-synchronous orbit.
SUN_SYNCHRONOUS_RATE = 2.0 * np.pi / (365.2421897 * 86400.0)


@dataclass(frozen=True)
class Elements:
    """Osculating Keplerian elements in GCRS axes: a [m], e, i, Ω (raan), ω (argp), ν [rad] (module docstring)."""

    a: float
    e: float
    i: float
    raan: float
    argp: float
    nu: float

    def state(self, mu=GM):
        """(r (3,), v (3,)) [m, m/s] of the elements about a body of GM ``mu`` (Vallado alg. 10)."""
        p = self.a * (1.0 - self.e**2)
        c, s = np.cos(self.nu), np.sin(self.nu)
        r_pqw = p / (1.0 + self.e * c) * np.array([c, s, 0.0])
        v_pqw = np.sqrt(mu / p) * np.array([-s, self.e + c, 0.0])
        R = perifocal_to_inertial(self.raan, self.i, self.argp)
        return R @ r_pqw, R @ v_pqw

    @classmethod
    def of_state(cls, r, v, mu=GM):
        """The osculating elements of a bound state (r, v) [m, m/s] (Vallado alg. 9; Ω, ω and ν in [0, 2π),
        ω = 0 for a circular orbit and Ω = 0 for an equatorial one, their sums then carried by ν)."""
        r, v = np.asarray(r, dtype=float), np.asarray(v, dtype=float)
        h = np.cross(r, v)
        node = np.cross([0.0, 0.0, 1.0], h)
        rn, vn, hn, nn = np.linalg.norm(r), np.linalg.norm(v), np.linalg.norm(h), np.linalg.norm(node)
        e_vec = ((vn**2 - mu / rn) * r - np.dot(r, v) * v) / mu
        e = float(np.linalg.norm(e_vec))
        energy = 0.5 * vn**2 - mu / rn
        if energy >= 0.0:
            raise InputError(f"orbit: the state is not bound (specific energy {energy:.4g} J/kg >= 0)")
        a = -mu / (2.0 * energy)
        i = float(np.arccos(np.clip(h[2] / hn, -1.0, 1.0)))
        raan = float(np.arctan2(node[1], node[0]) % (2.0 * np.pi)) if nn > 1e-12 * hn else 0.0
        line = node / nn if nn > 1e-12 * hn else np.array([1.0, 0.0, 0.0])
        normal_line = np.cross(h / hn, line)
        if e > 1e-12:
            argp = float(np.arctan2(np.dot(e_vec, normal_line), np.dot(e_vec, line)) % (2.0 * np.pi))
            nu = float(np.arctan2(np.dot(np.cross(e_vec / e, r), h / hn), np.dot(e_vec / e, r)) % (2.0 * np.pi))
        else:
            argp = 0.0
            nu = float(np.arctan2(np.dot(r, normal_line), np.dot(r, line)) % (2.0 * np.pi))
        return cls(a=float(a), e=e, i=i, raan=raan, argp=argp, nu=nu)

    @property
    def mean_anomaly(self):
        """M [rad] in [0, 2π) of the true anomaly (elliptic orbits; Vallado alg. 5)."""
        E = 2.0 * np.arctan2(np.sqrt(1.0 - self.e) * np.sin(0.5 * self.nu), np.sqrt(1.0 + self.e) * np.cos(0.5 * self.nu))
        return float((E - self.e * np.sin(E)) % (2.0 * np.pi))

    @classmethod
    def with_mean_anomaly(cls, a, e, i, raan, argp, mean_anomaly):
        """The elements of a mean anomaly M [rad] instead of ν: Kepler's equation M = E − e sin E by Newton's method
        to 1e-15 rad."""
        E = mean_anomaly if e < 0.8 else np.pi
        for _ in range(50):
            step = (E - e * np.sin(E) - mean_anomaly) / (1.0 - e * np.cos(E))
            E -= step
            if abs(step) < 1e-15:
                break
        nu = 2.0 * np.arctan2(np.sqrt(1.0 + e) * np.sin(0.5 * E), np.sqrt(1.0 - e) * np.cos(0.5 * E))
        return cls(a=a, e=e, i=i, raan=raan, argp=argp, nu=float(nu % (2.0 * np.pi)))


def perifocal_to_inertial(raan, i, argp):
    """The rotation (3, 3) of the perifocal axes (P to perigee, W along the angular momentum) into the inertial
    axes: R_z(Ω) R_x(i) R_z(ω)."""
    def r_z(x):
        c, s = np.cos(x), np.sin(x)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    c, s = np.cos(i), np.sin(i)
    return r_z(raan) @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]) @ r_z(argp)


def mean_motion(a, mu=GM):
    """n = √(μ/a³) [rad/s] of a semi-major axis a [m]."""
    return np.sqrt(mu / a**3)


def j2_node_rate(a, e, i, j2=J2, radius=R_EARTH, mu=GM):
    """Ω̇ [rad/s]: the secular rate of the node in the J2 field for mean elements a [m], e, i [rad], to second order
    in J2 (Brouwer 1959, the secular part h'' of his solution), with γ2' = (J2/2)(R/p)², η = √(1 − e²), θ = cos i and
    n0 = √(μ/a³):

        Ω̇ = n0 [−3 γ2' θ + (3/8) γ2'² ((−5 + 12η + 9η²) θ + (−35 − 36η − 5η²) θ³)],

    whose first term is the familiar −(3/2) n0 J2 (R/p)² cos i (Vallado eq. 9-41); the second is ~1e-3 of it. The
    time averages of the osculating a, e and i over whole revolutions are these mean elements to O(J2²)."""
    n0 = mean_motion(a, mu)
    eta = np.sqrt(1.0 - e**2)
    theta = np.cos(i)
    g2 = 0.5 * j2 * (radius / (a * (1.0 - e**2))) ** 2
    return n0 * (-3.0 * g2 * theta + 0.375 * g2**2 * ((-5.0 + 12.0 * eta + 9.0 * eta**2) * theta
                                                       + (-35.0 - 36.0 * eta - 5.0 * eta**2) * theta**3))


def sun_synchronous_inclination(a, e=0.0, j2=J2, radius=R_EARTH, mu=GM):
    """The inclination [rad] whose first-order J2 node rate −(3/2) n J2 (R/p)² cos i is the Sun's mean motion
    (Vallado eq. 11-17); an InputError for an orbit too high to be sun-synchronous (cos i < −1)."""
    p = a * (1.0 - e**2)
    cos_i = -SUN_SYNCHRONOUS_RATE / (1.5 * mean_motion(a, mu) * j2 * (radius / p) ** 2)
    if cos_i < -1.0:
        raise InputError(f"orbit: no sun-synchronous inclination for a = {a / 1e3:.0f} km (the J2 node rate is too slow)")
    return float(np.arccos(cos_i))
