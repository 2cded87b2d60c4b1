"""Load every compiled kernel of an identifier before its first frame (no solve pays for compilation).

Numba compiles (or loads from its on-disk cache, :mod:`startrack.compiled.numba_setup`) a kernel and everything it calls
at its first call with a given set of argument types.  :func:`load_kernels` therefore runs each strategy
of the identifier once on a frame of its own field stars (identified) and once on a frame of points on a
circle (not identifiable: the search runs to its end, through every fall-back), then one whole solve.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from startrack.identify.prior import Prior

#: Centroids of the unidentifiable frame (points on a circle: no sky looks like it).
_CIRCLE_POINTS = 8


def _sky_frame(identifier):
    """(uv, q_IS) of the field stars seen from the first of a few fixed attitudes that shows >= 6 of them."""
    camera, field = identifier.camera, identifier.field
    for angle in np.linspace(0.3, 3.0, 10):
        q_IS = Rotation.from_rotvec([angle, 0.5 * angle, 0.2]).as_quat()
        seen = camera.stars_in_field(q_IS, field.vectors)
        if seen.size >= 6:
            uv, _ = camera.project(q_IS, field.vectors[seen[:40]])
            return uv, q_IS
    return None, None


def _circle_frame(camera):
    phase = 2.0 * np.pi * np.arange(_CIRCLE_POINTS) / _CIRCLE_POINTS
    radius = 0.3 * min(camera.width, camera.height)
    return np.column_stack([camera.cx + radius * np.cos(phase), camera.cy + radius * np.sin(phase)])


def load_kernels(identifier) -> None:
    """Run every strategy of ``identifier`` on an identifiable and an unidentifiable frame, then solve once."""
    uv, q_IS = _sky_frame(identifier)
    frames = [_circle_frame(identifier.camera)] + ([] if uv is None else [uv])
    for frame_uv in frames:
        prior = Prior(q_IS=np.array([0.0, 0.0, 0.0, 1.0]) if q_IS is None else q_IS)
        frame = identifier.features(identifier.camera.unproject(frame_uv), np.arange(len(frame_uv)))
        for strategy in identifier.strategies:
            strategy.identify(frame, prior)
    if uv is not None:
        identifier.solve(uv, prior=Prior(q_IS=q_IS))
