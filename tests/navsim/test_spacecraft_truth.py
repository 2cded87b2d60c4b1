"""The spacecraft's truth (issue 51 item 2): the attitude laws against their geometry, the slew's bang-coast-bang
closed form, and the dynamics: the total angular momentum of the body and its wheels conserved without an external
torque, the gravity-gradient torque against its closed form, the controller's tracking of each law, the wheels'
limits."""

import numpy as np
import pytest

from navsim.orbit.elements import Elements, mean_motion
from navsim.orbit.numerical import NumericalOrbit
from navsim.truth.pointing import Nadir, SunPointing, Targets, reference_rates, slew_angle
from navsim.truth.spacecraft import Controller, Spacecraft, Wheels, _derivatives
from startrack.base.errors import InputError
from startrack.geometry import rotation as rot

A = 6378137.0 + 550e3
INERTIA = ((100.0, 0.0, 0.0), (0.0, 120.0, 0.0), (0.0, 0.0, 80.0))
TRIAD = Wheels(axes=((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))


@pytest.fixture(scope="module")
def leo():
    """1000 s of a circular 550 km orbit at 10 Hz: t, r, v, and a Sun off the orbit plane."""
    r0, v0 = Elements(a=A, e=0.0, i=1.7, raan=0.3, argp=0.0, nu=0.2).state()
    t = np.arange(0.0, 1000.0, 0.1)
    r, v = NumericalOrbit(tuple(r0), tuple(v0), float(t[-1])).states(t)
    return t, r, v, np.tile([1.2e11, 0.8e11, 0.3e11], (len(t), 1))


def test_nadir_points_z_down_and_turns_at_the_orbital_rate(leo):
    t, r, v, sun = leo
    q = Nadir().attitude(t, r, v, sun)
    z = rot.rotate(q, np.array([0.0, 0.0, 1.0]))
    assert np.max(np.abs(np.sum(z * r, axis=1) / np.linalg.norm(r, axis=1) + 1.0)) < 1e-12
    omega, _ = reference_rates(q, 0.1)
    # the LVLH frame turns about −y at |r × v|/r² (the radius vector's rate; n within the J2 oscillation) and about
    # z by the orbit plane's J2 wobble (~3e-4 of n)
    angular = np.linalg.norm(np.cross(r, v), axis=1) / np.sum(r * r, axis=1)
    assert np.allclose(omega[1:-1, 1], -angular[1:-1], rtol=1e-8, atol=0.0)
    assert np.abs(omega[1:-1, 0]).max() < 1e-12 and np.abs(omega[1:-1, 2]).max() < 1e-3 * mean_motion(A)


def test_sun_pointing_keeps_its_axis_on_the_sun_and_yaw_steering_follows_nadir(leo):
    t, r, v, sun = leo
    for law in (SunPointing(), SunPointing(yaw_steering=True)):
        q = law.attitude(t, r, v, sun)
        axis = rot.rotate(q, np.array([0.0, 0.0, 1.0]))
        to_sun = (sun - r) / np.linalg.norm(sun - r, axis=1, keepdims=True)
        assert np.max(np.abs(np.sum(axis * to_sun, axis=1) - 1.0)) < 1e-12
    x = rot.rotate(q, np.array([1.0, 0.0, 0.0]))
    nadir = -r / np.linalg.norm(r, axis=1, keepdims=True)
    in_plane = nadir - np.sum(nadir * to_sun, axis=1, keepdims=True) * to_sun
    assert np.allclose(x, in_plane / np.linalg.norm(in_plane, axis=1, keepdims=True), atol=1e-12)


@pytest.mark.parametrize("angle_deg", [90.0, 2.0])
def test_a_slew_is_bang_coast_bang_within_its_limits(angle_deg):
    rate, accel = np.radians(0.5), np.radians(0.01)
    angle = np.radians(angle_deg)
    t = np.arange(0.0, 400.0, 0.01)
    theta, duration = slew_angle(t, angle, rate, accel)
    expected = angle / rate + rate / accel if angle > rate**2 / accel else 2.0 * np.sqrt(angle / accel)
    assert duration == pytest.approx(expected, rel=1e-12)
    assert theta[-1] == pytest.approx(angle, rel=1e-12)
    speed = np.diff(theta) / 0.01
    assert speed.max() <= rate * (1 + 1e-9) and np.abs(np.diff(speed) / 0.01).max() <= accel * (1 + 1e-6)


def test_targets_hold_then_slew_to_the_next_attitude(leo):
    t, r, v, sun = leo
    q_to = tuple(rot.from_rotation_vector(np.radians([30.0, 20.0, 0.0])))
    law = Targets(((0.0, (0.0, 0.0, 0.0, 1.0)), (100.0, q_to)), max_rate=np.radians(0.5), max_acceleration=np.radians(0.01))
    q = law.attitude(t, r, v, sun)
    assert np.allclose(q[t < 100.0], [0.0, 0.0, 0.0, 1.0])
    done = t >= 100.0 + law.slews()[0][4]
    assert np.max(rot.attitude_error(q[done], np.broadcast_to(q_to, (done.sum(), 4)))) < 1e-12


def _momentum(motion, spacecraft):
    H_B = motion.omega_B[::4][:-1] @ np.asarray(spacecraft.inertia).T + motion.wheel_momentum @ spacecraft.wheels.G.T
    return rot.rotate(motion.q_IB[::4][:-1], H_B)


def test_without_an_external_torque_the_total_angular_momentum_is_conserved(leo):
    """Slewing between targets with a four-wheel pyramid and friction (internal torques): C_IB (J ω + G h_w) constant
    to 1e-9 of its size (RK4 at 40 Hz)."""
    t, r, v, sun = leo
    beta = np.arctan(1.0 / np.sqrt(2.0))
    axes = [(np.cos(beta) * np.cos(a), np.cos(beta) * np.sin(a), np.sin(beta)) for a in np.radians([45, 135, 225, 315])]
    spacecraft = Spacecraft(INERTIA, Wheels(axes=tuple(axes), viscous=1e-5, coulomb=1e-3), gravity_gradient=False)
    q_to = tuple(rot.from_rotation_vector(np.radians([40.0, -20.0, 10.0])))
    q = Targets(((0.0, (0.0, 0.0, 0.0, 1.0)), (50.0, q_to))).attitude(t, r, v, sun)
    motion = spacecraft.simulate(0.025, 4, q, *reference_rates(q, 0.1), r, np.array([0.3, -0.2, 0.1, 0.2]))
    H = _momentum(motion, spacecraft)
    assert np.max(np.linalg.norm(H - H[0], axis=1)) < 1e-9 * np.linalg.norm(H[0])
    assert np.max(motion.pointing_error[t > 600.0]) < np.radians(0.1 / 3600.0)  # the integral has taken the friction


def test_the_gravity_gradient_torque_is_the_closed_form():
    """A body pitched by θ from LVLH at the orbit's radius r: τ_y = (3μ/r³)(I_z − I_x) sin θ cos θ
    (Markley & Crassidis eq. 3.157)."""
    J = np.diag([100.0, 120.0, 80.0])
    theta, r = 0.3, 7.0e6
    q = rot.from_rotation_vector(np.array([0.0, theta, 0.0]))
    r_I = np.array([0.0, 0.0, -r])  # nadir along +z of the unrotated body
    limits = np.array([0.01, 0.1, 4.0, 0.0, 0.0, 3.986004418e14])
    out = np.empty(10)
    _derivatives(np.concatenate([q, np.zeros(6)]), np.zeros(3), J, np.linalg.inv(J), np.eye(3), limits, r_I, out)
    omega_dot = out[4:7]
    expected = 3.0 * 3.986004418e14 / r**3 * (80.0 - 100.0) * np.sin(theta) * np.cos(theta)
    assert J @ omega_dot == pytest.approx([0.0, expected, 0.0], abs=1e-12 * abs(expected))


def test_the_controller_follows_nadir_against_the_gravity_gradient_and_friction(leo):
    """Nadir with the pitch wheel biased at 0.3 N m s and the integral action: the pointing error of the truth below 1"
    after the start's transient. (Biased on every axis instead, the roll and yaw wheels trade their momentum at the
    orbital rate and cross zero speed twice an orbit: each crossing's Coulomb flip costs ~70", a real jitter.)"""
    t, r, v, sun = leo
    q = Nadir().attitude(t, r, v, sun)
    spacecraft = Spacecraft(INERTIA, Wheels(axes=TRIAD.axes, viscous=1e-5, coulomb=1e-3), Controller(0.2, 0.9, 10.0))
    motion = spacecraft.simulate(0.025, 4, q, *reference_rates(q, 0.1), r, np.array([0.0, 0.3, 0.0]))
    assert np.max(motion.pointing_error[t > 300.0]) < np.radians(1.0 / 3600.0)
    assert not motion.saturated.any()


def test_the_wheels_limits_cut_the_command_and_say_so(leo):
    t, r, v, sun = leo
    q_to = tuple(rot.from_rotation_vector(np.radians([90.0, 0.0, 0.0])))
    q = Targets(((0.0, (0.0, 0.0, 0.0, 1.0)), (10.0, q_to)), max_rate=np.radians(3.0), max_acceleration=np.radians(1.0)).attitude(
        t, r, v, sun)
    weak = Spacecraft(INERTIA, Wheels(axes=TRIAD.axes, max_torque=0.01, max_momentum=0.5), gravity_gradient=False)
    motion = weak.simulate(0.025, 4, q, *reference_rates(q, 0.1), r)
    assert motion.saturated.any()
    assert np.all(np.abs(motion.wheel_torque) <= 0.01 + 1e-15)
    assert np.max(np.abs(motion.wheel_momentum)) < 0.5 + 0.01 * 0.1 + 1e-12  # one control interval past the limit at most


def test_wheels_that_do_not_span_the_body_are_refused():
    with pytest.raises(InputError, match="rank 3"):
        Wheels(axes=((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.0))).check()
