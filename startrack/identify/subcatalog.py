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
(:meth:`startrack.catalog.navigation.NavigationCatalog.redundant_neighbours`); 000 states that this
tolerates a boresight error up to delta + (sqrt 2 - 1) rho_sub (6.97 deg for 000 §5).

With the dense table (every field star's pairs, ``dense_fallback``, the default) the frame's pattern
look-ups (:mod:`startrack.identify.pattern_hash`, restricted to the field stars within 2 rho_sub of the
predicted boresight) come first, in the same compiled call as the predicted sub-catalog's search; if
both fail, the search goes on over every field star within 2 rho_sub of the predicted boresight: it
holds every star of the four redundant sub-catalogs (their base points lie rho_sub from the boresight,
their stars within rho_sub of those) and also the stars the uniform guide selection of 000 §2.1 left
out, so it identifies every frame they would and the frames whose brightest stars hold too few guide
stars (about half of the rendered frames of 000 §5 with at most 7 stars); searching the neighbours
first would only cost time.  Its candidate pairs come from the k-vector ranges of the observed gates,
restricted to the region, and its N_h includes the look-ups'; the caller
(:class:`startrack.identify.StarIdentifier`) falls back to the full sky when this fails too.
"""

from __future__ import annotations

from startrack.identify.lost_in_space import search_tables
from startrack.identify.pattern_hash import NO_PATTERNS
from startrack.identify.zones import SKY, cap


class SubCatalog:
    """Pattern search restricted to the predicted sub-catalog, then the field stars of its region (with the
    dense table, after the pattern look-ups) or (``neighbours``) its 4 redundant sub-catalogs."""

    name = "subcatalog"

    def __init__(self, context, neighbours: bool = True):
        self.context = context
        self.catalog = context.catalog
        self.neighbours = bool(neighbours)
        self._dense = None
        if context.dense:
            self._dense = (context.tables["dense"].arrays,), (context.stars["dense"],)
        #: ``patterns`` of the region's search after the look-ups: none again, their N_h counted
        self._looked_up = (*NO_PATTERNS[:7], context.patterns[7])

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
        guide = (ctx.stars["guide"],)
        if self._dense is None:
            for b in self.cells(*prior.boresight_radec()):
                result = search_tables(frame.arrays, ctx.widths, (ctx.sub_catalogs.arrays(b),), guide, SKY,
                                       ctx.field_arrays, NO_PATTERNS)
                if result[0]:
                    return ctx.verified(result)
            return None
        region = cap(prior.boresight_vector(), 2.0 * self.catalog.rho_sub)
        b = int(self.catalog.sub_catalog_index(*prior.boresight_radec()))
        result = search_tables(frame.arrays, ctx.widths, (ctx.sub_catalogs.arrays(b),), guide, region,
                               ctx.field_arrays, ctx.patterns)
        if result[0]:
            return ctx.verified(result)
        tables, stars = self._dense
        return ctx.verified(search_tables(frame.arrays, ctx.widths, tables, stars, region, ctx.field_arrays,
                                          self._looked_up))
