"""The per-run sensor whose measurements are drawn before the run (open loop: they do not depend on
the filter): it reads its record frame by frame, logs nothing of its own, needs no prediction, and
neither the filter's verdicts nor faults that knock the estimate off change what it measures. The
record is also what the filter's compiled fast path takes whole (:mod:`navsim.closed_loop`)."""


class RecordedRun:
    """Base of the open-loop sensor runs; a subclass reads frame ``request.index`` of ``self._record``
    in ``observe(request)``."""

    log_fields = {}
    timing_fields = {}
    sample = None
    uses_prediction = False
    uses_prior = False

    def __init__(self, record):
        self._record = record

    def record(self):
        return self._record

    def after_update(self, update, posterior):
        pass

    def lose_track(self):
        pass
