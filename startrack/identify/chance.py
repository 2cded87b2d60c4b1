"""False-match probability of a hypothesis from the local density of the detections (issue 18).

Under a wrong attitude hypothesis the detections are unrelated to the predicted stars.  Predicted star
i then has a detection within the radius d by chance with probability q_i = 1 - exp(-rho_i pi d^2),
rho_i the density of the detections around it [px^-2] (measured on the frame: a crowd of false
detections, the Milky Way or compression noise around bright regions raise it where they are; for a
clustered field the Poisson formula with the local density over-states the chance of a neighbour,
so the probability stays an upper bound).  The number of predicted stars so matched is a sum of
independent Bernoulli variables; its tail is taken as that of a Poisson variable of the same mean
lambda = sum q_i (Le Cam 1960: the two laws differ by at most sum q_i^2 in total variation).  A search that could have produced N_h hypotheses could be fooled by any of them
(Bonferroni), so

    P_false = min(1, N_h P[Poisson(lambda) >= K]),

K the matches beyond the stars that seeded the hypothesis.  A dense frame needs many more matches
than a sparse one: 4000 false detections over a 1024 x 768 frame give lambda ~ 12 for 700 predicted
stars at d = 1 px, and about 45 matches for P[...] < 1e-12.  (The calibrated identifier of
:mod:`startrack.identify.verify` keeps its binomial model over the detections with the global density
of the predicted stars, for the simulated star-sensor frames of the closed loop.)
"""

from __future__ import annotations

import math

from startrack.compiled.numba_setup import njit


@njit
def poisson_tail(mean, k):
    """P[Poisson(mean) >= k], summed term by term from k upwards (accurate for tiny tails)."""
    if k <= 0:
        return 1.0
    if mean <= 0.0:
        return 0.0
    term = math.exp(k * math.log(mean) - mean - math.lgamma(k + 1))
    total = term
    j = k
    while term > 1e-17 * total:
        j += 1
        term *= mean / j
        total += term
    return min(total, 1.0)


@njit
def chance_match_probability(expected, k, n_hypotheses):
    """min(1, N_h P[S >= k]): S the number of predicted stars with a detection within the radius d by
    chance, under a wrong hypothesis, counted as a Poisson variable of mean sum_i (1 - exp(-x_i)),
    x_i = rho_i pi d^2 the expected detections within d of predicted star i (rho_i the local density
    of the detections there).  ``expected`` (m,) the x_i, ``k`` the matches beyond the seeds."""
    mean = 0.0
    for i in range(expected.size):
        mean += -math.expm1(-expected[i])
    return min(1.0, max(n_hypotheses, 1.0) * poisson_tail(mean, k))
