"""Monte Carlo campaigns: many seeded runs of one scenario, resumable, on a pool or a Dask cluster.

Layout of a campaign directory::

    DIR/campaign.json            what was asked (scenario, overrides, base seed, runs, truth sources
                                 switched off) and the backend
    DIR/runs/run_00000/          one finished run: scenario.json, summary.json, timeseries.npz
    DIR/runs/run_00007/error.json   a run that raised: its error and traceback
    DIR/summary.json             the aggregate of all finished runs

Run k uses the integer seed drawn from ``SeedSequence(base_seed, spawn_key=(k,))``, so its numbers
do not depend on which backend ran it, on how many workers there were, or on whether the campaign
was interrupted. Each run is written to a temporary directory and renamed into place when
complete, so a killed campaign leaves only whole runs; rerunning the command runs only the missing
ones. The aggregate is computed from the files, in run order, and is therefore identical whichever
way the runs were produced. A navigation campaign may switch error sources off in the truth alone
(``truth_off``, the kind's ``TRUTH_SOURCES``: the filter stays the scenario's), as the parts of
``navsim budget`` do. The statistics are the runs' kind's (:mod:`navsim.kinds`: ``pool``).
"""

import contextlib
import functools
import json
import multiprocessing
import os
import re
import shutil
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
from tqdm import tqdm

from navsim.kinds import of, resolve_scenario, run_kind, validate
from navsim.output import read_npz, write_json, write_run
from navsim.places import campaign_lock, check_output, mark, output_kind
from navsim.scenario import Scenario
from navsim.simulation import prepare, simulate
from navsim.studies import observers
from navsim.studies.common import add_timing
from startrack import InputError, compile_ahead, interrupted

RUN_DIR = "run_{:05d}"


def run_seed(base_seed, index):
    """The integer seed of run ``index`` of a campaign with ``base_seed``."""
    state = np.random.SeedSequence(base_seed, spawn_key=(index,)).generate_state(1, dtype=np.uint32)
    return int(state[0])


#: Time-series frames kept per campaign run (the summary always uses every frame).
CAMPAIGN_MAX_FRAMES = 2000


#: Most runs one campaign holds (its run directories and summaries live on one disk).
MAX_RUNS = 1_000_000
#: Failures a rerun may cure (the machine, not the scenario): retried whenever a campaign resumes.
ENVIRONMENT_ERRORS = (OSError, MemoryError, TimeoutError)


@functools.lru_cache(maxsize=1)
def _prepared(scenario_json, source, truth_off=()):
    """The seed-free part of a campaign's scenario (:func:`navsim.simulation.prepare`, with the truth
    sources ``truth_off`` switched off), computed once per process and kept for every chunk it runs (a
    navigation truth takes seconds per hour)."""
    data = json.loads(scenario_json)
    return prepare(Scenario(data=data, source=source, kind=of(data).NAME), truth_off=frozenset(truth_off))


def run_chunk(scenario_data, source, members, truth_off=()):
    """Run campaign members [(seed, run_dir), ...] of one scenario on its seed-free part (prepared once
    per process), with the truth's sources ``truth_off`` switched off; each run is written atomically,
    and a run that raises is recorded in ``run_dir/error.json`` (with its cause: the scenario, or the
    environment when a rerun may cure it) without stopping the others. Returns the errors."""
    errors = []
    try:
        prepared = _prepared(json.dumps(scenario_data, sort_keys=True), source, tuple(sorted(truth_off)))
    except Exception as error:  # the scenario itself fails: every member records it
        prepared, failure = None, error
    for seed, run_dir in members:
        run_dir = Path(run_dir)
        partial = run_dir.with_name(run_dir.name + ".partial")
        shutil.rmtree(partial, ignore_errors=True)
        try:
            if prepared is None:
                raise failure
            write_run(partial, simulate(prepared, seed), max_frames=CAMPAIGN_MAX_FRAMES)
            shutil.rmtree(run_dir, ignore_errors=True)
            os.replace(partial, run_dir)
        except KeyboardInterrupt:
            shutil.rmtree(partial, ignore_errors=True)
            raise
        except Exception as error:  # recorded, not raised: one bad run must not stop the others
            shutil.rmtree(partial, ignore_errors=True)
            if interrupted(error):
                raise KeyboardInterrupt from error
            errors.append(_record_failure(run_dir, seed, error))
    return errors



def _record_failure(run_dir, seed, error):
    message = f"{type(error).__name__}: {error}"
    cause = "environment" if isinstance(error, ENVIRONMENT_ERRORS) else "scenario"
    try:
        shutil.rmtree(run_dir, ignore_errors=True)
        run_dir.mkdir(parents=True, exist_ok=True)
        write_json(run_dir / "error.json", {"seed": seed, "error": message, "cause": cause,
                                            "traceback": traceback.format_exc()})
    except OSError:  # the disk refuses even the error record: the run stays pending
        pass
    return message


def _prepare(directory, scenario, runs, base_seed, backend, truth_off=()):
    """Write campaign.json (checked against an earlier one for a resume); returns the request. The
    truth sources switched off are recorded only when there are some (``truth_off``)."""
    request = {"scenario": scenario.name, "source": scenario.source, "base_seed": base_seed, "backend": backend,
               "runs": runs, "scenario_data": scenario.data}
    if truth_off:
        request["truth_off"] = sorted(truth_off)
    path = directory / "campaign.json"
    same = ("scenario_data", "base_seed", "truth_off")
    if path.exists():
        previous = _read_request(path)
        if {k: previous.get(k) for k in same} != {k: request.get(k) for k in same}:
            raise InputError(f"{directory}: holds a different campaign (scenario, overrides or seed differ); "
                             "use a new --out directory")
        request["runs"] = max(runs, int(previous.get("runs", 0)))
    (directory / "runs").mkdir(parents=True, exist_ok=True)
    write_json(path, request)
    return request


def _read_request(path):
    try:
        previous = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise InputError(f"{path}: not a readable campaign file (not JSON)") from None
    if not isinstance(previous, dict) or not isinstance(previous.get("runs"), int):
        raise InputError(f"{path}: not a campaign file (expected an object with runs, base_seed and scenario_data)")
    return previous


def pending_runs(directory, request, retry_failed=False):
    """Indices of runs to do: neither finished nor failed, or failed for a cause outside the scenario
    (a full disk, a killed worker: retried on every resume), or failed at all with ``retry_failed``."""
    runs_dir = Path(directory) / "runs"
    todo = []
    for k in range(request["runs"]):
        run_dir = runs_dir / RUN_DIR.format(k)
        if (run_dir / "summary.json").exists():
            continue
        error = run_dir / "error.json"
        if not error.exists() or retry_failed or _failure_cause(error) != "scenario":
            todo.append(k)
    return todo


def _failure_cause(path):
    try:
        return json.loads(path.read_text(encoding="utf-8")).get("cause", "scenario")
    except (OSError, ValueError, AttributeError):
        return "environment"


def run_campaign(scenario, runs, out, base_seed=None, overrides=(), workers=None, scheduler=None,
                 progress=True, chunk_size=25, retry_failed=False, truth_off=()):
    """Run (or resume) a campaign; returns the aggregate summary (also written to out/summary.json).

    ``workers``: local processes (default: the machine's cores); ``scheduler``: the address of a
    Dask distributed scheduler ('tcp://host:8786'), or a ``distributed.Client``. Runs are sent in
    chunks of at most ``chunk_size`` that share the scenario's seed-free part. Runs that failed
    for a cause outside the scenario are run again; ``retry_failed`` runs every failed run again.
    Interrupted (Ctrl-C), it cancels what is pending and keeps every finished run. ``truth_off``
    names error sources the truth leaves out, the filter not (the kind's ``TRUTH_SOURCES``).
    """
    if not 1 <= runs <= MAX_RUNS:
        raise InputError(f"--runs must be from 1 to {MAX_RUNS:,}, got {runs}; for more, run several campaigns "
                         "with different --seed")
    scenario = resolve_scenario(scenario, overrides)
    kind = run_kind(scenario, "a Monte Carlo campaign")
    truth_off = sorted(kind.check_truth_off(scenario, truth_off))
    directory = check_output(out, "campaign")
    base_seed = scenario["seed"] if base_seed is None else int(base_seed)
    n_workers = 1 if workers == 1 else (workers or os.cpu_count() or 1)
    client = _connect(scheduler) if isinstance(scheduler, str) else scheduler
    try:
        mark(directory, "campaign")
        with campaign_lock(directory):
            request = _prepare(directory, scenario, runs, base_seed, _backend(scheduler, n_workers), truth_off)
            todo = pending_runs(directory, request, retry_failed)
            members = [(run_seed(base_seed, k), str(directory / "runs" / RUN_DIR.format(k))) for k in todo]
            size = max(1, min(chunk_size, -(-len(members) // (4 * n_workers)) if members else 1))
            chunks = [members[i : i + size] for i in range(0, len(members), size)]
            with tqdm(total=request["runs"], initial=request["runs"] - len(todo), desc=f"{scenario.name} runs",
                      unit="run", disable=not progress) as bar:
                _execute(scenario, chunks, n_workers, client, bar, tuple(truth_off))
            summary = aggregate(directory)
            write_json(directory / "summary.json", summary.to_json())
    finally:
        if client is not None and client is not scheduler:
            client.close()
    return summary


def _execute(scenario, chunks, n_workers, client, bar, truth_off=()):
    """Run the chunks serially, on local processes or on a Dask cluster (``client``)."""
    if not chunks:
        return
    if client is not None:
        _run_dask(scenario, chunks, client, bar, truth_off)
    elif n_workers == 1:
        for chunk in chunks:
            run_chunk(scenario.data, scenario.source, chunk, truth_off)
            bar.update(len(chunk))
    else:
        _run_pool(scenario, chunks, n_workers, bar, truth_off)


#: One BLAS thread per worker process, set before the worker imports numpy: workers whose BLAS
#: starts a thread per core spin against each other on the same cores (2.6 times slower per run on
#: two cores, benchmarks/strapdown.py).
SINGLE_THREADED_BLAS = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@contextlib.contextmanager
def _environment(values):
    """``os.environ`` updated with ``values`` inside the block, restored after it."""
    saved = {key: os.environ.get(key) for key in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key)
            else:
                os.environ[key] = value


def _run_pool(scenario, chunks, n_workers, bar, truth_off=()):
    """Local processes (freshly spawned, single-threaded BLAS), after the kernels are compiled here (once
    for every worker, on every core: :mod:`startrack.compiled.compile_ahead`); on Ctrl-C the pending chunks are
    cancelled and the workers stopped at once."""
    compile_ahead(run_kind(scenario, "a Monte Carlo campaign").lanes(scenario))
    with _environment(SINGLE_THREADED_BLAS):
        pool = ProcessPoolExecutor(max_workers=n_workers, mp_context=multiprocessing.get_context("spawn"))
        futures = {pool.submit(run_chunk, scenario.data, scenario.source, c, truth_off): len(c) for c in chunks}
    try:
        for future in as_completed(futures):
            future.result()
            bar.update(futures[future])
    except KeyboardInterrupt:
        workers = list((getattr(pool, "_processes", None) or {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for process in workers:
            process.terminate()
        raise
    pool.shutdown()


def _backend(scheduler, n_workers):
    """How the runs are produced (recorded in campaign.json; the results do not depend on it)."""
    if scheduler is not None:
        return f"dask {scheduler if isinstance(scheduler, str) else 'client'}"
    return "serial" if n_workers == 1 else f"{n_workers} local processes"


#: A Dask scheduler address: [scheme://]host:port.
SCHEDULER_ADDRESS = re.compile(r"^((tcp|tls|ws|wss|ucx|inproc)://)?[A-Za-z0-9_.\-\[\]:]+:\d{1,5}$")


def _run_dask(scenario, chunks, client, bar, truth_off=()):
    from distributed import as_completed as dask_completed

    futures = [client.submit(run_chunk, scenario.data, scenario.source, chunk, truth_off, pure=False) for chunk in chunks]
    sizes = {future.key: len(chunk) for future, chunk in zip(futures, chunks)}
    for future in dask_completed(futures):
        future.result()
        bar.update(sizes[future.key])


def _connect(address, timeout_s=10):
    """A Dask client of the scheduler at ``address``, or one InputError within ``timeout_s``."""
    if not SCHEDULER_ADDRESS.match(address):
        raise InputError(f"--scheduler {address}: not a scheduler address (expected tcp://HOST:PORT)")
    from distributed import Client

    try:
        return Client(address, timeout=f"{timeout_s}s")
    except (OSError, TimeoutError) as error:
        raise InputError(f"--scheduler {address}: cannot connect within {timeout_s} s ({error})") from None


def _pooled_findings(summaries):
    """The observers' findings pooled over the runs (:func:`navsim.studies.observers`), with their
    comparison rows and notes; their wall-clock figures under ``timing``."""
    pooled = [found for found in (kind.pool(summaries) for kind in observers()) if found is not None]
    timing = {}
    add_timing(timing, pooled)
    if not pooled:
        return {}
    return {"findings": {f.key: f.stats for f in pooled}, "paper_comparison": [r for f in pooled for r in f.rows],
            "notes": [n for f in pooled for n in f.notes], "timing": timing}


def load_runs(directory):
    """(request, [(index, summary, series) of every finished run], [(index, error, cause) of every failed
    one]): the summaries are the records of the campaign's kind."""
    directory = Path(directory)
    request = _read_request(directory / "campaign.json")
    kind = of(request["scenario_data"])
    finished, failed = [], []
    for k in range(request["runs"]):
        run_dir = directory / "runs" / RUN_DIR.format(k)
        if (run_dir / "summary.json").exists():
            finished.append((k, kind.RunSummary.read(run_dir / "summary.json"), read_npz(run_dir / "timeseries.npz")))
        elif (run_dir / "error.json").exists():
            record = json.loads((run_dir / "error.json").read_text())
            failed.append((k, record["error"], record.get("cause", "scenario")))
    return request, finished, failed


def finished_series(directory, scenario, option="--compare", truth_off=()):
    """The finished runs' series of the campaign ``directory``; an InputError (naming ``option``) unless it is a
    campaign of ``scenario`` (validated again: today's defaults) with the truth sources ``truth_off`` switched off
    and finished runs."""
    if not Path(directory).is_dir() or output_kind(directory) != "campaign":
        raise InputError(f"{option} {directory}: not a campaign directory (navsim montecarlo --out)")
    request, finished, _ = load_runs(directory)
    if validate(request["scenario_data"], scenario.source).data != scenario.data:
        raise InputError(f"{option} {directory}: a campaign of another scenario (or other --set values) than "
                         f"{scenario.source}")
    if sorted(request.get("truth_off", ())) != sorted(truth_off):
        raise InputError(f"{option} {directory}: its truth switches off {sorted(request.get('truth_off', ())) or 'nothing'}, "
                         f"not {sorted(truth_off) or 'nothing'}")
    if not finished:
        raise InputError(f"{option} {directory}: no finished runs")
    return [series for _, _, series in finished]


def aggregate(directory):
    """The campaign summary of the run files (deterministic: no wall-clock values): the kind's record with
    the statistics the kind pools (:mod:`navsim.kinds`), the updates and the observers' findings."""
    request, finished, failed = load_runs(directory)
    kind = of(request["scenario_data"])
    base = {"scenario": request["scenario"], "base_seed": request["base_seed"], "runs_requested": request["runs"],
            "runs_finished": len(finished), "runs_failed": len(failed),
            "failures": [{"run": k, "error": message, "cause": cause} for k, message, cause in failed]}
    if not finished:
        return kind.CampaignSummary(**base)
    summaries = [summary for _, summary, _ in finished]
    return kind.CampaignSummary(**base, **kind.pool(finished, request["scenario_data"]["settle_s"]),
                                updates={key: int(sum(s["updates"][key] for s in summaries)) for key in ("accepted", "rejected")},
                                **_pooled_findings(summaries))
