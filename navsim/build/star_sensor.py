"""The star sensor of a scenario's ``star_sensor`` table (vector or image fidelity) with the faults that
act on it, and the per-frame observers (:mod:`navsim.studies`) the scenario asks for, in SI units."""

import dataclasses

import numpy as np

from navsim.build.faults import sensor_faults
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.star_image import ImageStarSensor
from navsim.sensors.star_vector import AttitudeFixSensor, StarVectorSensor
from navsim.studies import observers as observer_kinds
from startrack import units
from startrack.camera import Camera
from startrack.errors import InputError
from startrack.identify.identifier import StarIdentifier
from startrack.navigation_catalog import NavigationCatalogParams, load_navigation_catalog
from startrack.precompile import compile_ahead
from startrack.render import SensorModel


def star_sensor(scenario, star_catalog, frame_interval, epoch, lanes=()):
    """The star sensor of ``scenario['star_sensor']`` (vector or image fidelity) with the faults that
    act on it; ``star_catalog`` a :class:`startrack.star_catalog.StarCatalog` (stars measured or
    rendered), ``frame_interval`` the time between frames [s], ``epoch`` the catalog's [Julian year],
    ``lanes`` the run's compile-ahead lanes (:mod:`startrack.precompile`; image fidelity)."""
    sensor = scenario["star_sensor"]
    _, q_BS_true = mounting(scenario["star_sensor"])
    faults = sensor_faults(scenario["faults"], frame_interval)
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
        star_mags=np.asarray(stars.v_mag),
        fov=float(units.deg_to_rad(sensor["fov_deg"])),
        sigma=float(units.arcsec_to_rad(sensor["star_sigma_arcsec"])),
        max_stars=sensor["max_stars"],
        q_BS_true=q_BS_true,
        faults=faults,
    )


def vector_equivalent(scenario, star_catalog, frame_interval, epoch):
    """(the vector-fidelity sensor a covariance analysis sees, with the nominal mounting (its error is a state of
    the analysis); a note when it stands for an image-fidelity sensor, else None): at image fidelity the stars of
    the magnitude limit in the field, at most ``max_identified_stars``, each of σ = centroid σ / focal length."""
    table = scenario["star_sensor"]
    q_BS, _ = mounting(table)
    if table["fidelity"] != "image":
        return dataclasses.replace(star_sensor(scenario, star_catalog, frame_interval, epoch), q_BS_true=q_BS), None
    image, fov = table["image"], float(units.deg_to_rad(table["fov_deg"]))
    camera = Camera.from_fov(fov, image["width_px"], image["height_px"], circular_fov=image["field"] == "circular")
    if image["camera_file"] is not None:
        camera = Camera.from_file(image["camera_file"])
    stars = star_catalog.brighter_than(table["mag_limit"])
    sigma = image["centroid_sigma_px"] / camera.focal_px
    sensor = StarVectorSensor(star_vectors=np.asarray(stars.vectors), star_ids=np.asarray(stars.hip),
                              star_mags=np.asarray(stars.v_mag), fov=fov, sigma=float(sigma),
                              max_stars=image["max_identified_stars"], q_BS_true=q_BS,
                              faults=sensor_faults(scenario["faults"], frame_interval))
    note = (f"image fidelity modelled by its vector-fidelity equivalent: the V <= {table['mag_limit']:g} stars in the "
            f"{table['fov_deg']:g} deg field, at most {image['max_identified_stars']}, each "
            f"{units.rad_to_arcsec(sigma):.2f}\" per axis (centroid {image['centroid_sigma_px']:g} px)")
    return sensor, note


def image_star_sensor(scenario, star_catalog, q_BS_true, faults, epoch, lanes=()):
    """The image-fidelity sensor of ``scenario['star_sensor']`` and its ``image`` table: camera,
    detector, navigation catalog (eq. 1-8 of 000, at ``epoch`` [Julian year]) and identifier, the stars
    drawn into the frames; the run's kernels compiled ahead (``lanes``) once the scenario is checked."""
    sensor, image = scenario["star_sensor"], scenario["star_sensor"]["image"]
    fov = float(units.deg_to_rad(sensor["fov_deg"]))
    camera = Camera.from_fov(fov, image["width_px"], image["height_px"], circular_fov=image["field"] == "circular")
    if image["camera_file"] is not None:  # a calibrated camera (startrack solve --write-camera)
        camera = dataclasses.replace(Camera.from_file(image["camera_file"]), circular_fov=image["field"] == "circular")
    model = SensorModel(psf_sigma_px=image["psf_sigma_px"], exposure_s=image["exposure_s"],
                        zero_point_e_per_s=image["zero_point_e_per_s"], read_noise_e=image["read_noise_e"])
    params = NavigationCatalogParams(mag_limit=sensor["mag_limit"], fov=fov, n_d=image["catalog_nd"],
                                     max_delta=float(units.deg_to_rad(image["catalog_max_pointing_error_deg"])),
                                     epoch=epoch)
    stars = _rendered_stars(star_catalog, image)
    compile_ahead(lanes)  # the scenario checked: the identifier's kernels and the rest of the run's
    identifier = StarIdentifier(load_navigation_catalog(params, progress=False), camera,
                                centroid_sigma_px=image["centroid_sigma_px"], max_stars=image["max_identified_stars"])
    return ImageStarSensor(camera=camera, model=model, identifier=identifier, stars_I=np.asarray(stars.vectors),
                           stars_mag=np.asarray(stars.v_mag), stars_hip=np.asarray(stars.hip),
                           detection_sigmas=image["detection_sigmas"], window_half_px=image["tracking_window_px"],
                           stacking=image["dim_star_stacking"], start_tracking=image["start_tracking"], q_BS_true=q_BS_true, faults=faults)


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
