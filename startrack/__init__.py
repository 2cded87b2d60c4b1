"""startrack: the star sensor, usable on its own -- its public API (the one import point; navsim uses nothing else).

Hipparcos and Gaia star catalogs, navigation catalog (guide stars, k-vector pairs, sub-catalogs and their
address index), camera and rendering, detection and the position fit at the Cramér-Rao bound, dim-star
stacking, attitude determination and the boresight solves, star identification (full-sky lost-in-space,
predicted sub-catalog, tracking; and the plate solver for images of an unknown camera), apparent star
directions (aberration). Knows nothing of vehicles or filters (never imports ``navsim``). Units: radians
inside; degrees only at the command line. The layers below (docs/design.md, tests/startrack/test_layering.py):
``base``, ``compiled``, ``geometry`` and ``photometry``, ``attitude`` and ``catalog``, ``camera``, ``image``,
``identify``, then the application (``commands``, ``cli``). Names are imported on first use (PEP 562). What is
exported here, and the namespaces below, is the API; a module's own helpers and constants carry a leading underscore.
"""

from startrack.base.lazy_exports import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    # the foundations the system shares: the error contract of both command lines, lazy exports, output
    # paths checked before work, the compiled layer
    "startrack.base.errors": ("ArgumentParser", "InputError", "interrupted", "run_command"),
    "startrack.base.lazy_exports": ("lazy_exports",),
    "startrack.base.output_paths": ("check_file", "probe_directory"),
    "startrack.compiled.numba_setup": ("njit",),
    "startrack.compiled.compile_ahead": ("compile_ahead",),
    # geometry
    "startrack.geometry.attitude_angles": ("matrix_from_radec_roll", "quaternion_from_radec_roll",
                                           "radec_roll_from_quaternion"),
    "startrack.geometry.sphere": ("angular_distance", "azimuthal_equidistant", "radec_to_vector", "tangent_basis",
                                  "vector_to_radec"),
    # light
    "startrack.photometry.bands": ("BANDS", "band"),
    "startrack.photometry.detectors": ("DETECTORS", "detector"),
    # attitude
    "startrack.attitude.solvers": ("SOLVERS", "AttitudeSolution", "AttitudeSolver", "MultiVector", "QMethod", "Quest",
                                   "SvdWahba", "ThreeStarOptimal", "Triad", "cramer_rao_covariance", "get_solver"),
    "startrack.attitude.boresight": ("BoresightSolution",),
    # catalogs
    "startrack.catalog.apparent_place": ("aberrate", "earth_barycentric_velocity", "unaberrate"),
    "startrack.catalog.field_selection": ("field_radius", "radec_prefilter", "radec_window"),
    "startrack.catalog.gaia": ("load_gaia_catalog",),
    "startrack.catalog.hipparcos": ("StarCatalog", "load_star_catalog"),
    "startrack.catalog.kvector": ("KVector",),
    "startrack.catalog.navigation": ("NavigationCatalog", "NavigationCatalogParams", "build_navigation_catalog",
                                     "load_navigation_catalog"),
    # the camera
    "startrack.camera.model": ("Camera",),
    "startrack.camera.file": ("read_camera_file", "write_camera_file"),
    # the image chain
    "startrack.image.background": ("Background", "estimate_background", "mesh_background"),
    "startrack.image.detection": ("Detections", "detect", "detect_windows"),
    "startrack.image.files": ("read_frame", "read_image", "write_image"),
    "startrack.image.psf_fit": ("PixelNoise", "StarFits", "concatenate_fits", "fit_stars", "neighbour_reach"),
    "startrack.image.render": ("RenderedFrame", "SensorModel", "Sources", "Windows", "cosmic_ray", "expected_charge",
                               "render", "render_star_field"),
    "startrack.image.trail_detection": ("detect_trailed", "detection_probability", "snr_map", "snr_threshold",
                                        "trail_vector"),
    "startrack.image.sensor_photometry": ("SensorPhotometry",),
    "startrack.image.stacking": ("DimStarCache", "StackedStar", "stack"),
    "startrack.image.synthetic": ("SyntheticFrame", "centroid_frame", "random_attitude"),
    # identification
    "startrack.identify": ("IdentificationResult", "PlateSolver", "Prior", "StarIdentifier"),
    "startrack.identify.prior_match": ("PriorMatch", "PriorMatches", "Tracks"),
}, modules={
    # namespaces: the rotation convention (numpy, and its compiled twin), units, the address index of 000,
    # the boresight solves of 001
    "rotation": "startrack.geometry.rotation",
    "rotation_kernels": "startrack.geometry.rotation_kernels",
    "units": "startrack.base.units",
    "address": "startrack.catalog.address",
    "boresight": "startrack.attitude.boresight",
})
