"""Vector-fidelity star sensor: what the sensor would report, without images.

Two measurement models (docs/design.md, fidelity ``vector``):

- :class:`StarVectorSensor` returns the catalog stars inside the circular field as noisy unit
  vectors in the sensor frame S (one per identified star, brightest first);
- :class:`AttitudeFixSensor` returns a noisy attitude q_IS with its covariance in S
  (cross-boresight σ on x and y, roll σ about the boresight z).

Both see the true mounting R_BS,true = R_BS exp([δm×]) (the unknown misalignment δm in S) and, on a
vehicle near the Earth (``v_I``: the observer's barycentric velocity at each frame; ``air``: the frames'
refracting air), the apparent stars (:mod:`navsim.earth.apparent`): the star vectors are the aberrated
and refracted directions, the fix is turned by the rotation of its boresight; the reported catalog
directions stay the catalog's. Their noise does not depend on the filter, so a run draws every frame's measurements
when it starts (:meth:`StarVectorSensor.start`): the loop reads them frame by frame
(:class:`VectorRun`), or the filter takes the whole :class:`Record` at once on its compiled fast path.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.apparent import apparent, fix_rotation
from navsim.sensors.recorded_run import RecordedRun
from navsim.sensors.star_prior import Detections, PriorIdentifiedRun
from navsim.sensors.star_sensor import StarFrame, isotropic_covariance
from startrack import rotation as rot
from startrack import tangent_basis


@dataclass(frozen=True)
class StarFrames:
    """Star measurements of many frames, concatenated: frame f owns rows offsets[f]:offsets[f+1]; each star's
    direction σ [rad] per tangent axis (the filter's R) in ``sigma``, its catalog row ``index``, its band magnitude
    ``mag`` (the catalog's), the σ of its measured magnitude ``mag_sigma`` [mag] (NaN without a light budget) and,
    for a spacecraft's several heads, the ``head`` that saw it (None: one sensor)."""

    offsets: np.ndarray
    ref_I: np.ndarray
    obs_S: np.ndarray
    ids: np.ndarray
    sigma: np.ndarray
    index: np.ndarray
    mag: np.ndarray
    mag_sigma: np.ndarray
    head: np.ndarray | None = None

    def head_index(self):
        """(M,) int64: the head that saw each star (a spacecraft's several heads; all 0 for one sensor)."""
        return np.zeros(len(self.ref_I), dtype=np.int64) if self.head is None else np.ascontiguousarray(self.head, dtype=np.int64)

    def frame(self, f):
        """(ref_I (N, 3), obs_S (N, 3), ids (N,), σ (N,)) of frame f."""
        rows = slice(self.offsets[f], self.offsets[f + 1])
        return self.ref_I[rows], self.obs_S[rows], self.ids[rows], self.sigma[rows]

    @property
    def counts(self):
        """(F,) the number of stars of each frame."""
        return np.diff(self.offsets)


@dataclass(frozen=True)
class StarVectorSensor:
    """Stars brighter than the catalog cut inside the cone of half-angle fov/2 around +z_S.

    ``star_vectors`` (M, 3) unit vectors in I, ``star_ids`` (M,), ``star_mags`` (M,) in the sensor's band;
    ``fov`` full cone angle [rad]; ``sigma`` 1σ direction error per tangent axis [rad]; ``max_stars`` the
    most (brightest) stars reported; ``q_BS_true`` true mounting. With a light budget (``photometry``, a
    :class:`startrack.image.sensor_photometry.SensorPhotometry`) and the frames' sky (``sky``, a
    :class:`navsim.sensors.frame_sky.FrameSky`) a star is reported when the frame's sky lets the sensor detect
    it, with the σ of its own SNR, instead of every star with ``sigma``. On a spacecraft (``occultation``, a
    :class:`navsim.orbit.earth_disc.EarthDisc` of the frames) the stars behind the Earth are not seen.
    """

    star_vectors: np.ndarray
    star_ids: np.ndarray
    star_mags: np.ndarray
    fov: float
    sigma: float
    max_stars: int
    q_BS_true: np.ndarray
    faults: object  # navsim.sensors.faults.SensorFaults
    photometry: object = None
    sky: object = None
    identification: object = None  # navsim.sensors.star_prior.PriorIdentification
    occultation: object = None  # navsim.orbit.earth_disc.EarthDisc: the stars the Earth hides from a spacecraft

    def start(self, seed, q_IB_frames, t_frames, v_I=None, noise=True, air=None):
        """A run's sensor: every frame's stars drawn from ``seed`` for the true attitudes q_IB_frames
        (and observer velocities ``v_I`` (F, 3) [m/s], None: no aberration; ``air`` the frames' (up_I (F, 3),
        A (F,), B (F,)), None: no refraction); ``noise`` False measures every star exactly (its σ kept for the
        filter). With ``identification`` the run names its detections with the filter's prior
        (:class:`~navsim.sensors.star_prior.PriorIdentifiedRun`), else every star is reported identified."""
        rng = np.random.default_rng(seed)
        stars = self.observe_frames(q_IB_frames, rng, v_I, noise, air)
        available = self.faults.available(t_frames)
        if self.identification is None:
            return VectorRun(Record(available=available, stars=stars))
        detections = self.detections(stars, rng, available, noise)
        return PriorIdentifiedRun(detections, self.identification.matcher, self.star_vectors)

    def detections(self, stars, rng, available, noise=True):
        """The :class:`~navsim.sensors.star_prior.Detections` of the measured ``stars`` (:class:`StarFrames`) with
        the false detections of :attr:`identification` drawn from ``rng`` (module docstring of
        :mod:`navsim.sensors.star_prior`); ``noise`` False: magnitudes exact, no false detection."""
        ident, F = self.identification, len(stars.offsets) - 1
        scale = 1.0 if noise else 0.0
        colour = ident.colour_sigma * rng.standard_normal(len(self.star_mags))
        frame = np.repeat(np.arange(F), stars.counts)
        mag = stars.mag + scale * (colour[stars.index] + stars.mag_sigma * rng.standard_normal(len(frame)))
        limit = np.asarray(self.sky.limiting_magnitude(), dtype=float)
        n_false = rng.poisson(scale * ident.false_per_frame * np.isfinite(limit).astype(float))
        f_frame = np.repeat(np.arange(F), n_false)
        angle = 0.5 * self.fov * np.sqrt(rng.uniform(size=f_frame.size))
        azimuth = rng.uniform(0.0, 2.0 * np.pi, f_frame.size)
        f_obs = np.stack([np.sin(angle) * np.cos(azimuth), np.sin(angle) * np.sin(azimuth), np.cos(angle)], axis=-1)
        f_mag = limit[f_frame] - rng.uniform(size=f_frame.size)
        f_sigma = self.sky.measure(f_frame, f_mag)[1]
        order = np.argsort(np.concatenate([frame, f_frame]), kind="stable")
        offsets = np.concatenate([[0], np.cumsum(stars.counts + n_false)])
        return Detections(offsets=offsets, obs_S=np.vstack([stars.obs_S, f_obs])[order],
                          sigma=np.concatenate([stars.sigma, f_sigma])[order], mag=np.concatenate([mag, f_mag])[order],
                          mag_sigma=np.concatenate([stars.mag_sigma, self.sky.magnitude_sigma(f_frame, f_mag)])[order],
                          truth=np.concatenate([stars.index, np.full(f_frame.size, -1)])[order], available=available,
                          limiting_mag=limit)

    def observe_frames(self, q_IB_true, rng, v_I=None, noise=True, air=None):
        """Noisy star vectors for every true attitude q_IB_true (F, 4) -> :class:`StarFrames`.

        A star is seen when its angle from the boresight is at most fov/2 and, with a light budget, when the
        frame's sky lets the sensor detect it; the ``max_stars`` brightest (as seen) are reported, brightest
        first; each is measured at its apparent direction for the frame's observer velocity ``v_I`` (F, 3)
        and ``air`` (:meth:`start`; None: its catalog direction) with a direction noise isotropic in the plane
        perpendicular to it.
        """
        q_IS = rot.multiply(np.atleast_2d(q_IB_true), self.q_BS_true)
        frame, index = self._in_field(rot.rotate(q_IS, np.array([0.0, 0.0, 1.0])))
        if self.occultation is not None:
            seen = ~self.occultation.hides(self.star_vectors[index], frame)
            frame, index = frame[seen], index[seen]
        ref_I = self.star_vectors[index]
        seen_I = ref_I if v_I is None else apparent(ref_I, np.asarray(v_I)[frame], _rows(air, frame))
        sigma = np.full(len(index), self.sigma)
        mag = self.star_mags[index]
        mag_sigma = np.full(len(index), np.nan)
        if self.sky is not None:
            mag = self.sky.extinguished(frame, mag, seen_I)
            detected, sigma, _ = self.sky.measure(frame, mag)
            mag_sigma = self.sky.magnitude_sigma(frame, mag)
            frame, index, ref_I, seen_I, sigma, mag, mag_sigma = (a[detected] for a in (frame, index, ref_I, seen_I, sigma,
                                                                                         mag, mag_sigma))
        order = np.lexsort((mag, frame))  # per frame, brightest as seen first
        keep = order[_rank_in_frame(frame[order]) < self.max_stars]
        frame, index, ref_I, seen_I, sigma, mag_sigma = (a[keep] for a in (frame, index, ref_I, seen_I, sigma, mag_sigma))
        s_true = rot.rotate(rot.conjugate(q_IS[frame]), seen_I)
        draws = rng.standard_normal((len(index), 2)) * (sigma if noise else np.zeros_like(sigma))[:, None]
        obs = s_true + np.einsum("nij,ni->nj", tangent_basis(s_true), draws)
        obs /= np.linalg.norm(obs, axis=1, keepdims=True)
        offsets = np.concatenate([[0], np.cumsum(np.bincount(frame, minlength=len(q_IS)))])
        return StarFrames(offsets=offsets, ref_I=ref_I, obs_S=obs, ids=self.star_ids[index], sigma=sigma, index=index,
                          mag=self.star_mags[index], mag_sigma=mag_sigma)

    def _in_field(self, boresight, chunk=512):
        """(frame (K,), catalog index (K,)) of every star inside the cone of each boresight (F, 3), frame by
        frame, brightest in the catalog first."""
        order = np.argsort(self.star_mags, kind="stable")
        catalog = self.star_vectors[order]
        cos_half = np.cos(0.5 * self.fov)
        frames, stars = [], []
        for start in range(0, len(boresight), chunk):
            axes = boresight[start : start + chunk]
            near = _near(catalog, axes, 0.5 * self.fov)
            f, k = np.nonzero(axes @ catalog[near].T >= cos_half)
            frames.append(f + start)
            stars.append(near[k])
        return np.concatenate(frames), order[np.concatenate(stars)]


def _rows(air, frame):
    """The ``air`` (up_I (F, 3), A (F,), B (F,)) of the rows ``frame`` (N,), or None."""
    return None if air is None else tuple(np.asarray(x)[frame] for x in air)


def _rank_in_frame(sorted_frames):
    """Each row's rank (0, 1, ...) among the rows of its frame in ``sorted_frames`` (ascending)."""
    if not len(sorted_frames):
        return np.zeros(0, dtype=np.int64)
    first = np.flatnonzero(np.r_[True, sorted_frames[1:] != sorted_frames[:-1]])
    return np.arange(len(sorted_frames)) - np.repeat(first, np.diff(np.r_[first, len(sorted_frames)]))


#: Margin [rad] of :func:`_near`'s cap over the rounding of its cosines.
NEAR_MARGIN = 1e-9


def _near(catalog, axes, half_fov):
    """The indices (ascending) of the unit vectors ``catalog`` (N, 3) that may lie within ``half_fov`` [rad] of
    any of the unit ``axes`` (K, 3): those inside the cap around the axes' mean direction that reaches the
    farthest axis plus the half field (all of them when the axes spread over a hemisphere)."""
    centre = axes.sum(axis=0)
    norm = np.linalg.norm(centre)
    if norm < 1e-6 * len(axes):
        return np.arange(len(catalog))
    centre /= norm
    reach = np.arccos(np.clip(np.min(axes @ centre), -1.0, 1.0)) + half_fov + NEAR_MARGIN
    return np.arange(len(catalog)) if reach >= np.pi else np.flatnonzero(catalog @ centre >= np.cos(reach))


@dataclass(frozen=True)
class AttitudeFixSensor:
    """A star tracker reporting q_IS with independent errors: σ_cross about x_S and y_S, σ_roll about z_S [rad]."""

    sigma_cross: float
    sigma_roll: float
    q_BS_true: np.ndarray
    faults: object  # navsim.sensors.faults.SensorFaults

    def start(self, seed, q_IB_frames, t_frames, v_I=None, noise=True, air=None):
        """A run's sensor: every frame's fix drawn from ``seed`` for the true attitudes q_IB_frames (and
        observer velocities ``v_I`` (F, 3) [m/s], None: no aberration; ``air`` as the star vectors'); ``noise``
        False: exact fixes (``R_S`` kept for the filter)."""
        fixes = self.observe_frames(q_IB_frames, np.random.default_rng(seed), v_I, noise, air)
        return VectorRun(Record(available=self.faults.available(t_frames), fixes=fixes, R_S=self.R_S))

    @property
    def R_S(self):
        return np.diag([self.sigma_cross**2, self.sigma_cross**2, self.sigma_roll**2])

    def observe_frames(self, q_IB_true, rng, v_I=None, noise=True, air=None):
        """Measured q_IS = q_R⁻¹ ⊗ q_IS,true ⊗ exp(ν/2), ν ~ N(0, R_S) in sensor axes (0 without ``noise``), for
        q_IB_true (F, 4): q_R the rotation of the boresight to its apparent direction for the observer velocities
        ``v_I`` (F, 3) and the ``air`` (:func:`navsim.earth.apparent.fix_rotation`; None: no aberration)."""
        q_IS = rot.multiply(np.atleast_2d(q_IB_true), self.q_BS_true)
        if v_I is not None:
            q_R = fix_rotation(rot.rotate(q_IS, np.array([0.0, 0.0, 1.0])), np.asarray(v_I), air)
            q_IS = rot.multiply(rot.conjugate(q_R), q_IS)
        sigma = np.array([self.sigma_cross, self.sigma_cross, self.sigma_roll])
        nu = sigma * rng.standard_normal((len(q_IS), 3)) * (1.0 if noise else 0.0)
        return rot.multiply(q_IS, rot.from_rotation_vector(nu))


@dataclass(frozen=True)
class Record:
    """Every frame's measurements of a vector-fidelity run: attitude ``fixes`` (F, 4) with ``R_S``,
    or ``stars`` (:class:`StarFrames`, each with its direction σ [rad]); ``available`` (F,) False for
    frames lost to an outage or dropped."""

    available: np.ndarray
    fixes: np.ndarray | None = None
    R_S: np.ndarray | None = None
    stars: StarFrames | None = None

    def covariances(self):
        """The covariance of every star of every frame (M, 3, 3) [rad², S]: isotropic, its σ on each tangent axis."""
        return isotropic_covariance(self.stars.obs_S, self.stars.sigma)


class VectorRun(RecordedRun):
    """The per-run sensor of :class:`StarVectorSensor` and :class:`AttitudeFixSensor`: it reads its
    :class:`Record` frame by frame; tracking state and faults other than lost frames do not apply."""

    def observe(self, request):
        r, j = self._record, request.index
        if not r.available[j]:
            return StarFrame(mode="no_fix")
        if r.fixes is not None:
            return StarFrame(mode="tracking", q_IS=r.fixes[j], R_S=r.R_S)
        ref_I, obs_S, _, sigma = r.stars.frame(j)
        if not len(ref_I):
            return StarFrame(mode="no_fix")
        return StarFrame(mode="tracking", ref_I=ref_I, obs_S=obs_S, cov_S=isotropic_covariance(obs_S, sigma))
