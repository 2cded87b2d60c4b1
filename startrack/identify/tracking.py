"""Star tracking: identification from a prior attitude (and rate) by windows around predicted stars.

From the prior attitude R_IS(t0) and the body rate omega_S [rad/s] (sensor axes, constant over the
interval dt), the attitude at the frame is R_IS(t0 + dt) = R_IS(t0) exp([omega_S x] dt) (the
quaternion kinematics of 000 eq. 9 integrated exactly for a constant rate).  Every field star that
then projects inside the image (grown by the window) is predicted; each centroid is matched to its
nearest predicted star and back (one-to-one) if they lie within the tracking window; with three or
more matches the attitude is refitted by SVD and verified like a lost-in-space hypothesis
(:func:`startrack.identify.verify.verify` with the window as its first gate, one hypothesis -- the
prior -- and no seed stars).  Stars entering the field are simply new predictions, stars
leaving it drop out of the prediction; the stars tracked before that are predicted in the field but
not found now are reported as lost.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from startrack.identify.verify import verify


def propagate(q_IS, rate_S, dt: float):
    """R_IS (3, 3) at dt [s] after the attitude q_IS for the constant body rate rate_S [rad/s] (sensor axes)."""
    rotation = Rotation.from_quat(q_IS)
    if rate_S is not None and dt != 0.0:
        rotation = rotation * Rotation.from_rotvec(np.asarray(rate_S, dtype=float) * dt)
    return rotation.as_matrix()


class Tracking:
    """Identification by tracking windows around the stars predicted from the prior attitude."""

    name = "tracking"

    def __init__(self, field, window_px: float, threshold: float):
        self.field = field
        self.window_px = float(window_px)
        self.threshold = threshold

    def identify(self, frame, prior):
        """Verified solution or None; needs ``prior.q_IS``."""
        if prior is None or prior.q_IS is None:
            return None
        R_IS = propagate(prior.q_IS, prior.rate_S, prior.dt)
        return verify(frame.obs_S, R_IS, self.field, frame.verify_gate, n_hypotheses=1, threshold=self.threshold,
                      n_seed=0, first_gate=self.window_px / self.field.camera.focal_px)

    def lost_and_entered(self, prior, R_IS, matched_hip):
        """(lost, entered) HIP arrays: tracked stars predicted in the field but unmatched; new matches."""
        tracked = np.zeros(0, np.int64) if prior.tracked_hip is None else np.asarray(prior.tracked_hip, np.int64)
        in_field = self.field.hip[self.field.in_field(R_IS)[0]]
        lost = np.setdiff1d(np.intersect1d(tracked, in_field), matched_hip)
        entered = np.setdiff1d(matched_hip, tracked)
        return lost, entered
