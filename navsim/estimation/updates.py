"""What a filter update returns, and the statistics the run log keeps of a frame's updates.

A measurement is either one vector gated as a whole (an attitude fix, a position fix, a baro height)
or, for identified stars, one 2-dof residual per star, each gated alone (``per_row``). A frame
whose measurements are of several kinds (stars, a position fix and a baro height) is logged with the
statistics of all its updates together (:class:`FrameUpdate`).
"""

from dataclasses import dataclass

import numpy as np

from navsim.estimation import kernels


def star_covariances(cov_S, count, scale=1.0):
    """The covariances (count, 3, 3) [rad², S] of a star update's measured directions, checked and times
    ``scale`` (a filter's tuning factor, ``measurement_noise_scale``²), contiguous for the kernels."""
    cov = np.asarray(cov_S, dtype=float)
    if cov.shape != (count, 3, 3):
        raise ValueError(f"star covariances must have shape ({count}, 3, 3), got {cov.shape}")
    return np.ascontiguousarray(scale * cov)


@dataclass(frozen=True)
class UpdateResult:
    """Outcome of one measurement update: innovations z (one row per measurement), NIS per
    measurement against the prior, the accepted mask, whether each row is a measurement of its own
    (stars) rather than the rows of one vector, whether the state was re-initialised from the
    sensor's own fix before it (a lost track), and the unit of z ("rad" or "m")."""

    z: np.ndarray
    nis: np.ndarray
    accepted: np.ndarray
    per_row: bool = False
    reinitialised: bool = False
    unit: str = "rad"

    @property
    def n_accepted(self):
        return int(np.count_nonzero(self.accepted))

    @property
    def updates(self):
        """The frame's updates in their order: this one (as :attr:`FrameUpdate.updates`)."""
        return (self,)

    @property
    def n_rejected(self):
        return self.accepted.size - self.n_accepted

    def statistics(self):
        """(accepted, NIS sum of the accepted, its dof, RMS of their innovations [rad or m])."""
        if self.per_row:
            return kernels.star_statistics(self.z, self.nis, self.accepted)
        if not self.accepted[0]:
            return 0, np.nan, 0, np.nan
        dof = self.z.shape[1]
        return 1, float(self.nis[0]), dof, float(np.sqrt(np.sum(self.z * self.z) / dof))


@dataclass(frozen=True)
class FrameUpdate:
    """The updates of one frame with measurements of several kinds, logged together: accepted count,
    NIS and dof summed, the RMS over the accepted innovations of the unit of the first update with any
    (a star sensor's [rad] before a baro's [m]; a position fix's and a baro's together [m])."""

    updates: tuple

    @property
    def accepted(self):
        return np.concatenate([u.accepted for u in self.updates])

    @property
    def n_accepted(self):
        return int(np.count_nonzero(self.accepted))

    @property
    def reinitialised(self):
        return any(u.reinitialised for u in self.updates)

    def statistics(self):
        """(accepted, NIS sum of the accepted, its dof, RMS of their innovations), NaN when none was accepted."""
        parts = [(u, u.statistics()) for u in self.updates]
        parts = [(u, stats) for u, stats in parts if stats[0]]
        if not parts:
            return 0, np.nan, 0, np.nan
        unit = parts[0][0].unit
        count, nis, dof, squares, dof_unit = 0, 0.0, 0, 0.0, 0
        for u, (accepted, nis_u, dof_u, _) in parts:
            count, nis, dof = count + accepted, nis + nis_u, dof + dof_u
            if u.unit == unit:
                squares += float(np.sum(u.z[u.accepted] * u.z[u.accepted]))
                dof_unit += dof_u
        return count, nis, dof, float(np.sqrt(squares / dof_unit))
