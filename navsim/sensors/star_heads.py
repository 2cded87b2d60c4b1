"""A spacecraft's star-sensor heads (2-3, or one) as one sensor of the closed loop, at vector fidelity
(:class:`StarHeads`) or image fidelity (:class:`ImageHeads`: each head renders, detects and identifies its own frame
with its own prediction, and the frame fuses every head's stars).

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
from navsim.sensors.star_image import LOG_FIELDS, TIMING_FIELDS
from navsim.sensors.star_sensor import StarFrame, isotropic_covariance
from navsim.sensors.star_vector import Record, StarFrames
from startrack import aberrate
from startrack import rotation as rot


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


#: A head's frame modes in the order the heads' frame takes the best of them (a scalar per frame for the reports).
MODE_ORDER = ("tracking", "subcatalog", "lost_in_space", "stacked", "prior", "no_fix", "excluded", "outage", "dropped")
#: An identified star farther than this from where the truth puts its catalog star is a wrong identification [px].
WRONG_PX = 5.0
#: The heads' per-frame log (H per field): each head's mode, detections, identified stars, particle hits and wrong
#: identifications (the truth's check), beside the scalar fields of one sensor (their sums, the best mode, head 0's
#: pointing).
HEAD_FIELDS = ("head_mode", "head_detected", "head_identified", "head_hits", "head_wrong")


@dataclass(frozen=True)
class ImageHeads:
    """The heads at image fidelity: ``heads`` (:class:`~navsim.sensors.star_image.ImageStarSensor`, each with its
    true mounting, faults, exclusions, stray light and particle hits), their ``names``, nominal mountings ``q_BS``
    (H, 4), the σ [rad] of each head's mounting error drawn per run (``misalignment_sigma``) and whether its processing
    aberrates the identified stars' catalog directions with the orbit's velocity (``aberration_correction``)."""

    heads: tuple
    names: tuple
    q_BS: np.ndarray
    misalignment_sigma: tuple
    aberration_correction: tuple

    def start(self, seed, n_frames):
        """A run's sensor (:class:`ImageHeadsRun`): each head's child of the SeedSequence ``seed`` spawns three, the
        mounting draw, the false stars and particle hits, the rendering."""
        runs = []
        for head, sigma, child in zip(self.heads, self.misalignment_sigma, seed.spawn(len(self.heads))):
            draw_ss, storm_ss, render_ss = child.spawn(3)
            error = sigma * np.random.default_rng(draw_ss).standard_normal(3)
            head = replace(head, q_BS_true=rot.multiply(head.q_BS_true, rot.from_rotation_vector(error)))
            runs.append(head.start(np.random.default_rng(storm_ss), np.random.default_rng(render_ss), n_frames))
        return ImageHeadsRun(runs, self.q_BS, self.aberration_correction)


@dataclass(frozen=True)
class _Verdict:
    """A head's share of the filter's verdict on a frame (what :meth:`ImageRun.after_update` reads)."""

    n_accepted: int


class ImageHeadsRun:
    """The per-run sensor of :class:`ImageHeads`: each head observes with its own predicted attitude
    (``request.predict(h)``) and the frame fuses their stars together, each with its head."""

    uses_prediction = True
    uses_prior = False

    def __init__(self, runs, q_BS, aberration_correction):
        self.runs, self.q_BS, self.correction = runs, q_BS, aberration_correction
        H = len(runs)
        self.log_fields = {**LOG_FIELDS, **{name: ((H,), np.int32, 0) for name in HEAD_FIELDS}}
        self.timing_fields = TIMING_FIELDS
        self.q_BS_true = np.array([run.sensor.q_BS_true for run in runs])
        self._heads = np.zeros(0, dtype=np.int64)

    @property
    def sample(self):
        return self.runs[0].sample

    def record(self):
        return None

    def lose_track(self):
        for run in self.runs:
            run.lose_track()

    def after_update(self, update, posterior):
        """Each head's tracking follows the filter's verdict on its own stars."""
        for h, run in enumerate(self.runs):
            run.after_update(None if update is None else _Verdict(int(np.count_nonzero(update.accepted[self._heads == h]))),
                             posterior)

    def observe(self, request):
        frames = []
        for h, run in enumerate(self.runs):
            q_IS, omega_S = request.predict(h)
            frames.append(run.observe(replace(request, q_IS_pred=q_IS, omega_S_pred=omega_S)))
        self._heads = np.concatenate([np.full(len(f.ref_I), h) for h, f in enumerate(frames)]).astype(np.int64)
        best = min(frames, key=lambda f: MODE_ORDER.index(f.mode))
        info = {**frames[0].info, "mode": best.info["mode"],
                "n_detected": sum(f.info.get("n_detected", 0) for f in frames),
                "n_identified": sum(f.info.get("n_identified", 0) for f in frames),
                "n_stacked": sum(f.n_stacked for f in frames),
                "id_ms": float(np.nansum([f.info.get("id_ms", np.nan) for f in frames])),
                "head_mode": [f.info["mode"] for f in frames], "head_detected": [f.info.get("n_detected", 0) for f in frames],
                "head_identified": [f.info.get("n_identified", 0) for f in frames],
                "head_hits": [run.last_hits for run in self.runs],
                "head_wrong": [self._wrong(request, h, f) for h, f in enumerate(frames)]}
        fix = next(((f.fix_q_IS, h) for h, f in enumerate(frames) if f.fix_q_IS is not None), None)
        v_I = request.truth.v_I
        ref_I = [aberrate(f.ref_I, np.asarray(v_I)) if c and v_I is not None and len(f.ref_I) else f.ref_I
                 for f, c in zip(frames, self.correction)]
        return StarFrame(mode=best.mode, reason=best.reason, ref_I=np.vstack(ref_I),
                         obs_S=np.vstack([f.obs_S for f in frames]), cov_S=np.concatenate([f.cov_S for f in frames]),
                         n_stacked=info["n_stacked"], fix_q_IS=None if fix is None else self._as_head_0(*fix), info=info,
                         heads=self._heads)

    def _as_head_0(self, q_IS, head):
        """Head ``head``'s fix as the attitude of head 0 through the nominal mountings (the filter re-initialises
        from head 0's): q_IS ⊗ q_BS,h⁻¹ ⊗ q_BS,0."""
        return rot.multiply(rot.multiply(q_IS, rot.conjugate(self.q_BS[head])), self.q_BS[0])

    def _wrong(self, request, head, frame):
        """The head's identified stars that the truth places more than :data:`WRONG_PX` from where it measured them
        (their catalog star's apparent direction through the true attitude and mounting)."""
        if not len(frame.ref_I):
            return 0
        run = self.runs[head]
        camera = run.sensor.camera
        q_IS = rot.multiply(request.truth.q_IB, run.sensor.q_BS_true)
        seen = frame.ref_I if request.truth.v_I is None else aberrate(frame.ref_I, np.asarray(request.truth.v_I))
        true = rot.rotate(rot.conjugate(q_IS), seen)
        angle = np.arccos(np.clip(np.sum(true * frame.obs_S, axis=1), -1.0, 1.0))
        return int(np.count_nonzero(angle * camera.focal_px > WRONG_PX))
