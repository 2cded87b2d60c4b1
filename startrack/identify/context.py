"""What every search strategy of one identifier shares: pair tables, field stars, limits.

Built once per :class:`~startrack.identify.identifier.StarIdentifier`: the guide catalog's pair table
(k-vector of 000 eq. 3-5) and, with the dense fall-back, the pairs of every field star; the
sub-catalogs' pairs (:class:`~startrack.identify.pairs.SubCatalogPairs`); the work arrays of the
search (one identifier per thread); the field stars and the verification gates as the tuple the
compiled kernels take.
"""

from __future__ import annotations

import numpy as np

from startrack.identify.pairs import PairTable, SubCatalogPairs
from startrack.identify.pattern_hash import NO_PATTERNS, pattern_arrays
from startrack.identify.verify import Verified


def _stars(vectors):
    """(read-only copy of the unit vectors (N, 3), work array (N,) int32 of -1): one type for every table."""
    vectors = np.array(vectors, dtype=float, order="C")
    vectors.flags.writeable = False
    return vectors, np.full(len(vectors), -1, np.int32)


class SearchContext:
    """Tables, work arrays and the verification tuple of one identifier.

    catalog: the navigation catalog; field: :class:`~startrack.identify.verify.FieldStars`;
    pattern_stars: the brightest centroids searched first (then twice as many); verify_gate: match
    radius r [rad] (passes at 3 r then r); threshold: largest accepted false-match probability; sigma:
    centroid noise [rad]; dense: also build the field stars' pair table and the pattern level of the
    look-ups (~0.3 s).
    """

    def __init__(self, catalog, field, pattern_stars: int, verify_gate: float, threshold: float, sigma: float,
                 dense: bool):
        self.catalog = catalog
        self.field = field
        self.widths = np.array([pattern_stars, 2 * pattern_stars], np.int64)
        self.tables = {"guide": PairTable.full_sky(catalog)}
        #: per table: (vectors (N, 3) of the stars it indexes, the search's work array (N,) of -1)
        self.stars = {"guide": _stars(catalog.guide_vectors)}
        self.sub_catalogs = SubCatalogPairs(catalog)
        #: the pattern look-ups before the pyramid search (with the dense table; :mod:`~startrack.identify.pattern_hash`)
        self.patterns = NO_PATTERNS
        if dense:
            self.tables["dense"] = PairTable.of_stars(field.vectors, catalog.params.theta_min, catalog.params.theta_max)
            self.stars["dense"] = _stars(field.vectors)
            self.patterns = pattern_arrays(field)
        pass_gates = np.array([3.0 * verify_gate, verify_gate])
        #: verify_near's ``field``: (vectors, zones, search radius [rad], camera parameters, pass gates [rad],
        #: f [px], field solid angle [sr], threshold, centroid noise [rad])
        self.field_arrays = (field.vectors, field.zones, float(field.search_radius), field.camera_params, pass_gates,
                             float(field.camera.focal_px), float(field.solid_angle), float(threshold), float(sigma))

    def with_first_gate(self, gate: float):
        """:attr:`field_arrays` with a first matching pass at ``gate`` [rad] before 3 r and r (tracking)."""
        field = self.field_arrays
        return (*field[:4], np.concatenate([[gate], field[4]]), *field[5:])

    @property
    def dense(self) -> bool:
        """Whether the field stars' pair table was built."""
        return "dense" in self.tables

    @staticmethod
    def verified(result):
        """A :class:`~startrack.identify.verify.Verified` from verify_near's tuple, or None."""
        ok, R_IS, obs_index, star_index, probability, n_predicted = result
        if not ok:
            return None
        return Verified(R_IS=R_IS, obs_index=obs_index, star_index=star_index, false_match_probability=probability,
                        n_predicted=int(n_predicted))
