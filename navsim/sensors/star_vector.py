"""Vector-fidelity star sensor: what the sensor would report, without images.

Two measurement models (docs/design.md, fidelity ``vector``):

- :class:`StarVectorSensor` returns the catalog stars inside the circular field as noisy unit
  vectors in the sensor frame S (one per identified star, brightest first);
- :class:`AttitudeFixSensor` returns a noisy attitude q_IS with its covariance in S
  (cross-boresight σ on x and y, roll σ about the boresight z).

Both see the true mounting R_BS,true = R_BS exp([δm×]) (the unknown misalignment δm in S) and, on a
vehicle near the Earth (``v_I``: the observer's barycentric velocity at each frame), the apparent
stars (:mod:`navsim.earth.apparent`): the star vectors are the aberrated directions, the fix is
turned by the aberration rotation of its boresight; the reported catalog directions stay the
catalog's. Their noise does not depend on the filter, so a run draws every frame's measurements
when it starts (:meth:`StarVectorSensor.start`): the loop reads them frame by frame
(:class:`VectorRun`), or the filter takes the whole :class:`Record` at once on its compiled fast path.
"""

from dataclasses import dataclass

import numpy as np

from navsim.earth.apparent import fix_rotation
from navsim.sensors.recorded_run import RecordedRun
from navsim.sensors.star_sensor import StarFrame, isotropic_covariance
from startrack import rotation as rot
from startrack.aberration import aberrate


def tangent_basis(s):
    """Two orthonormal rows (N, 2, 3) spanning the plane perpendicular to each unit vector s (N, 3)."""
    helper = np.zeros_like(s)
    helper[np.arange(len(s)), np.argmin(np.abs(s), axis=1)] = 1.0
    e1 = np.cross(s, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return np.stack([e1, np.cross(s, e1)], axis=1)


@dataclass(frozen=True)
class StarFrames:
    """Star measurements of many frames, concatenated: frame f owns rows offsets[f]:offsets[f+1]."""

    offsets: np.ndarray
    ref_I: np.ndarray
    obs_S: np.ndarray
    ids: np.ndarray

    def frame(self, f):
        """(ref_I (N, 3), obs_S (N, 3), ids (N,)) of frame f."""
        rows = slice(self.offsets[f], self.offsets[f + 1])
        return self.ref_I[rows], self.obs_S[rows], self.ids[rows]


@dataclass(frozen=True)
class StarVectorSensor:
    """Stars brighter than the catalog cut inside the cone of half-angle fov/2 around +z_S.

    ``star_vectors`` (M, 3) unit vectors in I, ``star_ids`` (M,), ``star_mags`` (M,);
    ``fov`` full cone angle [rad]; ``sigma`` 1σ direction error per tangent axis [rad];
    ``max_stars`` the most (brightest) stars reported; ``q_BS_true`` true mounting.
    """

    star_vectors: np.ndarray
    star_ids: np.ndarray
    star_mags: np.ndarray
    fov: float
    sigma: float
    max_stars: int
    q_BS_true: np.ndarray
    faults: object  # navsim.sensors.faults.SensorFaults

    def start(self, seed, q_IB_frames, t_frames, v_I=None):
        """A run's sensor: every frame's stars drawn from ``seed`` for the true attitudes q_IB_frames
        (and observer velocities ``v_I`` (F, 3) [m/s], None: no aberration)."""
        stars = self.observe_frames(q_IB_frames, np.random.default_rng(seed), v_I)
        return VectorRun(Record(available=self.faults.available(t_frames), stars=stars, sigma=self.sigma))

    def observe_frames(self, q_IB_true, rng, v_I=None, chunk=512):
        """Noisy star vectors for every true attitude q_IB_true (F, 4) -> :class:`StarFrames`.

        A star is seen when its angle from the boresight is at most fov/2; the ``max_stars``
        brightest are reported, brightest first; each is measured at its apparent direction for the
        frame's observer velocity ``v_I`` (F, 3) (None: its catalog direction) with a direction noise
        isotropic in the plane perpendicular to it.
        """
        q_IS = rot.multiply(np.atleast_2d(q_IB_true), self.q_BS_true)
        order = np.argsort(self.star_mags, kind="stable")
        catalog = self.star_vectors[order]
        boresight = rot.rotate(q_IS, np.array([0.0, 0.0, 1.0]))
        cos_half = np.cos(0.5 * self.fov)
        frames, stars = [], []
        for start in range(0, len(q_IS), chunk):
            axes = boresight[start : start + chunk]
            near = _near(catalog, axes, 0.5 * self.fov)
            inside = axes @ catalog[near].T >= cos_half
            inside &= np.cumsum(inside, axis=1) <= self.max_stars
            f, k = np.nonzero(inside)
            frames.append(f + start)
            stars.append(near[k])
        frame = np.concatenate(frames)
        index = order[np.concatenate(stars)]
        ref_I = self.star_vectors[index]
        seen_I = ref_I if v_I is None else aberrate(ref_I, np.asarray(v_I)[frame])
        s_true = rot.rotate(rot.conjugate(q_IS[frame]), seen_I)
        noise = np.einsum("nij,ni->nj", tangent_basis(s_true), self.sigma * rng.standard_normal((len(index), 2)))
        obs = s_true + noise
        obs /= np.linalg.norm(obs, axis=1, keepdims=True)
        offsets = np.concatenate([[0], np.cumsum(np.bincount(frame, minlength=len(q_IS)))])
        return StarFrames(offsets=offsets, ref_I=ref_I, obs_S=obs, ids=self.star_ids[index])


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

    def start(self, seed, q_IB_frames, t_frames, v_I=None):
        """A run's sensor: every frame's fix drawn from ``seed`` for the true attitudes q_IB_frames (and
        observer velocities ``v_I`` (F, 3) [m/s], None: no aberration)."""
        fixes = self.observe_frames(q_IB_frames, np.random.default_rng(seed), v_I)
        return VectorRun(Record(available=self.faults.available(t_frames), fixes=fixes, R_S=self.R_S))

    @property
    def R_S(self):
        return np.diag([self.sigma_cross**2, self.sigma_cross**2, self.sigma_roll**2])

    def observe_frames(self, q_IB_true, rng, v_I=None):
        """Measured q_IS = q_R⁻¹ ⊗ q_IS,true ⊗ exp(ν/2), ν ~ N(0, R_S) in sensor axes, for q_IB_true
        (F, 4): q_R the aberration rotation of the boresight for the observer velocities ``v_I`` (F, 3)
        (:func:`navsim.earth.apparent.fix_rotation`; None: no aberration)."""
        q_IS = rot.multiply(np.atleast_2d(q_IB_true), self.q_BS_true)
        if v_I is not None:
            q_R = fix_rotation(rot.rotate(q_IS, np.array([0.0, 0.0, 1.0])), np.asarray(v_I))
            q_IS = rot.multiply(rot.conjugate(q_R), q_IS)
        sigma = np.array([self.sigma_cross, self.sigma_cross, self.sigma_roll])
        nu = sigma * rng.standard_normal((len(q_IS), 3))
        return rot.multiply(q_IS, rot.from_rotation_vector(nu))


@dataclass(frozen=True)
class Record:
    """Every frame's measurements of a vector-fidelity run: attitude ``fixes`` (F, 4) with ``R_S``,
    or ``stars`` (:class:`StarFrames`) with their direction σ [rad]; ``available`` (F,) False for
    frames lost to an outage or dropped."""

    available: np.ndarray
    fixes: np.ndarray | None = None
    R_S: np.ndarray | None = None
    stars: StarFrames | None = None
    sigma: float = 0.0

    def covariances(self):
        """The covariance of every star of every frame (M, 3, 3) [rad², S]: isotropic, σ on each tangent axis."""
        return isotropic_covariance(self.stars.obs_S, self.sigma)


class VectorRun(RecordedRun):
    """The per-run sensor of :class:`StarVectorSensor` and :class:`AttitudeFixSensor`: it reads its
    :class:`Record` frame by frame; tracking state and faults other than lost frames do not apply."""

    def observe(self, request):
        r, j = self._record, request.index
        if not r.available[j]:
            return StarFrame(mode="no_fix")
        if r.fixes is not None:
            return StarFrame(mode="tracking", q_IS=r.fixes[j], R_S=r.R_S)
        ref_I, obs_S, _ = r.stars.frame(j)
        if not len(ref_I):
            return StarFrame(mode="no_fix")
        return StarFrame(mode="tracking", ref_I=ref_I, obs_S=obs_S, cov_S=isotropic_covariance(obs_S, r.sigma))
