"""A replay's run directory: ``scenario.json`` (the checked replay file), ``summary.json``
(:func:`navsim.replay.summary.summarize`) and ``timeseries.npz`` (the per-fix-epoch log of :mod:`navsim.replay.run`:
t [s after the start], lat, lon [rad], h [m], v_n, q_nb, sigma_ned, error_ned [m], accepted, nis, gyro_bias [rad/s],
accel_bias [m/s²], sigma_bias (ε, ∇), outage, held_out, at_rest (the IMU's detector), zupt, nhc (−1 not applied,
0 rejected, 1 accepted) and their NIS zupt_nis, nhc_nis),
written by :func:`navsim.output.write_npz` (no pickle)."""

from pathlib import Path

from navsim.output import write_json, write_npz
from navsim.replay import run, scenario, summary


def replay(path, overrides=()):
    """(data, summary, series) of the replay file ``path`` with ``--set`` ``overrides``."""
    data = scenario.load(path, overrides)
    inputs = run.read(data["replay"])
    series, counts = run.simulate(inputs)
    return data, summary.summarize(data["name"], inputs, series, counts), series


def write(directory, data, result, series):
    """Write a replay into ``directory``."""
    directory = Path(directory)
    write_json(directory / "scenario.json", data)
    write_json(directory / "summary.json", result)
    write_npz(directory / "timeseries.npz", series)
    return directory
