"""What is known before a frame (:class:`Prior`): an attitude estimate and rate, or only a boresight; the
prediction every strategy of the identifier starts from."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError
from startrack.geometry.sphere import radec_to_vector
from startrack.identify.tracking import propagate

_NO_RATE = np.zeros(3)


@dataclass(frozen=True)
class Prior:
    """What is known before the frame: an attitude estimate and rate, or only a boresight.

    q_IS: (4,) attitude estimate at the prior's time (scalar-last, S -> I); rate_S: (3,) body rate
    [rad/s] in sensor axes; dt: time from the prior to the frame [s]; boresight: (ra, dec) [rad],
    used when q_IS is None; tracked_hip: HIP numbers tracked in the previous frame (for the lost and
    entering stars of tracking).
    """

    q_IS: np.ndarray | None = None
    rate_S: np.ndarray | None = None
    dt: float = 0.0
    boresight: tuple[float, float] | None = None
    tracked_hip: np.ndarray | None = None

    def __post_init__(self):
        if self.q_IS is not None:
            q = np.asarray(self.q_IS, dtype=float)
            if q.shape != (4,) or not np.all(np.isfinite(q)) or not np.linalg.norm(q) > 0.0:
                raise InputError(f"prior q_IS must be 4 finite numbers, not all zero; got {self.q_IS!r}.")
            object.__setattr__(self, "q_IS", q / np.linalg.norm(q))
        if self.rate_S is not None:
            rate = np.asarray(self.rate_S, dtype=float)
            if rate.shape != (3,) or not np.all(np.isfinite(rate)):
                raise InputError(f"prior rate_S must be 3 finite numbers [rad/s]; got {self.rate_S!r}.")
            object.__setattr__(self, "rate_S", rate)
        if not math.isfinite(self.dt):
            raise InputError(f"prior dt must be a finite number of seconds; got {self.dt!r}.")
        if self.boresight is not None and (len(self.boresight) != 2 or not all(math.isfinite(x) for x in self.boresight)
                                           or abs(self.boresight[1]) > math.pi / 2):
            raise InputError(f"prior boresight must be (ra, dec) in rad with |dec| <= pi/2; got {self.boresight!r}.")

    @functools.cached_property
    def predicted_R_IS(self):
        """R_IS (3, 3) predicted at the frame (the prior propagated by ``rate_S`` over ``dt``), or None."""
        if self.q_IS is None:
            return None
        return propagate(self.q_IS, _NO_RATE if self.rate_S is None else self.rate_S, float(self.dt))

    def boresight_vector(self):
        """Unit vector (3,) in I of the predicted boresight, or None."""
        if self.q_IS is not None:
            return np.ascontiguousarray(self.predicted_R_IS[:, 2])
        if self.boresight is not None:
            return radec_to_vector(*self.boresight)
        return None

    def boresight_radec(self):
        """(ra, dec) [rad] of the predicted boresight, or None."""
        if self.q_IS is not None:
            x, y, z = self.predicted_R_IS[:, 2].tolist()
            return math.atan2(y, x) % (2.0 * math.pi), math.asin(max(-1.0, min(1.0, z)))
        if self.boresight is not None:
            return float(self.boresight[0]), float(self.boresight[1])
        return None
