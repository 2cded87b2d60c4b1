"""startrack: the star sensor, usable on its own.

Hipparcos star catalog, navigation catalog (guide stars, k-vector pairs, sub-catalogs and their
address index), camera and rendering, detection and centroiding, dim-star stacking, attitude
determination and the boresight solves, star identification (full-sky lost-in-space, predicted
sub-catalog, tracking). Knows nothing of vehicles or filters (never imports
``navsim``). Units: radians inside; degrees only at the command line.
"""

from startrack.attitude import SOLVERS, AttitudeSolution, cramer_rao_covariance, get_solver
from startrack.attitude_angles import quaternion_from_radec_roll, radec_roll_from_quaternion
from startrack.boresight import BoresightSolution
from startrack.camera import Camera
from startrack.detection import Detections, detect, detect_windows, estimate_background
from startrack.errors import InputError
from startrack.fov_select import field_radius, radec_prefilter
from startrack.identify import IdentificationResult, Prior, StarIdentifier
from startrack.image_io import read_image, write_image
from startrack.kvector import KVector
from startrack.navigation_catalog import (
    NavigationCatalog,
    NavigationCatalogParams,
    build_navigation_catalog,
    load_navigation_catalog,
)
from startrack.render import SensorModel, Sources, Windows, expected_charge, render, render_star_field
from startrack.sphere import angular_distance, radec_to_vector, vector_to_radec
from startrack.stacking import DimStarCache, stack
from startrack.star_catalog import StarCatalog, load_star_catalog

__all__ = [
    "SOLVERS",
    "AttitudeSolution",
    "BoresightSolution",
    "Camera",
    "Detections",
    "IdentificationResult",
    "DimStarCache",
    "InputError",
    "KVector",
    "NavigationCatalog",
    "NavigationCatalogParams",
    "Prior",
    "SensorModel",
    "Sources",
    "StarCatalog",
    "StarIdentifier",
    "Windows",
    "angular_distance",
    "build_navigation_catalog",
    "cramer_rao_covariance",
    "detect",
    "detect_windows",
    "estimate_background",
    "expected_charge",
    "field_radius",
    "get_solver",
    "load_navigation_catalog",
    "load_star_catalog",
    "quaternion_from_radec_roll",
    "radec_prefilter",
    "radec_roll_from_quaternion",
    "radec_to_vector",
    "read_image",
    "render",
    "render_star_field",
    "stack",
    "vector_to_radec",
    "write_image",
]
