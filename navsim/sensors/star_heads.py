"""A spacecraft's star-sensor heads (2-3, or one) as one sensor of the closed loop, at vector fidelity.

Each head is a :class:`~navsim.sensors.star_vector.StarVectorSensor` or an
:class:`~navsim.sensors.star_vector.AttitudeFixSensor` with its own mounting, field, exclusions and faults (all
heads of one measurement kind: stars or fixes). A run draws every head's frames from its own stream (the star
sensor's SeedSequence spawns one per head, in head order) and merges them into one
:class:`~navsim.sensors.star_vector.Record` whose stars carry their head (``StarFrames.head``), or whose fixes are
(F, H, 4) with each head's availability (F, H). A head whose mounting error is uncertain
(``misalignment_sigma``) has its true mounting drawn per run, δm ~ N(0, σ² I) in its axes on top of its given
misalignment (each head's stream spawns two: the draw, then the frames). The filter fuses each measurement through its head's mounting
(:mod:`navsim.estimation.attitude_filter`), on its compiled fast path or frame by frame (:class:`HeadsRun`).

The truth's stars are apparent (the spacecraft's barycentric velocity: ~20" of orbital plus annual aberration);
with ``aberration_correction`` (per head, default) the processing aberrates the catalog directions it fuses with
the velocity it knows from its orbit (taken as the truth's: a GNSS orbit's 0.1 m/s is 0.07 mas), or turns a fix
back by the rotation of its boresight (:mod:`navsim.earth.apparent`).
"""

from dataclasses import dataclass, replace

import numpy as np

from navsim.earth.apparent import fix_rotation
from navsim.sensors.recorded_run import RecordedRun
from navsim.sensors.star_sensor import StarFrame, isotropic_covariance
from navsim.sensors.star_vector import Record, StarFrames
from startrack import rotation as rot
from startrack.aberration import aberrate


@dataclass(frozen=True)
class StarHeads:
    """The heads (``heads``: vector-fidelity sensors, one kind of measurement) with their ``names``, whether the
    processing of each corrects the aberration (``aberration_correction``) and the σ [rad] of each head's mounting
    error drawn per run (``misalignment_sigma``; empty: none)."""

    heads: tuple
    names: tuple
    aberration_correction: tuple
    misalignment_sigma: tuple = ()

    @property
    def fixes(self):
        """True when the heads report attitude fixes, False for star vectors."""
        return not hasattr(self.heads[0], "star_vectors")

    def start(self, seed, q_IB_frames, t_frames, v_I=None, noise=True):
        """A run's sensor (:class:`HeadsRun`): each head's frames drawn from its own child of the SeedSequence
        ``seed`` for the true attitudes ``q_IB_frames`` (F, 4) at ``t_frames`` (F,) [s] seen with the barycentric
        velocities ``v_I`` (F, 3) [m/s] (None: no aberration); ``noise`` False: exact measurements."""
        heads = []
        for head, sigma, child in zip(self.heads, self.misalignment_sigma or (0.0,) * len(self.heads),
                                      seed.spawn(len(self.heads))):
            draw_ss, frames_ss = child.spawn(2)
            error = sigma * np.random.default_rng(draw_ss).standard_normal(3)
            heads.append((replace(head, q_BS_true=rot.multiply(head.q_BS_true, rot.from_rotation_vector(error))), frames_ss))
        records = [head.start(child, q_IB_frames, t_frames, v_I, noise).record() for head, child in heads]
        records = [self._corrected(r, v_I, c) for r, c in zip(records, self.aberration_correction)]
        return HeadsRun(merged_fixes(records) if self.fixes else merged_stars(records),
                        np.array([head.q_BS_true for head, _ in heads]))

    @staticmethod
    def _corrected(record, v_I, correction):
        """The record as the processing fuses it: catalog directions aberrated, or fixes turned back (module
        docstring), when it corrects the aberration of a velocity it has."""
        if v_I is None or not correction:
            return record
        if record.fixes is not None:
            boresight = rot.rotate(record.fixes, np.array([0.0, 0.0, 1.0]))
            return replace(record, fixes=rot.multiply(fix_rotation(boresight, np.asarray(v_I)), record.fixes))
        stars = record.stars
        frame = np.repeat(np.arange(len(stars.offsets) - 1), stars.counts)
        return replace(record, stars=replace(stars, ref_I=aberrate(stars.ref_I, np.asarray(v_I)[frame])))


def merged_fixes(records):
    """One :class:`Record` of the heads' fix records: fixes (F, H, 4), R_S (H, 3, 3), available (F, H)."""
    return Record(available=np.stack([r.available for r in records], axis=1), fixes=np.stack([r.fixes for r in records], axis=1),
                  R_S=np.stack([r.R_S for r in records]))


def merged_stars(records):
    """One :class:`Record` of the heads' star records: per frame the stars of every head available at it, head by
    head, with their head; a frame is available when any head is."""
    frames = len(records[0].available)
    parts, heads, counts = [], [], np.zeros(frames, dtype=np.int64)
    for h, r in enumerate(records):
        kept = np.repeat(r.available, r.stars.counts)
        rows = np.flatnonzero(kept)
        parts.append((rows, r.stars))
        heads.append(np.full(rows.size, h))
        counts += np.bincount(np.repeat(np.arange(frames), r.stars.counts)[rows], minlength=frames)
    frame_of = np.concatenate([np.repeat(np.arange(frames), s.counts)[rows] for rows, s in parts])
    order = np.argsort(frame_of, kind="stable")  # frame by frame, head 0's stars first

    def field(name):
        return np.concatenate([getattr(s, name)[rows] for rows, s in parts])[order]

    stars = StarFrames(offsets=np.concatenate([[0], np.cumsum(counts)]), ref_I=field("ref_I"), obs_S=field("obs_S"),
                       ids=field("ids"), sigma=field("sigma"), index=field("index"), mag=field("mag"),
                       mag_sigma=field("mag_sigma"), head=np.concatenate(heads)[order])
    return Record(available=np.any([r.available for r in records], axis=0) & (counts > 0), stars=stars)


class HeadsRun(RecordedRun):
    """The per-run sensor of :class:`StarHeads`: it reads its merged :class:`Record` frame by frame; ``q_BS_true``
    (H, 4) the heads' true mountings of the run."""

    def __init__(self, record, q_BS_true):
        super().__init__(record)
        self.q_BS_true = q_BS_true

    def observe(self, request):
        r, j = self._record, request.index
        if r.fixes is not None:
            seen = np.flatnonzero(r.available[j])
            if not seen.size:
                return StarFrame(mode="no_fix")
            return StarFrame(mode="tracking", q_IS=r.fixes[j, seen], R_S=r.R_S[seen], heads=seen)
        if not r.available[j]:
            return StarFrame(mode="no_fix")
        ref_I, obs_S, _, sigma = r.stars.frame(j)
        heads = r.stars.head[r.stars.offsets[j] : r.stars.offsets[j + 1]]
        return StarFrame(mode="tracking", ref_I=ref_I, obs_S=obs_S, cov_S=isotropic_covariance(obs_S, sigma), heads=heads)
