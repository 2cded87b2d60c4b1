"""Scenario keys of the star sensor and of the faults, shared by the attitude and navigation schemas
(units in the key names), and the cross-key rules both kinds apply to them."""

from navsim.scenario.inertial_fields import MAX_ARCSEC, MAX_BIAS
from navsim.scenario.schema import ListOfTables, Table, Value
from startrack import BANDS, DETECTORS, InputError, units
from startrack import rotation as rot

#: The star sensor's keys: fidelity, measurement, rate, field, noise, mounting and the image table.
STAR_SENSOR = {
    "fidelity": Value("str", default="vector", choices=("vector", "image"),
                      doc="vector: noisy star vectors or fixes; image: rendered frames through "
                          "detection, identification and (dim stars) stacking"),
    "measurement": Value("str", default="stars", choices=("stars", "attitude")),
    "rate_hz": Value("float", exclusive_minimum=0.0, maximum=1e3),
    "fov_deg": Value("float", exclusive_minimum=0.0, maximum=120.0,
                     doc="full cone angle of the circular field"),
    "band": Value("str", default="V", choices=tuple(BANDS),
                  doc="the sensor's photometric band: every magnitude key and the catalog's stars are in it"),
    "mag_limit": Value("float", default=6.0, minimum=-2.0, maximum=12.0,
                       doc="the catalog's depth in the band (with a light budget: the faintest star it may report)"),
    "max_stars": Value("int", default=10, minimum=1, maximum=1000),
    "star_sigma_arcsec": Value("float", default=5.0, exclusive_minimum=0.0, maximum=MAX_ARCSEC,
                               doc="1σ direction error per star and tangent axis"),
    "attitude_sigma_cross_arcsec": Value("float", default=5.0, exclusive_minimum=0.0, maximum=MAX_ARCSEC),
    "attitude_sigma_roll_arcsec": Value("float", default=40.0, exclusive_minimum=0.0, maximum=MAX_ARCSEC),
    "mounting_rotvec_deg": Value("vector", default=[0.0, 0.0, 0.0], minimum=-360.0, maximum=360.0,
                                 doc="nominal R_BS (sensor to body) as a rotation vector"),
    "misalignment_arcsec": Value("vector", default=[0.0, 0.0, 0.0], minimum=-MAX_ARCSEC, maximum=MAX_ARCSEC,
                                 doc="true, unknown mounting error (rotation vector in S)"),
    "image": Table(
        {
            "width_px": Value("int", default=1024, minimum=16, maximum=8192),
            "height_px": Value("int", default=1024, minimum=16, maximum=8192),
            "field": Value("str", default="circular", choices=("circular", "rectangular"),
                           doc="circular: the circle of diameter fov_deg inscribed in the width"),
            "psf_sigma_px": Value("float", default=0.671, exclusive_minimum=0.0, maximum=10.0),
            "exposure_s": Value("float", default=0.1, exclusive_minimum=0.0, maximum=10.0),
            "zero_point_e_per_s": Value("float", default=None, exclusive_minimum=0.0, maximum=1e15,
                                        doc="photoelectrons per second of a magnitude-0 star (default 5e6; with "
                                            "star_sensor.photometry: its aperture, optics and detector's)"),
            "read_noise_e": Value("float", default=None, minimum=0.0, maximum=1e6,
                                  doc="default 20 e-; with star_sensor.photometry: its detector's"),
            "render_mag_limit": Value("float", default=7.0, minimum=-2.0, maximum=12.0,
                                      doc="faintest star drawn into the frames"),
            "detection_sigmas": Value("float", default=5.0, exclusive_minimum=0.0, maximum=1e3,
                                      doc="a of V_th = b + a σ_n (eq. 4 of 004)"),
            "detection": Value("str", default="threshold", choices=("threshold", "matched"),
                               doc="full frames: threshold, 004's V_th on single pixels; matched, the matched filter "
                                   "for the trail the predicted rate draws at the boresight (startrack.detect_trailed); "
                                   "windows stay thresholded"),
            "centroid_sigma_px": Value("float", default=0.1, exclusive_minimum=0.0, maximum=100.0,
                                       doc="centroid error the identification assumes (its gates); the filter takes each star's covariance from its position fit"),
            "catalog_nd": Value("int", default=53, minimum=4, maximum=400,
                                doc="n_d of the navigation catalog (eq. 1-2 of 000)"),
            "catalog_max_pointing_error_deg": Value("float", default=2.0, exclusive_minimum=0.0,
                                                    doc="max(δ) of eq. 6 of 000"),
            "tracking_window_px": Value("int", default=5, minimum=2, maximum=50,
                                        doc="half-width of the readout windows while tracking"),
            "max_identified_stars": Value("int", default=12, minimum=3, maximum=1000),
            "dim_star_stacking": Value("bool", default=True,
                                       doc="stack the predicted dim star over 4 frames when < 3 stars"),
            "sky_hip": Value("ints", default=[], minimum=1, maximum=10**6,
                             doc="render only these Hipparcos stars (004 §3 renders four); "
                                 "empty: the whole catalog"),
            "start_tracking": Value("bool", default=False,
                                    doc="the sensor starts in tracking, with the filter's initial "
                                        "attitude as prior (004's set-up)"),
            "compare_without_stacking": Value("bool", default=False,
                                              doc="also run a shadow filter that never gets the "
                                                  "stacked star, for the paired comparison of 004"),
            "camera_file": Value("str", default=None,
                                 doc="camera file (startrack solve --write-camera), relative to the "
                                     "scenario file: sets the camera's size, focal length, principal "
                                     "point and distortion (fov_deg still sizes the catalog)"),
        },
        optional=True,
    ),
}

#: The light budget of a star sensor that sees a real sky (a navigation run): with it the sky's brightness in the
#: band, the extinction along each star's line of sight and the detector decide which stars a frame shows and
#: how well each is placed (navsim.sensors.frame_sky); its exposure, PSF, detection threshold and pixel scale
#: are the image table's.
PHOTOMETRY = Table(
    {
        "aperture_mm": Value("float", exclusive_minimum=0.0, maximum=2000.0, doc="the entrance pupil's diameter"),
        "transmission": Value("float", default=0.8, exclusive_minimum=0.0, maximum=1.0,
                              doc="of the optics and filter in the band"),
        "detector": Value("str", default="silicon_cmos", choices=tuple(DETECTORS),
                          doc="the detector preset (startrack.photometry.detectors); the keys below override its values"),
        "qe": Value("float", default=None, exclusive_minimum=0.0, maximum=1.0,
                    doc="quantum efficiency in the band (default: the preset's at the band's centre)"),
        "read_noise_e": Value("float", default=None, minimum=0.0, maximum=1e5),
        "dark_e_per_px_s": Value("float", default=None, minimum=0.0, maximum=1e9),
        "full_well_e": Value("float", default=None, exclusive_minimum=0.0, maximum=1e9),
        "relative_humidity_percent": Value("float", default=40.0, minimum=1.0, maximum=95.0,
                                           doc="of the ground air: its water vapour (Schaefer 1998)"),
        "visibility_km": Value("float", default=38.0, exclusive_minimum=0.0, maximum=1000.0,
                               doc="the ground's meteorological visibility: the aerosol optical depth at 550 nm by "
                                   "Koschmieder's law, (3.912/V − β_Rayleigh) × 1.5 km (38 km: 0.137, 23 km: 0.24)"),
        "aerosol_optical_depth": Value("float", default=None, minimum=0.0, maximum=5.0,
                                       doc="the boundary-layer aerosol's optical depth at 550 nm from sea level "
                                           "(given: it replaces the visibility's)"),
        "angstrom_exponent": Value("float", default=1.3, minimum=-1.0, maximum=4.0,
                                   doc="α of the aerosol's τ(λ) = τ_550 (λ/0.55 µm)^−α (1.3: continental)"),
        "ground_temperature_c": Value("float", default=15.0, minimum=-60.0, maximum=50.0),
    },
    optional=True,
    doc="the sensor's light budget: with it the sky decides which stars each frame shows (night, Moon, twilight, "
        "day) and each star's σ follows its SNR",
)

#: The refraction of a star sensor inside the air (a navigation run; navsim.earth.refraction): the truth sees every
#: star raised by the real air at the vehicle, the processing corrects it with the standard atmosphere at the INS's
#: height; the real air's departure from it is left in every star.
REFRACTION = Table(
    {
        "correction": Value("bool", default=True,
                            doc="the processing refracts the catalog stars by the standard atmosphere at the INS's "
                                "height (the truth always sees refracted stars)"),
        "pressure_error_percent": Value("float", default=0.0, minimum=-50.0, maximum=50.0,
                                        doc="the real air's pressure at the vehicle against the standard atmosphere's"),
        "temperature_error_k": Value("float", default=0.0, minimum=-60.0, maximum=60.0,
                                     doc="the real air's temperature at the vehicle against the standard atmosphere's"),
        "pressure_sigma_percent": Value("float", default=0.0, minimum=0.0, maximum=50.0,
                                        doc="what the processing takes its model air's pressure error to be (1σ); "
                                            "with temperature_sigma_k the σ of the filter's refraction consider state "
                                            "(0 and 0: no state)"),
        "temperature_sigma_k": Value("float", default=0.0, minimum=0.0, maximum=60.0,
                                     doc="what the processing takes its model air's temperature error to be (1σ)"),
        "drawn": Value("bool", default=False,
                       doc="each run's real air departs from the errors above by a pressure and a temperature error "
                           "drawn from pressure_sigma_percent and temperature_sigma_k (a campaign then checks that σ)"),
    },
    doc="atmospheric refraction of the stars and its correction",
)

#: How a navigation run's star sensor names its stars (vector fidelity, issue 30): every detected star as the
#: catalog star it is (the pattern identification of a field with enough stars, taken to succeed), or each detection
#: with the INS's prior (navsim.sensors.star_prior: 1-3 stars by day, false detections, a wrong-match ceiling).
IDENTIFICATION = Table(
    {
        "method": Value("str", default="catalog", choices=("catalog", "prior"),
                        doc="catalog: every detected star identified; prior: each detection matched to the star the "
                            "INS predicts (startrack.identify.prior_match)"),
        "gate_probability": Value("float", default=0.9999, minimum=0.9, maximum=0.999999,
                                  doc="the chi-square gate's probability of holding the true star"),
        "max_wrong_probability": Value("float", default=1e-3, exclusive_minimum=0.0, maximum=0.1,
                                       doc="a match is kept when its chance of being a coincidence is below this"),
        "false_stars_per_frame": Value("float", default=0.0, minimum=0.0, maximum=100.0,
                                       doc="mean false detections per frame (drawn, and expected by the matcher)"),
        "mag_window_sigmas": Value("float", default=3.0, exclusive_minimum=0.0, maximum=10.0,
                                   doc="half-width of the magnitude window in σ of the measured and catalog magnitudes"),
        "colour_sigma_mag": Value("float", default=0.12, minimum=0.0, maximum=1.0,
                                  doc="the error of the catalog's band magnitudes from the colours (one draw per star)"),
    },
    doc="how the star sensor identifies its stars",
)

#: The faults both kinds of run take: outages, attitude jumps, false-star storms, gyro bias steps and
#: dropped frames; and the tracking-failure probes of 000 §5 (a per-frame observer, :mod:`navsim.studies`).
FAULTS = {
    "outages": ListOfTables(Table({"start_s": Value("float", minimum=0.0),
                                   "end_s": Value("float", minimum=0.0),
                                   "reason": Value("str", default="Sun in the field")})),
    "attitude_jumps": ListOfTables(Table({"time_s": Value("float", minimum=0.0),
                                          "angle_deg": Value("float", exclusive_minimum=0.0, maximum=180.0)}),
                                   doc="the filter's attitude is knocked off by this angle "
                                       "(tracking loss); the sensor must re-acquire"),
    "false_star_storms": ListOfTables(Table({"start_s": Value("float", minimum=0.0),
                                            "end_s": Value("float", minimum=0.0),
                                            "count": Value("int", minimum=1, maximum=1000)})),
    "gyro_bias_steps": ListOfTables(Table({"time_s": Value("float", minimum=0.0),
                                           "step_deg_per_h": Value("vector", minimum=-MAX_BIAS, maximum=MAX_BIAS)})),
    "dropped_frames_s": Value("list", default=[], minimum=0.0, doc="times of frames that are lost"),
    "tracking_failure_probes": Table(
        {"count": Value("int", minimum=1, maximum=100000),
         "angle_3sigma_deg": Value("float", exclusive_minimum=0.0, maximum=90.0)},
        optional=True,
        doc="000 §5: at `count` random frames the prior is disturbed (Rayleigh angle of "
            "3σ = angle_3sigma_deg) and the predicted sub-catalog and full-sky methods are both "
            "run on that frame's centroids; the filter is not disturbed",
    ),
}

#: The faults (and probes) that act on frames, which only image fidelity has.
FRAME_FAULTS = ("tracking_failure_probes", "attitude_jumps", "false_star_storms")


def mounting(sensor):
    """(q_BS nominal, q_BS true) of a ``star_sensor`` table: its mounting rotation vector, then the
    true misalignment δm (sensor axes): q_BS,true = q_BS ⊗ δq(δm)."""
    q_BS = rot.from_rotation_vector(units.deg_to_rad(sensor["mounting_rotvec_deg"]))
    q_BS_true = rot.multiply(q_BS, rot.from_rotation_vector(units.arcsec_to_rad(sensor["misalignment_arcsec"])))
    return q_BS, q_BS_true


#: The image table's detector values without a light budget.
LEGACY_DETECTOR = {"zero_point_e_per_s": 5.0e6, "read_noise_e": 20.0}


def check_star_sensor(sensor, source):
    """Cross-key rules of a checked ``star_sensor`` table: image fidelity measures stars, gets its
    image table's defaults when absent and reads its camera file now; a light budget (``photometry``)
    measures stars, takes the image table's camera at either fidelity and sets its detector's values
    (which the image table then must not give)."""
    photometry = sensor.get("photometry")
    if sensor["fidelity"] == "image" or photometry is not None:
        if sensor["measurement"] != "stars":
            what = "image fidelity" if photometry is None else "a sensor with a light budget (star_sensor.photometry)"
            raise InputError(f"{source}: star_sensor.measurement: {what} measures stars, not {sensor['measurement']!r}")
        if "image" not in sensor:
            sensor["image"] = STAR_SENSOR["image"].check("star_sensor.image", {})
        _apply_camera_file(sensor["image"], source)
    image = sensor.get("image")
    if image is None:
        return
    for key, legacy in LEGACY_DETECTOR.items():
        if photometry is not None and image[key] is not None:
            raise InputError(f"{source}: star_sensor.image.{key}: set by star_sensor.photometry (aperture, optics and "
                             "detector); leave it out")
        if image[key] is None and photometry is None:
            image[key] = legacy


def check_faults(faults, fidelity, source):
    """Cross-key rules of a checked ``faults`` table for a star sensor of ``fidelity`` (None: none):
    faults acting on frames need image fidelity, intervals end after they start."""
    for kind in FRAME_FAULTS:
        if faults.get(kind) and fidelity != "image":
            raise InputError(f"{source}: faults.{kind}: needs star_sensor.fidelity = 'image' (it acts on frames)")
    for kind in ("outages", "false_star_storms"):
        for k, interval in enumerate(faults[kind]):
            if interval["end_s"] <= interval["start_s"]:
                raise InputError(f"{source}: faults.{kind}[{k}]: end_s must be after start_s")


def _apply_camera_file(image, source):
    """A given ``star_sensor.image.camera_file`` is read now (one InputError for a missing or bad file)
    and sets ``width_px`` and ``height_px``; build.py takes the camera from it."""
    if image.get("camera_file") is None:
        return
    from startrack import read_camera_file

    try:
        camera = read_camera_file(image["camera_file"]).camera
    except InputError as error:
        raise InputError(f"{source}: star_sensor.image.camera_file: {error}") from None
    image["width_px"], image["height_px"] = camera.width, camera.height
