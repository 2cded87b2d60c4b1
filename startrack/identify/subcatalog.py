"""Recognition in the predicted sub-catalog and its 4 redundant neighbours (§4 of document 000).

When tracking fails, the attitude predicted from the last fix (or the navigation filter) still gives
the boresight (alpha, delta) to within some error.  The sub-catalog at its eq. 7-8 address holds
every guide star within rho_sub = ceil(s_max)/2 + max(delta) + theta_FOV/2 of its base point and the
pattern pairs among them (000 §2.3): a few hundred pairs instead of the full sky's tens of thousands.
The compiled search (:func:`~startrack.identify.lost_in_space.search_tables`) is the full sky's pyramid search
(:mod:`startrack.identify.pyramid`) over the sub-catalog's own pairs, stored contiguously
(:class:`~startrack.identify.pairs.SubCatalogPairs`, a few kilobytes): every star of a hypothesis
lies in the sub-catalog.

If the predicted sub-catalog gives nothing, the four redundant sub-catalogs at the boresights moved by
rho_sub east, west, north and south are searched in turn
(:meth:`startrack.navigation_catalog.NavigationCatalog.redundant_neighbours`); 000 states that this
tolerates a boresight error up to delta + (sqrt 2 - 1) rho_sub (6.97 deg for 000 §5).

With the dense table (every field star's pairs, ``dense_fallback``) the search is instead the one over
every field star within 2 rho_sub of the predicted boresight: it holds every star of the predicted
sub-catalog and of its four redundant neighbours (their base points lie rho_sub from the boresight,
their stars within rho_sub of those) and also the stars the uniform guide selection of 000 §2.1 left
out, so it identifies every frame they would and the frames whose brightest stars hold too few guide
stars (about half of the rendered frames of 000 §5 with at most 7 stars); searching the guide
sub-catalogs first would only cost time (their pyramid walks ~70 observed triangles before one of guide
stars on the benchmark frames, against ~2 in the dense table).  The search is the full sky's
(:func:`~startrack.identify.lost_in_space.search_tables`: pattern look-ups, then pyramids) with every
star of a hypothesis inside the region; the caller (:class:`startrack.identify.StarIdentifier`) falls
back to the full sky when it fails.
"""

from __future__ import annotations

from startrack.identify.lost_in_space import search_tables
from startrack.identify.pattern_hash import NO_PATTERNS
from startrack.identify.zones import SKY, cap


class SubCatalog:
    """Pattern search restricted to the field stars of the predicted boresight's region (with the dense
    table), or to the predicted sub-catalog and then (``neighbours``) its 4 redundant sub-catalogs."""

    name = "subcatalog"

    def __init__(self, context, neighbours: bool = True):
        self.context = context
        self.catalog = context.catalog
        self.neighbours = bool(neighbours)
        self._dense = None
        if context.dense:
            self._dense = (context.tables["dense"].arrays,), (context.stars["dense"],)

    def cells(self, ra: float, dec: float):
        """Sub-catalog indices to search for a predicted boresight (ra, dec) [rad], predicted one first; the
        neighbours' addresses are only computed if the predicted sub-catalog fails (a generator)."""
        first = int(self.catalog.sub_catalog_index(ra, dec))
        yield first
        if self.neighbours:
            seen = {first}
            for b in self.catalog.redundant_neighbours(ra, dec).tolist():
                if b not in seen:
                    seen.add(b)
                    yield int(b)

    def identify(self, frame, prior):
        """Verified hypothesis or None; needs a predicted boresight (``prior.q_IS`` or ``prior.boresight``)."""
        if prior is None or (prior.q_IS is None and prior.boresight is None):
            return None
        ctx = self.context
        if self._dense is not None:
            tables, stars = self._dense
            region = cap(prior.boresight_vector(), 2.0 * self.catalog.rho_sub)
            return ctx.verified(search_tables(frame.arrays, ctx.widths, tables, stars, region,
                                              ctx.field_arrays, ctx.patterns))
        for b in self.cells(*prior.boresight_radec()):
            result = search_tables(frame.arrays, ctx.widths, (ctx.sub_catalogs.arrays(b),),
                                   (ctx.stars["guide"],), SKY, ctx.field_arrays, NO_PATTERNS)
            if result[0]:
                return ctx.verified(result)
        return None
