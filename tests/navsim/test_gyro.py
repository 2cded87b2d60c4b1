"""Gyro model: Allan deviation (allantools) recovers the noise terms; scaling, errors, presets."""

import allantools
import numpy as np
import pytest

from navsim.sensors.gyro import GyroModel, allan_variance, bias_instability_to_sigma
from startrack.base import units

RATE_HZ = 10.0


def _adev(rates, taus, rate_hz=RATE_HZ):
    tau_out, adev, _, _ = allantools.oadev(rates, rate=rate_hz, data_type="freq", taus=taus)
    return tau_out, adev


def test_allan_deviation_recovers_arw_and_rrw():
    """-1/2 slope: ADEV = N/√τ; +1/2 slope: ADEV = K √(τ/3). Read on each line, 3 axes averaged.

    A 24-day record at 1 Hz; the lines cross at τ_c = √3 N / K = 30 s, read at τ ≤ τ_c/15 and
    20 τ_c ≤ τ ≤ T/200, where the other term adds under 0.5 % and ≥ 200 clusters average."""
    arw = units.arw_to_si(0.15)  # rad/√s
    tau_cross = 30.0
    rrw = np.sqrt(3.0) * arw / tau_cross
    model = GyroModel(rate_hz=1.0, arw=arw, rrw=rrw)
    record = model.measure(np.zeros((2**21, 3)), np.random.SeedSequence(11))
    short = np.array([1.0, 2.0])
    long = np.array([600.0, 1200.0, 2400.0, 4800.0, 9600.0])
    n_est, k_est = [], []
    for axis in range(3):
        tau_s, adev_s = _adev(record.omega[:, axis], short, rate_hz=1.0)
        n_est.append(np.mean(adev_s * np.sqrt(tau_s)))
        tau_l, adev_l = _adev(record.omega[:, axis], long, rate_hz=1.0)
        k_est.append(np.mean(adev_l * np.sqrt(3.0 / tau_l)))
    assert np.mean(n_est) == pytest.approx(arw, rel=0.10)
    assert np.mean(k_est) == pytest.approx(rrw, rel=0.10)


def test_allan_deviation_floor_of_the_bias_instability():
    """Gauss-Markov bias instability of floor B: the top of its Allan hump (near τ = 1.89 T) is
    0.664 B — exactly in theory, within 20 % in a simulated record."""
    bias_instability = units.deg_per_h_to_rad_per_s(1.0)
    model = GyroModel(rate_hz=RATE_HZ, arw=units.arw_to_si(0.002),
                      bias_instability_sigma=bias_instability_to_sigma(bias_instability),
                      bias_correlation_time=50.0)
    record = model.measure(np.zeros((2**20, 3)), np.random.SeedSequence(5))
    taus = np.logspace(1, 3, 16)
    theory = np.sqrt(allan_variance(taus, model)).max()
    assert theory == pytest.approx(0.664 * bias_instability, rel=0.02)
    floors = [_adev(record.omega[:, axis], taus)[1].max() for axis in range(3)]
    assert np.mean(floors) == pytest.approx(0.664 * bias_instability, rel=0.20)


def test_theoretical_allan_curve_matches_a_simulated_record():
    model = GyroModel.preset("tactical", RATE_HZ)
    record = model.measure(np.zeros((2**19, 3)), np.random.SeedSequence(3))
    taus = np.array([1.0, 10.0, 100.0, 1000.0])
    _, adev = _adev(record.omega[:, 0], taus)
    np.testing.assert_allclose(adev, np.sqrt(allan_variance(taus, model)), rtol=0.25)


@pytest.mark.parametrize("rate_hz", [10.0, 100.0, 400.0])
def test_white_noise_scales_with_the_sample_interval(rate_hz):
    """An interval-averaged sample of ARW σ_v has σ = σ_v / √Δt."""
    arw = units.arw_to_si(0.125)
    record = GyroModel(rate_hz=rate_hz, arw=arw).measure(np.zeros((200_000, 3)), 1)
    assert record.omega.std() == pytest.approx(arw * np.sqrt(rate_hz), rel=0.01)


def test_constant_errors_scale_factor_misalignment_and_bias():
    model = GyroModel(rate_hz=100.0, bias_turn_on_sigma=1e-4, scale_factor_sigma=1e-3, misalignment_sigma=1e-3)
    omega = np.tile([0.3, -0.2, 0.5], (1000, 1))
    record = model.measure(omega, 9)
    expected = omega @ record.matrix.T + record.bias
    np.testing.assert_allclose(record.omega, expected, atol=1e-15)  # rounding level: the same products
    assert np.all(np.abs(np.diag(record.matrix) - 1.0) < 5e-3)
    assert np.any(np.abs(record.matrix - np.diag(np.diag(record.matrix))) > 0)


def test_quantisation_keeps_the_accumulated_angle_within_one_lsb():
    lsb = units.arcsec_to_rad(1.0)
    model = GyroModel(rate_hz=100.0, arw=units.arw_to_si(0.01), quantization=lsb)
    omega = np.tile([0.01, 0.02, -0.03], (5000, 1))
    quantised = model.measure(omega, 4).omega
    exact = GyroModel(rate_hz=100.0, arw=units.arw_to_si(0.01)).measure(omega, 4).omega
    counts = quantised / 100.0 / lsb
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-6)  # rounding level: whole LSBs, once divided
    drift = np.abs(np.cumsum(quantised - exact, axis=0) / 100.0)
    assert drift.max() <= 0.5 * lsb + 1e-15


def test_saturation_clips_the_rate():
    model = GyroModel(rate_hz=100.0, saturation=units.deg_to_rad(400.0))
    omega = np.tile(units.deg_to_rad([500.0, -450.0, 10.0]), (10, 1))
    out = model.measure(omega, 2).omega
    np.testing.assert_allclose(out[:, :2], units.deg_to_rad([400.0, -400.0]) * np.ones((10, 2)))


def test_same_seed_same_numbers():
    model = GyroModel.preset("mems", 100.0)
    a = model.measure(np.zeros((100, 3)), np.random.SeedSequence(42))
    b = model.measure(np.zeros((100, 3)), np.random.SeedSequence(42))
    c = model.measure(np.zeros((100, 3)), np.random.SeedSequence(43))
    np.testing.assert_array_equal(a.omega, b.omega)
    assert not np.array_equal(a.omega, c.omega)


@pytest.mark.parametrize("name, arw, bias", [("navigation", 0.002, 0.0035), ("tactical", 0.125, 1.0), ("mems", 0.15, 0.5)])
def test_presets_carry_their_datasheet_figures(name, arw, bias):
    model = GyroModel.preset(name, 100.0)
    assert model.arw == pytest.approx(units.arw_to_si(arw))
    assert model.bias_turn_on_sigma == pytest.approx(units.deg_per_h_to_rad_per_s(bias))
    gauss_markov_only = GyroModel(rate_hz=100.0, bias_instability_sigma=model.bias_instability_sigma,
                                  bias_correlation_time=model.bias_correlation_time)
    floor = np.sqrt(allan_variance(np.logspace(0, 6, 600), gauss_markov_only)).max()
    assert floor == pytest.approx(0.664 * units.deg_per_h_to_rad_per_s(bias), rel=1e-3)


def test_the_schema_offers_every_preset_both_sensors_have():
    from navsim.scenario.inertial_fields import PRESETS
    from navsim.sensors import accelerometer, gyro

    assert tuple(gyro.PRESETS) == tuple(accelerometer.PRESETS) == PRESETS


def test_unknown_preset_is_named():
    with pytest.raises(ValueError, match="unknown gyro preset 'fog'"):
        GyroModel.preset("fog", 100.0)
