"""Trade sweeps: a grid over scenario keys, one metric per point, by linear covariance analysis (seconds a
point) or by a Monte Carlo campaign per point; resumable, on local processes or a Dask cluster.

    navsim sweep SCENARIO.toml --vary KEY=V1,V2,... [--vary KEY2=...] --metric NAME[@TIME] --out DIR
                 [--method covariance | --method montecarlo --runs N] [--requirement VALUE]
                 [--workers K | --scheduler tcp://HOST:PORT]

Every point's scenario is validated before anything runs (a key that does not exist, a value of the wrong
type or unit, an empty grid, an unknown metric or a time outside a run: one InputError, nothing written).
``DIR/sweep.json`` holds the request and, once all points are in, the grid of values; each finished point is
``DIR/points/point_NNNNN.json`` (written whole), so an interrupted sweep resumes where it stopped;
``DIR/sweep.csv`` is the table, ``DIR/sweep.pdf`` the requirement chart (:mod:`navsim.report.sweep`).
"""

import itertools
import json
import multiprocessing
import re
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from tqdm import tqdm

from navsim.analysis import check_metric, covariance_metric, montecarlo_metric
from navsim.campaign.montecarlo import SINGLE_THREADED_BLAS, _connect, _environment, load_runs, run_campaign
from navsim.kinds import resolve_scenario, run_kind, scenario_from_dict
from navsim.output import write_json
from navsim.places import check_output, mark
from navsim.scenario import parse_override
from startrack import InputError

FORMAT = "navsim.sweep/1"
METHODS = ("covariance", "montecarlo")
#: The most points of a sweep.
MAX_POINTS = 10_000
POINT = "point_{:05d}"
#: A time: a number with an optional unit.
TIME = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(s|min|h)?\s*$")
TIME_UNITS = {None: 1.0, "s": 1.0, "min": 60.0, "h": 3600.0}


def parse_vary(text):
    """``'imu.gyro.arw_deg_per_sqrt_h=0.001,0.002'`` -> ('imu.gyro.arw_deg_per_sqrt_h', [0.001, 0.002]): each value
    read as TOML (a bare word as a string; an array in brackets is one value)."""
    if "=" not in text:
        raise InputError(f"--vary {text!r}: expected KEY=V1,V2,..., e.g. --vary star_sensor.star_sigma_arcsec=2,5,10")
    key, raw = text.split("=", 1)
    values = [parse_override(f"{key}={item}")[1] for item in _split(raw)]
    if not values:
        raise InputError(f"--vary {key.strip()}: no values (an empty grid)")
    return key.strip(), values


def _split(raw):
    """The comma-separated items of ``raw``, commas inside brackets kept."""
    items, depth, current = [], 0, ""
    for char in raw:
        depth += {"[": 1, "]": -1}.get(char, 0)
        if char == "," and depth == 0:
            items.append(current)
            current = ""
        else:
            current += char
    items.append(current)
    return [item.strip() for item in items if item.strip()]


def parse_metric(text):
    """``'horizontal_position@4h'`` -> ('horizontal_position', 14400.0); no time: the end of the run (None)."""
    name, _, when = text.partition("@")
    if not when:
        return name.strip(), None
    match = TIME.match(when)
    if match is None:
        raise InputError(f"--metric {text}: the time must be a number of s, min or h, e.g. @4h or @1800")
    return name.strip(), float(match.group(1)) * TIME_UNITS[match.group(2)]


def grid(scenario, varies, overrides=()):
    """The points of the grid: [(values, Scenario)], the first key varying slowest; each point is ``scenario`` (a
    path, a dictionary or a Scenario) with ``overrides`` and its values applied, validated."""
    keys = [key for key, _ in varies]
    if len(set(keys)) != len(keys):
        raise InputError(f"--vary: a key given twice ({', '.join(keys)})")
    combos = list(itertools.product(*(values for _, values in varies)))
    if not 1 <= len(combos) <= MAX_POINTS:
        raise InputError(f"--vary: {len(combos)} points; a sweep has 1 to {MAX_POINTS:,}")
    base = [f"{k}={json.dumps(v)}" for k, v in overrides.items()] if isinstance(overrides, dict) else list(overrides)
    points = []
    for combo in combos:
        settings = [f"{key}={json.dumps(value)}" for key, value in zip(keys, combo)]
        try:
            point = resolve_scenario(scenario, [*base, *settings])
        except InputError as error:
            raise InputError(f"--vary {', '.join(settings)}: {error}") from None
        points.append((list(combo), point))
    return points


def run_sweep(scenario, varies, metric, out, method="covariance", runs=None, requirement=None, workers=None,
              scheduler=None, overrides=(), progress=True):
    """Run (or resume) the sweep of ``scenario`` over ``varies`` ([(key, [values])]) for ``metric`` (NAME[@TIME])
    into ``out``; returns the content of ``sweep.json``."""
    source, scenario = scenario, resolve_scenario(scenario, overrides)
    kind = run_kind(scenario, "a sweep")
    if method not in METHODS:
        raise InputError(f"--method {method}: must be one of {', '.join(METHODS)}")
    if method == "covariance" and runs is not None:
        raise InputError("--runs: a Monte Carlo option; the covariance method draws nothing (add --method montecarlo)")
    if method == "montecarlo" and (runs is None or runs < 2):
        raise InputError(f"--runs: --method montecarlo needs at least 2 runs per point, got {runs}")
    if workers is not None and workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    name, time_s = parse_metric(metric)
    points = grid(source, varies, overrides)
    for _, point in points:
        check_metric(point, name, time_s, kind.COVARIANCE_QUANTITIES)
    request = {"format": FORMAT, "scenario": scenario.name, "source": scenario.source, "scenario_data": scenario.data,
               "vary": [[key, values] for key, values in varies], "metric": name, "time_s": time_s, "method": method,
               "runs": runs, "requirement": requirement, "unit": kind.COVARIANCE_QUANTITIES[name][0]}
    directory = check_output(out, "sweep")
    _check_request(directory, request)
    mark(directory, "sweep")
    write_json(directory / "sweep.json", request)
    (directory / "points").mkdir(exist_ok=True)
    todo = [k for k in range(len(points)) if not (directory / "points" / f"{POINT.format(k)}.json").is_file()]
    with tqdm(total=len(points), initial=len(points) - len(todo), desc=f"{scenario.name} sweep", unit="point",
              disable=not progress) as bar:
        if method == "montecarlo":
            for k in todo:
                _montecarlo_point(kind, directory, k, points[k], name, time_s, runs, workers, scheduler)
                bar.update(1)
        else:
            _covariance_points(directory, [(k, points[k]) for k in todo], name, time_s, workers, scheduler, bar)
    result = {**request, "points": [_read_point(directory, k) for k in range(len(points))]}
    write_json(directory / "sweep.json", result)
    _write_csv(directory / "sweep.csv", result)
    return result


def _check_request(directory, request):
    """A sweep directory resumes only the same request."""
    path = directory / "sweep.json"
    if path.is_file():
        held = json.loads(path.read_text(encoding="utf-8"))
        if {k: held.get(k) for k in request} != request:
            raise InputError(f"--out {directory}: holds a sweep of another request (scenario, --vary, --metric, --method "
                             "or --runs); give a new directory")


def covariance_point(data, source, name, time_s):
    """One point by covariance analysis (a worker's job): the metric's value and the filter's σ of it."""
    scenario = scenario_from_dict(data, source=source)
    kind = run_kind(scenario, "a sweep")
    return covariance_metric(kind.covariance_analysis(scenario), name, time_s)


def _covariance_points(directory, todo, name, time_s, workers, scheduler, bar):
    jobs = [(k, point.data, point.source) for k, (_, point) in todo]
    if not jobs:
        return
    if scheduler is not None:
        client = _connect(scheduler) if isinstance(scheduler, str) else scheduler
        from distributed import as_completed as dask_completed

        futures = {client.submit(covariance_point, data, source, name, time_s, pure=False): k for k, data, source in jobs}
        for future in dask_completed(list(futures)):
            _write_point(directory, futures[future], todo, future.result())
            bar.update(1)
        return
    first, jobs = jobs[0], jobs[1:]  # here first: the kernels compile once, the workers load them
    _write_point(directory, first[0], todo, covariance_point(first[1], first[2], name, time_s))
    bar.update(1)
    if workers == 1 or len(jobs) <= 1:
        for k, data, source in jobs:
            _write_point(directory, k, todo, covariance_point(data, source, name, time_s))
            bar.update(1)
        return
    with _environment(SINGLE_THREADED_BLAS):
        pool = ProcessPoolExecutor(max_workers=workers or None, mp_context=multiprocessing.get_context("spawn"))
        futures = {pool.submit(covariance_point, data, source, name, time_s): k for k, data, source in jobs}
    try:
        for future in as_completed(futures):
            _write_point(directory, futures[future], todo, future.result())
            bar.update(1)
    except KeyboardInterrupt:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()


def _montecarlo_point(kind, directory, k, point, name, time_s, runs, workers, scheduler):
    values, scenario = point
    campaign = directory / "points" / POINT.format(k)
    run_campaign(scenario, runs, campaign, workers=workers, scheduler=scheduler, progress=False)
    _, finished, _ = load_runs(campaign)
    if not finished:
        raise InputError(f"sweep point {k} ({values}): no run finished ({campaign}/runs/*/error.json)")
    _write_point(directory, k, [(k, point)], montecarlo_metric(
        [series for _, _, series in finished], name, time_s, kind.covariance_run_errors(scenario), kind.COVARIANCE_QUANTITIES[name][1]))


def _write_point(directory, k, todo, metric):
    values = dict(todo)[k][0]
    path = directory / "points" / f"{POINT.format(k)}.json"
    partial = path.with_suffix(".partial")
    write_json(partial, {"index": k, "values": values, **metric})
    partial.replace(path)


def _read_point(directory, k):
    return json.loads((directory / "points" / f"{POINT.format(k)}.json").read_text(encoding="utf-8"))


def _write_csv(path, result):
    keys = [key for key, _ in result["vary"]]
    unit = result["unit"]
    lines = [",".join([*keys, f"{result['metric']} [{unit}]", f"filter sigma [{unit}]"])]
    for point in result["points"]:
        lines.append(",".join([*(json.dumps(v) if not isinstance(v, str) else v for v in point["values"]),
                               f"{point['value']:.6g}", "" if point.get("filter_sigma") is None else f"{point['filter_sigma']:.6g}"]))
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
