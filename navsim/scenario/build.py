"""From a validated scenario (units in key names) to model objects in SI units."""

import dataclasses

import numpy as np
import scipy.linalg

from navsim.estimation.attitude_filter import AttitudeFilter
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.accelerometer import AccelerometerModel
from navsim.sensors.faults import SensorFaults
from navsim.sensors.gyro import GyroModel, bias_instability_to_sigma
from navsim.sensors.star_image import ImageStarSensor
from navsim.sensors.star_vector import AttitudeFixSensor, StarVectorSensor
from navsim.studies import observers as observer_kinds
from navsim.truth.profiles import ConstantRate, RateSegments, RigidBody, SinusoidalAxis
from navsim.warmup import kernel_lanes
from startrack import units
from startrack.camera import Camera
from startrack.errors import InputError
from startrack.identify.identifier import StarIdentifier
from startrack.navigation_catalog import NavigationCatalogParams, load_navigation_catalog
from startrack.precompile import compile_ahead
from startrack.render import SensorModel


def truth_profile(scenario):
    """The truth-motion strategy object of ``scenario['truth']``."""
    truth = scenario["truth"]
    profile = truth["profile"]
    spec = truth[profile]
    if profile == "constant_rate":
        return ConstantRate(rate=tuple(units.deg_to_rad(spec["rate_deg_per_s"])))
    if profile == "sinusoidal_axis":
        return SinusoidalAxis(
            axis=tuple(spec["axis"]),
            theta0=float(units.deg_to_rad(spec["theta0_deg"])),
            amplitude=float(units.deg_to_rad(spec["amplitude_deg"])),
            angular_frequency=spec["angular_frequency_rad_per_s"],
            phase=float(units.deg_to_rad(spec["phase_deg"])),
        )
    if profile == "rate_segments":
        return RateSegments(
            segments=tuple(
                (s["duration_s"], tuple(units.deg_to_rad(s["rate_deg_per_s"]))) for s in spec["segments"]
            )
        )
    return RigidBody(
        inertia=tuple(map(tuple, spec["inertia_kg_m2"])),
        initial_rate=tuple(units.deg_to_rad(spec["initial_rate_deg_per_s"])),
        torque_segments=tuple((s["duration_s"], tuple(s["torque_N_m"])) for s in spec["torque_segments"]),
    )


def gyro_model(table, rate_hz):
    """The gyro of a scenario table (``gyro``, ``imu.gyro``) at ``rate_hz``: a preset (if named) with any
    given datasheet field (:data:`~navsim.scenario.inertial_fields.GYRO_ERRORS`) overriding it."""
    base = GyroModel.preset(table["preset"], rate_hz) if table.get("preset") else GyroModel(rate_hz=rate_hz)
    fields = {
        "arw_deg_per_sqrt_h": ("arw", units.arw_to_si),
        "rrw_deg_per_h_per_sqrt_h": ("rrw", units.rrw_to_si),
        "bias_turn_on_deg_per_h": ("bias_turn_on_sigma", units.deg_per_h_to_rad_per_s),
        "bias_instability_deg_per_h": ("bias_instability_sigma", _bias_instability),
        "bias_correlation_s": ("bias_correlation_time", float),
        "scale_factor_ppm": ("scale_factor_sigma", lambda v: v * 1e-6),
        "misalignment_arcsec": ("misalignment_sigma", units.arcsec_to_rad),
        "quantization_arcsec": ("quantization", units.arcsec_to_rad),
        "saturation_deg_per_s": ("saturation", units.deg_to_rad),
    }
    changes = {name: float(convert(table[key])) for key, (name, convert) in fields.items() if table.get(key) is not None}
    return GyroModel(**{**base.__dict__, **changes})


def accelerometer_model(table, rate_hz):
    """The accelerometer of ``imu.accelerometer`` at ``rate_hz``: a preset (if named) with any given
    datasheet field (:data:`~navsim.scenario.inertial_fields.ACCELEROMETER_ERRORS`) overriding it."""
    base = AccelerometerModel.preset(table["preset"], rate_hz) if table.get("preset") else AccelerometerModel(rate_hz=rate_hz)
    fields = {
        "vrw_m_per_s_per_sqrt_h": ("vrw", units.vrw_to_si),
        "bias_rw_micro_g_per_sqrt_h": ("bias_rw", units.micro_g_per_sqrt_h_to_si),
        "bias_turn_on_micro_g": ("bias_turn_on_sigma", units.micro_g_to_si),
        "bias_instability_micro_g": ("bias_instability_sigma", lambda v: bias_instability_to_sigma(units.micro_g_to_si(v))),
        "bias_correlation_s": ("bias_correlation_time", float),
        "scale_factor_ppm": ("scale_factor_sigma", lambda v: v * units.PPM),
        "misalignment_arcsec": ("misalignment_sigma", units.arcsec_to_rad),
        "quantization_m_per_s": ("quantization", float),
        "saturation_m_per_s2": ("saturation", float),
    }
    changes = {name: float(convert(table[key])) for key, (name, convert) in fields.items() if table.get(key) is not None}
    return AccelerometerModel(**{**base.__dict__, **changes})


def _bias_instability(deg_per_h):
    return bias_instability_to_sigma(units.deg_per_h_to_rad_per_s(deg_per_h))


def star_sensor(scenario, star_catalog, frame_interval):
    """The star sensor of ``scenario['star_sensor']`` (vector or image fidelity) with the faults that
    act on it; ``star_catalog`` a :class:`startrack.star_catalog.StarCatalog` (stars measured or
    rendered), ``frame_interval`` the time between frames [s]."""
    sensor = scenario["star_sensor"]
    _, q_BS_true = mounting(scenario["star_sensor"])
    sensor_faults = SensorFaults.from_scenario(scenario["faults"], frame_interval)
    if sensor["fidelity"] == "image":
        return image_star_sensor(scenario, star_catalog, q_BS_true, sensor_faults)
    if sensor["measurement"] == "attitude":
        return AttitudeFixSensor(
            sigma_cross=float(units.arcsec_to_rad(sensor["attitude_sigma_cross_arcsec"])),
            sigma_roll=float(units.arcsec_to_rad(sensor["attitude_sigma_roll_arcsec"])),
            q_BS_true=q_BS_true,
            faults=sensor_faults,
        )
    stars = star_catalog.brighter_than(sensor["mag_limit"])
    return StarVectorSensor(
        star_vectors=np.asarray(stars.vectors),
        star_ids=np.asarray(stars.hip),
        star_mags=np.asarray(stars.v_mag),
        fov=float(units.deg_to_rad(sensor["fov_deg"])),
        sigma=float(units.arcsec_to_rad(sensor["star_sigma_arcsec"])),
        max_stars=sensor["max_stars"],
        q_BS_true=q_BS_true,
        faults=sensor_faults,
    )


def image_star_sensor(scenario, star_catalog, q_BS_true, sensor_faults):
    """The image-fidelity sensor of ``scenario['star_sensor']`` and its ``image`` table: camera,
    detector, navigation catalog (eq. 1-8 of 000) and identifier, the stars drawn into the frames."""
    sensor, image = scenario["star_sensor"], scenario["star_sensor"]["image"]
    fov = float(units.deg_to_rad(sensor["fov_deg"]))
    camera = Camera.from_fov(fov, image["width_px"], image["height_px"], circular_fov=image["field"] == "circular")
    if image["camera_file"] is not None:  # a calibrated camera (startrack solve --write-camera)
        camera = dataclasses.replace(Camera.from_file(image["camera_file"]), circular_fov=image["field"] == "circular")
    model = SensorModel(psf_sigma_px=image["psf_sigma_px"], exposure_s=image["exposure_s"],
                        zero_point_e_per_s=image["zero_point_e_per_s"], read_noise_e=image["read_noise_e"])
    params = NavigationCatalogParams(mag_limit=sensor["mag_limit"], fov=fov, n_d=image["catalog_nd"],
                                     max_delta=float(units.deg_to_rad(image["catalog_max_pointing_error_deg"])),
                                     epoch=scenario.catalog_epoch)
    stars = _rendered_stars(star_catalog, image)
    compile_ahead(kernel_lanes(scenario))  # the scenario checked: the identifier's kernels and the rest of the run's
    identifier = StarIdentifier(load_navigation_catalog(params, progress=False), camera,
                                centroid_sigma_px=image["centroid_sigma_px"], max_stars=image["max_identified_stars"])
    return ImageStarSensor(camera=camera, model=model, identifier=identifier, stars_I=np.asarray(stars.vectors),
                           stars_mag=np.asarray(stars.v_mag), stars_hip=np.asarray(stars.hip),
                           detection_sigmas=image["detection_sigmas"], window_half_px=image["tracking_window_px"],
                           stacking=image["dim_star_stacking"], start_tracking=image["start_tracking"], q_BS_true=q_BS_true, faults=sensor_faults)


def _rendered_stars(star_catalog, image):
    """The stars drawn into the frames: to ``render_mag_limit``, or only the ``sky_hip`` stars."""
    if not image["sky_hip"]:
        return star_catalog.brighter_than(image["render_mag_limit"])
    wanted = np.asarray(image["sky_hip"], dtype=np.int64)
    missing = np.setdiff1d(wanted, np.asarray(star_catalog.hip))
    if missing.size:
        raise InputError(f"star_sensor.image.sky_hip: HIP {', '.join(map(str, missing))} not in the catalog")
    return star_catalog.select(np.isin(np.asarray(star_catalog.hip), wanted))


def observers(scenario, sensor):
    """The per-frame observers (:func:`navsim.studies.observers`) the scenario asks for, built once;
    they watch the image chain, so a vector-fidelity run has none."""
    if scenario["star_sensor"]["fidelity"] != "image":
        return ()
    return tuple(kind.build(scenario, sensor) for kind in observer_kinds() if kind.wanted(scenario))


def initial_covariance(scenario, gyro):
    """P0 (n x n) from the filter's initial σ; defaults follow the gyro's own errors."""
    f = scenario["filter"]
    sigma_att = float(units.deg_to_rad(f["initial_attitude_sigma_deg"]))
    if f["initial_bias_sigma_deg_per_h"] is not None:
        sigma_bias = float(units.deg_per_h_to_rad_per_s(f["initial_bias_sigma_deg_per_h"]))
    else:
        sigma_bias = float(np.hypot(gyro.bias_turn_on_sigma, gyro.bias_instability_sigma))
        sigma_bias = max(sigma_bias, float(units.deg_per_h_to_rad_per_s(0.001)))
    treatment = filter_states(scenario, gyro)
    blocks = [np.eye(3) * sigma_att**2, np.eye(3) * sigma_bias**2]
    if treatment["bias_instability"] != "ignore":  # b = b_turn-on + g: the total and its Gauss-Markov part
        g2 = min(gyro.bias_instability_sigma**2, sigma_bias**2)
        blocks[1] = np.block([[np.eye(3) * sigma_bias**2, np.eye(3) * g2], [np.eye(3) * g2, np.eye(3) * g2]])
    diag = []
    if treatment["scale_factor"] != "ignore":
        ppm = f["initial_scale_factor_sigma_ppm"] or max(gyro.scale_factor_sigma / units.PPM, 1.0)
        diag += [(ppm * units.PPM) ** 2] * 3
    if treatment["gyro_misalignment"] != "ignore":
        arcsec = f["initial_gyro_misalignment_sigma_arcsec"] or max(gyro.misalignment_sigma / units.ARCSEC, 1.0)
        diag += [(arcsec * units.ARCSEC) ** 2] * 6
    if treatment["mounting"] != "ignore":
        diag += [(f["initial_mounting_sigma_arcsec"] * units.ARCSEC) ** 2] * 3
    return scipy.linalg.block_diag(*blocks, np.diag(diag)) if diag else scipy.linalg.block_diag(*blocks)


def filter_states(scenario, gyro):
    """How the filter treats each group of extra states: the scenario's choice, else (the gyro's
    datasheet in, the filter model out) "estimate" for a gyro error the gyro has and "ignore" otherwise."""
    f = scenario["filter"]
    return {"bias_instability": f["bias_instability"] or ("estimate" if gyro.bias_instability_sigma > 0.0 else "ignore"),
            "scale_factor": f["scale_factor"] or ("estimate" if gyro.scale_factor_sigma > 0.0 else "ignore"),
            "gyro_misalignment": f["gyro_misalignment"] or ("estimate" if gyro.misalignment_sigma > 0.0 else "ignore"),
            "mounting": f["mounting"]}


def attitude_filter(scenario, gyro, q0, P0):
    """The MEKF of ``scenario['filter']`` starting from attitude q0, zero bias and P0."""
    f = scenario["filter"]
    q_BS, _ = mounting(scenario["star_sensor"])
    states = filter_states(scenario, gyro)
    arw = gyro.arw if f["arw_deg_per_sqrt_h"] is None else float(units.arw_to_si(f["arw_deg_per_sqrt_h"]))
    rrw = gyro.rrw if states["bias_instability"] != "ignore" else gyro.filter_rrw
    if f["rrw_deg_per_h_per_sqrt_h"] is not None:
        rrw = float(units.rrw_to_si(f["rrw_deg_per_h_per_sqrt_h"]))
    return AttitudeFilter(
        q=q0,
        b=np.zeros(3),
        P=P0,
        arw=arw,
        rrw=rrw,
        q_BS=q_BS,
        **states,
        bias_instability_sigma=gyro.bias_instability_sigma,
        bias_correlation_time=gyro.bias_correlation_time,
        process_noise_scale=f["process_noise_scale"],
        measurement_noise_scale=f["measurement_noise_scale"],
        gate_probability=f["gate_probability"],
    )
