"""startrack: the star sensor, usable on its own.

Hipparcos star catalog, navigation catalog (guide stars, k-vector pairs, sub-catalogs and their
address index), camera and rendering, detection and centroiding, dim-star stacking, attitude
determination and the boresight solves, star identification (full-sky lost-in-space, predicted
sub-catalog, tracking; and the plate solver for images of an unknown camera), apparent star directions
(aberration). Knows nothing of vehicles or filters (never imports
``navsim``). Units: radians inside; degrees only at the command line.
"""

from startrack.lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "startrack.aberration": ("aberrate", "earth_barycentric_velocity", "unaberrate"),
    "startrack.attitude": ("SOLVERS", "AttitudeSolution", "cramer_rao_covariance", "get_solver"),
    "startrack.attitude_angles": ("quaternion_from_radec_roll", "radec_roll_from_quaternion"),
    "startrack.boresight": ("BoresightSolution",),
    "startrack.background": ("Background", "estimate_background", "mesh_background"),
    "startrack.camera": ("Camera",),
    "startrack.camera_file": ("read_camera_file", "write_camera_file"),
    "startrack.detection": ("Detections", "detect", "detect_windows"),
    "startrack.errors": ("InputError",),
    "startrack.fov_select": ("field_radius", "radec_prefilter"),
    "startrack.gaia_catalog": ("load_gaia_catalog",),
    "startrack.identify": ("IdentificationResult", "PlateSolver", "Prior", "StarIdentifier"),
    "startrack.image_io": ("read_frame", "read_image", "write_image"),
    "startrack.kvector": ("KVector",),
    "startrack.navigation_catalog": ("NavigationCatalog", "NavigationCatalogParams", "build_navigation_catalog",
                                     "load_navigation_catalog"),
    "startrack.render": ("SensorModel", "Sources", "Windows", "expected_charge", "render", "render_star_field"),
    "startrack.sphere": ("angular_distance", "radec_to_vector", "vector_to_radec"),
    "startrack.stacking": ("DimStarCache", "stack"),
    "startrack.star_catalog": ("StarCatalog", "load_star_catalog"),
})
