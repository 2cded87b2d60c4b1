"""Quaternion kinematics (navsim.kinematics and its compiled twin) against scipy's Rotation, closed forms and the seed document 000."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from navsim import kinematics, kinematics_jit
from startrack.geometry import rotation as rot

RNG = np.random.default_rng(20261122)
ARCSEC = np.pi / 180 / 3600


def random_quats(n):
    return Rotation.random(n, random_state=7).as_quat()








def test_omega_matrix_of_eq9_equals_the_right_product():
    """eq. 9 of 000: q̇ = ½ Ω(ω) q is docs/design.md's q̇ = ½ q ⊗ [ω, 0] for scalar-last q."""
    q = random_quats(20)
    w = RNG.standard_normal((20, 3))
    via_omega = 0.5 * np.einsum("nij,nj->ni", kinematics.omega_matrix(w), q)
    via_product = 0.5 * rot.multiply(q, np.concatenate([w, np.zeros((20, 1))], axis=1))
    # rounding level: the same products, as a matrix and as a quaternion product
    np.testing.assert_allclose(via_omega, via_product, atol=1e-15)
    np.testing.assert_allclose(kinematics.derivative(q, w), via_product, atol=1e-15)


def test_body_rate_convention_matches_scipy():
    """q_IB(t+dt) = q_IB ⊗ exp(ω dt/2): the body rate composes on the right, like scipy's R1 * R2."""
    q = random_quats(1)[0]
    w = np.array([0.3, -0.2, 0.5])
    expected = (Rotation.from_quat(q) * Rotation.from_rotvec(w * 0.7)).as_quat()
    got = kinematics.propagate_constant_rate(q, w, 0.7)
    assert abs(abs(got @ expected) - 1.0) < 1e-14  # rounding level: one closed-form rotation, two implementations


def _rk4_error(dt, total=2.0):
    q0 = random_quats(1)[0]
    w = np.array([0.4, -0.3, 0.6])
    q = q0.copy()
    for _ in range(int(round(total / dt))):
        q = kinematics.rk4_step(q, w, w, w, dt)
    exact = kinematics.propagate_constant_rate(q0, w, total)
    return np.linalg.norm(rot.attitude_error(exact, q))


def test_rk4_matches_constant_rate_closed_form():
    """At a constant rate RK4 multiplies q by the quartic Taylor polynomial of exp(½Ω Δt), renormalised: a
    turn about ω by φ = 2 atan2(a (1 − a²/6), 1 − a²/2 + a⁴/24), a = |ω|Δt/2; after n steps the error is n |φ − 2a|."""
    dt, steps = 0.01, 200
    a = np.linalg.norm([0.4, -0.3, 0.6]) * dt / 2  # _rk4_error's rate
    truncation = steps * abs(2.0 * np.arctan2(a * (1 - a * a / 6), 1 - a * a / 2 + a**4 / 24) - 2.0 * a)  # 3.0e-12 rad
    assert _rk4_error(dt) < truncation + 1e-13  # and the rounding of 200 steps (~1e-15 seen)


def test_rk4_is_fourth_order():
    """Halving the step divides the global error by ~16 (time-varying rate, 000's profile)."""
    from navsim.truth.profiles import SinusoidalAxis

    profile = SinusoidalAxis(axis=(np.sqrt(2) / 2, 0.5, 0.5), theta0=np.pi / 3, amplitude=np.pi / 6,
                             angular_frequency=1.0)
    axis = np.array(profile.axis) / np.linalg.norm(profile.axis)

    def rate(t):
        return profile.amplitude * profile.angular_frequency * np.cos(t) * axis

    def error(dt, total=3.0):
        q = rot.from_rotation_vector(profile.theta0 * axis)
        t = 0.0
        for _ in range(int(round(total / dt))):
            q = kinematics.rk4_step(q, rate(t), rate(t + dt / 2), rate(t + dt), dt)
            t += dt
        exact = rot.from_rotation_vector((profile.theta0 + profile.amplitude * np.sin(total)) * axis)
        return np.linalg.norm(rot.attitude_error(exact, q))

    e1, e2, e3 = error(0.2), error(0.1), error(0.05)
    assert 13.0 < e1 / e2 < 19.0
    assert 13.0 < e2 / e3 < 19.0


def test_rk4_norm_stays_unit_over_long_runs():
    q = random_quats(1)[0]
    w = np.array([0.5, 0.5, -0.5])
    for _ in range(5000):
        q = kinematics.rk4_step(q, w, w, w, 0.2)
    assert abs(np.linalg.norm(q) - 1.0) < 1e-14  # rounding level: renormalised at every step


def test_rk4_unnormalised_norm_loss_matches_its_closed_form():
    """RK4 on q̇ = ½Ω q multiplies q by the quartic Taylor polynomial of exp(½Ω dt); with
    a = |ω|dt/2 its gain is (1 − a⁶/72 + a⁸/576)^½, the per-step norm loss that renormalisation removes."""
    q = random_quats(1)[0]
    w = np.array([0.8, -0.4, 0.6])
    dt = 0.3
    k1 = kinematics.derivative(q, w)
    k2 = kinematics.derivative(q + 0.5 * dt * k1, w)
    k3 = kinematics.derivative(q + 0.5 * dt * k2, w)
    k4 = kinematics.derivative(q + dt * k3, w)
    raw = q + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    a = np.linalg.norm(w) * dt / 2  # rounding level: an exact identity of the polynomial
    assert np.linalg.norm(raw) == pytest.approx(np.sqrt(1 - a**6 / 72 + a**8 / 576), abs=1e-15)


# Table 2 of 000: true quaternions (q1, q2, q3, q4) and the boresight declinations [deg].
TABLE2 = [
    ((0.3536, 0.2500, 0.2500, 0.8660), 38.67),
    ((0.4274, 0.3022, 0.3022, 0.7960), 26.84),
    ((0.2959, 0.2092, 0.2092, 0.9082), 47.51),
    ((0.2261, 0.1599, 0.1599, 0.9475), 57.91),
]


@pytest.mark.parametrize("q, dec_deg", TABLE2)
def test_boresight_declination_of_table2(q, dec_deg):
    """eq. 10 of 000 from the printed true quaternions reproduces the printed declinations.

    (The printed right ascensions do not follow eq. 10 — see shared/seeds/README.md.)"""
    q = np.array(q) / np.linalg.norm(q)
    _, dec = kinematics.boresight_radec(q)
    assert np.degrees(dec) == pytest.approx(dec_deg, abs=0.1)
    q1, q2, q3, q4 = q
    assert np.sin(dec) == pytest.approx(-q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4, abs=1e-12)  # rounding level: closed forms


def test_boresight_right_ascension_follows_eq10():
    q = random_quats(200)
    ra, _ = kinematics.boresight_radec(q)
    q1, q2, q3, q4 = q.T
    tan_eq10 = (q2 * q3 - q1 * q4) / (q1 * q3 + q2 * q4)  # rounding level (of tan near ±π/2): closed forms
    np.testing.assert_allclose(np.tan(ra), tan_eq10, rtol=1e-9, atol=1e-9)
    boresight = Rotation.from_quat(q).apply([0, 0, 1])
    np.testing.assert_allclose(ra, np.mod(np.arctan2(boresight[:, 1], boresight[:, 0]), 2 * np.pi), atol=1e-12)


def test_boresight_with_a_mounting_rotation():
    q_IB = random_quats(1)[0]
    R_BS = Rotation.from_euler("y", 90, degrees=True).as_matrix()  # boresight along +x_B
    ra, dec = kinematics.boresight_radec(q_IB, R_BS)
    x_I = Rotation.from_quat(q_IB).apply([1, 0, 0])  # rounding level: closed forms
    assert np.sin(dec) == pytest.approx(x_I[2], abs=1e-12)
    assert ra == pytest.approx(np.mod(np.arctan2(x_I[1], x_I[0]), 2 * np.pi), abs=1e-12)


def test_compiled_twin_equals_the_numpy_forms():
    q = random_quats(1)[0]
    w = np.array([0.2, 0.1, -0.3])  # rounding level: compiled twins of the same operations
    np.testing.assert_allclose(kinematics_jit.rk4_hold(q, w, 0.1), kinematics.rk4_step(q, w, w, w, 0.1), atol=1e-15)
    np.testing.assert_allclose(kinematics_jit.quat_derivative(q, w), kinematics.derivative(q, w), atol=1e-15)
