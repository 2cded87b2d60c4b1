"""The driver loop of docs/design.md: truth -> IMU -> predict -> sensors -> update -> log.

One loop serves every filter and every sensor run of a simulation: the attitude filter with a star
sensor (:mod:`navsim.sensors.star_sensor`), the navigation filter with its aiding sensors
(:mod:`navsim.sensors.aiding`). A filter offers ``predict(samples, dt)``, an update per measurement
kind it takes (:data:`UPDATES`), ``snapshot()`` and, with a star sensor, ``sensor_prediction(last_sample)``,
``reinitialise(q_IS)`` and ``disturb(rotation_vector)``. Per frame:

1. the filter propagates over the frame's IMU samples (observers see the same samples);
2. faults that knock the estimate off (attitude jumps) are applied, and the sensor loses track;
3. the sensors observe from the truth at the frame (and, for a sensor that points itself with it,
   the filter's predicted attitude and rate);
4. each measurement of the frame goes through the filter's gated update for its kind; when the filter
   rejects every star of a sub-catalog or full-sky identification (it lost track), it is
   re-initialised from that fix and updated again; the sensor learns the verdict;
5. observers (the source documents' per-frame experiments, :mod:`navsim.studies`) see the frame,
   and the log keeps the filter's state, the update statistics and the sensor's quantities.

When every measurement is known before the run (vector fidelity, open-loop aiding) and nothing acts
inside the loop, the filter's compiled fast path (``process_record``) runs the whole record at once;
it is tested equal to the step-by-step loop.
"""

import dataclasses
import functools
import time
from dataclasses import dataclass

import numpy as np

from navsim.estimation.updates import FrameUpdate
from navsim.sensors.star_sensor import MODES, FrameRequest

#: Update statistics logged at every frame: name -> (dtype, value when nothing was fused).
UPDATE_FIELDS = {"n_measurements": (np.int32, 0), "n_accepted": (np.int32, 0), "nis": (np.float64, np.nan),
                 "nis_dof": (np.int32, 0), "innovation_rms": (np.float64, np.nan)}


@dataclass(frozen=True)
class FrameGrid:
    """The run's time base: IMU interval dt [s], IMU samples per frame (a star-sensor frame, an aiding
    epoch), frame count."""

    dt: float
    ratio: int
    n_frames: int

    @property
    def frame_k(self):
        """IMU sample index at each frame (the frame closes interval k)."""
        return np.arange(1, self.n_frames + 1) * self.ratio


def run_loop(filt, sensor_run, imu, truth, grid, jumps=None, observers=(), compiled=True):
    """Run ``filt`` with ``sensor_run`` over every frame of ``grid``; returns a :class:`FrameLog`.

    ``imu`` (M, ·) the measured IMU samples (rates [rad/s]; with the specific force [m/s²] beside them
    for the INS); ``truth`` the run's truth on the IMU grid, whose ``at(k)`` is the truth record of
    the frame closing interval k; ``jumps``: an :class:`~navsim.sensors.faults.AttitudeJumps` or None;
    ``observers``: per-run observers; ``compiled``: allow the fast path.
    """
    log = FrameLog(grid.n_frames, sensor_run.log_fields, sensor_run.timing_fields)
    record = sensor_run.record()
    if compiled and record is not None and jumps is None and not observers:
        log.arrays.update(filt.process_record(imu[: grid.n_frames * grid.ratio], grid.ratio, grid.dt, record))
        return log
    for j, k in enumerate(grid.frame_k):
        started = time.perf_counter()
        samples = imu[k - grid.ratio : k]
        filt.predict(samples, grid.dt)
        for observer in observers:
            observer.on_predict(samples, grid.dt)
        for rotation_vector in jumps.due(k * grid.dt) if jumps is not None else ():
            filt.disturb(rotation_vector)
            sensor_run.lose_track()
        prediction = filt.sensor_prediction(imu[k - 1]) if sensor_run.uses_prediction else (None, None)
        request = FrameRequest(index=j, t=k * grid.dt, truth=truth.at(k), q_IS_pred=prediction[0],
                               omega_S_pred=prediction[1], prior=filt.sensor_prior() if sensor_run.uses_prior else None,
                               predict=functools.partial(filt.sensor_prediction, imu[k - 1]) if sensor_run.uses_prediction
                               else None)
        frame = sensor_run.observe(request)
        update = fuse(filt, frame)
        sensor_run.after_update(update, filt.sensor_prior() if sensor_run.uses_prior else None)
        for observer in observers:
            observer.on_frame(request, frame, update)
        log.record(j, request.t, filt.snapshot(), frame, update, 1e3 * (time.perf_counter() - started))
    return log


#: The filter method that takes each kind of measurement a frame may carry (``frame.measurements``).
UPDATES = {"attitude": "update_attitude", "stars": "update_stars", "position": "update_position", "baro": "update_baro"}


def fuse(filt, frame):
    """The gated updates with the frame's measurements, in their order: the update (None when the
    frame has none, a :class:`~navsim.estimation.updates.FrameUpdate` for several kinds). A filter
    that rejects every star of a sub-catalog or full-sky identification has lost track: it is
    re-initialised from that identification's attitude and updated again."""
    updates = []
    for kind, measurement in frame.measurements:
        update = getattr(filt, UPDATES[kind])(*measurement)
        if kind == "stars" and update.n_accepted == 0 and frame.fix_q_IS is not None:
            filt.reinitialise(frame.fix_q_IS)
            update = dataclasses.replace(filt.update_stars(*measurement), reinitialised=True)
        updates.append(update)
    if len(updates) > 1:
        return FrameUpdate(tuple(updates))
    return updates[0] if updates else None


class FrameLog:
    """Per-frame arrays of a run — the filter's snapshot, the update statistics and the sensor's
    ``log_fields`` — and the list of mode transitions with their reasons (``arrays``, reproducible
    from the seed); apart, in ``timing``, the wall-clock measurements: the sensor's ``timing_fields``
    and (with a sensor that logs its mode) the time of each frame [ms]."""

    def __init__(self, n_frames, sensor_fields, timing_fields):
        self.n_frames = n_frames
        self.arrays = {name: np.full(n_frames, fill, dtype) for name, (dtype, fill) in UPDATE_FIELDS.items()}
        self.timing = {}
        for fields, target in ((sensor_fields, self.arrays), (timing_fields, self.timing)):
            for name, (shape, dtype, fill) in fields.items():
                target[name] = np.full((n_frames, *shape), fill, dtype)
        self.logs_modes = "mode" in sensor_fields
        if self.logs_modes:
            self.timing["frame_ms"] = np.zeros(n_frames)
        self.transitions = []

    def record(self, j, t, snapshot, frame, update, frame_ms):
        for name, value in snapshot.items():
            if name not in self.arrays:
                self.arrays[name] = np.empty((self.n_frames, *np.shape(value)))
            self.arrays[name][j] = value
        for name, value in frame.info.items():
            (self.timing if name in self.timing else self.arrays)[name][j] = value
        if update is not None:
            self.arrays["n_measurements"][j] = update.accepted.size
            stats = update.statistics()
            for name, value in zip(("n_accepted", "nis", "nis_dof", "innovation_rms"), stats):
                self.arrays[name][j] = value
        if self.logs_modes:
            self.timing["frame_ms"][j] = frame_ms
            self._note_mode(t, frame, update)

    def _note_mode(self, t, frame, update):
        if self.transitions and self.transitions[-1]["mode"] == frame.mode:
            return
        reason = frame.reason + ("; attitude re-initialised from the fix" if update is not None and update.reinitialised else "")
        self.transitions.append({"time_s": float(t), "mode": frame.mode, "reason": reason})


def mode_statistics(arrays, transitions):
    """Per-mode frame counts and identified stars for the run summary."""
    out = {}
    for code, name in enumerate(MODES):
        frames = arrays["mode"] == code
        if frames.any():
            out[name] = {"frames": int(frames.sum()), "identified_stars_mean": float(arrays["n_identified"][frames].mean())}
    return {"modes": list(MODES), "per_mode": out, "transitions": transitions,
            "stacked_frames": int(arrays["n_stacked"].sum())}


def mode_timing(mode, timing):
    """Wall-clock figures of the run summary's ``timing``: identification time per mode and the
    frame time [ms] (median, p95)."""
    out = {}
    for code, name in enumerate(MODES):
        ms = timing["id_ms"][(mode == code) & np.isfinite(timing["id_ms"])]
        if ms.size:
            out[name] = {"id_ms_median": float(np.median(ms)), "id_ms_p95": float(np.percentile(ms, 95))}
    frame_ms = timing["frame_ms"]
    return {"identification_ms": out, "frame_ms": {"median": float(np.median(frame_ms)),
                                                   "p95": float(np.percentile(frame_ms, 95)),
                                                   "max": float(frame_ms.max())}}
