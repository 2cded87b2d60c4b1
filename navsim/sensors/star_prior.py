"""A star sensor that identifies its few stars with the INS's prior (vector fidelity, issue 30).

By day a narrow SWIR field shows one to three stars, which no pattern search can name. Each frame's detections --
the stars the sky lets the sensor see (:class:`~navsim.sensors.star_vector.StarVectorSensor`), each with its
direction, its σ and its measured magnitude (the catalog's band magnitude off by the colour transform's error,
one draw per star and run, plus the photometric noise of its SNR), and the false detections the sensor expects
(Poisson per frame, uniform in the field, between one magnitude above the frame's limit and the limit) -- are
drawn before the run like the vector sensor's stars, but which star each is gets decided in the loop:
:class:`startrack.identify.prior_match.PriorMatch` against the catalog stars predicted from the filter's prior
(``request.prior``: its attitude, the covariance of its error and the processing that makes a catalog star
apparent). The matches are fused as star vectors (one star updates two axes); the truth checks each (``n_wrong``:
a detection matched to a star it is not). The same path serves any frame with few stars, by night or after an
outage. The processing is taken to correct the extinction of each star exactly (its magnitude compared with the
catalog's above the air).

Track gate. A star the filter accepted is tracked for :data:`TRACK_LIFETIME`: in later frames it is gated on the
direction it was last measured at (:class:`startrack.identify.prior_match.Tracks`), carried by the INS's own
relative attitude -- the filter's attitude with the corrections its updates made since then taken out. With K the
product of the updates' corrections q_post ⊗ q_prior* since the run began (in I), a star measured at o_j (S) with
the posterior attitude R_IS,j is predicted at frame j' at

    s = R_SI,j' [K_j' K_jᵀ R_IS,j o_j + a_j' − a_j],   C_t = C_o,j + N² Δt I + Δt² P_ε,                    (1)

a the processing's apparent direction of its catalog entry (its aberration and refraction change between the
frames) and the drift of :meth:`~navsim.sensors.star_sensor.SensorPrior.drift`. The attitude's own error then
cancels: the gate is that of two centroids and the gyro's drift over Δt, not the prior's.
"""

import time
from dataclasses import dataclass

import numpy as np

from navsim.sensors.star_sensor import MODE_CODE, StarFrame, isotropic_covariance
from startrack import Tracks
from startrack import rotation as rot

#: The run log's per-frame fields (shape, dtype, fill): the mode, detections, stars identified (none stacked) and of
#: them those gated on their track, the identifications the truth finds wrong, the largest wrong-match probability
#: of the frame's matches (eq. 2 of :mod:`startrack.identify.prior_match`) and their sum (the wrong matches the
#: matcher expects); and the identification's wall time.
LOG_FIELDS = {"mode": ((), np.int8, MODE_CODE["no_fix"]), "n_detected": ((), np.int32, 0),
              "n_identified": ((), np.int32, 0), "n_tracked": ((), np.int32, 0), "n_stacked": ((), np.int32, 0),
              "n_wrong": ((), np.int32, 0), "wrong_probability": ((), np.float64, 0.0),
              "wrong_expected": ((), np.float64, 0.0)}
#: How long [s] a star stays tracked after the filter last accepted it; then it is gated on the prior again. Eq. (1)
#: neglects what grows with the time between (the scale factor's error times the turn, the refraction's change times
#: the model air's error): within it, those stay below a tenth of an arcsecond on the shipped vehicles.
TRACK_LIFETIME = 60.0
TIMING_FIELDS = {"id_ms": ((), np.float64, np.nan)}


@dataclass(frozen=True)
class PriorIdentification:
    """How the sensor names its detections: ``matcher`` a :class:`~startrack.identify.prior_match.PriorMatch` over
    the sensor's catalog, ``false_per_frame`` the mean of the false detections drawn per frame, ``colour_sigma`` the
    band magnitudes' error [mag] drawn per star."""

    matcher: object
    false_per_frame: float
    colour_sigma: float


@dataclass(frozen=True)
class Detections:
    """Every frame's detections, concatenated (frame f owns rows offsets[f]:offsets[f+1]): unit directions
    ``obs_S`` (M, 3), σ ``sigma`` (M,) [rad] per tangent axis, measured magnitudes ``mag`` (M,) ± ``mag_sigma``
    (M,), the catalog index each truly is ``truth`` (M,) (−1: a false detection); per frame ``available`` (F,)
    and the limiting magnitude ``limiting_mag`` (F,)."""

    offsets: np.ndarray
    obs_S: np.ndarray
    sigma: np.ndarray
    mag: np.ndarray
    mag_sigma: np.ndarray
    truth: np.ndarray
    available: np.ndarray
    limiting_mag: np.ndarray


class PriorIdentifiedRun:
    """The per-run sensor: the pre-drawn :class:`Detections`, identified frame by frame with the filter's prior by
    ``matcher`` over the catalog ``star_vectors`` (catalog directions: the filter makes them apparent), the stars the
    filter accepted gated on their tracks (eq. 1)."""

    log_fields = LOG_FIELDS
    timing_fields = TIMING_FIELDS
    sample = None
    uses_prediction = False
    uses_prior = True

    def __init__(self, detections, matcher, star_vectors):
        self._detections, self._matcher, self._vectors = detections, matcher, star_vectors
        self._K = np.array([0.0, 0.0, 0.0, 1.0])  # the updates' corrections so far (eq. 1)
        self._tracks = {}  # catalog row -> (K_jᵀ R_IS,j o_j (3,), a_j (3,), C_o,j in I (3, 3), t_j [s])
        self._prior, self._matched = None, None

    def record(self):
        return None

    def observe(self, request):
        d, j = self._detections, request.index
        self._prior, self._matched = request.prior, None
        rows = slice(d.offsets[j], d.offsets[j + 1])
        detected = rows.stop - rows.start
        if not d.available[j] or not detected:
            return StarFrame(mode="no_fix", reason="no star detected", info=_info("no_fix", detected))
        started = time.perf_counter()
        obs_S = d.obs_S[rows]
        cov = isotropic_covariance(obs_S, d.sigma[rows])
        prior, tracks = request.prior, self._track_gates(request.t, request.prior)
        found = self._matcher.match(obs_S, d.mag[rows], d.mag_sigma[rows], cov, prior.q_IS, prior.P_theta,
                                    d.limiting_mag[j], prior.apparent, tracks)
        k = found.obs_index
        self._matched = (request.t, found.star_index, obs_S[k], cov[k])
        wrong = int(np.count_nonzero(d.truth[rows][k] != found.star_index))
        mode = "prior" if k.size else "no_fix"
        info = _info(mode, detected, k.size, int(np.count_nonzero(np.isin(found.star_index, tracks.star_index))),
                     wrong, found.wrong_probability, 1e3 * (time.perf_counter() - started))
        if not k.size:
            return StarFrame(mode="no_fix", reason="no detection identified with the prior", info=info)
        return StarFrame(mode="prior", ref_I=self._vectors[found.star_index], obs_S=obs_S[k], cov_S=cov[k], info=info)

    def after_update(self, update, posterior):
        """The frame's corrections into K, and a track for each match the filter accepted (eq. 1)."""
        q_post = posterior.q_IS
        self._K = rot.normalize(rot.multiply(rot.multiply(q_post, rot.conjugate(self._prior.q_IS)), self._K))
        if self._matched is None or update is None:
            return
        t, stars, obs_S, cov = self._matched
        accepted = update.accepted
        R = rot.to_matrix(rot.multiply(rot.conjugate(self._K), q_post))  # K_jᵀ R_IS,j
        carried, C = obs_S[accepted] @ R.T, R @ cov[accepted] @ R.T
        apparent = posterior.apparent(self._vectors[stars[accepted]])
        for star, v, a, c in zip(stars[accepted], carried, apparent, C):
            self._tracks[int(star)] = (v, a, c, t)

    def lose_track(self):
        self._tracks = {}

    def _track_gates(self, t, prior):
        """The :class:`~startrack.identify.prior_match.Tracks` of eq. (1) at time ``t`` [s] for ``prior``; tracks
        older than :data:`TRACK_LIFETIME` are dropped."""
        self._tracks = {star: track for star, track in self._tracks.items() if t - track[3] <= TRACK_LIFETIME}
        if not self._tracks:
            return Tracks.none()
        stars = np.fromiter(self._tracks, np.int64, len(self._tracks))
        carried, a, C, t_last = (np.array(column) for column in zip(*self._tracks.values()))
        R_SK = rot.to_matrix(prior.q_IS).T @ rot.to_matrix(self._K)  # from the corrections-free frame K_jᵀ I to S
        s = carried @ R_SK.T + (prior.apparent(self._vectors[stars]) - a) @ rot.to_matrix(prior.q_IS)
        s /= np.linalg.norm(s, axis=1, keepdims=True)
        cov = R_SK @ C @ R_SK.T + np.array([prior.drift(t - tj) for tj in t_last])
        return Tracks(star_index=stars, s=s, cov=cov)


def _info(mode, detected, identified=0, tracked=0, wrong=0, probabilities=(), id_ms=np.nan):
    return {"mode": MODE_CODE[mode], "n_detected": detected, "n_identified": identified, "n_tracked": tracked,
            "n_wrong": wrong, "wrong_probability": float(np.max(probabilities, initial=0.0)),
            "wrong_expected": float(np.sum(probabilities)), "id_ms": id_ms}
