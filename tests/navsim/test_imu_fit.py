"""navsim.inertial_log: the Allan deviation against allantools, the estimates' covariance against the exact
quadratic forms and Greenhall's EDF, and the noise fit on logs of the project's own sensor models of known
parameters and a rate ramp (each recovered within 3 of its stated σ on >= 95 % of seeds), whose [imu] block the scenarios take and
whose model's curve lies in the log's band."""

import re
import tomllib
from pathlib import Path

import allantools
import numpy as np
import pytest
from scipy import optimize

from navsim.build.inertial import accelerometer_model, gyro_model
from navsim.inertial_log import allan, axis_fit, noise_fit, preset
from navsim.inertial_log.estimate_covariance import covariance_terms, estimate_covariance
from navsim.inertial_log.reading import ImuLog
from navsim.kinds import load_scenario
from navsim.sensors.accelerometer import AccelerometerModel
from navsim.sensors.gyro import GyroModel
from navsim.sensors.inertial import allan_variance
from startrack import units

ROOT = Path(__file__).resolve().parents[2]
RATE_HZ = 100.0
#: A gyro whose three terms show in a 22-minute log: ARW 0.15 deg/√h, the RRW line crossing it at 10 s, and an LSB
#: of 0.5" (about half the angle noise of one sample); an accelerometer alike (an LSB of half its velocity noise of
#: one sample: a term much below the others at every τ is not resolved, and its share then goes to its neighbour).
ARW = float(units.arw_to_si(0.15))
GYRO = GyroModel(rate_hz=RATE_HZ, arw=ARW, rrw=np.sqrt(3.0) * ARW / 10.0, quantization=float(units.arcsec_to_rad(0.5)))
ACCELEROMETER = AccelerometerModel(rate_hz=RATE_HZ, vrw=float(units.vrw_to_si(0.05)),
                                   bias_rw=np.sqrt(3.0) * float(units.vrw_to_si(0.05)) / 10.0, quantization=4e-5)


def _truth(model):
    """The model's IEEE 952 coefficients: Q = LSB/√12 (preset's docstring), N, K."""
    return {"Q": model.quantization / np.sqrt(12.0), "N": model.white_noise, "K": model.random_walk}


def _fit_axis(rates):
    sizes = allan.cluster_sizes(rates.size)
    tau = sizes / RATE_HZ
    return noise_fit.fit_noise(tau, allan.overlapping_avar(rates, RATE_HZ, sizes), rates.size, sizes, RATE_HZ)


def test_overlapping_adev_is_allantools_oadev():
    """The same estimator (rounding level: the sums are taken in another order, the mean removed first)."""
    rates = GYRO.measure(np.zeros((50_000, 3)), 4).omega[:, 0] + 1e-3  # a bias: removed before the sum
    sizes = allan.cluster_sizes(rates.size)
    _, adev, _, _ = allantools.oadev(rates, rate=RATE_HZ, data_type="freq", taus=sizes / RATE_HZ)
    np.testing.assert_allclose(np.sqrt(allan.overlapping_avar(rates, RATE_HZ, sizes)), adev, rtol=1e-9)


def test_estimate_covariance_is_the_exact_covariance_of_the_quadratic_forms():
    """2 tr(A_a Σ A_b Σ) + 4 μᵀ A_a Σ A_b μ of a 40-sample log of white rate, the model's interval-mean rate random
    walk, white angle (quantisation) noise and a rate ramp (the phase's mean μ), built as explicit matrices (every
    lag is summed there: rounding level)."""
    n, c = 40, np.array([0.3, 1.0, 0.0, 0.2, 0.1])
    sizes = allan.cluster_sizes(n)
    k = np.arange(n)
    lower = np.minimum.outer(k, k)
    walk = np.where(lower == k[:, None], k[:, None] + 1.0 / 3.0, lower + 0.5) * (k[:, None] == k[None, :]) + \
        np.where(k[:, None] == k[None, :], 0.0, lower + 0.5)  # E[ȳ_i ȳ_j] of a unit Wiener process's interval means
    to_phase = np.vstack([np.zeros(n), np.tril(np.ones((n, n)))])  # x_i = Σ_(k<i) y_k (τ0 = 1)
    phase = to_phase @ (c[1] * np.eye(n) + c[3] * walk) @ to_phase.T + c[0] * np.eye(n + 1)

    def quadratic(m):
        d = np.array([np.eye(n + 1)[i + 2 * m] - 2 * np.eye(n + 1)[i + m] + np.eye(n + 1)[i] for i in range(n + 1 - 2 * m)])
        return d.T @ d / (2.0 * m**2 * (n + 1 - 2 * m))

    mean = np.sqrt(c[4]) * np.arange(n + 1) ** 2 / 2.0  # Σ_(k<i) of the ramp's interval means R (k + ½)
    exact = np.array([[2.0 * np.trace(quadratic(a) @ phase @ quadratic(b) @ phase)
                       + 4.0 * mean @ quadratic(a) @ phase @ quadratic(b) @ mean for b in sizes] for a in sizes])
    np.testing.assert_allclose(estimate_covariance(covariance_terms(sizes, n, 1.0), c), exact, rtol=1e-10)


@pytest.mark.parametrize(("term", "alpha"), [(1, 0), (2, -1), (3, -2)])
def test_edf_of_one_noise_is_greenhalls(term, alpha):
    """ν = 2 σ⁴/Var(σ̂²) of a pure power-law noise against allantools' Greenhall & Riley EDF at m >= 64 of a 2e5-sample
    log (the lags summed at a step of m/16 there; 3 %: the flicker structure function's and the step's approximations)."""
    n = 200_000
    sizes = allan.cluster_sizes(n)[6:]
    c = np.eye(5)[term]
    variance = np.diag(estimate_covariance(covariance_terms(sizes, n, 1.0), c))
    dof = 2.0 * (noise_fit.basis(sizes.astype(float)) @ c) ** 2 / variance
    greenhall = [allantools.edf_greenhall(alpha=alpha, d=2, m=int(m), N=n + 1, overlapping=True) for m in sizes]
    np.testing.assert_allclose(dof, greenhall, rtol=0.03)


#: A gyro of white noise only, and the rate ramp [rad/s²] added to its log (the models have none).
WHITE, RAMP = GyroModel(rate_hz=RATE_HZ, arw=ARW), 1e-7
CASES = {"gyro": (GYRO, 0.0), "accelerometer": (ACCELEROMETER, 0.0), "ramp": (WHITE, RAMP)}


def _coverage(cases, seeds, samples):
    """The fraction of seeds whose terms all lie within 3 of their stated σ (Q, N, K of the model, R of the ramp),
    the terms absent from the log not resolved; seed k draws a log of ``cases[k % len(cases)]``."""
    good = 0
    for seed in seeds:
        model, ramp = CASES[cases[seed % len(cases)]]
        truth = {t: v for t, v in {**_truth(model), "B": 0.0, "R": ramp}.items() if v > 0.0}
        record = model.measure(np.zeros((samples, 3)), np.random.SeedSequence(seed))
        rates = (record.omega if isinstance(model, GyroModel) else record.force)[:, seed % 3]
        fit = _fit_axis(rates + ramp * (np.arange(samples) + 0.5) / RATE_HZ)
        good += all(fit.terms[t].resolved == (t in truth) for t in noise_fit.TERMS) and all(
            abs(fit.terms[t].value - v) <= 3.0 * fit.terms[t].sigma for t, v in truth.items())
    return good / len(seeds)


def test_the_fit_gives_the_models_parameters_back():
    """21 seeds of 22-minute logs, the three cases in turn (at most one seed of the 21 may miss)."""
    assert _coverage(sorted(CASES), range(21), 2**17) >= 0.95


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(CASES))
def test_the_fit_gives_the_models_parameters_back_on_many_long_logs(case):
    """100 seeds of 87-minute logs of each case."""
    assert _coverage([case], range(100, 200), 2**19) >= 0.95


@pytest.fixture(scope="module")
def fits():
    """The six axes of a 44-minute log of GYRO and ACCELEROMETER fitted."""
    return _fits(7)


def _fits(seed, samples=2**18):
    gyro = GYRO.measure(np.zeros((samples, 3)), np.random.SeedSequence(seed)).omega
    force = ACCELEROMETER.measure(np.zeros((samples, 3)), np.random.SeedSequence(seed + 1)).force
    axes = {**{n: gyro[:, k] for k, n in enumerate(("gx", "gy", "gz"))},
            **{n: force[:, k] for k, n in enumerate(("ax", "ay", "az"))}}
    return axis_fit.fit_axes(ImuLog(RATE_HZ, axes), progress=False)


def test_the_block_is_a_scenarios_and_its_model_reproduces_the_logs_curve(tmp_path, fits):
    """The [imu] block in a navigation scenario validates; the models it builds (navsim.build.inertial) have an
    Allan curve (their allan_variance, plus the LSB's 3 (S²/12)/τ²) inside the log's 95 % band at >= 90 % of the
    cluster times of the six axes (95 % expected; 90 % leaves room for one axis's tail)."""
    block = preset.imu_block(preset.sensor_figures(fits), RATE_HZ, "test")
    text = (ROOT / "scenarios" / "free_ins_navigation_aircraft.toml").read_text()
    text = re.sub(r"\[imu\]\n(?:.+\n)+?\n", lambda _: block + "\n", text)
    (tmp_path / "fitted.toml").write_text(text)
    imu = load_scenario(tmp_path / "fitted.toml")["imu"]
    table = tomllib.loads(block)["imu"]
    models = {"gyro": gyro_model(table["gyro"], RATE_HZ), "accelerometer": accelerometer_model(table["accelerometer"], RATE_HZ)}
    assert imu["gyro"]["arw_deg_per_sqrt_h"] == table["gyro"]["arw_deg_per_sqrt_h"]
    inside = []
    for name, axis in fits.items():
        model = models["gyro" if name.startswith("g") else "accelerometer"]
        adev = np.sqrt(allan_variance(axis.tau, model) + 3.0 * model.quantization**2 / 12.0 / axis.tau**2)
        inside += list((axis.low <= adev) & (adev <= axis.high))
    assert np.mean(inside) >= 0.90


def test_the_block_states_what_the_fit_found(fits):
    """Each key is the worst axis's term in the key's unit (N in deg/√h, the LSB √12 Q in arcsec ...)."""
    table = tomllib.loads(preset.imu_block(preset.sensor_figures(fits), RATE_HZ, "test"))["imu"]
    worst = max(fits[a].fit.terms["N"].value for a in ("gx", "gy", "gz"))
    assert table["gyro"]["arw_deg_per_sqrt_h"] == pytest.approx(worst / units.arw_to_si(1.0), rel=1e-3)  # 4 digits
    lsb = max(fits[a].fit.terms["Q"].value for a in ("gx", "gy", "gz")) * np.sqrt(12.0)
    assert table["gyro"]["quantization_arcsec"] == pytest.approx(lsb / units.ARCSEC, rel=1e-3)
    assert table["gyro"]["bias_instability_deg_per_h"] == 0.0 and "bias_correlation_s" not in table["gyro"]


def test_gauss_markov_peak_time():
    """The Allan deviation of a first-order Gauss-Markov process peaks at τ = 1.8926 T (and 0.6174 σ_g)."""
    gm = AccelerometerModel(rate_hz=1.0, bias_instability_sigma=1.0, bias_correlation_time=1.0)
    peak = optimize.minimize_scalar(lambda t: -allan_variance(t, gm), bounds=(0.5, 5.0), method="bounded", options={"xatol": 1e-8})
    assert peak.x == pytest.approx(preset.GAUSS_MARKOV_PEAK_TAU, abs=1e-4)
    assert np.sqrt(-peak.fun) == pytest.approx(0.6174, abs=1e-4)
