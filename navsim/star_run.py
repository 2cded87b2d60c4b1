"""A run's star sensor, whatever the kind of run: its random streams, per-frame observers and attitude
jumps before the loop, and what the loop's log says of it afterwards (the modes with their times, the
observers' findings).

At image fidelity the star sensor's stream spawns four, all before the first frame: 0 attitude jumps,
1 false-star storms, 2 rendering, 3 the per-frame observers (docs/design.md, "Randomness").
"""

import numpy as np

from navsim.closed_loop import mode_statistics, mode_timing
from navsim.sensors.faults import AttitudeJumps
from navsim.sensors.star_sensor import MODES
from navsim.studies.common import add_timing


def start_image(sensor, seed, n_frames, filt, observer_specs, jumps):
    """(the image-fidelity sensor's run, the observers' runs, its :class:`~navsim.sensors.faults.AttitudeJumps`
    or None) of a run: ``sensor`` an :class:`~navsim.sensors.star_image.ImageStarSensor`, ``seed`` the star
    sensor's SeedSequence, ``filt`` the run's filter (observers may shadow it), ``observer_specs`` the
    scenario's observers (:func:`navsim.build.star_sensor.observers`), ``jumps`` its attitude jumps in SI."""
    jump_ss, storm_ss, render_ss, observer_ss = seed.spawn(4)
    observer_rng = np.random.default_rng(observer_ss)
    observers = [spec.start(filt, observer_rng, n_frames) for spec in observer_specs]
    full_frames = set().union(*(o.full_frames for o in observers))
    run = sensor.start(np.random.default_rng(storm_ss), np.random.default_rng(render_ss), n_frames, full_frames)
    return run, observers, AttitudeJumps(jumps, np.random.default_rng(jump_ss)) if jumps else None


def finish(summary, series, log, observers, steady):
    """(``summary`` with the sensor's modes and the observers' findings, comparison rows and notes;
    the wall-clock figures for its ``timing``): the observers' series join ``series``."""
    timing = {}
    if log.logs_modes:
        summary = summary.replace(identification=mode_statistics(series, log.transitions), modes=list(MODES))
        timing = mode_timing(series["mode"], log.timing)
    findings = [found for found in (observer.finish(series, steady) for observer in observers) if found is not None]
    for found in findings:
        series.update(found.series)
    add_timing(timing, findings)
    if findings:
        summary = summary.replace(findings={f.key: f.stats for f in findings}, paper_comparison=[r for f in findings for r in f.rows],
                                  notes=[n for f in findings for n in f.notes])
    return summary, timing
