"""What a star-aided navigation run (SINS/CNS) adds to its summary (``celestial``): the star sensor,
the analytic-horizon floor, the aberration and what skipping its correction costs, and the
observability of each state.

Analytic horizon. The star sensor measures the psi angle ψ = φ − δθ_n (the inertial attitude of the
INS, :mod:`navsim.estimation.celestial_kernels`), which obeys ψ̇ = −ω_in × ψ − C_nb ε whatever the
velocity and position errors (Titterton & Weston, 2nd ed., §12.2.1): stars fix ψ and the gyro
biases, not the position. The horizontal channels keep their Schuler dynamics, driven in level flight
by δv̇_N = g φ_E + ∇_N − δg_N, δv̇_E = −g φ_N + ∇_E − δg_E (δg the truth's gravity disturbance the INS
lacks); with ψ held at zero, φ = δθ_n, and the position error oscillates at the Schuler period
about its equilibrium

    δN = (R_M + h) (∇_N − δg_N)/γ,   δE = (R_N + h) (∇_E − δg_E)/γ,                      (1)

the floor R·∇/g of the accelerometer bias (100 µg: 637 m) plus R times the deflection of the vertical
(δg_N = −ξγ: 1" gives 31 m); gyro drift, now estimated, no longer grows it. The summary compares the
Schuler mean of the horizontal error (its mean over the steady frames) with eq. (1) for the true bias
and disturbance (``horizon_floor``).

Aberration. An attitude from apparent stars is turned by the rotation r of the boresight's
aberration (:func:`navsim.earth.apparent.fix_rotation`); uncorrected, the filter takes its
horizontal part r_h (navigation axes) for a tilt and settles R·r_h away (20" -> ~600 m).

Refraction. The air raises the boresight towards the zenith by ΔZ (eq. 1 of :mod:`navsim.earth.refraction`), a
rotation about a horizontal axis: uncorrected it costs R·ΔZ (58" at 45° at sea level: 1.8 km; 15" at 12 km), and
the real air's departure from the processing's model leaves R·δΔZ.

Observability. Per state the ratio of the filter's σ at the end to its initial σ, and the
eigen-decomposition of the final covariance normalised by the initial σ (Ham & Brown 1983): an
eigenvalue near 1 is a direction the measurements left as it was, one near 0 is observed.
"""

import numpy as np

from navsim.earth.apparent import fix_rotation
from navsim.earth.frames import q_en
from navsim.earth.gravity import normal_gravity
from navsim.earth.wgs84 import radii
from startrack import rotation as rot
from startrack import units

#: Schuler period at the Earth's surface [s] (2π √(R/g)), for the number of periods a mean covers.
SCHULER_PERIOD_S = 5063.0
#: Components listed per eigenvector of the normalised covariance.
EIGEN_COMPONENTS = 3


def summary(scenario, series, sky, orientation, q_BS_true, geometry, air):
    """The ``celestial`` block of a star-aided run's summary (module docstring); ``geometry`` the frames'
    :class:`~navsim.navigation.exclusion.SkyGeometry`, ``air`` the run's real :class:`~navsim.earth.refraction.Air`."""
    sensor = scenario["star_sensor"]
    steady = series["t"] >= scenario["settle_s"]
    return {"star_sensor": {"fidelity": sensor["fidelity"], "measurement": sensor["measurement"],
                            "rate_hz": sensor["rate_hz"], "aberration_correction": sensor["aberration_correction"],
                            "frames_with_stars": int(np.count_nonzero(series["n_measurements"]))},
            "sky": sky_summary(geometry, series, sensor),
            "horizon_floor": horizon_floor(series, steady),
            "aberration": aberration(series, sky, orientation, q_BS_true, sensor["aberration_correction"], steady),
            "refraction": refraction(series, sky, orientation, q_BS_true, sensor["refraction"], air, steady),
            "observability": observability(series),
            **({"star_identification": star_identification(series)} if "n_wrong" in series else {})}


def star_identification(series):
    """What identifying the detections with the INS's prior did (:mod:`navsim.sensors.star_prior`): frames with
    detections and with stars identified, stars detected and identified (and of them on their tracks), the
    identifications the truth finds wrong, the largest wrong-match probability the matcher stated and the sum of them
    all (the wrong identifications it expects)."""
    identified = series["n_identified"]
    return {"frames_detected": int(np.count_nonzero(series["n_detected"])),
            "frames_identified": int(np.count_nonzero(identified)), "stars_detected": int(series["n_detected"].sum()),
            "stars_identified": int(identified.sum()), "stars_tracked": int(series["n_tracked"].sum()),
            "wrong": int(series["n_wrong"].sum()),
            "wrong_probability_max": float(series["wrong_probability"].max(initial=0.0)),
            "wrong_expected": float(series["wrong_expected"].sum())}


def sky_summary(geometry, series, sensor):
    """The Sun, the Moon and the horizon over the frames: the least angles of the Sun and the Moon from the
    boresight, the boresight's lowest elevation [deg], the frames with the Sun above the horizon, the Moon's mean
    illuminated fraction and the frames each exclusion took (:mod:`navsim.navigation.exclusion`); the hours with
    stars measured and the stars per frame (an attitude fix counts as one); with a light budget the band and the range of the sky's brightness
    [mag arcsec⁻²] and of the limiting magnitude at the boresight (:mod:`navsim.navigation.sky_background`)."""
    degrees = np.degrees
    stars = series["n_stars"]
    out = {"sun_angle_min_deg": float(degrees(geometry.sun_angle.min())),
           "moon_angle_min_deg": float(degrees(geometry.moon_angle.min())),
           "boresight_elevation_min_deg": float(degrees(geometry.boresight_elevation.min())),
           "frames_sun_up": int(np.count_nonzero(geometry.sun_elevation > 0.0)),
           "moon_illuminated_mean": float(np.mean(geometry.moon_illuminated)),
           "frames_excluded": geometry.counts(),
           "hours_with_stars": float(np.count_nonzero(stars) / sensor["rate_hz"] / units.HOUR),
           "stars_per_frame": {"mean": float(np.mean(stars)), "median": float(np.median(stars)),
                               "max": int(np.max(stars, initial=0))}}
    if "limiting_mag" in series:
        out["band"] = sensor["band"]
        out["sky_background_mag"] = _range(series["sky_background_mag"])
        out["limiting_mag"] = _range(series["limiting_mag"])
    out["frames_without_stars"] = without_stars(geometry, series)
    return out


def without_stars(geometry, series):
    """Why the frames without a measured star had none, {reason: frames}: an exclusion (the Sun, the Moon, the
    horizon), the sky's light filling the pixels (no star detectable: the limiting magnitude is −inf), no star of the
    field above the limiting magnitude, or (a light budget's frames with detections) none identified."""
    none = series["n_stars"] == 0
    excluded = geometry.reason >= 0
    out = {"excluded": int(np.count_nonzero(none & excluded))}
    rest = none & ~excluded
    if "limiting_mag" in series:
        blind = rest & ~np.isfinite(series["limiting_mag"])
        out["sky fills the pixels"] = int(np.count_nonzero(blind))
        rest &= ~blind
    if "n_detected" in series:
        unnamed = rest & (series["n_detected"] > 0)
        out["detections not identified"] = int(np.count_nonzero(unnamed))
        rest &= ~unnamed
    out["no star above the limit"] = int(np.count_nonzero(rest))
    return out


def _range(values):
    """{min, median, max} of the finite ``values`` (None: none finite)."""
    finite = values[np.isfinite(values)]
    if not finite.size:
        return {"min": None, "median": None, "max": None}
    return {"min": float(finite.min()), "median": float(np.median(finite)), "max": float(finite.max())}


def floor_ned(series, bias=None):
    """(accelerometer-bias part, gravity part) (F, 2) [m] of eq. (1): the true bias (or ``bias`` (F, 3)
    [m/s²] in body axes, e.g. what the filter left of it) resolved in the navigation frame and the
    truth's gravity disturbance, north and east."""
    lat, h = series["lat_true"], series["h_true"]
    r_m, r_n = radii(lat)
    scale = np.stack([r_m + h, r_n + h], axis=-1) / normal_gravity(lat, h)[:, None]
    bias_n = rot.rotate(series["q_nb_true"], series["accel_bias_true"] if bias is None else bias)
    return scale * bias_n[:, :2], -scale * series["gravity_disturbance_true"][:, :2]


def horizon_floor(series, steady):
    """The Schuler mean of the horizontal position error against eq. (1) over the steady frames [m]:
    north and east means and magnitudes of the error, of the floor and of its two parts."""
    bias, gravity = (part[steady].mean(axis=0) for part in floor_ned(series))
    error = series["position_error_m"][steady, :2].mean(axis=0)
    span = float(series["t"][steady][-1] - series["t"][steady][0])
    return {"position_error_mean_ne_m": [float(v) for v in error], "position_error_mean_m": float(np.hypot(*error)),
            "floor_ne_m": [float(v) for v in bias + gravity], "floor_m": float(np.hypot(*(bias + gravity))),
            "accel_bias_m": float(np.hypot(*bias)), "gravity_m": float(np.hypot(*gravity)),
            "schuler_periods": span / SCHULER_PERIOD_S}


def aberration(series, sky, orientation, q_BS_true, corrected, steady):
    """The aberration at the true boresight: the annual part (the Earth's orbit), the vehicle's (the
    Earth's rotation and the vehicle's ground velocity) and the whole [arcsec, mean and max], the
    whole's horizontal part in the navigation frame, and the position error R·r_h that skipping the
    correction costs [m] (module docstring)."""
    boresight = _boresight(sky, q_BS_true)
    annual = rot.to_rotation_vector(fix_rotation(boresight, orientation.v_earth))
    vehicle = rot.to_rotation_vector(fix_rotation(boresight, sky.v_I - orientation.v_earth))
    total = rot.to_rotation_vector(fix_rotation(boresight, sky.v_I))
    total_n = _in_navigation_axes(total, series, orientation)
    return {"corrected": bool(corrected), "annual_arcsec": _arcsec(annual, steady), "vehicle_arcsec": _arcsec(vehicle, steady),
            "total_arcsec": _arcsec(total, steady),
            "horizontal_arcsec": _arcsec(total_n[:, :2], steady),
            "uncorrected_position_m": _position_cost(total_n, series, steady)}


def refraction(series, sky, orientation, q_BS_true, keys, air, steady):
    """The refraction of the true boresight by the real ``air`` (the run's: its pressure and temperature errors are
    reported, drawn or given) [arcsec, mean and max over the steady frames], its residual against the processing's
    model air at the true height, their position costs R·ΔZ [m] (module docstring) and, when the filter carries it, its
    refraction consider state: the truth's ε_r and the filter's σ (``considered``: {"fraction_true",
    "fraction_sigma"} of the last frame [-], else None); ``keys`` the scenario's ``star_sensor.refraction`` table."""
    modelled = air.modelled()
    boresight = _boresight(sky, q_BS_true)
    at_rest = np.zeros_like(boresight)
    real = rot.to_rotation_vector(fix_rotation(boresight, at_rest, sky.air(slice(None))))
    a, b = modelled.coefficients(series["h_true"])
    model = rot.to_rotation_vector(fix_rotation(boresight, at_rest, (sky.up_I, a, b)))
    residual = real - model if keys["correction"] else real
    return {"corrected": bool(keys["correction"]), "drawn": bool(keys["drawn"]),
            "pressure_error_percent": round(100.0 * air.pressure_error, 12), "temperature_error_k": air.temperature_error,
            "total_arcsec": _arcsec(real, steady),
            "residual_arcsec": _arcsec(residual, steady),
            "residual_position_m": _position_cost(_in_navigation_axes(residual, series, orientation), series, steady),
            "uncorrected_position_m": _position_cost(_in_navigation_axes(real, series, orientation), series, steady),
            "considered": _considered(series)}


def _considered(series):
    """The refraction consider state at the last frame (truth and σ) or None (:func:`refraction`)."""
    names = list(series["state_names"])
    if "refraction" not in names:
        return None
    i = names.index("refraction")
    return {"fraction_true": float(series["error_state"][-1, i]), "fraction_sigma": float(series["error_sigma"][-1, i])}


def _boresight(sky, q_BS_true):
    """The true boresight (F, 3) in I."""
    return rot.rotate(rot.multiply(sky.q_IB, q_BS_true), np.array([0.0, 0.0, 1.0]))


def _in_navigation_axes(rotation_vector_I, series, orientation):
    """Rotation vectors (F, 3) in I resolved in the true NED axes."""
    q_in = rot.multiply(orientation.q_ie, np.stack(q_en(series["lat_true"], series["lon_true"]), axis=-1))
    return rot.rotate(rot.conjugate(q_in), rotation_vector_I)


def _position_cost(r_n, series, steady):
    """R·r_h [m]: the position error a filter settles at when it takes the horizontal part of the attitude offsets
    r_n (F, 3) (NED) for a tilt, the size of its mean over the steady frames."""
    r_m, r_n_radius = radii(series["lat_true"])
    cost = np.stack([-r_n[:, 1] * (r_m + series["h_true"]), r_n[:, 0] * (r_n_radius + series["h_true"])], axis=-1)
    return float(np.hypot(*cost[steady].mean(axis=0)))


def _arcsec(v, steady):
    """{mean, max} [arcsec] of the sizes of the rotation vectors v (F, 3) over the steady frames."""
    size = np.linalg.norm(v[steady], axis=-1) / units.ARCSEC
    return {"mean": float(size.mean()), "max": float(size.max())}


def observability(series):
    """Per state σ_end/σ_0 and the spectrum of the final covariance normalised by the initial σ
    (eigenvalues ascending, each with its largest components: state name and weight)."""
    names, sigma0 = list(series["state_names"]), series["error_sigma_initial"]
    normalised = series["covariance_final"] / np.outer(sigma0, sigma0)
    values, vectors = np.linalg.eigh(0.5 * (normalised + normalised.T))
    modes = []
    for value, vector in zip(values, vectors.T):
        top = np.argsort(-np.abs(vector))[:EIGEN_COMPONENTS]
        modes.append({"eigenvalue": float(value), "components": [[names[i], float(vector[i])] for i in top]})
    return {"states": names, "sigma_ratio_final": [float(v) for v in series["error_sigma"][-1] / sigma0], "spectrum": modes}
