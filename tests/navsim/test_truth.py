"""Truth motion: 000's experiment, exact profiles, and rigid-body invariants."""

import numpy as np
import pytest

from navsim import kinematics
from navsim.truth.profiles import ConstantRate, RateSegments, RigidBody, SinusoidalAxis, interval_mean_rates
from startrack.geometry import rotation as rot

PAPER000 = SinusoidalAxis(axis=(np.sqrt(2) / 2, 0.5, 0.5), theta0=np.pi / 3, amplitude=np.pi / 6, angular_frequency=1.0)
IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def test_paper000_profile_reproduces_table2_true_quaternions():
    """Table 2 of 000 (T = 0.5 s, 2 Hz): the truth at 0, T, 7T, 8T. The vector parts agree to the
    four printed digits; so do the scalar parts except in row T, which is not of unit norm as
    printed (0.99894): the q4 that makes its printed vector part a unit quaternion is what we get."""
    t = np.arange(0, 4.0 + 1e-9, 0.5)
    q, _ = PAPER000.simulate(t, IDENTITY)
    printed = {0: (0.3536, 0.2500, 0.2500, 0.8660), 1: (0.4274, 0.3022, 0.3022, 0.7960),
               7: (0.2959, 0.2092, 0.2092, 0.9082), 8: (0.2261, 0.1599, 0.1599, 0.9475)}
    for k, expected in printed.items():
        np.testing.assert_allclose(q[k][:3], expected[:3], atol=1.5e-4)
        if k != 1:
            assert q[k][3] == pytest.approx(expected[3], abs=1.5e-4)
    unit_q4 = np.sqrt(1.0 - np.sum(np.square(printed[1][:3])))  # 0.7966
    assert q[1][3] == pytest.approx(unit_q4, abs=1e-4)


def test_paper000_peak_rate_is_30_deg_per_s():
    t = np.linspace(0, 2 * np.pi, 2001)
    _, w = PAPER000.simulate(t, IDENTITY)
    # rounding level: the grid holds t = 0, where the closed-form rate peaks
    assert np.degrees(np.linalg.norm(w, axis=1).max()) == pytest.approx(30.0, rel=1e-6)


@pytest.mark.parametrize(
    "profile",
    [
        ConstantRate(rate=(0.1, -0.2, 0.3)),
        PAPER000,
        RateSegments(segments=((1.0, (0.1, 0.0, 0.0)), (1.0, (0.0, 0.2, -0.1)), (2.0, (0.0, 0.0, 0.3)))),
    ],
)
def test_prescribed_profiles_satisfy_the_kinematics(profile):
    """q(t+h) = RK4 of q̇ = ½ q ⊗ [ω, 0] from q(t) with the profile's own rates."""
    t = np.arange(0, 3.0 + 1e-9, 1e-3)
    q, w = profile.simulate(t, rot.from_rotation_vector([0.1, 0.2, 0.3]))
    for k in range(0, len(t) - 2, 97):
        if isinstance(profile, RateSegments) and np.any(w[k] != w[k + 2]):
            continue
        q_next = kinematics.rk4_step(q[k], w[k], w[k + 1], w[k + 2], 2e-3)
        # RK4's local error is below h⁵ = 3e-14 rad here (rates and all their derivatives < 1 s⁻¹; the profiles
        # are closed forms); 1e-13 covers it and the rounding of the two quaternions (6e-16 seen)
        assert np.linalg.norm(rot.attitude_error(q[k + 2], q_next)) < 1e-13


def test_rate_segments_must_cover_the_run():
    with pytest.raises(ValueError, match="cover"):
        RateSegments(segments=((1.0, (0, 0, 0.1)),)).simulate(np.linspace(0, 2, 11), IDENTITY)


def test_torque_free_rigid_body_conserves_momentum_and_energy():
    J = np.diag([10.0, 12.0, 7.0])
    body = RigidBody(inertia=tuple(map(tuple, J)), initial_rate=(0.01, 0.005, -0.012))
    t = np.arange(0, 600.0 + 1e-9, 0.05)
    q, w = body.simulate(t, IDENTITY)
    h_inertial = rot.rotate(q, w @ J)
    energy = 0.5 * np.einsum("ni,ij,nj->n", w, J, w)
    # RK4's truncation at |ω|h = 8e-4 is n (|ω|h)⁵/120 = 4e-14 relative over the 12000 steps; their rounding adds
    # at most one ulp each: 12000 ulp = 1.7e-13 of |h| = 0.1 N m s, 2.7e-12 of the energy (3e-15, 6e-15 seen)
    np.testing.assert_allclose(h_inertial, np.broadcast_to(h_inertial[0], h_inertial.shape), rtol=0, atol=1e-12)
    np.testing.assert_allclose(energy, energy[0], rtol=1e-11)


def test_axisymmetric_body_precesses_at_the_analytic_rate():
    """I1 = I2: ω_xy rotates at λ = (I3 − I1)/I1 · ω3 in body axes (Euler's equations)."""
    I1, I3, w3 = 10.0, 4.0, 0.2
    body = RigidBody(inertia=((I1, 0, 0), (0, I1, 0), (0, 0, I3)), initial_rate=(0.05, 0.0, w3))
    t = np.arange(0, 100.0 + 1e-9, 0.01)
    _, w = body.simulate(t, IDENTITY)
    lam = (I3 - I1) / I1 * w3
    expected = 0.05 * np.stack([np.cos(lam * t), np.sin(lam * t)], axis=1)
    # RK4 turns ω_xy by λh − (λh)⁵/120 a step: n (λh)⁵/120 of phase times the 0.05 rad/s amplitude (1.0e-14,
    # 9.9e-15 seen); allowed twice that, and one ulp of the amplitude per step for the rounding of any CPU
    phase_error = t.size * (abs(lam) * 0.01) ** 5 / 120
    rounding = t.size * np.finfo(float).eps * 0.05
    np.testing.assert_allclose(w[:, :2], expected, atol=2 * 0.05 * phase_error + rounding)
    np.testing.assert_allclose(w[:, 2], w3, atol=1e-14)  # rounding level: ω̇3 = 0 exactly (I1 = I2)


def test_constant_torque_spins_up_linearly():
    body = RigidBody(inertia=((2.0, 0, 0), (0, 2.0, 0), (0, 0, 2.0)), initial_rate=(0, 0, 0),
                     torque_segments=((10.0, (0.0, 0.0, 0.1)),))
    t = np.arange(0, 20.0 + 1e-9, 0.1)
    _, w = body.simulate(t, IDENTITY)
    # rounding level: RK4 is exact for a rate linear in time
    np.testing.assert_allclose(w[t <= 10.0, 2], 0.05 * t[t <= 10.0], atol=1e-12)
    np.testing.assert_allclose(w[t >= 10.0, 2], 0.5, atol=1e-12)


def test_interval_mean_rates_are_exact_delta_angles():
    """Rotation about a fixed axis: the mean rate over an interval is Δθ/Δt along the axis."""
    t = np.arange(0, 2.0 + 1e-12, 0.01)
    q, _ = PAPER000.simulate(t, IDENTITY)
    means = interval_mean_rates(q, 10, 0.1)
    theta = PAPER000.theta0 + PAPER000.amplitude * np.sin(t[::10])
    axis = np.array(PAPER000.axis) / np.linalg.norm(PAPER000.axis)
    np.testing.assert_allclose(means, np.diff(theta)[:, None] / 0.1 * axis, atol=1e-14)  # rounding level: exact


def test_interval_mean_rates_are_exact_across_rate_steps():
    segments = RateSegments(segments=((0.35, (0.1, 0.0, 0.0)), (0.65, (0.0, 0.2, 0.0))))
    t = np.arange(0, 1.0 + 1e-12, 0.05)
    q, _ = segments.simulate(t, IDENTITY)
    means = interval_mean_rates(q, 2, 0.1)  # rounding level below: exact at rate steps on the grid
    np.testing.assert_allclose(means[3], [0.05, 0.1, 0.0], atol=1e-12)  # [0.3, 0.4]: half of each
    np.testing.assert_allclose(means[2], [0.1, 0.0, 0.0], atol=1e-12)
