"""The compile-ahead task of an attitude scenario's covariance analysis (:mod:`startrack.precompile`)."""

from navsim.attitude.covariance import covariance_analysis
from navsim.attitude.scenario import validate
from navsim.scenario import Scenario

#: 4 s of a constant rate with star vectors at 2 Hz and every group of the MEKF: the pass's kernels.
SCENARIO = {
    "name": "compile-ahead", "seed": 0, "duration_s": 4.0,
    "truth": {"profile": "constant_rate", "rate_hz": 40.0, "constant_rate": {"rate_deg_per_s": [0.5, -0.3, 0.8]}},
    "gyro": {"rate_hz": 10.0, "preset": "tactical"},
    "star_sensor": {"measurement": "stars", "rate_hz": 2.0, "fov_deg": 16.0},
    "filter": {"mounting": "estimate"},
}


def covariance():
    """Task: the covariance analysis of the short run, its sources together and apart."""
    scenario = Scenario(data=validate(SCENARIO, "<compile-ahead>"), source="<compile-ahead>", kind="attitude")
    covariance_analysis(scenario)
    covariance_analysis(scenario, split=True)
