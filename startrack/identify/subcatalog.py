"""Recognition in the predicted sub-catalog and its 4 redundant neighbours (§4 of document 000).

When tracking fails, the attitude predicted from the last fix (or the navigation filter) still gives
the boresight (alpha, delta) to within some error.  The sub-catalog at its eq. 7-8 address holds
every guide star within rho_sub = ceil(s_max)/2 + max(delta) + theta_FOV/2 of its base point and the
pattern pairs among them (000 §2.3), so the same pattern matcher as the full-sky search runs on a
few hundred pairs instead of tens of thousands.  If it finds nothing, the four redundant
sub-catalogs at the boresights moved by rho_sub east, west, north and south are searched in turn
(:meth:`startrack.navigation_catalog.NavigationCatalog.redundant_neighbours`); 000 states that this
tolerates a boresight error up to delta + (sqrt 2 - 1) rho_sub (6.97 deg for 000 §5).  As the full-sky
search does, a frame whose brightest stars hold too few guide stars is searched again over the pairs
of every field star, restricted to the region those sub-catalogs cover (within 2 rho_sub of the
predicted boresight).  The caller (:class:`startrack.identify.StarIdentifier`) falls back to the full
sky when this fails too.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from startrack.identify.lost_in_space import PairTable, PatternMatcher


class SubCatalog:
    """Pattern matching restricted to the predicted sub-catalog (and, with ``neighbours``, its 4 redundant ones)."""

    name = "subcatalog"

    def __init__(self, catalog, matcher: PatternMatcher, neighbours: bool = True, dense=None):
        self.catalog = catalog
        self.matcher = matcher
        self.neighbours = bool(neighbours)
        self.dense = dense
        self._tables = functools.lru_cache(maxsize=64)(self._table)
        self._regional = functools.lru_cache(maxsize=16)(self._regional_table)
        if dense is not None:  # CSR index of the dense table's pairs by their first star: start (N+1,), order
            order = np.argsort(dense[1].first, kind="stable")
            self._dense_pairs_by_star = (np.searchsorted(dense[1].first[order], np.arange(len(dense[0].guide_vectors) + 1)),
                                         order)

    def _regional_table(self, b: int) -> PairTable:
        """Field-star pairs with both stars within 2 rho_sub of base point ``b`` (cached per cell), gathered
        through the pairs of the near stars rather than by a pass over every pair of the sky."""
        matcher, table = self.dense
        centre = self.catalog.base_vectors[b]
        near = matcher.guide_vectors @ centre >= math.cos(min(2.0 * self.catalog.rho_sub, math.pi))
        stars = np.flatnonzero(near)
        start, order = self._dense_pairs_by_star
        lengths = start[stars + 1] - start[stars]
        offsets = np.repeat(start[stars] - np.cumsum(lengths) + lengths, lengths) + np.arange(lengths.sum())
        index = np.sort(order[offsets])                   # ascending pair index: sorted by distance
        index = index[near[table.second[index]]]
        return PairTable(table.theta[index], table.first[index], table.second[index], np.zeros(0, np.int64))

    def _table(self, b: int) -> PairTable:
        """The pair table of sub-catalog ``b`` (cached: consecutive frames reuse the same few)."""
        return PairTable.subset(self.catalog, self.catalog.sub_catalog_pairs(b))

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
        """Verified hypothesis or None; needs ``prior.boresight_radec()``."""
        boresight = prior.boresight_radec() if prior is not None else None
        if boresight is None:
            return None
        ra, dec = boresight
        if not (math.isfinite(ra) and math.isfinite(dec)):
            return None
        for b in self.cells(ra, dec):
            table = self._tables(b)
            verified, exhausted = self.matcher.match_fast(frame, table)
            if verified is None:
                verified = self.matcher.match(frame, table, widths=(2,) if exhausted else (1, 2))
            if verified is not None:
                return verified
        if self.dense is not None:
            dense_matcher = self.dense[0]
            table = self._regional(int(self.catalog.sub_catalog_index(ra, dec)))
            for width in (1, 2):
                verified = dense_matcher.match(frame, table, (width,))
                if verified is not None:
                    return verified
        return None
