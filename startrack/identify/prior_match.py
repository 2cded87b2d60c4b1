"""Few-star identification with an attitude prior: which catalog star each of 1-3 detections is.

A daytime star sensor sees one to three stars -- too few for any pattern (lost-in-space needs 3-4, tracking
refits an attitude from 3). With the attitude the INS predicts and its covariance, each detection is matched
to the catalog star predicted where it lies, as aircraft star trackers do (the validation gate and Poisson clutter model of
target tracking: Bar-Shalom, Li & Kirubarajan).

Prediction. A catalog star of direction u (I) is predicted in the sensor at s = R_IS,priorᵀ u. The prior's
attitude error δθ (sensor axes, covariance P_θ [rad²]) moves it by δs = [s×] δθ, so a detection of measured
direction o (covariance C_o) of that star has the tangent-plane residual r = T (o − s) of covariance

    S = T ([s×] P_θ [s×]ᵀ + C_o) Tᵀ,     d² = rᵀ S⁻¹ r,                                          (1)

T the 2x3 tangent basis at s. The gate is d² <= χ²₂(p_gate) = −2 ln(1 − p_gate) (the true star falls outside
it with probability 1 − p_gate), and the magnitudes must agree: |m_obs − m_cat| <= k_m √(σ_obs² + σ_cat²), σ_cat
the band magnitudes' own error (:mod:`startrack.photometry.colours`: 0.10-0.14 mag RMS in J and H).

Track gate. A star matched in an earlier frame is predicted instead where it was last measured: its measured
direction carried to this frame by the attitude the caller knows between the two frames (an INS's relative
attitude), of covariance C_t = C_o,last + the relative attitude's error (:class:`Tracks`, built by the caller).
In (1) the star's s is then the track's and [s×] P_θ [s×]ᵀ is replaced by C_t: a gate of ~2 centroid σ² in place of
the prior's, so the chance (2) that a coincidence falls inside it shrinks by the ratio of the two areas, and a
detection that lies in the prior's gate but not in the track's is not that star. This is the validation gate of a confirmed
track in target tracking (Bar-Shalom, Li & Kirubarajan). A match on a track is wrong only when the star went
undetected and a false detection fell inside its gate: its (2) keeps the false detections' ρ_f alone in λ. Another star
inside the gate, √χ²₂ √2 σ_c ≈ 6 centroid σ from the track, is one the sensor does not resolve from it, and one
that stays there was there at the track's first match, whose (2) counts it.

Uniqueness. A detection is matched to a star only when that star is the only one in its gate and the detection
the only one in the star's gate.

Wrong match. A detection that is not the star its gate holds lies where the sky puts it independently of the
catalog: another star whose own entry fell outside the gate (or an object the catalog lacks), or a false
detection -- which uniqueness leaves only when the star itself went undetected or fell outside its gate (else two
detections share it). With clutter of density λ = ρ_m + ρ_f [sr⁻¹] in the gate, the chance that the detection is
clutter and not the star is the parametric PDA's association probability β_0 of a single validated measurement
(Bar-Shalom, Daum & Huang 2009, "the PDAF", β_i and β_0 of the Poisson clutter model):

    P_wrong = λ (1 − P_D P_G) / (λ (1 − P_D P_G) + P_D N(r; 0, S)),
    N(r; 0, S) = exp(−d²/2) / (2π √det S)   [sr⁻¹],                                                  (2)

ρ_m the density of catalog stars inside the detection's magnitude window (counted in a cap around the predicted
boresight), ρ_f the density of false detections the sensor expects (their magnitudes are not trusted to reject
them), P_G = p_gate, and P_D = 1 − P_miss, P_miss = Φ((m − m_lim)/0.3 mag) the chance that the star of magnitude m
went undetected below the frame's limiting magnitude m_lim, times the chance that the star truly lies inside the
field (its prediction near the edge may be inside while it is outside: Φ((ρ − θ)/σ_θ), θ its predicted angle from
the boresight). (2) is the posterior probability given where the
detection lies, so its sum over a run's matches is the number of wrong matches to expect: a star below the limit
(P_D small) is named only when its detection lies much closer to it than clutter would, and a detection at the
gate's edge needs a rarer coincidence than one at its centre. With no limiting magnitude the star counts as
detectable (the magnitude's factor of P_D taken as 1) but its miss is not ruled out (the factor 1 − P_D P_G taken as 1). A match
is kept when P_wrong <= ``max_wrong`` (the ceiling). The ρ_m term supposes the detection unrelated to the star
whatever its gate probability: (2) bounds the rate of wrong matches from above. Not modelled: the planets
(bright, not in the catalog: the ρ_m term counts stars only).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import norm

from startrack.base.errors import InputError
from startrack.geometry import rotation as rot
from startrack.geometry.sphere import tangent_basis

#: Radius [rad] of the cap around the predicted boresight in which ρ_m of eq. (2) is counted (at least).
_DENSITY_RADIUS = np.radians(10.0)
#: Width [mag] of the detection's fall-off around the limiting magnitude in P_D of eq. (2).
_LIMIT_WIDTH = 0.3


@dataclass(frozen=True)
class PriorMatches:
    """What :meth:`PriorMatch.match` found: ``obs_index`` (K,) detections and ``star_index`` (K,) the catalog
    rows they are, each match's ``wrong_probability`` (K,) (eq. 2) and Mahalanobis ``d2`` (K,) (eq. 1);
    ``rejected`` (M,) why each detection was left: "" (matched), "no star", "ambiguous", "shared",
    "chance"."""

    obs_index: np.ndarray
    star_index: np.ndarray
    wrong_probability: np.ndarray
    d2: np.ndarray
    rejected: tuple


@dataclass(frozen=True)
class Tracks:
    """Stars matched before, as eq. (1) predicts them now: catalog rows ``star_index`` (T,), predicted unit
    directions ``s`` (T, 3) in the sensor's axes and the covariance ``cov`` (T, 3, 3) [rad²] of each prediction's
    error (the last measurement's and the relative attitude's); the module docstring's track gate."""

    star_index: np.ndarray
    s: np.ndarray
    cov: np.ndarray

    @classmethod
    def none(cls):
        return cls(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3, 3)))


@dataclass(frozen=True)
class PriorMatch:
    """Few-star identification against ``vectors`` (N, 3) catalog unit vectors in I with their magnitudes ``mags``
    (N,) in the sensor's band (module docstring).

    field_radius: angle [rad] from the boresight within which a star can be detected; gate_probability: p_gate of
    eq. (1); mag_sigmas: k_m; catalog_mag_sigma: σ_cat [mag]; false_per_frame: the false detections the sensor
    expects per frame inside its field (ρ_f = that over the field's solid angle); max_wrong: the ceiling of eq. (2).
    """

    vectors: np.ndarray
    mags: np.ndarray
    field_radius: float
    gate_probability: float = 0.9999
    mag_sigmas: float = 3.0
    catalog_mag_sigma: float = 0.15
    false_per_frame: float = 1.0
    max_wrong: float = 1e-3

    def __post_init__(self):
        if not 0.0 < self.field_radius < 0.5 * np.pi:
            raise InputError(f"prior match: field radius {self.field_radius!r} rad must be in (0, π/2)")
        if not 0.0 < self.gate_probability < 1.0:
            raise InputError(f"prior match: gate probability {self.gate_probability!r} must be in (0, 1)")
        if not 0.0 < self.max_wrong < 1.0:
            raise InputError(f"prior match: the wrong-match ceiling {self.max_wrong!r} must be in (0, 1)")
        if self.false_per_frame < 0.0 or self.mag_sigmas <= 0.0 or self.catalog_mag_sigma < 0.0:
            raise InputError("prior match: false_per_frame and catalog_mag_sigma must be >= 0, mag_sigmas > 0")

    @property
    def gate(self):
        """χ²₂(p_gate) = −2 ln(1 − p_gate)."""
        return -2.0 * np.log1p(-self.gate_probability)

    @property
    def false_density(self):
        """ρ_f [sr⁻¹]: the expected false detections over the field's solid angle."""
        return self.false_per_frame / (2.0 * np.pi * (1.0 - np.cos(self.field_radius)))

    def match(self, obs_S, obs_mag, obs_mag_sigma, cov_S, q_IS, P_theta, limiting_mag=None, apparent=None,
              tracks=None):
        """The matches (:class:`PriorMatches`) of detections ``obs_S`` (M, 3) (unit, sensor axes) of magnitudes
        ``obs_mag`` (M,) ± ``obs_mag_sigma`` (M,) and direction covariances ``cov_S`` (M, 3, 3) [rad²], for the
        prior attitude ``q_IS`` (4,) whose error in sensor axes has the covariance ``P_theta`` (3, 3) [rad²], on a
        frame of limiting magnitude ``limiting_mag`` (None: unknown, any star may have been missed); ``apparent`` maps
        catalog unit vectors (K, 3) in I to the directions the sensor sees them at (aberration, refraction; None: the
        catalog's); ``tracks`` (:class:`Tracks` or None) the stars gated on their last measured position."""
        obs_S = np.atleast_2d(np.asarray(obs_S, dtype=float))
        R_SI = rot.to_matrix(np.asarray(q_IS, dtype=float)).T
        boresight = R_SI[2]
        reach = self.field_radius + 5.0 * np.sqrt(max(np.linalg.eigvalsh(P_theta)[-1], 0.0))
        candidates = np.flatnonzero(self.vectors @ boresight >= np.cos(min(reach, np.pi)))
        u = self.vectors[candidates]
        s = (u if apparent is None else apparent(u)) @ R_SI.T  # predicted directions (K, 3) in S
        C = _attitude_covariance(s, np.asarray(P_theta, dtype=float))
        tracked = np.zeros(candidates.size, dtype=bool)
        if tracks is not None:
            rows, k = np.intersect1d(tracks.star_index, candidates, assume_unique=True, return_indices=True)[1:]
            s[k], C[k], tracked[k] = tracks.s[rows], tracks.cov[rows], True
        d2, area = _mahalanobis(obs_S, np.asarray(cov_S, dtype=float), s, C)
        window = self.mag_sigmas * np.hypot(np.asarray(obs_mag_sigma, dtype=float), self.catalog_mag_sigma)
        mag_ok = np.abs(np.asarray(obs_mag, dtype=float)[:, None] - self.mags[candidates][None, :]) <= window[:, None]
        inside = (d2 <= self.gate) & mag_ok
        density = self._window_density(boresight, np.asarray(obs_mag, dtype=float), window)
        detect = _in_field(s, C, self.field_radius)
        if limiting_mag is not None:
            detect = detect * norm.sf((self.mags[candidates] - limiting_mag) / _LIMIT_WIDTH)
        return self._unique(inside, d2, area, density, detect, candidates, tracked, limiting_mag is None)

    def _window_density(self, boresight, obs_mag, window):
        """ρ_m (M,) [sr⁻¹]: catalog stars within each detection's magnitude window per steradian of the cap of
        radius max(:data:`_DENSITY_RADIUS`, the field radius) around the boresight."""
        radius = max(_DENSITY_RADIUS, self.field_radius)
        near = self.mags[self.vectors @ boresight >= np.cos(radius)]
        counts = np.array([np.count_nonzero(np.abs(near - m) <= w) for m, w in zip(obs_mag, window)])
        return np.maximum(counts, 1) / (2.0 * np.pi * (1.0 - np.cos(radius)))

    def _unique(self, inside, d2, area, density, detect, candidates, tracked, unknown_limit):
        """The mutually unique gate pairs, each kept when its eq. (2) is under the ceiling (ρ_m left out of λ for a
        ``tracked`` (K,) star: the module docstring's track gate); ``detect`` (K,) P_D of eq. (2), its miss not
        ruled out when the frame's limit is unknown (``unknown_limit``)."""
        per_obs, per_star = inside.sum(axis=1), inside.sum(axis=0)
        obs_index, star_index, wrong, dist, rejected = [], [], [], [], []
        for i in range(inside.shape[0]):
            if per_obs[i] == 0:
                rejected.append("no star")
                continue
            if per_obs[i] > 1:
                rejected.append("ambiguous")
                continue
            k = int(np.flatnonzero(inside[i])[0])
            if per_star[k] > 1:
                rejected.append("shared")
                continue
            p_d = detect[k]
            unseen = 1.0 if unknown_limit else 1.0 - p_d * self.gate_probability
            p = _wrong_probability(((0.0 if tracked[k] else density[i]) + self.false_density) * unseen, p_d,
                                   d2[i, k], area[i, k])
            if p > self.max_wrong:
                rejected.append("chance")
                continue
            rejected.append("")
            obs_index.append(i)
            star_index.append(int(candidates[k]))
            wrong.append(p)
            dist.append(d2[i, k])
        return PriorMatches(obs_index=np.array(obs_index, np.int64), star_index=np.array(star_index, np.int64),
                            wrong_probability=np.array(wrong), d2=np.array(dist), rejected=tuple(rejected))


def _wrong_probability(unseen, detect, d2, area):
    """P_wrong of eq. (2) from the clutter's share λ (1 − P_D P_G) ``unseen`` [sr⁻¹], the star's P_D ``detect``, the
    detection's d² and π √det S ``area`` [sr] (:func:`_mahalanobis`); 1 when neither hypothesis can hold."""
    total = unseen + detect * np.exp(-0.5 * d2) / (2.0 * area)
    return unseen / total if total > 0.0 else 1.0


def _in_field(s, C, field_radius):
    """P_in (K,): the chance that each predicted star s (K, 3) of prediction covariance C (K, 3, 3) [rad²] truly lies
    within ``field_radius`` [rad] of the boresight (the sensor's z): Φ((ρ − θ)/σ_θ), θ = arccos s_z and
    σ_θ² = C_zz / sin²θ (eq. 2's P_D near the field's edge)."""
    theta = np.arccos(np.clip(s[:, 2], -1.0, 1.0))
    sigma = np.sqrt(np.maximum(C[:, 2, 2], 1e-30)) / np.maximum(np.sin(theta), 1e-12)
    return norm.cdf((field_radius - theta) / sigma)


def _attitude_covariance(s, P_theta):
    """[s×] P_θ [s×]ᵀ (K, 3, 3) [rad²]: the covariance of each predicted direction s (K, 3) from the attitude's error
    (eq. 1)."""
    cross = rot.skew(s)
    return cross @ P_theta[None] @ np.swapaxes(cross, 1, 2)


def _mahalanobis(obs_S, cov_S, s, C):
    """(d² (M, K) of eq. (1), gate-ellipse area per unit χ², π √det S (M, K) [sr]) of every detection against every
    predicted star s (K, 3) of prediction covariance C (K, 3, 3)."""
    T = tangent_basis(s)  # (K, 2, 3)
    prior = np.einsum("kab,kbc,kdc->kad", T, C, T)  # (K, 2, 2)
    meas = np.einsum("kab,mbc,kdc->mkad", T, cov_S, T)  # (M, K, 2, 2)
    S = prior[None] + meas
    r = np.einsum("kab,mkb->mka", T, obs_S[:, None, :] - s[None, :, :])
    det = S[..., 0, 0] * S[..., 1, 1] - S[..., 0, 1] * S[..., 1, 0]
    d2 = (S[..., 1, 1] * r[..., 0] ** 2 - 2.0 * S[..., 0, 1] * r[..., 0] * r[..., 1] + S[..., 0, 0] * r[..., 1] ** 2) / det
    behind = (obs_S @ s.T) <= 0.0
    return np.where(behind, np.inf, d2), np.pi * np.sqrt(det)
