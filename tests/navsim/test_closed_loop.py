"""The closed loop: acquisition, tracking, re-acquisition after a tracking loss, outages, false stars,
the faults at vector fidelity, the loop driven by stub filter and sensor, and the filter's compiled
fast path against the step-by-step loop."""

import copy

import numpy as np
import pytest

import navsim
from navsim.closed_loop import FrameGrid, run_loop
from navsim.estimation.updates import UpdateResult
from navsim.sensors.faults import AttitudeJumps
from navsim.sensors.star_sensor import MODE_CODE, StarFrame, isotropic_covariance
from navsim.simulation import prepare, simulate
from navsim.truth.profiles import TruthRecord
from startrack.base import units
from startrack.base.errors import InputError


def image_scenario(base, duration_s=30.0, **faults):
    scenario = copy.deepcopy(base)
    scenario["duration_s"] = duration_s
    scenario["star_sensor"] = {"fidelity": "image", "measurement": "stars", "rate_hz": 2.0, "fov_deg": 16.0,
                               "mag_limit": 6.0, "image": {"centroid_sigma_px": 0.15}}
    scenario["filter"] = {"initial_attitude_sigma_deg": 0.3}
    scenario["faults"] = faults
    return scenario


def modes(result):
    return result.series["mode"]


def test_acquires_then_tracks_with_many_stars(base_scenario):
    result = navsim.run(image_scenario(base_scenario), seed=3)
    mode = modes(result)
    tracking = mode == MODE_CODE["tracking"]
    assert tracking[4:].mean() > 0.9
    assert np.median(result.series["n_identified"][tracking]) >= 6
    assert result.summary["cross_boresight_rms_arcsec"] < 10.0
    assert result.summary["updates"]["rejected"] <= 0.05 * result.summary["updates"]["measurements"]
    assert result.summary["identification"]["transitions"][0]["time_s"] == pytest.approx(0.5)
    sub = result.series["subcatalog_index"]
    assert np.all(sub >= 0) and np.all(sub < 3100)
    assert result.sample_frame is not None and result.sample_frame["image"].dtype == np.uint16


def test_reacquires_after_a_tracking_loss(base_scenario):
    """A 5 deg knock at 10 s: tracking fails, the predicted sub-catalog with its redundant
    neighbours (or lost-in-space) re-acquires, the attitude is re-initialised, tracking resumes."""
    scenario = image_scenario(base_scenario, attitude_jumps=[{"time_s": 10.0, "angle_deg": 5.0}])
    result = navsim.run(scenario, seed=4)
    t, mode = result.series["t"], modes(result)
    after = (t >= 10.0) & (t < 12.0)
    assert np.any(np.isin(mode[after], [MODE_CODE["subcatalog"], MODE_CODE["lost_in_space"]]))
    assert np.all(mode[t >= 13.0] == MODE_CODE["tracking"])
    error = units.rad_to_arcsec(np.linalg.norm(result.series["attitude_error"], axis=1))
    assert error[t >= 13.0].max() < 60.0
    reasons = [tr["reason"] for tr in result.summary["identification"]["transitions"]]
    assert any("re-initialised" in r for r in reasons)


def test_outage_and_dropped_frames_are_logged_and_survived(base_scenario):
    scenario = image_scenario(base_scenario, outages=[{"start_s": 10.0, "end_s": 14.0}], dropped_frames_s=[20.0])
    result = navsim.run(scenario, seed=5)
    t, mode = result.series["t"], modes(result)
    assert np.all(mode[(t >= 10.0) & (t < 14.0)] == MODE_CODE["outage"])
    assert mode[np.argmin(np.abs(t - 20.0))] == MODE_CODE["dropped"]
    assert mode[np.argmin(np.abs(t - 14.5))] == MODE_CODE["tracking"]
    sigma = np.sqrt(result.series["P_diag"][:, 0])
    assert sigma[np.argmin(np.abs(t - 13.5))] > sigma[np.argmin(np.abs(t - 9.5))]  # grows while blind


def test_false_star_storm_does_not_corrupt_the_attitude(base_scenario):
    """30 cosmic-ray tracks per frame for 8 s."""
    scenario = image_scenario(base_scenario, false_star_storms=[{"start_s": 8.0, "end_s": 16.0, "count": 30}])
    result = navsim.run(scenario, seed=6)
    t = result.series["t"]
    storm = (t >= 8.0) & (t < 16.0)
    # windows around the predicted stars are read while tracking: stray hits fall mostly outside them
    assert np.all(modes(result)[storm] == MODE_CODE["tracking"])
    assert result.series["n_accepted"][storm].min() >= 3
    error = units.rad_to_arcsec(np.linalg.norm(result.series["attitude_error"], axis=1))
    assert error[t >= 4.0].max() < 60.0


def test_gyro_bias_step_is_absorbed_at_vector_fidelity(base_scenario):
    scenario = copy.deepcopy(base_scenario)
    scenario["duration_s"] = 120.0
    scenario["faults"] = {"gyro_bias_steps": [{"time_s": 40.0, "step_deg_per_h": [20.0, 0.0, 0.0]}]}
    result = navsim.run(scenario, seed=7)
    t = result.series["t"]
    jump = result.series["bias_true"][t > 41.0, 0] - result.series["bias_true"][t < 39.0, 0].mean()
    assert units.rad_per_s_to_deg_per_h(jump.mean()) == pytest.approx(20.0, abs=1.0)
    # the filter's bias random walk (0.5 deg/h/√h) absorbs a step slowly, but it does absorb it
    bias_error = units.rad_per_s_to_deg_per_h(result.series["bias_true"][:, 0] - result.series["bias_est"][:, 0])
    assert abs(bias_error[np.argmin(np.abs(t - 41.0))]) > 15.0
    assert abs(bias_error[-1]) < 10.0


def test_outages_at_vector_fidelity_skip_updates(base_scenario):
    scenario = copy.deepcopy(base_scenario)
    scenario["faults"] = {"outages": [{"start_s": 10.0, "end_s": 20.0}], "dropped_frames_s": [30.0]}
    result = navsim.run(scenario, seed=8)
    t = result.series["t"]
    assert np.all(result.series["n_measurements"][(t >= 10.0) & (t < 20.0)] == 0)
    assert result.series["n_measurements"][np.argmin(np.abs(t - 30.0))] == 0
    assert result.series["n_measurements"][np.argmin(np.abs(t - 25.0))] == 1


def test_frame_faults_need_image_fidelity(base_scenario):
    base_scenario["faults"] = {"attitude_jumps": [{"time_s": 1.0, "angle_deg": 2.0}]}
    with pytest.raises(InputError, match="faults.attitude_jumps: needs star_sensor.fidelity = 'image'"):
        navsim.run(base_scenario)


def test_paper004_dim_star_is_stacked_and_fused():
    """004's four stars only: once C leaves, A and B plus the dim X stacked over 4 frames (eq. 13-18)
    keep three stars in the update; the shadow filter without X runs beside it."""
    from pathlib import Path

    scenario = Path(__file__).resolve().parents[2] / "scenarios" / "paper004_dim_star.toml"
    result = navsim.run(scenario, seed=1)
    mode, t = modes(result), result.series["t"]
    assert np.all(result.series["n_detected"][t < 1.4] == 3)  # A, B, C; X is under V_th alone
    assert result.series["n_stacked"].sum() >= 2
    assert np.any(mode == MODE_CODE["stacked"])
    stacked = result.series["n_stacked"] == 1
    assert np.all(result.series["n_identified"][stacked] == 2)  # A and B ...
    assert np.all(result.series["n_measurements"][stacked] == 3)  # ... and the stacked X in the update
    dim = result.summary["dim_star"]
    assert {"two_star_triad", "three_star_optimal", "filter_with_stacking", "filter_without_stacking"} <= set(dim)
    assert "attitude_error_without_stacking" in result.series
    rows = {row["quantity"]: row for row in result.summary["paper_comparison"]}
    assert "three star optimal roll RMS [arcsec]" in rows
    # adding a star can only lower the Cramér-Rao bound, never raise it
    bound = [rows[f"third star allowed by the Cramér-Rao bound: {axis} RMS change [%]"]["ours"]
             for axis in ("cross-boresight", "roll")]
    assert max(bound) <= 0.0
    # the phase-corrected stacked centroid: within 1 px of the true star position (~0.3 px RMS per axis)
    assert max(dim["stacked_centroid"]["rms_error_px"]) < 1.0


class _RecordingFilter:
    """Only the filter interface the loop may use; every call is recorded."""

    def __init__(self):
        self.calls = []
        self.q = np.array([0.0, 0.0, 0.0, 1.0])

    def predict(self, samples, dt):
        self.calls.append(("predict", len(samples), dt))

    def sensor_prediction(self, last_sample):
        self.calls.append(("sensor_prediction",))
        return self.q, np.zeros(3)

    def update_stars(self, ref_I, obs_S, sigma):
        self.calls.append(("update_stars", len(ref_I)))
        first = sum(c[0] == "update_stars" for c in self.calls) == 1  # the first identification is rejected
        accepted = np.full(len(ref_I), not first)
        return UpdateResult(z=np.zeros((len(ref_I), 2)), nis=np.ones(len(ref_I)), accepted=accepted, per_row=True)

    def update_attitude(self, q_IS, R_S):
        self.calls.append(("update_attitude",))
        return UpdateResult(z=np.zeros((1, 3)), nis=np.ones(1), accepted=np.ones(1, bool))

    def reinitialise(self, q_IS):
        self.calls.append(("reinitialise",))

    def disturb(self, rotation_vector):
        self.calls.append(("disturb", float(np.linalg.norm(rotation_vector))))

    def snapshot(self):
        return {"q_est": self.q.copy()}


class _ScriptedSensor:
    """Frame 0: three stars from a sub-catalog identification; 1: an attitude fix; 2: nothing; then stars."""

    log_fields = {"mode": ((), np.int8, 0)}
    timing_fields = {}
    sample = None
    uses_prediction = True
    uses_prior = False

    def __init__(self):
        self.verdicts, self.lost = [], 0

    def record(self):
        return None

    def observe(self, request):
        stars = np.tile([0.0, 0.0, 1.0], (3, 1))
        if request.index == 1:
            return StarFrame(mode="tracking", q_IS=request.q_IS_pred, R_S=np.eye(3), info={"mode": 0})
        if request.index == 2:
            return StarFrame(mode="no_fix", info={"mode": MODE_CODE["no_fix"]})
        return StarFrame(mode="subcatalog", ref_I=stars, obs_S=stars, cov_S=isotropic_covariance(stars, 1.0),
                         fix_q_IS=request.q_IS_pred, info={"mode": MODE_CODE["subcatalog"]})

    def after_update(self, update, posterior):
        self.verdicts.append(None if update is None else update.n_accepted)

    def lose_track(self):
        self.lost += 1


def test_the_loop_needs_nothing_but_the_filter_interface():
    """A stub filter and a stub sensor: the loop predicts over each frame's samples, asks for the
    prediction, fuses fixes and stars, re-initialises after a rejected identification, applies the
    attitude jump and tells the sensor every verdict."""
    filt, sensor = _RecordingFilter(), _ScriptedSensor()
    grid = FrameGrid(dt=0.1, ratio=5, n_frames=4)
    truth = TruthRecord(t=np.arange(21) * 0.1, q_IB=np.tile([0.0, 0.0, 0.0, 1.0], (21, 1)), omega_mean=np.zeros((20, 3)))
    jumps = AttitudeJumps([(1.0, np.radians(2.0))], np.random.default_rng(0))
    log = run_loop(filt, sensor, np.zeros((20, 3)), truth, grid, jumps)
    names = [c[0] for c in filt.calls]
    assert names[:4] == ["predict", "sensor_prediction", "update_stars", "reinitialise"]
    assert filt.calls[0] == ("predict", 5, 0.1)
    assert names.count("predict") == 4 and names.count("update_attitude") == 1
    assert ("disturb", pytest.approx(np.radians(2.0))) in filt.calls and sensor.lost == 1
    assert sensor.verdicts == [3, 1, None, 3]
    assert log.transitions[0]["reason"].endswith("attitude re-initialised from the fix")
    assert list(log.arrays["n_measurements"]) == [3, 1, 0, 3]


@pytest.mark.parametrize("overrides", [
    {},
    {"star_sensor.measurement": "stars", "star_sensor.mag_limit": 5.0},
    {"star_sensor.measurement": "stars", "gyro.preset": "tactical", "filter.gyro_misalignment": "consider",
     "filter.mounting": "estimate",
     "star_sensor.misalignment_arcsec": [20.0, -10.0, 30.0], "faults.outages": [{"start_s": 5.0, "end_s": 9.0}],
     "filter.measurement_noise_scale": 1.5},
])
def test_compiled_fast_path_equals_the_step_by_step_loop(base_scenario, overrides):
    base_scenario["duration_s"] = 20.0
    prepared = prepare(base_scenario, overrides)
    fast, steps = simulate(prepared, 11), simulate(prepared, 11, compiled=False)
    for name in ("q_est", "bias_est", "P_diag", "n_measurements", "n_accepted", "nis", "nis_dof", "innovation_rms"):
        np.testing.assert_array_equal(fast.series[name], steps.series[name], err_msg=name)
