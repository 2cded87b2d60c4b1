"""Accelerometer model (Allan deviation with allantools recovers VRW, bias random walk and the
bias-instability floor, as for the gyro), its constant errors and presets; the baro altimeter."""

import allantools
import numpy as np
import pytest

from navsim.sensors.accelerometer import AccelerometerModel
from navsim.sensors.baro import BaroModel
from navsim.sensors.inertial import allan_variance, bias_instability_to_sigma
from navsim.truth import trajectory
from navsim.truth.segments import Hold, Profile, Start
from startrack.base import units
from startrack.base.errors import InputError


def _adev(values, taus, rate_hz):
    tau_out, adev, _, _ = allantools.oadev(values, rate=rate_hz, data_type="freq", taus=taus)
    return tau_out, adev


def test_allan_deviation_recovers_vrw_and_bias_random_walk():
    """−½ slope: ADEV = N/√τ; +½ slope: ADEV = K √(τ/3), read where the other term adds < 0.5 %
    (lines cross at τ_c = √3 N/K = 30 s; 2^20 s at 1 Hz)."""
    vrw = units.vrw_to_si(0.05)
    bias_rw = np.sqrt(3.0) * vrw / 30.0
    record = AccelerometerModel(rate_hz=1.0, vrw=vrw, bias_rw=bias_rw).measure(np.zeros((2**20, 3)), 21)
    short = (_adev(record.force[:, a], np.array([1.0, 2.0]), 1.0) for a in range(3))
    n_est = [np.mean(adev * np.sqrt(tau)) for tau, adev in short]
    k_est = [np.mean(adev * np.sqrt(3.0 / tau)) for tau, adev in
             (_adev(record.force[:, a], np.array([600.0, 1200.0, 2400.0, 4800.0]), 1.0) for a in range(3))]
    assert np.mean(n_est) == pytest.approx(vrw, rel=0.10)
    assert np.mean(k_est) == pytest.approx(bias_rw, rel=0.10)


def test_allan_floor_of_the_bias_instability():
    """Gauss-Markov bias instability of floor B = 100 µg: the top of its Allan hump is 0.664 B."""
    floor_b = units.micro_g_to_si(100.0)
    model = AccelerometerModel(rate_hz=10.0, vrw=units.vrw_to_si(0.002),
                               bias_instability_sigma=bias_instability_to_sigma(floor_b), bias_correlation_time=50.0)
    record = model.measure(np.zeros((2**19, 3)), 5)
    taus = np.logspace(1, 3, 16)
    assert np.sqrt(allan_variance(taus, model)).max() == pytest.approx(0.664 * floor_b, rel=0.02)
    floors = [_adev(record.force[:, axis], taus, 10.0)[1].max() for axis in range(3)]
    assert np.mean(floors) == pytest.approx(0.664 * floor_b, rel=0.20)


def test_theoretical_allan_curve_matches_a_tactical_record():
    model = AccelerometerModel.preset("tactical", 10.0)
    record = model.measure(np.zeros((2**18, 3)), 3)
    taus = np.array([1.0, 10.0, 100.0, 1000.0])
    np.testing.assert_allclose(_adev(record.force[:, 0], taus, 10.0)[1], np.sqrt(allan_variance(taus, model)), rtol=0.25)


def test_level_accelerometer_at_rest_reads_minus_g():
    """Error-free, fed by the truth at rest on a level table: f = [0, 0, −γ] in NED body axes."""
    truth = trajectory.generate(Profile(Start(30.0, 0.0), (Hold(1.0),)), 100.0)
    force = AccelerometerModel(rate_hz=100.0).measure(truth.dv / truth.dt, 0).force
    # rounding level (of 10 m/s²): level and at rest, the horizontal force is exactly zero
    assert np.allclose(force[:, :2], 0.0, atol=1e-12) and np.all(force[:, 2] < -9.79)


@pytest.mark.parametrize("rate_hz", [10.0, 200.0])
def test_white_noise_scales_with_the_sample_interval(rate_hz):
    vrw = units.vrw_to_si(0.05)
    record = AccelerometerModel(rate_hz=rate_hz, vrw=vrw).measure(np.zeros((100_000, 3)), 1)
    assert record.force.std() == pytest.approx(vrw * np.sqrt(rate_hz), rel=0.01)


def test_constant_errors_quantisation_and_saturation():
    model = AccelerometerModel(rate_hz=100.0, bias_turn_on_sigma=1e-3, scale_factor_sigma=1e-3, misalignment_sigma=1e-3)
    force = np.tile([0.3, -2.0, -9.8], (500, 1))
    record = model.measure(force, 9)
    np.testing.assert_allclose(record.force, force @ record.matrix.T + record.bias, atol=1e-13)  # rounding level
    lsb = 1e-4
    quantised = AccelerometerModel(rate_hz=100.0, vrw=1e-3, quantization=lsb).measure(force, 4).force
    exact = AccelerometerModel(rate_hz=100.0, vrw=1e-3).measure(force, 4).force
    assert np.abs(np.cumsum(quantised - exact, axis=0) / 100.0).max() <= 0.5 * lsb + 1e-15
    clipped = AccelerometerModel(rate_hz=100.0, saturation=5.0).measure(force, 2).force
    np.testing.assert_allclose(clipped[0], [0.3, -2.0, -5.0])


def test_same_seed_same_numbers():
    model = AccelerometerModel.preset("mems", 100.0)
    a, b, c = (model.measure(np.zeros((100, 3)), s).force for s in (42, 42, 43))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


@pytest.mark.parametrize("name, vrw, bias_ug", [("navigation", 0.002, 25.0), ("tactical", 0.05, 1000.0), ("mems", 0.06, 500.0)])
def test_presets_carry_their_datasheet_figures(name, vrw, bias_ug):
    model = AccelerometerModel.preset(name, 100.0)
    assert model.vrw == pytest.approx(vrw / 60.0)
    assert model.bias_turn_on_sigma == pytest.approx(bias_ug * 1e-6 * 9.80665)
    gm_only = AccelerometerModel(rate_hz=100.0, bias_instability_sigma=model.bias_instability_sigma,
                                 bias_correlation_time=model.bias_correlation_time)
    floor = np.sqrt(allan_variance(np.logspace(0, 6, 600), gm_only)).max()
    assert floor == pytest.approx(0.664 * model.bias_turn_on_sigma, rel=1e-3)
    with pytest.raises(ValueError, match="unknown accelerometer preset"):
        AccelerometerModel.preset("quartz", 100.0)


def test_baro_noise_bias_and_lag():
    """Noise σ and bias as set; a height step reaches 1 − e⁻¹ of its size after one lag time constant."""
    flat = BaroModel(rate_hz=10.0, noise_sigma=0.5, bias_sigma=3.0).measure(np.full(50_000, 100.0), 7)
    assert (flat.h - 100.0 - flat.bias).std() == pytest.approx(0.5, rel=0.02)
    assert np.all(flat.bias == flat.bias[0]) and flat.bias[0] != 0.0
    step = np.concatenate([np.zeros(10), np.full(200, 10.0)])
    lagged = BaroModel(rate_hz=10.0, lag_time_constant=2.0).measure(step, 1).h
    # rounding level: the lag is discretised exactly (e^(−Δt/τ) a step)
    assert lagged[9] == 0.0 and lagged[9 + 20] == pytest.approx(10.0 * (1.0 - np.exp(-1.0)), rel=1e-12)


@pytest.mark.parametrize("kwargs, key", [({"rate_hz": 0.0}, "baro.rate_hz"),
                                         ({"rate_hz": 1.0, "noise_sigma": -1.0}, "baro.noise_sigma")])
def test_baro_bad_input_is_named(kwargs, key):
    with pytest.raises(InputError, match=key):
        BaroModel(**kwargs)
