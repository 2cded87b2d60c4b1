"""From a validated navigation scenario (units in key names) to model objects in SI units: the
trajectory, the IMU, the baro, the position-fix sensor, the star sensor, the gravity disturbance and
the navigation filter's configuration with its initial covariance and its models of the star sensor
and of the gravity disturbance (datasheet in, filter model out)."""

import numpy as np

from navsim.build import star_sensor as star_sensors
from navsim.build.inertial import accelerometer_model, gyro_model
from navsim.earth.frames import julian_year
from navsim.earth.gravity import GravityDisturbance, normal_gravity
from navsim.earth.refraction import Air
from navsim.earth.wgs84 import OMEGA_IE
from navsim.estimation.nav_filter import GravityUncertainty, ImuNoise, NavFilterConfig, StarSensorModel
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.aiding import PositionFixSensor
from navsim.sensors.baro import BaroModel
from navsim.truth.route import profile_of
from startrack import band, units

#: Floors of the default initial σ, so that P0 stays positive definite with perfect sensors:
#: tilt [rad], heading [rad], gyro bias [rad/s], accelerometer bias [m/s²], scale factor [-].
FLOORS = {"tilt": units.ARCSEC, "heading": 10.0 * units.ARCSEC, "gyro_bias": 1e-4 * units.DEG / units.HOUR,
          "accel_bias": units.micro_g_to_si(0.1), "scale_factor": units.PPM}
#: Most initial heading σ taken from gyrocompassing [rad] (the error state is linear in φ).
MAX_DEFAULT_HEADING = 10.0 * units.DEG
#: Floors of the filter's gravity σ taken from a constant disturbance (a component of zero value still
#: gets a positive σ): deflection [rad], anomaly [m/s²].
GRAVITY_FLOORS = (0.01 * units.ARCSEC, 0.1 * units.MILLIGAL)


def profile(scenario):
    """The trajectory's :class:`~navsim.truth.segments.Profile` (segments or a route)."""
    return profile_of(scenario["trajectory"])


def imu(scenario):
    """(gyro, accelerometer) models of ``scenario['imu']`` at the IMU rate."""
    table = scenario["imu"]
    return gyro_model(table["gyro"], table["rate_hz"]), accelerometer_model(table["accelerometer"], table["rate_hz"])


def baro(scenario):
    """The :class:`~navsim.sensors.baro.BaroModel` of ``scenario['baro']``, or None."""
    table = scenario.data.get("baro")
    if table is None:
        return None
    return BaroModel(rate_hz=table["rate_hz"], noise_sigma=table["noise_sigma_m"], bias_sigma=table["bias_sigma_m"],
                     bias_rw=table["bias_rw_m_per_sqrt_h"] / np.sqrt(units.HOUR), lag_time_constant=table["lag_s"])


def position_sensor(scenario, frame_hz):
    """The :class:`~navsim.sensors.aiding.PositionFixSensor` of ``aiding.position`` on frames of
    ``frame_hz``, or None (a free INS)."""
    table = scenario["aiding"].get("position")
    if table is None:
        return None
    return PositionFixSensor(every=int(round(frame_hz / table["rate_hz"])), sigma_ned=np.array(table["sigma_ned_m"]))


def gravity_disturbance(scenario):
    """The :class:`~navsim.earth.gravity.GravityDisturbance` of ``scenario['gravity']``, or None."""
    table = scenario.data.get("gravity")
    if table is None:
        return None
    xi, eta = units.arcsec_to_rad(table["xi_arcsec"]), units.arcsec_to_rad(table["eta_arcsec"])
    anomaly = table["anomaly_mgal"] * units.MILLIGAL
    if table["model"] == "constant":
        return GravityDisturbance.constant(xi, eta, anomaly)
    return GravityDisturbance.random(xi, eta, anomaly, table["correlation_length_m"])


def catalog_epoch(scenario):
    """The star catalog's epoch [Julian year]: the scenario's ``epoch_utc``."""
    return julian_year(scenario["epoch_utc"])


def star_sensor(scenario, star_catalog, lanes=()):
    """The star sensor of ``scenario['star_sensor']`` (vector or image fidelity) with its faults, seeing
    the stars of ``star_catalog`` (:func:`navsim.build.star_sensor.star_sensor`; ``lanes`` compiled
    ahead at image fidelity), or None."""
    if "star_sensor" not in scenario.data:
        return None
    return star_sensors.star_sensor(scenario, star_catalog, 1.0 / scenario["star_sensor"]["rate_hz"],
                                    catalog_epoch(scenario), lanes)


def star_sensor_model(scenario, orientation, h):
    """The filter's :class:`~navsim.estimation.nav_filter.StarSensorModel` (nominal mounting, treatment
    of its error, the Earth's orientation at the frames, aberration and refraction correction with the σ of
    its air at the start height ``h`` [m]), or None."""
    if "star_sensor" not in scenario.data:
        return None
    sensor = scenario["star_sensor"]
    q_BS, _ = mounting(sensor)
    return StarSensorModel(q_BS=q_BS, mounting=scenario["filter"]["mounting"], orientation=orientation,
                           correct_aberration=sensor["aberration_correction"], refraction=modelled_air(scenario),
                           refraction_sigma=refraction_sigma(scenario, h))


def real_air(scenario, truth_off=(), rng=None):
    """The :class:`~navsim.earth.refraction.Air` the truth's stars are refracted by: the standard atmosphere with
    the scenario's pressure and temperature errors, plus, with ``star_sensor.refraction.drawn``, errors of the stated
    σ drawn from the Generator ``rng`` (a run's; None: the fixed errors alone, the air's mean); none when
    ``truth_off`` has "refraction"."""
    sensor = scenario["star_sensor"]
    refraction = sensor["refraction"]
    pressure, temperature = refraction["pressure_error_percent"] / 100.0, refraction["temperature_error_k"]
    if refraction["drawn"] and rng is not None:
        draw = rng.standard_normal(2)
        pressure += draw[0] * refraction["pressure_sigma_percent"] / 100.0
        temperature += draw[1] * refraction["temperature_sigma_k"]
    air = Air(band(sensor["band"]).centre_um, pressure, temperature)
    return air.modelled() if "refraction" in truth_off else air


def refraction_residual(scenario):
    """Whether refraction leaves an error in the stars the filter fuses: uncorrected, or the real air not the model's
    (given, or drawn per run)."""
    refraction = scenario["star_sensor"]["refraction"]
    return not refraction["correction"] or bool(refraction["pressure_error_percent"] or refraction["temperature_error_k"]
                                                or refraction["drawn"])


def modelled_air(scenario):
    """The air the processing corrects the refraction with (the standard atmosphere), or None when it does not."""
    return real_air(scenario).modelled() if scenario["star_sensor"]["refraction"]["correction"] else None


def refraction_sigma(scenario, h):
    """σ of the fractional error ε_r of the processing's model air at height ``h`` [m] (its consider state: 0 for
    none), from ``star_sensor.refraction``'s pressure and temperature σ (:meth:`~navsim.earth.refraction.Air.fraction_sigma`)."""
    air = modelled_air(scenario)
    refraction = scenario["star_sensor"]["refraction"]
    if air is None:
        return 0.0
    return float(air.fraction_sigma(h, refraction["pressure_sigma_percent"] / 100.0, refraction["temperature_sigma_k"]))


def refraction_fraction(scenario, h, air):
    """The truth's ε_r (...,) at heights ``h`` [m]: the real ``air``'s refraction as a fraction of the processing's
    model (0 without a correction: no model to err)."""
    if modelled_air(scenario) is None:
        return np.zeros(np.shape(h))
    return air.fraction(h)


def gravity_uncertainty(scenario, lat, h):
    """The filter's :class:`~navsim.estimation.nav_filter.GravityUncertainty` at (L, h) [rad, m], or None
    (``filter.gravity = "ignore"``, or neither a [gravity] table nor a filter σ). Each σ and the
    correlation length come from the filter's keys, else from [gravity]: a random field's σ and D,
    a constant one's magnitudes (floored) and an infinite D."""
    f, table = scenario["filter"], scenario.data.get("gravity")
    keys = (f["deflection_sigma_arcsec"], f["anomaly_sigma_mgal"], f["gravity_correlation_length_m"])
    if f["gravity"] == "ignore" or (table is None and all(k is None for k in keys)):
        return None
    table = table or {"model": "constant", "xi_arcsec": 0.0, "eta_arcsec": 0.0, "anomaly_mgal": 0.0}
    random = table["model"] == "random"
    xi, eta = (units.arcsec_to_rad(abs(table[k])) for k in ("xi_arcsec", "eta_arcsec"))
    anomaly = abs(table["anomaly_mgal"]) * units.MILLIGAL
    if not random:
        xi, eta, anomaly = max(xi, GRAVITY_FLOORS[0]), max(eta, GRAVITY_FLOORS[0]), max(anomaly, GRAVITY_FLOORS[1])
    if keys[0] is not None:
        xi = eta = units.arcsec_to_rad(keys[0])
    if keys[1] is not None:
        anomaly = keys[1] * units.MILLIGAL
    length = keys[2] or (table["correlation_length_m"] if random else np.inf)
    gamma = normal_gravity(lat, h)
    sigma = np.array([xi * gamma, eta * gamma, anomaly], dtype=float)
    return GravityUncertainty(sigma=np.maximum(sigma, [GRAVITY_FLOORS[0] * gamma] * 2 + [GRAVITY_FLOORS[1]]),
                              correlation_length=float(length))


def estimates_scale_factors(scenario, gyro, accel):
    """Whether the filter carries the six scale-factor states: the scenario's choice, else whenever
    either sensor's datasheet has a scale-factor error."""
    choice = scenario["filter"]["scale_factors"]
    if choice is not None:
        return choice == "estimate"
    return gyro.scale_factor_sigma > 0.0 or accel.scale_factor_sigma > 0.0


def initial_covariance(scenario, gyro, accel, lat, h):
    """P0 (n x n, diagonal) of the error state [φ, δv, δL, δλ, δh, ε, ∇ (, δs_g, δs_a) (, μ) (, δg) (, ε_r)] at (L, h).

    Defaults from the datasheets: the tilt of levelling, σ_∇/γ, and the heading of gyrocompassing,
    σ_ε/(ω_ie cos L) (at most 10 deg) (Titterton & Weston, 2nd ed., ch. 10), with σ the turn-on and
    bias-instability σ in quadrature; the biases' and scale factors' own σ; the mounting's
    ``filter.initial_mounting_sigma_arcsec``; the gravity disturbance's σ (:func:`gravity_uncertainty`).
    Each is floored (:data:`FLOORS`) so that P0 is positive definite with perfect sensors."""
    f = scenario["filter"]
    gyro_bias = max(float(np.hypot(gyro.bias_turn_on_sigma, gyro.bias_instability_sigma)), FLOORS["gyro_bias"])
    accel_bias = max(float(np.hypot(accel.bias_turn_on_sigma, accel.bias_instability_sigma)), FLOORS["accel_bias"])
    tilt = (units.arcsec_to_rad(f["initial_tilt_sigma_arcsec"]) if f["initial_tilt_sigma_arcsec"] is not None
            else max(accel_bias / normal_gravity(lat, h), FLOORS["tilt"]))
    heading = (units.deg_to_rad(f["initial_heading_sigma_deg"]) if f["initial_heading_sigma_deg"] is not None
               else max(min(gyro_bias / (OMEGA_IE * np.cos(lat)), MAX_DEFAULT_HEADING), FLOORS["heading"]))
    position = f["initial_position_sigma_m"] * np.ones(3)
    sigma = [tilt, tilt, heading, *[f["initial_velocity_sigma_m_per_s"]] * 3, *position, *[gyro_bias] * 3,
             *[accel_bias] * 3]
    if estimates_scale_factors(scenario, gyro, accel):
        sigma += [max(gyro.scale_factor_sigma, FLOORS["scale_factor"])] * 3
        sigma += [max(accel.scale_factor_sigma, FLOORS["scale_factor"])] * 3
    if "star_sensor" in scenario.data and f["mounting"] != "ignore":
        sigma += [units.arcsec_to_rad(f["initial_mounting_sigma_arcsec"])] * 3
    gravity = gravity_uncertainty(scenario, lat, h)
    if gravity is not None:
        sigma += list(gravity.sigma)
    if "star_sensor" in scenario.data and refraction_sigma(scenario, h) > 0.0:
        sigma.append(refraction_sigma(scenario, h))
    return np.diag(np.square(np.array(sigma, dtype=float)))


def filter_config(scenario, gyro, accel, lat, h, dt, orientation=None):
    """The :class:`~navsim.estimation.nav_filter.NavFilterConfig` of ``scenario['filter']`` at the start (L, h)
    [rad, m] on IMU intervals of ``dt`` [s]: its initial covariance (:func:`initial_covariance`), the noise of
    the datasheets, its star sensor (with the Earth's ``orientation`` at the frames), its gravity model
    (:func:`gravity_uncertainty`), tuning and gates."""
    f = scenario["filter"]
    noise = ImuNoise(arw=gyro.arw, vrw=accel.vrw, gyro_bias_rw=gyro.filter_rrw, accel_bias_rw=accel.filter_bias_rw)
    return NavFilterConfig(initial_covariance(scenario, gyro, accel, lat, h), noise, dt,
                           estimate_scale_factors=estimates_scale_factors(scenario, gyro, accel),
                           star_sensor=star_sensor_model(scenario, orientation, h), gravity=gravity_uncertainty(scenario, lat, h),
                           covariance_interval=f["covariance_interval"], gate_probability=f["gate_probability"],
                           process_noise_scale=f["process_noise_scale"], measurement_noise_scale=f["measurement_noise_scale"],
                           baro_states=f["baro_states"])
