"""The attitude kind's own tables in SI units: the truth attitude profile and its start, the gyro, and
the MEKF with its initial covariance and the treatment of each group of states (datasheet in, filter
model out). The star sensor and faults are built by :mod:`navsim.build`."""

import numpy as np
import scipy.linalg

from navsim.build.inertial import gyro_model
from navsim.estimation.attitude_filter import AttitudeFilterConfig
from navsim.scenario.star_sensor_fields import mounting
from navsim.truth.profiles import ConstantRate, RateSegments, RigidBody, SinusoidalAxis
from startrack import quaternion_from_radec_roll, units
from startrack import rotation as rot


def initial_attitude(scenario):
    """q_IB at t = 0: ``truth.initial_radec_roll_deg`` (boresight RA, Dec, roll through the nominal
    mounting) when given, else ``truth.initial_q_IB``."""
    radec_roll = scenario["truth"]["initial_radec_roll_deg"]
    if radec_roll is None:
        return rot.normalize(scenario["truth"]["initial_q_IB"])
    q_IS = quaternion_from_radec_roll(*units.deg_to_rad(radec_roll))
    q_BS, _ = mounting(scenario["star_sensor"])
    return rot.normalize(rot.multiply(q_IS, rot.conjugate(q_BS)))


def gyro(scenario):
    """The gyro of ``scenario['gyro']`` at its rate."""
    return gyro_model(scenario["gyro"], scenario["gyro"]["rate_hz"])


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


def initial_covariance(scenario, gyro, mountings=None, mounting_sigmas=None):
    """P0 (n x n) from the filter's initial σ; defaults follow the gyro's own errors. ``mountings``: the mounting
    treatment of each head of a spacecraft (default: ``filter.mounting`` for the one sensor); when any head carries
    its mounting, each head has three states, an ignored head's with σ 0; ``mounting_sigmas`` [arcsec] each head's
    initial σ (default ``filter.initial_mounting_sigma_arcsec``)."""
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
    mountings = (treatment["mounting"],) if mountings is None else tuple(mountings)
    if any(t != "ignore" for t in mountings):
        sigmas = mounting_sigmas or [f["initial_mounting_sigma_arcsec"]] * len(mountings)
        for t, sigma in zip(mountings, sigmas):
            diag += [(sigma * units.ARCSEC) ** 2 if t != "ignore" else 0.0] * 3
    return scipy.linalg.block_diag(*blocks, np.diag(diag)) if diag else scipy.linalg.block_diag(*blocks)


def filter_states(scenario, gyro):
    """How the filter treats each group of extra states: the scenario's choice, else (the gyro's
    datasheet in, the filter model out) "estimate" for a gyro error the gyro has and "ignore" otherwise."""
    f = scenario["filter"]
    return {"bias_instability": f["bias_instability"] or ("estimate" if gyro.bias_instability_sigma > 0.0 else "ignore"),
            "scale_factor": f["scale_factor"] or ("estimate" if gyro.scale_factor_sigma > 0.0 else "ignore"),
            "gyro_misalignment": f["gyro_misalignment"] or ("estimate" if gyro.misalignment_sigma > 0.0 else "ignore"),
            "mounting": f["mounting"]}


def filter_config(scenario, gyro, q_BS=None, mountings=None, mounting_sigmas=None):
    """The :class:`~navsim.estimation.attitude_filter.AttitudeFilterConfig` of ``scenario['filter']``: its
    initial covariance (:func:`initial_covariance`), the noise and state treatments of the gyro's datasheet
    unless the scenario names its own, the nominal mounting (``q_BS``: one per head (H, 4) with their
    ``mountings`` treatments and initial σ ``mounting_sigmas`` [arcsec]; default the one ``star_sensor`` table's),
    tuning and gate."""
    f = scenario["filter"]
    q_BS = mounting(scenario["star_sensor"])[0] if q_BS is None else np.asarray(q_BS, dtype=float)
    states = filter_states(scenario, gyro)
    if mountings is not None:
        states["mounting"] = tuple(mountings)
    arw = gyro.arw if f["arw_deg_per_sqrt_h"] is None else float(units.arw_to_si(f["arw_deg_per_sqrt_h"]))
    rrw = gyro.rrw if states["bias_instability"] != "ignore" else gyro.filter_rrw
    if f["rrw_deg_per_h_per_sqrt_h"] is not None:
        rrw = float(units.rrw_to_si(f["rrw_deg_per_h_per_sqrt_h"]))
    return AttitudeFilterConfig(
        P0=initial_covariance(scenario, gyro, mountings, mounting_sigmas),
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
