"""Segment tables of the phase-2 scenarios, TOML-ready (units in the key names): an aircraft flight of
2 h with turns, climbs and speed changes, and a ship of 24 h rolling, pitching and heaving.
:meth:`navsim.truth.segments.Profile.from_table` validates them."""

AIRCRAFT_2H = {
    "start": {"lat_deg": 45.0, "lon_deg": 7.0, "height_m": 1000.0, "speed_m_per_s": 120.0, "heading_deg": 30.0},
    "segments": [
        {"kind": "straight", "duration_s": 300.0},
        {"kind": "accelerate", "speed_m_per_s": 220.0, "acceleration_m_per_s2": 1.0},
        {"kind": "climb", "height_change_m": 6000.0, "rate_m_per_s": 12.0},
        {"kind": "turn", "heading_change_deg": 90.0, "rate_deg_per_s": 3.0},
        {"kind": "straight", "duration_s": 1200.0},
        {"kind": "turn", "heading_change_deg": -135.0, "rate_deg_per_s": 2.0},
        {"kind": "straight", "duration_s": 900.0},
        {"kind": "turn", "heading_change_deg": 270.0, "rate_deg_per_s": 3.0},
        {"kind": "climb", "height_change_m": -3000.0, "rate_m_per_s": 10.0},
        {"kind": "straight", "duration_s": 1200.0},
        {"kind": "turn", "heading_change_deg": -90.0, "rate_deg_per_s": 3.0},
        {"kind": "accelerate", "speed_m_per_s": 180.0, "acceleration_m_per_s2": 0.5},
        {"kind": "climb", "height_change_m": -3000.0, "rate_m_per_s": 8.0},
        {"kind": "straight", "duration_s": 1996.5},
    ],
}

SHIP_24H = {
    "start": {"lat_deg": 35.0, "lon_deg": -30.0, "height_m": 0.0, "speed_m_per_s": 8.0, "heading_deg": 60.0},
    "segments": [
        {"kind": "ship", "duration_s": 43000.0, "roll_amplitude_deg": 5.0, "roll_period_s": 10.0,
         "pitch_amplitude_deg": 2.0, "pitch_period_s": 7.0, "heave_amplitude_m": 1.0, "heave_period_s": 9.0},
        {"kind": "turn", "heading_change_deg": 90.0, "rate_deg_per_s": 0.3},
        {"kind": "ship", "duration_s": 43097.0, "roll_amplitude_deg": 5.0, "roll_period_s": 10.0,
         "pitch_amplitude_deg": 2.0, "pitch_period_s": 7.0, "heave_amplitude_m": 1.0, "heave_period_s": 9.0},
    ],
}
