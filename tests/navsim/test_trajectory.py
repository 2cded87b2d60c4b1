"""Truth trajectories: segment shapes, position against an independent ODE solver, the IMU increments
against closed forms (at rest) and against finite differences of the attitude, and bad input."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from navsim.earth.frames import earth_rate_n
from navsim.earth.gravity import GravityDisturbance, normal_gravity
from navsim.earth.wgs84 import radii
from navsim.truth import trajectory
from navsim.truth.segments import Climb, Hold, Profile, ShipMotion, Start, Straight, Turn, window
from startrack.base import units
from startrack.base.errors import InputError
from startrack.geometry import rotation as rot
from tests.navsim.ins_helpers import trajectory_table

MANOEUVRES = {
    "start": {"lat_deg": 60.0, "lon_deg": -20.0, "height_m": 500.0, "speed_m_per_s": 150.0, "heading_deg": 10.0},
    "segments": [
        {"kind": "turn", "heading_change_deg": 120.0, "rate_deg_per_s": 4.0},
        {"kind": "climb", "height_change_m": 800.0, "rate_m_per_s": 15.0},
        {"kind": "accelerate", "speed_m_per_s": 100.0, "acceleration_m_per_s2": 2.0},
        {"kind": "ship", "duration_s": 120.0, "ramp_s": 20.0},
    ],
}


def test_window_is_smooth_and_integrates_to_its_area():
    tau = np.linspace(0.0, 10.0, 100_001)
    big, e, de, dde = window(tau, 10.0, 3.0)
    step = tau[1] - tau[0]
    assert e[0] == 0.0 and e[-1] == pytest.approx(0.0, abs=1e-15) and big[-1] == pytest.approx(7.0)  # rounding level
    # np.gradient's truncation, allowed twice its leading term: central differences h²/6 |f'''|, first-order ends
    # h/2 |f''| (zero for E and e: ė = ë = 0 there; ë's derivative (2π)² cos(2πx) / ramp³ is not, nor continuous)
    third = (2.0 * np.pi) ** 2 / 3.0**3  # max |d³e/dτ³|
    np.testing.assert_allclose(np.gradient(big, step), e, atol=2 * step**2 / 6 * np.abs(dde).max())  # 1.2e-9 seen
    np.testing.assert_allclose(np.gradient(e, step), de, atol=2 * step**2 / 6 * third)  # 2.4e-9 seen
    np.testing.assert_allclose(np.gradient(de, step), dde, atol=2 * step / 2 * third)  # 7.3e-5 seen


def test_position_against_an_independent_ode_solver():
    """L, λ, h of the generator against scipy's DOP853 on the same channels (rtol 1e-13): < 1 mm."""
    profile = Profile.from_table(MANOEUVRES)
    truth = trajectory.generate(profile, 20.0)

    def rates(t, y):
        ch = profile.channels(np.array([t]))
        v_n, v_e = ch.speed * np.cos(ch.heading), ch.speed * np.sin(ch.heading)
        r_m, r_n = radii(y[0])
        return [v_n[0] / (r_m + y[2]), v_e[0] / ((r_n + y[2]) * np.cos(y[0])), ch.climb[0]]

    start = profile.start
    sol = solve_ivp(rates, (0.0, truth.t[-1]), [start.lat_deg * units.DEG, start.lon_deg * units.DEG, start.height_m],
                    method="DOP853", rtol=1e-13, atol=1e-14, t_eval=truth.t[::200], max_step=1.0)
    r_m, r_n = radii(sol.y[0])
    assert np.max(np.abs(truth.lat[::200] - sol.y[0]) * r_m) < 1e-3
    assert np.max(np.abs(truth.lon[::200] - sol.y[1]) * r_n * np.cos(sol.y[0])) < 1e-3
    assert np.max(np.abs(truth.h[::200] - sol.y[2])) < 1e-3


def test_increments_at_rest_are_earth_rate_and_gravity():
    """Stationary and level, heading ψ: Δθ = C_bn ω_ie^n Δt and Δv = [0, 0, −γ] Δt (f = a − g)."""
    profile = Profile(Start(52.0, 4.0, 200.0, heading_deg=30.0), (Hold(10.0),))
    truth = trajectory.generate(profile, 100.0)
    lat = 52.0 * units.DEG
    C_bn = rot.to_matrix(truth.q_nb[0]).T
    # rounding level (of 7e-7 rad and 0.1 m/s increments): the quadrature of constants is exact
    np.testing.assert_allclose(truth.dtheta, np.tile(C_bn @ np.array(earth_rate_n(lat)) * 0.01, (1000, 1)), atol=1e-20)
    expected_dv = np.array([0.0, 0.0, -normal_gravity(lat, 200.0) * 0.01])
    np.testing.assert_allclose(truth.dv, np.tile(expected_dv, (1000, 1)), atol=1e-16)


def test_body_rate_against_finite_differences_of_the_attitude():
    """Δθ/Δt − C_bn ω_in^n is the vehicle rate ω_nb^b: compared with 2 vec(q⁻¹ q̇) of the truth
    quaternions by central differences (turn roll-in, climb pull-up and ship motion)."""
    truth = trajectory.generate(Profile.from_table(MANOEUVRES), 200.0)
    dq = rot.multiply(rot.conjugate(truth.q_nb[:-1]), truth.q_nb[1:])
    rate_nb = rot.to_rotation_vector(dq) / truth.dt  # mean ω_nb^b over each interval (to O(Δt²))
    lat_mid = 0.5 * (truth.lat[:-1] + truth.lat[1:])
    w_ie = np.stack(earth_rate_n(lat_mid), axis=-1)
    from navsim.earth.frames import transport_rate_n
    v_mid = 0.5 * (truth.v_n[:-1] + truth.v_n[1:])
    h_mid = 0.5 * (truth.h[:-1] + truth.h[1:])
    w_en = np.stack(transport_rate_n(lat_mid, h_mid, v_mid[:, 0], v_mid[:, 1]), axis=-1)
    q_mid = rot.multiply(truth.q_nb[:-1], rot.from_rotation_vector(0.5 * rot.to_rotation_vector(dq)))
    w_in_b = np.einsum("nji,nj->ni", rot.to_matrix(q_mid), w_ie + w_en)
    # twice the coning term: q⁻¹ q_next's rotation vector exceeds ∫ω by Δt³/12 ω × ω̇ (9.3e-8 rad/s here, all
    # of the 9.3e-8 seen)
    np.testing.assert_allclose(truth.dtheta / truth.dt - w_in_b, rate_nb, atol=2e-7)
    assert np.abs(rate_nb).max() > 0.05  # the profile does rotate


def test_the_shipped_trajectories_last_as_named():
    assert Profile.from_table(trajectory_table("free_ins_navigation_aircraft")).duration == pytest.approx(7200.0)
    assert Profile.from_table(trajectory_table("free_ins_navigation_ship")).duration == pytest.approx(86400.0)


def test_gravity_disturbance_enters_the_specific_force():
    """A constant anomaly Δg adds −Δg to the body-down specific force at rest, a deflection ξ adds ξγ north."""
    profile = Profile(Start(10.0, 0.0), (Hold(2.0),))
    plain = trajectory.generate(profile, 10.0)
    disturbed = trajectory.generate(profile, 10.0, GravityDisturbance.constant(2e-5, 0.0, 5e-4))
    difference = (disturbed.dv - plain.dv) / plain.dt
    gamma = normal_gravity(10.0 * units.DEG, 0.0)
    # rounding level (of 10 m/s² specific forces): the same products at rest
    np.testing.assert_allclose(difference, np.tile([2e-5 * gamma, 0.0, -5e-4], (20, 1)), atol=1e-12)


@pytest.mark.parametrize("table_patch, key, problem", [
    ({"start": {"lat_deg": 91.0, "lon_deg": 0.0}}, "trajectory.start.lat_deg", "<= 90"),
    ({"start": {"lat_deg": 10.0, "lon_deg": 0.0, "height_m": -1500.0}}, "trajectory.start.height_m", ">= -1000"),
    ({"segments": [{"kind": "turn", "heading_change_deg": 90.0, "rate_deg_per_s": 3.0, "bank_deg": 10.0}]},
     "trajectory.segments[0].bank_deg", "cannot be flown"),
    ({"segments": [{"kind": "turn", "heading_change_deg": 90.0, "rate_deg_per_s": 0.0}]},
     "trajectory.segments[0].rate_deg_per_s", "> 0"),
    ({"segments": [{"kind": "climb", "height_change_m": 100.0, "rate_m_per_s": -5.0}]},
     "trajectory.segments[0].rate_m_per_s", "> 0"),
    ({"segments": [{"kind": "hold", "duration_s": 10.0}]}, "trajectory.segments[0].kind", "zero speed"),
    ({"segments": [{"kind": "straight", "duration_s": 10.0, "speed": 3}]}, "trajectory.segments[0].speed", "unknown key"),
    ({"segments": [{"kind": "loop", "duration_s": 10.0}]}, "trajectory.segments[0].kind", "must be one of"),
    ({"segments": [{"kind": "turn", "rate_deg_per_s": 3.0}]}, "trajectory.segments[0].heading_change_deg", "missing"),
])
def test_bad_segments_are_named(table_patch, key, problem):
    """One InputError naming the key and the problem (a turn at 3 deg/s and 100 m/s banks 28 deg)."""
    table = {"start": {"lat_deg": 10.0, "lon_deg": 0.0, "speed_m_per_s": 100.0},
             "segments": [{"kind": "straight", "duration_s": 10.0}]}
    table.update(table_patch)
    with pytest.raises(InputError) as error:
        Profile.from_table(table)
    message = str(error.value)
    assert message.startswith(key + ":") and problem in message
    assert "\n" not in message


def test_zero_or_negative_imu_rate_is_named():
    profile = Profile(Start(0.0, 0.0), (Hold(1.0),))
    for rate in (0.0, -10.0):
        with pytest.raises(InputError, match="imu.rate_hz: must be > 0"):
            trajectory.generate(profile, rate)


def test_segment_objects_check_their_own_fields():
    with pytest.raises(InputError, match="duration_s"):
        Straight(0.0)
    with pytest.raises(InputError, match="ramp_s"):
        ShipMotion(duration_s=10.0, ramp_s=30.0)
    with pytest.raises(InputError, match="transition_s"):
        Profile(Start(0.0, 0.0, speed_m_per_s=50.0), (Climb(10.0, 5.0),))
    with pytest.raises(InputError, match="roll_in_s"):
        Profile(Start(0.0, 0.0, speed_m_per_s=50.0), (Turn(5.0, 3.0),))


def test_random_gravity_disturbance_matches_a_quadrature_at_the_nodes():
    """The trapezoidal −∫ C_bn δg_n dt of with_gravity against four-node Gauss quadrature of the same
    linear-in-time field with the attitude at the nodes, through turns, a climb and ship motion."""
    profile = Profile.from_table(MANOEUVRES)
    disturbance = GravityDisturbance.random(10.0 * units.ARCSEC, 10.0 * units.ARCSEC, 5e-4, 2000.0)
    kin = trajectory.kinematics(profile, 100.0)
    disturbed = trajectory.with_gravity(kin, disturbance, np.random.SeedSequence(3))
    dt, g = kin.t[1], disturbed.gravity_disturbance
    nodes = trajectory.NODES
    g_nodes = g[:-1, None, :] * (1.0 - nodes)[:, None] + g[1:, None, :] * nodes[:, None]
    q_nodes = trajectory.attitude(profile.channels((kin.t[:-1, None] + dt * nodes).ravel()))
    g_b = rot.rotate(rot.conjugate(q_nodes), g_nodes.reshape(-1, 3)).reshape(-1, 4, 3)
    reference = -dt * np.einsum("k,nkc->nc", trajectory.WEIGHTS, g_b)
    assert np.abs(disturbed.dv - kin.dv).max() > 1e-6  # the field is there
    np.testing.assert_array_equal(disturbed.dtheta, kin.dtheta)
    error = disturbed.dv - kin.dv - reference  # the trapezoid's truncation Δt³/12 |(C_bn δg)''| per interval
    assert np.abs(error).max() < 2e-10  # m/s per 10 ms interval (8e-11 in the roll-in)
    assert np.abs(np.cumsum(error, axis=0)).max() < 2e-8  # m/s summed over the 4 min
    assert np.abs(np.cumsum(np.cumsum(error, axis=0), axis=0) * dt).max() < 1e-6  # m of position
