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
"""

import time
from dataclasses import dataclass

import numpy as np

from navsim.sensors.star_sensor import MODE_CODE, StarFrame, isotropic_covariance

#: The run log's per-frame fields (shape, dtype, fill): the mode, detections, stars identified (none stacked), the
#: identifications the truth finds wrong and the largest wrong-match probability of the frame's matches (eq. 2 of
#: :mod:`startrack.identify.prior_match`); and the identification's wall time.
LOG_FIELDS = {"mode": ((), np.int8, MODE_CODE["no_fix"]), "n_detected": ((), np.int32, 0),
              "n_identified": ((), np.int32, 0), "n_stacked": ((), np.int32, 0), "n_wrong": ((), np.int32, 0),
              "wrong_probability": ((), np.float64, 0.0)}
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
    ``matcher`` over the catalog ``star_vectors`` (catalog directions: the filter makes them apparent)."""

    log_fields = LOG_FIELDS
    timing_fields = TIMING_FIELDS
    sample = None
    uses_prediction = False
    uses_prior = True

    def __init__(self, detections, matcher, star_vectors):
        self._detections, self._matcher, self._vectors = detections, matcher, star_vectors

    def record(self):
        return None

    def observe(self, request):
        d, j = self._detections, request.index
        rows = slice(d.offsets[j], d.offsets[j + 1])
        detected = rows.stop - rows.start
        if not d.available[j] or not detected:
            return StarFrame(mode="no_fix", reason="no star detected", info=_info("no_fix", detected))
        started = time.perf_counter()
        obs_S = d.obs_S[rows]
        cov = isotropic_covariance(obs_S, d.sigma[rows])
        prior = request.prior
        found = self._matcher.match(obs_S, d.mag[rows], d.mag_sigma[rows], cov, prior.q_IS, prior.P_theta,
                                    d.limiting_mag[j], prior.apparent)
        k = found.obs_index
        wrong = int(np.count_nonzero(d.truth[rows][k] != found.star_index))
        mode = "prior" if k.size else "no_fix"
        info = _info(mode, detected, k.size, wrong, float(found.wrong_probability.max(initial=0.0)),
                     1e3 * (time.perf_counter() - started))
        if not k.size:
            return StarFrame(mode="no_fix", reason="no detection identified with the prior", info=info)
        return StarFrame(mode="prior", ref_I=self._vectors[found.star_index], obs_S=obs_S[k], cov_S=cov[k], info=info)

    def after_update(self, update):
        pass

    def lose_track(self):
        pass


def _info(mode, detected, identified=0, wrong=0, probability=0.0, id_ms=np.nan):
    return {"mode": MODE_CODE[mode], "n_detected": detected, "n_identified": identified, "n_wrong": wrong,
            "wrong_probability": probability, "id_ms": id_ms}
