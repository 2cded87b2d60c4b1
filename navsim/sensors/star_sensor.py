"""The star sensor as the closed loop sees it: one request per frame in, one :class:`StarFrame` out.

A star sensor (vector fidelity: :mod:`navsim.sensors.star_vector`; image fidelity:
:mod:`navsim.sensors.star_image`) is built once from the validated scenario, in SI units, and
shared by the runs of a batch. ``sensor.start(seed, ...)`` returns the run's own sensor state,
which answers three calls:

- ``observe(request) -> StarFrame``: the frame's measurements (identified star vectors with their
  covariances, or an attitude fix), the mode used, counts, timings and the diagnostics observers read;
- ``after_update(update, posterior)``: the filter's verdict on the frame (tracking continues while it accepts
  the stars), ``None`` when nothing was fused, and for a run that ``uses_prior`` the filter's :class:`SensorPrior`
  after the frame's updates (None otherwise);
- ``lose_track()``: the estimate was knocked off (attitude-jump fault), start acquiring again.

``uses_prediction`` says whether the run points itself with the filter's predicted attitude and rate
(the image-fidelity sensor does; pre-drawn vector-fidelity frames do not); ``uses_prior`` whether it identifies
its stars with the filter's prior and its covariance (:mod:`navsim.sensors.star_prior`).

``record()`` returns the measurements of every frame when they are known before the run (vector
fidelity: they do not depend on the filter), which lets the filter take its compiled fast path;
otherwise None. ``log_fields`` declares the per-frame quantities the sensor adds to the run log, and
``timing_fields`` those that are wall-clock measurements (kept apart: they differ between runs of one seed).
"""

from dataclasses import dataclass, field

import numpy as np

#: Frame modes, in the order of their integer codes in the time series.
MODES = ("tracking", "subcatalog", "lost_in_space", "stacked", "no_fix", "outage", "dropped", "excluded", "prior")
MODE_CODE = {name: code for code, name in enumerate(MODES)}


def isotropic_covariance(obs_S, sigma):
    """The covariances (N, 3, 3) of unit vectors ``obs_S`` (N, 3) measured with the same σ [rad] on each axis
    of their tangent plane: σ² (I − s sᵀ) (``sigma`` a number or one per vector)."""
    obs_S = np.asarray(obs_S, dtype=float)
    sigma2 = np.broadcast_to(np.asarray(sigma, dtype=float) ** 2, (len(obs_S),))
    return sigma2[:, None, None] * (np.eye(3) - obs_S[:, :, None] * obs_S[:, None, :])


@dataclass(frozen=True)
class FrameRequest:
    """What the loop knows at a frame: its index and time [s], the truth record of the frame (for
    the star sensor :class:`~navsim.truth.profiles.FrameTruth`: q_IB and the body rate over the last
    gyro interval [rad/s], from which the sky is seen) and, for a sensor run that ``uses_prediction``,
    the filter's prediction of the sensor attitude q_IS and of the rate in sensor axes [rad/s] (of a spacecraft's
    head h: ``predict(h)``); for one that ``uses_prior``, the filter's :class:`SensorPrior`."""

    index: int
    t: float
    truth: object
    q_IS_pred: np.ndarray | None = None
    omega_S_pred: np.ndarray | None = None
    prior: object = None
    predict: object = None


@dataclass(frozen=True)
class SensorPrior:
    """What the filter knows of the sensor's attitude at a frame: its estimate ``q_IS``, the covariance ``P_theta``
    (3, 3) [rad², sensor axes] of its error, ``apparent``, its processing's map of catalog unit vectors (K, 3)
    in I to the apparent directions it predicts them at (aberration and refraction as it corrects them), and what
    its attitude error gains over a time: the gyro's angle random walk ``arw`` [rad/√s] it assumes and the
    covariance ``P_bias`` (3, 3) [rad²/s², sensor axes] of its gyro-bias error (:meth:`drift`)."""

    q_IS: np.ndarray
    P_theta: np.ndarray
    apparent: object
    arw: float = 0.0
    P_bias: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def drift(self, dt):
        """The covariance (3, 3) [rad², sensor axes] of the attitude error the INS gains over ``dt`` [s] from now:
        N² dt I + dt² P_ε, from φ̇ = … − C_wb ε − w of :func:`navsim.estimation.nav_kernels.continuous_f` (the gyro's white noise
        and its bias error; the Earth-rate and transport terms, ω dt of the error, and the scale factor's error times
        the turn are neglected)."""
        return self.arw**2 * dt * np.eye(3) + dt**2 * self.P_bias


@dataclass(frozen=True)
class StarFrame:
    """One frame's output. Measurements: ``ref_I``/``obs_S`` (N, 3) with the covariance of each measured
    direction ``cov_S`` (N, 3, 3) [rad², sensor axes] (a stacked dim star last, counted by ``n_stacked``),
    or an attitude fix ``q_IS`` with covariance
    ``R_S`` in sensor axes. ``fix_q_IS``: the attitude of a sub-catalog or full-sky identification,
    from which the filter may be re-initialised when it rejects the stars (a lost track).
    ``info``: the per-frame log quantities (``log_fields``); ``diagnostics``: what observers read
    (detections, the stacked star, the true sensor attitude); ``aiding``: the measurements of the other
    sensors of the same frame (an INS's baro and position fixes), fused after the star sensor's. A spacecraft's
    several heads (:mod:`navsim.sensors.star_heads`) give ``heads``: the head of each star, or with fixes ``q_IS``
    (K, 4) and ``R_S`` (K, 3, 3) of the heads ``heads`` (K,), each fused through its head's mounting."""

    mode: str
    reason: str = ""
    ref_I: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    obs_S: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    cov_S: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3)))
    n_stacked: int = 0
    q_IS: np.ndarray | None = None
    R_S: np.ndarray | None = None
    fix_q_IS: np.ndarray | None = None
    info: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)
    aiding: tuple = ()
    heads: np.ndarray | None = None

    @property
    def star_measurements(self):
        """((kind, arguments of the filter's update), ...) of the star sensor: an attitude fix (one per head), stars
        or nothing."""
        if self.q_IS is not None and self.heads is not None:
            return tuple(("attitude", (q, R, int(h))) for q, R, h in zip(self.q_IS, self.R_S, self.heads))
        if self.q_IS is not None:
            return (("attitude", (self.q_IS, self.R_S)),)
        if len(self.ref_I):
            heads = () if self.heads is None else (self.heads,)
            return (("stars", (self.ref_I, self.obs_S, self.cov_S, *heads)),)
        return ()

    @property
    def measurements(self):
        """((kind, arguments of the filter's update), ...) of the frame: the star sensor's, then ``aiding``."""
        return self.star_measurements + self.aiding
