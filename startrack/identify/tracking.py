"""Star tracking: identification from a prior attitude (and rate) by windows around predicted stars.

From the prior attitude R_IS(t0) and the body rate omega_S [rad/s] (sensor axes, constant over the
interval dt), the attitude at the frame is R_IS(t0 + dt) = R_IS(t0) exp([omega_S x] dt) (the
quaternion kinematics of 000 eq. 9 integrated exactly for a constant rate).  Every field star that
then projects inside the image (grown by the window) is predicted; each centroid is matched to its
nearest predicted star and back (one-to-one) if they lie within the tracking window; with three or
more matches the attitude is refitted by SVD and verified like a lost-in-space hypothesis
(:func:`startrack.identify.verify.verify_near` with the window as its first gate, one hypothesis --
the prior -- and no seed stars): one compiled call.  Stars entering the field are simply new predictions, stars
leaving it drop out of the prediction; the stars tracked before that are predicted in the field but
not found now are reported as lost.
"""

from __future__ import annotations

import numpy as np

from startrack.compiled.numba_setup import njit
from startrack.compiled.sorts import unique
from startrack.identify.verify import NO_SEEDS, verify_near


@njit
def propagate(q_IS, rate_S, dt):  # pragma: no cover  (compiled)
    """R_IS (3, 3) at dt [s] after the unit attitude q_IS (scalar-last) for the constant body rate rate_S
    [rad/s] (sensor axes): R(q_IS) exp([rate_S x] dt), the exponential by Rodrigues' formula."""
    x, y, z, w = q_IS
    R = np.array([[1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
                  [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
                  [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)]])
    angle = np.sqrt(rate_S[0] ** 2 + rate_S[1] ** 2 + rate_S[2] ** 2) * abs(dt)
    if angle == 0.0:
        return R
    k = rate_S * np.sign(dt) / (angle / abs(dt))
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return R @ (np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K))


class Tracking:
    """Identification by tracking windows around the stars predicted from the prior attitude."""

    name = "tracking"

    def __init__(self, context, window_px: float):
        self.context = context
        self.field = context.field
        self.window_px = float(window_px)
        self._field = context.with_first_gate(self.window_px / self.field.camera.focal_px)

    def identify(self, frame, prior):
        """Verified solution or None; needs ``prior.q_IS``."""
        if prior is None or prior.q_IS is None:
            return None
        return self.context.verified(verify_near(frame.obs_S, prior.predicted_R_IS, self._field, 1.0, NO_SEEDS))

    def lost_and_entered(self, prior, R_IS, matched_hip):
        """(lost, entered) HIP arrays: tracked stars predicted in the field but unmatched; new matches."""
        if prior.tracked_hip is None or len(prior.tracked_hip) == 0:  # nothing tracked: nothing lost
            return _NO_STARS, np.unique(matched_hip)
        in_field = self.field.hip[self.field.in_field(R_IS)[0]]
        return changes(in_field, np.asarray(prior.tracked_hip, np.int64), matched_hip)


_NO_STARS = np.zeros(0, np.int64)


@njit
def changes(in_field, tracked, matched):  # pragma: no cover  (compiled)
    """(lost, entered) sorted unique HIP arrays: the ``tracked`` HIP numbers that are ``in_field`` and not
    ``matched``; the ``matched`` HIP numbers not ``tracked``."""
    in_field = unique(in_field)
    tracked = unique(tracked)
    matched = unique(matched)
    lost = np.empty(tracked.size, np.int64)
    n_lost = 0
    for h in tracked:
        if _member(in_field, h) and not _member(matched, h):
            lost[n_lost] = h
            n_lost += 1
    entered = np.empty(matched.size, np.int64)
    n_entered = 0
    for h in matched:
        if not _member(tracked, h):
            entered[n_entered] = h
            n_entered += 1
    return lost[:n_lost], entered[:n_entered]


@njit(_nrt=False)
def _member(sorted_values, value):  # pragma: no cover  (compiled)
    """Whether ``value`` is in the ascending array ``sorted_values``."""
    k = np.searchsorted(sorted_values, value)
    return k < sorted_values.size and sorted_values[k] == value
