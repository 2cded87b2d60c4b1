"""Full-sky lost-in-space identification (001 ch. 4): pattern look-ups, then the pyramid over every catalog pair.

The guide catalog of 000 §2.1 keeps about half of the stars to the magnitude limit (one star per base
point), so among a frame's brightest centroids roughly every other one is a guide star, and the first
triangle of guide stars comes after ~20 observed triangles (median, 16 deg frames); the pairs of every
field star (the dense table: every star the sensor can show) hold them all, and the first triangle of
the brightest stars usually is one.  The full-sky search therefore runs over the dense table when the
identifier has it (a superset of the guide pairs: searching the guide table first only costs time;
measured 0.11 vs 0.07 ms median on the benchmark frames), else over the guide catalog's pairs.  One
compiled call (:func:`search_tables`) first looks the brightest centroids' four-star patterns up
(:mod:`startrack.identify.pattern_hash`, with the dense table: 0.035 against 0.053 ms median on the
benchmark's main frames), then searches the brightest ``pattern_stars`` centroids and then twice
as many (:func:`startrack.identify.pyramid.search`: pyramids verified as found, then the triangles no
fourth star extended) and returns the first verified hypothesis.
"""

from __future__ import annotations

import numpy as np

from startrack.compiled.numba_setup import njit
from startrack.identify.features import fill_features
from startrack.identify.pattern_hash import hash_search
from startrack.identify.pyramid import TRIANGLE_BUFFER, gate_cosines, no_result, search, verify_triangles
from startrack.identify.zones import SKY


@njit
def search_tables(frame, widths, tables, stars, region, field, patterns):  # pragma: no cover  (compiled)
    """The pattern look-ups (:func:`startrack.identify.pattern_hash.hash_search`), then for each width n of
    ``widths`` (ascending), each table in turn (:func:`startrack.identify.pyramid.search`, then its
    unextended triangles); the first verified hypothesis (verify_near's tuple).  ``frame``:
    :attr:`~startrack.identify.features.FrameFeatures.arrays` (features filled here as needed);
    ``stars``: per table, (vectors (N, 3) of the stars it indexes, work array (N,) int32 of -1);
    ``patterns``: :func:`~startrack.identify.pattern_hash.pattern_arrays` (or ``NO_PATTERNS``)."""
    obs, beta, gate, filled, focal_px, delta_px = frame
    result = hash_search(obs, beta, gate, filled, focal_px, delta_px, patterns, region, field)
    if result[0]:
        return result
    n_h_before = patterns[7]
    cos_low, cos_high = gate_cosines(beta)
    triangles = np.empty((TRIANGLE_BUFFER, 6), np.int64)
    done = 0
    for w in range(widths.size):
        n = min(widths[w], beta.shape[0])
        if n <= done:
            continue
        done = n
        fill_features(obs, n, focal_px, delta_px, beta, gate, filled)
        for t in range(len(tables)):
            vectors, head = stars[t]
            result, n_h, kept = search(obs, n, beta, gate, cos_low, cos_high, tables[t], vectors, region, field, head,
                                       triangles, n_h_before)
            if result[0]:
                return result
            result = verify_triangles(obs, triangles, kept, vectors, field, n_h)
            if result[0]:
                return result
    return no_result()


class LostInSpace:
    """Full-sky identification over every field star's pairs (``dense``), or the guide catalog's.

    ``context``: the identifier's :class:`~startrack.identify.context.SearchContext`.
    """

    name = "lost_in_space"

    def __init__(self, context, dense: bool = True):
        self.context = context
        names = ("dense",) if dense else ("guide",)
        self.tables = tuple(context.tables[name].arrays for name in names)
        self.stars = tuple(context.stars[name] for name in names)

    def identify(self, frame, prior):
        """Verified hypothesis or None; ``prior`` is not used."""
        ctx = self.context
        return ctx.verified(search_tables(frame.arrays, ctx.widths, self.tables, self.stars,
                                          SKY, ctx.field_arrays, ctx.patterns))

