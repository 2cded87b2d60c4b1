"""The compile-ahead task of a navigation run (:mod:`startrack.compiled.compile_ahead`; :data:`navsim.navigation.run.VECTOR_LANES`)."""

from navsim.navigation import run as navigation_run
from navsim.navigation.scenario import validate
from navsim.scenario import Scenario

#: 20 s of level flight of a SINS/CNS at vector fidelity with a baro and the random gravity field: the
#: kernels of the truth, the INS, its filter and its star, baro and summary steps.
SCENARIO = {
    "name": "compile-ahead", "seed": 0, "epoch_utc": "2024-01-15T20:00:00",
    "trajectory": {"start": {"lat_deg": 45.0, "lon_deg": 7.0, "height_m": 11000.0, "speed_m_per_s": 250.0,
                             "heading_deg": 90.0},
                   "segments": [{"kind": "straight", "duration_s": 10.0},
                                {"kind": "turn", "heading_change_deg": 15.0, "rate_deg_per_s": 1.5}]},
    "imu": {"rate_hz": 100.0, "gyro": {"preset": "navigation"}, "accelerometer": {"preset": "navigation"}},
    "baro": {"rate_hz": 1.0, "noise_sigma_m": 5.0},
    "star_sensor": {"measurement": "stars", "rate_hz": 1.0, "fov_deg": 16.0, "mag_limit": 6.0, "max_stars": 10,
                    "star_sigma_arcsec": 5.0, "mounting_rotvec_deg": [180.0, 0.0, 0.0]},
    "gravity": {"model": "random", "xi_arcsec": 3.0, "eta_arcsec": 3.0, "anomaly_mgal": 20.0,
                "correlation_length_m": 100000.0},
}


def run():
    """Task: a short SINS/CNS run at vector fidelity, step by step and by the compiled record path."""
    prepared = navigation_run.prepare(Scenario(data=validate(SCENARIO, "<compile-ahead>"), source="<compile-ahead>",
                                               kind="navigation"))
    navigation_run.simulate(prepared, 0)
    navigation_run.simulate(prepared, 0, compiled=False)

