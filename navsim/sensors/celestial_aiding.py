"""The sensors of a star-aided INS (SINS/CNS) as the closed loop sees them: the star sensor (vector or
image fidelity, :mod:`navsim.sensors.star_sensor`) and the open-loop aiding sensors beside it (baro,
position fixes: :mod:`navsim.sensors.aiding`) on one frame grid, the star sensor's (every other
aiding rate divides it). Each frame is the star sensor's :class:`~navsim.sensors.star_sensor.StarFrame`
carrying the aiding measurements of that frame; the star sensor learns the filter's verdict on its
own measurements only."""

import dataclasses


class CelestialAidingRun:
    """The per-run sensors of a star-aided INS: ``star_run`` (a star sensor's run) and ``aiding_run``
    (an :class:`~navsim.sensors.aiding.AidingRun`), frame by frame (the loop's step-by-step path)."""

    def __init__(self, star_run, aiding_run):
        self.star_run, self.aiding_run = star_run, aiding_run
        self.log_fields, self.timing_fields = star_run.log_fields, star_run.timing_fields
        self.uses_prediction, self.uses_prior = star_run.uses_prediction, star_run.uses_prior
        self._star_measured = False

    @property
    def sample(self):
        return self.star_run.sample

    def record(self):
        return None

    def observe(self, request):
        frame = self.star_run.observe(request)
        self._star_measured = bool(frame.star_measurements)
        return dataclasses.replace(frame, aiding=self.aiding_run.observe(request).measurements)

    def after_update(self, update, posterior):
        """The star sensor's part of the frame's verdict (the first update, when it measured)."""
        self.star_run.after_update(update.updates[0] if self._star_measured else None, posterior)

    def lose_track(self):
        self.star_run.lose_track()
