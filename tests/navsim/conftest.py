"""Small scenarios for the navsim tests (dictionaries, validated like TOML files)."""

import copy

import pytest

BASE = {
    "name": "test",
    "duration_s": 60.0,
    "seed": 0,
    "truth": {"profile": "constant_rate", "rate_hz": 40.0, "constant_rate": {"rate_deg_per_s": [0.5, -0.3, 0.8]}},
    "gyro": {"rate_hz": 10.0, "arw_deg_per_sqrt_h": 0.1, "rrw_deg_per_h_per_sqrt_h": 0.5,
             "bias_turn_on_deg_per_h": 5.0},
    "star_sensor": {"measurement": "attitude", "rate_hz": 10.0, "fov_deg": 16.0,
                    "attitude_sigma_cross_arcsec": 10.0, "attitude_sigma_roll_arcsec": 30.0},
    "filter": {"initial_attitude_sigma_deg": 0.2},
}


@pytest.fixture
def base_scenario():
    return copy.deepcopy(BASE)
