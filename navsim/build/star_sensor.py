"""The star sensor of a scenario's ``star_sensor`` table (vector or image fidelity) with the faults that
act on it, its light budget (``star_sensor.photometry``) and the per-frame observers (:mod:`navsim.studies`)
the scenario asks for, in SI units. The stars are the catalog's in the sensor's band."""

import dataclasses

import numpy as np

from navsim.build.faults import sensor_faults
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.frame_detection import FULL_FRAME_DETECTORS
from navsim.sensors.star_image import ImageStarSensor
from navsim.sensors.star_prior import PriorIdentification
from navsim.sensors.star_vector import AttitudeFixSensor, StarVectorSensor
from navsim.studies import observers as observer_kinds
from startrack import (
    Camera,
    InputError,
    NavigationCatalogParams,
    PriorMatch,
    SensorModel,
    SensorPhotometry,
    StarIdentifier,
    band,
    compile_ahead,
    detector,
    load_navigation_catalog,
    read_camera_file,
    units,
)

#: The grey-level range of a sensor with a light budget: 16 bits over its full well (bias included).
PHYSICAL_FULL_SCALE_DN = 65536


def star_sensor(scenario, star_catalog, frame_interval, epoch, lanes=()):
    """The star sensor of ``scenario['star_sensor']`` (vector or image fidelity) with the faults that
    act on it; ``star_catalog`` a :class:`startrack.catalog.hipparcos.StarCatalog` (stars measured or
    rendered), ``frame_interval`` the time between frames [s], ``epoch`` the catalog's [Julian year],
    ``lanes`` the run's compile-ahead lanes (:mod:`startrack.compiled.compile_ahead`; image fidelity); an attitude-fix
    sensor needs no catalog (None)."""
    sensor = scenario["star_sensor"]
    _, q_BS_true = mounting(scenario["star_sensor"])
    faults = sensor_faults(scenario["faults"], frame_interval)
    if star_catalog is not None:
        star_catalog = star_catalog.in_band(sensor["band"])
    if sensor["fidelity"] == "image":
        return image_star_sensor(scenario, star_catalog, q_BS_true, faults, epoch, lanes)
    if sensor["measurement"] == "attitude":
        return AttitudeFixSensor(
            sigma_cross=float(units.arcsec_to_rad(sensor["attitude_sigma_cross_arcsec"])),
            sigma_roll=float(units.arcsec_to_rad(sensor["attitude_sigma_roll_arcsec"])),
            q_BS_true=q_BS_true,
            faults=faults,
        )
    stars = star_catalog.brighter_than(sensor["mag_limit"])
    return StarVectorSensor(
        star_vectors=np.asarray(stars.vectors),
        star_ids=np.asarray(stars.hip),
        star_mags=np.asarray(stars.mag),
        fov=float(units.deg_to_rad(sensor["fov_deg"])),
        sigma=float(units.arcsec_to_rad(sensor["star_sigma_arcsec"])),
        max_stars=sensor["max_stars"],
        q_BS_true=q_BS_true,
        faults=faults,
        photometry=photometry(sensor),
        identification=prior_identification(sensor, stars),
    )


def prior_identification(sensor, stars):
    """The :class:`~navsim.sensors.star_prior.PriorIdentification` of a ``star_sensor`` table whose
    ``identification.method`` is "prior", over the sensor's catalog ``stars``, or None."""
    table = sensor.get("identification")
    if table is None or table["method"] != "prior":
        return None
    matcher = PriorMatch(np.asarray(stars.vectors), np.asarray(stars.mag), 0.5 * float(units.deg_to_rad(sensor["fov_deg"])),
                         gate_probability=table["gate_probability"], mag_sigmas=table["mag_window_sigmas"],
                         catalog_mag_sigma=table["colour_sigma_mag"], false_per_frame=table["false_stars_per_frame"],
                         max_wrong=table["max_wrong_probability"])
    return PriorIdentification(matcher=matcher, false_per_frame=table["false_stars_per_frame"],
                               colour_sigma=table["colour_sigma_mag"])


def camera(sensor):
    """The :class:`startrack.camera.model.Camera` of a ``star_sensor`` table with an image table: its camera file's, or an
    ideal pinhole of the field and the size."""
    image, fov = sensor["image"], float(units.deg_to_rad(sensor["fov_deg"]))
    if image["camera_file"] is not None:  # a calibrated camera (startrack solve --write-camera)
        return dataclasses.replace(read_camera_file(image["camera_file"]).camera, circular_fov=image["field"] == "circular")
    return Camera.from_fov(fov, image["width_px"], image["height_px"], circular_fov=image["field"] == "circular")


def photometry(sensor, sensor_camera=None):
    """The :class:`startrack.image.sensor_photometry.SensorPhotometry` of a ``star_sensor`` table's light budget, or None
    (no ``photometry`` table): its band, detector (the preset with the table's overrides), aperture and optics, the
    image table's exposure, PSF and detection threshold, and the pixel scale of ``sensor_camera`` (default:
    :func:`camera`)."""
    table = sensor.get("photometry")
    if table is None:
        return None
    sensor_camera = sensor_camera or camera(sensor)
    overrides = {key: table[key] for key in ("qe", "read_noise_e", "dark_e_per_px_s", "full_well_e") if table[key] is not None}
    image = sensor["image"]
    return SensorPhotometry(band=band(sensor["band"]), detector=detector(table["detector"]).with_overrides(**overrides),
                            aperture_area=np.pi * (0.5e-3 * table["aperture_mm"]) ** 2, transmission=table["transmission"],
                            exposure_s=image["exposure_s"], psf_sigma_px=image["psf_sigma_px"],
                            pixel_scale=1.0 / sensor_camera.focal_px, detection_sigmas=image["detection_sigmas"])


def sensor_model(sensor, budget):
    """The renderer's :class:`startrack.image.render.SensorModel` of a ``star_sensor`` table's image table: with a light
    budget (``budget``, :func:`photometry`) its detector's zero point, read noise, dark current and full well (16 bits
    over the well); otherwise (None) the image table's zero point and read noise."""
    image = sensor["image"]
    common = {"psf_sigma_px": image["psf_sigma_px"], "exposure_s": image["exposure_s"]}
    if budget is None:
        return SensorModel(zero_point_e_per_s=image["zero_point_e_per_s"], read_noise_e=image["read_noise_e"], **common)
    d, bias = budget.detector, SensorModel.bias_dn
    return SensorModel(zero_point_e_per_s=budget.zero_point_e_per_s / budget.transmission, transmission=budget.transmission,
                       read_noise_e=d.read_noise_e, dark_e_per_px_s=d.dark_e_per_px_s, full_well_e=d.full_well_e,
                       full_scale_dn=PHYSICAL_FULL_SCALE_DN, gain_e_per_dn=d.full_well_e / (PHYSICAL_FULL_SCALE_DN - 1 - bias),
                       **common)


def vector_equivalent(scenario, star_catalog, frame_interval, epoch):
    """(the vector-fidelity sensor a covariance analysis sees, with the nominal mounting (its error is a state of
    the analysis); a note when it stands for an image-fidelity sensor, else None): at image fidelity the stars of
    the magnitude limit in the field, at most ``max_identified_stars``, each of σ = centroid σ / focal length."""
    table = scenario["star_sensor"]
    q_BS, _ = mounting(table)
    if table["fidelity"] != "image":
        sensor = dataclasses.replace(star_sensor(scenario, star_catalog, frame_interval, epoch), q_BS_true=q_BS)
        if getattr(sensor, "identification", None) is None:
            return sensor, None
        return dataclasses.replace(sensor, identification=None), (
            "the detections named with the INS's prior (star_sensor.identification) taken to be every detected star, "
            "none false: the runs leave those the wrong-match ceiling rejects")
    image, fov = table["image"], float(units.deg_to_rad(table["fov_deg"]))
    stars = star_catalog.in_band(table["band"]).brighter_than(table["mag_limit"])
    sensor_camera = camera(table)
    sigma = image["centroid_sigma_px"] / sensor_camera.focal_px
    budget = photometry(table, sensor_camera)
    sensor = StarVectorSensor(star_vectors=np.asarray(stars.vectors), star_ids=np.asarray(stars.hip),
                              star_mags=np.asarray(stars.mag), fov=fov, sigma=float(sigma),
                              max_stars=image["max_identified_stars"], q_BS_true=q_BS,
                              faults=sensor_faults(scenario["faults"], frame_interval), photometry=budget)
    each = ("each at the Cramér-Rao bound of its SNR on the frame's sky" if budget is not None else
            f"each {units.rad_to_arcsec(sigma):.2f}\" per axis (centroid {image['centroid_sigma_px']:g} px)")
    note = (f"image fidelity modelled by its vector-fidelity equivalent: the {table['band']} <= {table['mag_limit']:g} "
            f"stars in the {table['fov_deg']:g} deg field, at most {image['max_identified_stars']}, {each}")
    return sensor, note


def image_star_sensor(scenario, star_catalog, q_BS_true, faults, epoch, lanes=()):
    """The image-fidelity sensor of ``scenario['star_sensor']`` and its ``image`` table: camera,
    detector, navigation catalog (eq. 1-8 of 000, at ``epoch`` [Julian year]) and identifier, the stars
    drawn into the frames; the run's kernels compiled ahead (``lanes``) once the scenario is checked."""
    sensor, image = scenario["star_sensor"], scenario["star_sensor"]["image"]
    fov = float(units.deg_to_rad(sensor["fov_deg"]))
    params = NavigationCatalogParams(mag_limit=sensor["mag_limit"], fov=fov, n_d=image["catalog_nd"],
                                     max_delta=float(units.deg_to_rad(image["catalog_max_pointing_error_deg"])),
                                     epoch=epoch, band=sensor["band"])
    stars = _rendered_stars(star_catalog, image)
    compile_ahead(lanes)  # the scenario checked: the identifier's kernels and the rest of the run's
    sensor_camera = camera(sensor)
    budget = photometry(sensor, sensor_camera)
    identifier = StarIdentifier(load_navigation_catalog(params, progress=False), sensor_camera,
                                centroid_sigma_px=image["centroid_sigma_px"], max_stars=image["max_identified_stars"])
    return ImageStarSensor(camera=sensor_camera, model=sensor_model(sensor, budget), identifier=identifier,
                           stars_I=np.asarray(stars.vectors), stars_mag=np.asarray(stars.mag), stars_hip=np.asarray(stars.hip),
                           detection_sigmas=image["detection_sigmas"], window_half_px=image["tracking_window_px"],
                           stacking=image["dim_star_stacking"], start_tracking=image["start_tracking"], q_BS_true=q_BS_true,
                           faults=faults, photometry=budget,
                           detection=FULL_FRAME_DETECTORS[image["detection"]](image))


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
