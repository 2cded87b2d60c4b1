"""Star-pattern search: triangles and four-star groups on the pair table (001 ch. 4, pyramid-style).

For the brightest centroids of a frame (brightest first):

1. every observed pair (a, b) gives an interval [beta_ab - e_ab, beta_ab + e_ab] (e_ab the gate of
   001 §4.3.1, :mod:`startrack.identify.features`); the pair table returns the catalog pairs inside it
   (the k-vector of 000 eq. 3-5 for the full sky, a binary search in a sub-catalog);
2. triangles (001 §4.4.2): catalog pairs matched to the observed pairs (i, j) and (i, k) that share
   the catalog star A of i form a candidate triangle (A, B, C); it is kept when the distance (B, C)
   (from the catalog vectors, so it may exceed the table's theta_max, e.g. across the diagonal of a
   square field) lies within the gate of (j, k) and the triangle has the handedness of the observed
   one (a mirror image is not a rotation);
3. higher-order star groups (001 §4.4.3; the fourth star of the pyramid algorithm): a triangle is
   extended by any other centroid r with a catalog star D matched to (i, r) whose distances to B and
   C also lie within the gates of (j, r) and (k, r): the four-star group ijkr, all six distances
   consistent.  Stars outside every group (false stars, stars missing from the guide catalog) never
   enter a hypothesis; missing stars only remove triangles, they cannot create a wrong one.

The search (a compiled kernel; the per-frame hot loop) runs anchor by anchor, brightest first (then j,
then k), and stops after a few groups per anchor, which are verified before the next anchor is
searched: a false star or a star missing from the guide catalog as anchor costs one short pass.  The
groups of an anchor are ordered by the sum of their brightness ranks and, among equals, best
conditioned first (smallest sum of the six gates, which grow for short and badly measured pairs);
triangles are verified only when no group was accepted.  The common case -- the first groups of the
brightest stars, verified -- runs as one compiled call (:meth:`PatternMatcher.match_fast`).

The guide catalog holds about half of the stars to the magnitude limit (000 §2.1 keeps one star per
base point), so a frame may show fewer than 3 guide stars among its brightest centroids; the full-sky
search then continues over the pairs of every field star (:class:`LostInSpace`, ``dense``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from startrack.identify.verify import Verified, verify, verify_near, wahba_svd
from startrack.jit import njit
from startrack.kvector import KVector
from startrack.navigation_catalog import pattern_pairs


@dataclass(frozen=True, eq=False)
class PairTable:
    """Catalog star pairs sorted by angular distance: ``theta`` [rad], guide-star indices ``first``, ``second``.

    With a k-vector (``k`` int64, ``slope`` m and ``intercept`` q of eq. 3-4 of 000; the full table)
    a distance interval is found by eq. 5; without one (``k`` empty: the sub-catalog tables, a few
    hundred pairs) by a binary search.
    """

    theta: np.ndarray
    first: np.ndarray
    second: np.ndarray
    k: np.ndarray
    slope: float = 1.0
    intercept: float = 0.0

    def __post_init__(self):
        for name in ("theta", "first", "second"):  # one array type for every table: one compiled kernel
            array = np.ascontiguousarray(getattr(self, name))
            array.flags.writeable = False
            object.__setattr__(self, name, array)

    @classmethod
    def full_sky(cls, catalog) -> "PairTable":
        """Every pattern pair of the navigation catalog, searched with its k-vector."""
        kv = catalog.kvector
        return cls(catalog.pair_theta, catalog.pair_i, catalog.pair_j, kv.k.astype(np.int64), float(kv.slope),
                   float(kv.intercept))

    @classmethod
    def of_stars(cls, vectors, theta_min: float, theta_max: float) -> "PairTable":
        """Every pair of the unit vectors (N, 3) with distance in [theta_min, theta_max] [rad] (000 §2.2),
        with its own k-vector (eq. 3-4)."""
        theta, first, second = pattern_pairs(vectors, theta_min, theta_max)
        kv = KVector.build(theta, theta_min, theta_max)
        return cls(theta, first, second, kv.k.astype(np.int64), float(kv.slope), float(kv.intercept))

    @classmethod
    def subset(cls, catalog, pair_index) -> "PairTable":
        """The pattern pairs ``pair_index`` (ascending, hence sorted by distance), e.g. a sub-catalog's."""
        return cls(catalog.pair_theta[pair_index], catalog.pair_i[pair_index], catalog.pair_j[pair_index],
                   np.zeros(0, np.int64))


@njit
def _pair_range(theta, k, slope, intercept, low, high):
    """[lo, hi) indices of the pairs with theta in [low, high]; k-vector superset, or exact without one.

    With the k-vector: eq. 5 of 000 widened by one bucket each side, k(j_start) .. k(j_end)
    (Mortari); the caller tests theta of each pair, which trims the few just outside.
    """
    n = k.size
    if n == 0:
        return np.searchsorted(theta, low), np.searchsorted(theta, high, side="right")
    start = min(max(np.floor((low - intercept) / slope) - 1.0, 1.0), float(n))
    stop = min(max(np.ceil((high - intercept) / slope) + 1.0, 1.0), float(n))
    return k[int(start) - 1], k[int(stop) - 1]


@dataclass(frozen=True)
class Hypotheses:
    """Star-group hypotheses in search order: observed indices (h, s) and guide-star indices (h, s).

    ``groups`` have s = 4 stars, ``triangles`` s = 3; ``n_pair_matches`` is the number of oriented
    catalog pairs that matched an observed pair within its gate (N_h of :mod:`startrack.identify.verify`).
    """

    groups_obs: np.ndarray
    groups_cat: np.ndarray
    triangles_obs: np.ndarray
    triangles_cat: np.ndarray
    n_pair_matches: int


@njit
def _inside(guide, x, y, cos_low, cos_high):
    """cos_low <= guide[x] . guide[y] <= cos_high (the angle lies inside its gate)."""
    c = guide[x, 0] * guide[y, 0] + guide[x, 1] * guide[y, 1] + guide[x, 2] * guide[y, 2]
    return cos_low <= c <= cos_high


@njit
def _triple(p, q, r):
    """p . (q x r) of three 3-vectors."""
    return (p[0] * (q[1] * r[2] - q[2] * r[1]) + p[1] * (q[2] * r[0] - q[0] * r[2])
            + p[2] * (q[0] * r[1] - q[1] * r[0]))


@njit
def _pair_candidates(beta, gate, theta, k, slope, intercept):  # pragma: no cover  (compiled)
    """Candidate ranges (lo, hi) (n, n) of every observed pair s < t, the cosines of their gate ends
    (cos_low = cos(beta + e), cos_high = cos(max(beta - e, 0))) and N_h (oriented in-gate matches)."""
    n = beta.shape[0]
    lo = np.zeros((n, n), np.int64)
    hi = np.zeros((n, n), np.int64)
    cos_low = np.zeros((n, n))
    cos_high = np.zeros((n, n))
    n_matches = 0
    for s in range(n):
        for t in range(s + 1, n):
            low, high = beta[s, t] - gate[s, t], beta[s, t] + gate[s, t]
            lo[s, t], hi[s, t] = _pair_range(theta, k, slope, intercept, low, high)
            cos_high[s, t] = np.cos(max(low, 0.0))
            cos_low[s, t] = np.cos(min(high, np.pi))
            cos_high[t, s], cos_low[t, s] = cos_high[s, t], cos_low[s, t]
            for q in range(lo[s, t], hi[s, t]):
                if low <= theta[q] <= high:
                    n_matches += 1
    return lo, hi, cos_low, cos_high, 2 * n_matches


@njit
def _group_search(obs, beta, gate, lo, hi, cos_low, cos_high, theta, first, second, guide, anchor_start,
                  anchor_stop, max_groups, max_triangles, head, partners):  # pragma: no cover  (compiled)
    """Triangles and four-star groups (module text) with anchors i in [anchor_start, anchor_stop).

    Returns (groups (g, 8), triangles (t, 6)).  For each anchor star i (brightest first; the smallest
    index of its groups) the catalog pairs matched to every observed pair (i, t > i) (candidate
    ranges ``lo``, ``hi``) are chained per
    (t, catalog star of i) in linked lists (with a bit mask per catalog star of the partners t whose
    list is not empty; at most 63 stars), so that a triangle (i, j, k) is found by following, for
    each catalog assignment (A, B) of (i, j), the list of (k, A) and testing the distance (B, C)
    against the gate of (j, k) and the handedness; each triangle is extended to a group by the lists
    of every other star r.  Stops after ``max_groups`` groups.  ``head`` (n_guide, >= n) int32 is a
    work array of -1 (the list heads, catalog-star major so that the lists of one catalog star share a
    cache line) and ``partners`` (n_guide,) int64 one of zeros, both returned as found.
    """
    n = obs.shape[0]
    low = beta - gate
    high = beta + gate
    capacity = 1  # list entries of one anchor: both orientations of its candidate pairs
    for i in range(anchor_start, anchor_stop):
        count = 0
        for t in range(i + 1, n):
            count += 2 * (hi[i, t] - lo[i, t])
        capacity = max(capacity, count + 1)
    groups = np.empty((max_groups, 8), np.int64)
    triangles = np.empty((max_triangles, 6), np.int64)
    n_groups = 0
    n_triangles = 0
    # partners[A]: bit t set when the list (A, t) is not empty
    entry_other = np.empty(capacity, np.int32)
    entry_next = np.empty(capacity, np.int32)
    entry_partner = np.empty(capacity, np.int32)
    entry_anchor = np.empty(capacity, np.int32)
    for i in range(anchor_start, anchor_stop):
        m = 0
        for t in range(i + 1, n):  # the anchor is the brightest (smallest index) star of its groups
            for q in range(lo[i, t], hi[i, t]):
                if not low[i, t] <= theta[q] <= high[i, t]:
                    continue
                for orientation in range(2):
                    a_cat = first[q] if orientation == 0 else second[q]
                    entry_other[m] = second[q] if orientation == 0 else first[q]
                    entry_next[m] = head[a_cat, t]
                    entry_partner[m] = t
                    entry_anchor[m] = a_cat
                    head[a_cat, t] = m
                    partners[a_cat] |= np.int64(1) << t
                    m += 1
        done = False
        for j in range(i + 1, n):
            for q in range(lo[i, j], hi[i, j]):
                if done or not low[i, j] <= theta[q] <= high[i, j]:
                    continue
                for orientation in range(2):
                    if done:
                        break
                    a_cat = first[q] if orientation == 0 else second[q]
                    b_cat = second[q] if orientation == 0 else first[q]
                    later = partners[a_cat] >> (j + 1)
                    k = j
                    while later != 0 and not done:
                        k += 1
                        present = later & 1
                        later >>= 1
                        if present == 0:
                            continue
                        e = head[a_cat, k]
                        while e >= 0 and not done:
                            c_cat = entry_other[e]
                            e = entry_next[e]
                            if c_cat == b_cat or not _inside(guide, b_cat, c_cat, cos_low[j, k], cos_high[j, k]):
                                continue
                            if _triple(obs[i], obs[j], obs[k]) * _triple(guide[a_cat], guide[b_cat], guide[c_cat]) <= 0.0:
                                continue
                            if n_triangles < max_triangles:
                                triangles[n_triangles, 0] = i
                                triangles[n_triangles, 1] = j
                                triangles[n_triangles, 2] = k
                                triangles[n_triangles, 3] = a_cat
                                triangles[n_triangles, 4] = b_cat
                                triangles[n_triangles, 5] = c_cat
                                n_triangles += 1
                            for r in range(i + 1, n):
                                if r == j or r == k or done or (partners[a_cat] >> r) & 1 == 0:
                                    continue
                                jr0, jr1 = min(j, r), max(j, r)
                                kr0, kr1 = min(k, r), max(k, r)
                                f = head[a_cat, r]
                                while f >= 0:
                                    d_cat = entry_other[f]
                                    f = entry_next[f]
                                    if d_cat == b_cat or d_cat == c_cat:
                                        continue
                                    if not _inside(guide, b_cat, d_cat, cos_low[jr0, jr1], cos_high[jr0, jr1]):
                                        continue
                                    if not _inside(guide, c_cat, d_cat, cos_low[kr0, kr1], cos_high[kr0, kr1]):
                                        continue
                                    groups[n_groups, 0] = i
                                    groups[n_groups, 1] = j
                                    groups[n_groups, 2] = k
                                    groups[n_groups, 3] = r
                                    groups[n_groups, 4] = a_cat
                                    groups[n_groups, 5] = b_cat
                                    groups[n_groups, 6] = c_cat
                                    groups[n_groups, 7] = d_cat
                                    n_groups += 1
                                    if n_groups == max_groups:
                                        done = True
                                    break
        for e in range(m):
            head[entry_anchor[e], entry_partner[e]] = -1
            partners[entry_anchor[e]] = 0
        if done:
            break
    return groups[:n_groups], triangles[:n_triangles]


@njit
def _fast_lost_in_space(obs_S, n, beta, gate, theta, first, second, k, slope, intercept, guide, max_groups, head,
                        partners, field_vectors, cos_field_radius, camera_params, pass_gates, focal_px, solid_angle,
                        threshold):  # pragma: no cover  (compiled)
    """The fast path of :meth:`PatternMatcher.match` in one compiled call: candidates, the first
    ``max_groups`` groups of the brightest ``n`` centroids over all anchors, each verified
    (:func:`startrack.identify.verify.verify_near`) in rank order until one is accepted.
    Returns (ok, R_IS, obs indices, field-star indices, P_false, stars predicted in the field, groups
    found)."""
    obs = obs_S[:n].copy()
    beta_n = beta[:n, :n].copy()
    gate_n = gate[:n, :n].copy()
    lo, hi, cos_low, cos_high, n_hypotheses = _pair_candidates(beta_n, gate_n, theta, k, slope, intercept)
    groups, _ = _group_search(obs, beta_n, gate_n, lo, hi, cos_low, cos_high, theta, first, second, guide, 0, n,
                              max_groups, 0, head, partners)
    rank = np.empty(groups.shape[0])
    for g in range(groups.shape[0]):  # rank sum, then (tie-break) the sum of the six gates, scaled below 1
        gates = 0.0
        for a in range(4):
            for b in range(a + 1, 4):
                gates += gate_n[groups[g, a], groups[g, b]]
        rank[g] = groups[g, 0] + groups[g, 1] + groups[g, 2] + groups[g, 3] + gates / (1.0 + gates)
    for g in np.argsort(rank):
        R_IS = wahba_svd(guide[groups[g, 4:]], obs[groups[g, :4]])
        ok, R_IS, obs_index, star_index, probability, n_predicted = verify_near(
            obs_S, field_vectors, R_IS, cos_field_radius, camera_params, pass_gates, focal_px, solid_angle,
            n_hypotheses, threshold, 2)
        if ok:
            return True, R_IS, obs_index, star_index, probability, n_predicted, groups.shape[0]
    empty = np.zeros(0, np.int64)
    return False, np.eye(3), empty, empty, 1.0, 0, groups.shape[0]


def new_workspace(n_guide: int, n_stars: int):
    """Work arrays of :func:`search` for up to ``n_stars`` stars: list heads (-1) and partner bit masks (0)."""
    if n_stars > 63:
        raise ValueError(f"the pattern search takes at most 63 stars, not {n_stars}")
    return np.full((n_guide, n_stars), -1, np.int32), np.zeros(n_guide, np.int64)


def pair_candidates(beta, gate, table: PairTable):
    """(lo, hi, cos_low, cos_high, N_h): catalog-pair ranges of every observed pair (s < t), the cosines
    of the gate ends, and the number of oriented catalog pairs inside the gates (k-vector of eq. 5 for
    the full sky, a binary search else)."""
    lo, hi, cos_low, cos_high, n_matches = _pair_candidates(
        np.ascontiguousarray(beta), np.ascontiguousarray(gate), table.theta, table.k, table.slope, table.intercept)
    return lo, hi, cos_low, cos_high, int(n_matches)


def search(obs_S, beta, gate, table: PairTable, guide_vectors, max_groups: int = 4, max_triangles: int = 8,
           workspace=None, anchors=None, candidates=None) -> Hypotheses:
    """Triangles and four-star groups of the centroid directions ``obs_S`` (n, 3), brightest first.

    ``beta`` (n, n) observed angular distances and ``gate`` (n, n) their bounds e_ij [rad];
    ``table`` the catalog pairs to search; ``guide_vectors`` (n_g, 3) the guide stars in I.  The
    search stops after ``max_groups`` four-star groups; up to ``max_triangles`` triangles found on the
    way are kept for frames without a group.  ``anchors`` (start, stop): the brightest star of the
    groups searched (default: all); ``candidates``: :func:`pair_candidates` if already computed;
    ``workspace``: (:func:`new_workspace`) reused between calls (left as found).
    """
    n = len(obs_S)
    if workspace is None or workspace[0].shape[1] < n:
        workspace = new_workspace(len(guide_vectors), n)
    beta, gate = np.ascontiguousarray(beta), np.ascontiguousarray(gate)
    lo, hi, cos_low, cos_high, n_matches = pair_candidates(beta, gate, table) if candidates is None else candidates
    start, stop = (0, n) if anchors is None else anchors
    groups, triangles = _group_search(np.ascontiguousarray(obs_S), beta, gate, lo, hi, cos_low, cos_high,
                                      table.theta, table.first, table.second, guide_vectors, start, stop, max_groups,
                                      max_triangles, *workspace)
    groups = groups[_ranked(groups[:, :4], gate)]
    triangles = triangles[_ranked(triangles[:, :3], gate)]
    return Hypotheses(groups[:, :4], groups[:, 4:], triangles[:, :3], triangles[:, 3:], n_matches)


def _ranked(stars, gate):
    """Order of star groups (rows of observed indices): smallest rank sum, then smallest sum of gates."""
    if len(stars) < 2:
        return np.arange(len(stars))
    a, b = _PAIRS_OF[stars.shape[1]]
    gate_sum = gate[stars[:, a], stars[:, b]].sum(axis=1)
    return np.lexsort((gate_sum, stars.sum(axis=1)))


#: Index pairs (a, b) of the pairs of a triangle and of a four-star group.
_PAIRS_OF = {3: np.triu_indices(3, 1), 4: np.triu_indices(4, 1)}


class PatternMatcher:
    """Hypotheses from :func:`search` on a pair table, each verified until one is accepted.

    ``star_vectors`` (N, 3): the stars the pair tables index (the guide stars of the navigation
    catalog, or the field stars for the dense fall-back).  The brightest ``pattern_stars`` centroids
    are searched first, anchor by anchor; if no hypothesis is accepted the search is widened
    (:meth:`match`).  Holds a work array: one matcher per thread.
    """

    def __init__(self, star_vectors, field, pattern_stars: int, max_groups: int, max_triangles: int,
                 threshold: float):
        self.guide_vectors = np.array(star_vectors, dtype=float, order="C")
        self.guide_vectors.flags.writeable = False  # one array type for every matcher: one compiled kernel
        self.field = field
        self.pattern_stars = pattern_stars
        self.max_groups = max_groups
        self.max_triangles = max_triangles
        self.triangle_budget = 32 * max_triangles  # triangles kept by a full pass and verified at most
        self.threshold = threshold
        self._workspace = new_workspace(len(self.guide_vectors), 2 * pattern_stars)

    def match(self, frame, table: PairTable, widths=(1, 2), triangles=True):
        """A :class:`startrack.identify.verify.Verified` for ``frame`` (:class:`FrameFeatures`) or None.

        For each width w of ``widths`` in turn, the brightest w ``pattern_stars`` centroids: the first
        ``max_groups`` groups of a pass over all anchors are verified; if none is accepted and the pass
        stopped at that budget, anchor by anchor (brightest first) the groups of up to 4
        ``max_groups`` found with that anchor; then, with ``triangles``, the triangles collected on the
        way (the 32 ``max_triangles`` brightest verified).
        """
        tried = set()
        done = 0
        for width in widths:
            n = min(len(frame), width * self.pattern_stars)
            if n <= done:
                continue
            done = n
            verified = self._match_stars(frame, table, n, tried, triangles)
            if verified is not None:
                return verified
        return None

    def _match_stars(self, frame, table, n, tried, with_triangles):
        """:meth:`match` for the brightest ``n`` centroids."""
        obs, beta, gate = frame.obs_S[:n], frame.beta[:n, :n], frame.gate[:n, :n]
        candidates = pair_candidates(beta, gate, table)
        n_hypotheses = candidates[-1]
        # Fast path: the first groups over all anchors (one pass for most frames) ...
        budget = self.triangle_budget if with_triangles else 0
        found = search(obs, beta, gate, table, self.guide_vectors, self.max_groups, budget, self._workspace, None,
                       candidates)
        verified = self._first_verified(frame, zip(found.groups_obs, found.groups_cat), n_hypotheses, tried)
        if verified is not None:
            return verified
        triangles = list(zip(found.triangles_obs, found.triangles_cat))
        if len(found.groups_obs) < self.max_groups:
            anchors = ()  # the pass ran to its end: every group and (up to the budget) triangle is known
        else:  # ... then anchor by anchor, so that false groups of one anchor cannot hide the rest
            anchors = range(n - 2)
        for anchor in anchors:
            found = search(obs, beta, gate, table, self.guide_vectors, 4 * self.max_groups,
                           4 * self.max_triangles if with_triangles else 0, self._workspace, (anchor, anchor + 1),
                           candidates)
            triangles.extend(zip(found.triangles_obs, found.triangles_cat))
            verified = self._first_verified(frame, zip(found.groups_obs, found.groups_cat), n_hypotheses, tried)
            if verified is not None:
                return verified
        triangles.sort(key=lambda t: int(t[0].sum()))
        return self._first_verified(frame, triangles[: self.triangle_budget], n_hypotheses, tried)

    def match_fast(self, frame, table: PairTable):
        """The fast path of :meth:`match` (first groups of the brightest ``pattern_stars``, all anchors)
        in one compiled call: (a :class:`~startrack.identify.verify.Verified` or None, whether every
        group of those stars was tried)."""
        n = min(len(frame), self.pattern_stars)
        field = self.field
        ok, R_IS, obs_index, star_index, probability, n_predicted, n_groups = _fast_lost_in_space(
            frame.obs_S, n, frame.beta, frame.gate, table.theta, table.first, table.second, table.k, table.slope,
            table.intercept, self.guide_vectors, self.max_groups, *self._workspace, field.vectors,
            field.cos_field_radius, field.camera_params, np.array([3.0 * frame.verify_gate, frame.verify_gate]),
            field.camera.focal_px, field.solid_angle, self.threshold)
        if not ok:
            return None, n_groups < self.max_groups
        return Verified(R_IS=R_IS, obs_index=obs_index, star_index=star_index, false_match_probability=probability,
                        n_predicted=int(n_predicted)), True

    def _first_verified(self, frame, hypotheses, n_hypotheses, tried):
        """The first hypothesis (observed indices, guide indices) not tried before that verifies, or None."""
        for obs_index, cat_index in hypotheses:
            key = frozenset(zip(obs_index.tolist(), cat_index.tolist()))
            if key in tried:
                continue
            tried.add(key)
            R_IS = wahba_svd(self.guide_vectors[cat_index], frame.obs_S[obs_index])
            verified = verify(frame.obs_S, R_IS, self.field, frame.verify_gate, n_hypotheses, self.threshold)
            if verified is not None:
                return verified
        return None


class LostInSpace:
    """Full-sky lost-in-space identification: the pattern search over every pair of the guide catalog.

    With ``dense`` (a :class:`PatternMatcher` over the field stars and their :class:`PairTable`),
    frames the guide catalog cannot identify -- fewer than 3 guide stars among the centroids, since the
    uniform guide selection of 000 §2.1 keeps about half of the stars to the magnitude limit -- are
    searched again over every field star.
    """

    name = "lost_in_space"

    def __init__(self, catalog, matcher: PatternMatcher, dense=None):
        self.table = PairTable.full_sky(catalog)
        self.matcher = matcher
        self.dense = dense

    def identify(self, frame, prior):
        """Verified hypothesis or None; ``prior`` is not used.

        Order: the compiled fast path (:meth:`PatternMatcher.match_fast`), then the guide catalog
        with the brightest ``pattern_stars`` centroids, the field stars with
        as many, then both with twice as many (a frame whose brightest stars hold too few guide stars
        is solved sooner by the dense table than by a wider guide search).  With the dense table the
        guide catalog is searched for four-star groups only; the dense search also verifies triangles.
        """
        verified, exhausted = self.matcher.match_fast(frame, self.table)
        if verified is not None:
            return verified
        if self.dense is None:
            return self.matcher.match(frame, self.table)
        dense_matcher, dense_table = self.dense
        for width in (1, 2):
            if not (width == 1 and exhausted):  # the fast path already tried every group of these stars
                verified = self.matcher.match(frame, self.table, (width,), triangles=False)
                if verified is not None:
                    return verified
            verified = dense_matcher.match(frame, dense_table, (width,))
            if verified is not None:
                return verified
        return None
