"""startrack: the star sensor, usable on its own.

Hipparcos star catalog, navigation catalog (guide stars, k-vector pairs,
sub-catalogs and their address index), camera and rendering, detection and
centroiding, dim-star stacking, star identification and attitude determination.
Knows nothing of vehicles or filters (it never imports ``navsim``).
"""

from startrack.errors import InputError
from startrack.sphere import angular_distance, radec_to_vector, vector_to_radec

__all__ = ["InputError", "angular_distance", "radec_to_vector", "vector_to_radec"]
