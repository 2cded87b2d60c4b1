"""Monte Carlo campaigns: many seeded runs of one scenario, resumable, on a pool or a Dask cluster.

Layout of a campaign directory::

    DIR/campaign.json            what was asked (scenario, overrides, base seed, runs)
    DIR/runs/run_00000/          one finished run: scenario.json, summary.json, timeseries.npz
    DIR/runs/run_00007/error.json   a run that raised: its error and traceback
    DIR/summary.json             the aggregate of all finished runs

Run k uses the integer seed drawn from ``SeedSequence(base_seed, spawn_key=(k,))``, so its numbers
do not depend on which backend ran it, on how many workers there were, or on whether the campaign
was interrupted. Each run is written to a temporary directory and renamed into place when
complete, so a killed campaign leaves only whole runs; rerunning the command runs only the missing
ones. The aggregate is computed from the files, in run order, and is therefore identical whichever
way the runs were produced.
"""

import json
import os
import shutil
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
from scipy.stats import chi2
from tqdm import tqdm

from navsim.closed_loop import DIM_STAR_SOLVERS, paper000_comparison, paper000_notes, paper004_comparison, paper004_notes
from navsim.output import read_npz, write_json, write_run
from navsim.scenario import Scenario, resolve_scenario
from navsim.simulation import NEES_DOF, prepare, simulate
from startrack import units
from startrack.errors import InputError

RUN_FORMAT = "run_{:05d}"


def run_seed(base_seed, index):
    """The integer seed of run ``index`` of a campaign with ``base_seed``."""
    state = np.random.SeedSequence(base_seed, spawn_key=(index,)).generate_state(1, dtype=np.uint32)
    return int(state[0])


#: Time-series frames kept per campaign run (the summary always uses every frame).
CAMPAIGN_MAX_FRAMES = 2000


def run_chunk(scenario_data, source, members):
    """Run campaign members [(seed, run_dir), ...] of one scenario, preparing its seed-free part
    once (:func:`navsim.simulation.prepare`); each run is written atomically, and a run that
    raises is recorded in ``run_dir/error.json`` without stopping the others. Returns the errors."""
    errors = []
    try:
        prepared = prepare(Scenario(data=scenario_data, source=source))
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
        except Exception as error:  # recorded, not raised: one bad run must not stop the others
            shutil.rmtree(partial, ignore_errors=True)
            run_dir.mkdir(parents=True, exist_ok=True)
            message = f"{type(error).__name__}: {error}"
            write_json(run_dir / "error.json", {"seed": seed, "error": message, "traceback": traceback.format_exc()})
            errors.append(message)
    return errors


def _prepare(directory, scenario, runs, base_seed):
    directory = Path(directory)
    request = {
        "scenario": scenario.name,
        "source": scenario.source,
        "base_seed": base_seed,
        "runs": runs,
        "scenario_data": scenario.data,
        "seeds": [run_seed(base_seed, k) for k in range(runs)],
    }
    path = directory / "campaign.json"
    if path.exists():
        try:
            previous = json.loads(path.read_text())
        except json.JSONDecodeError:
            raise InputError(f"{path}: not a readable campaign file") from None
        same = {k: previous.get(k) for k in ("scenario_data", "base_seed")} == {
            k: request[k] for k in ("scenario_data", "base_seed")
        }
        if not same:
            raise InputError(
                f"{directory}: holds a different campaign (scenario, overrides or seed differ); "
                "use a new --out directory"
            )
        if previous["runs"] > runs:
            request["runs"] = previous["runs"]
            request["seeds"] = previous["seeds"]
    (directory / "runs").mkdir(parents=True, exist_ok=True)
    write_json(path, request)
    return directory, request


def pending_runs(directory, request):
    """Indices of runs with neither a finished result nor a recorded error."""
    runs_dir = Path(directory) / "runs"
    todo = []
    for k in range(request["runs"]):
        run_dir = runs_dir / RUN_FORMAT.format(k)
        if not (run_dir / "summary.json").exists() and not (run_dir / "error.json").exists():
            todo.append(k)
    return todo


def run_campaign(scenario, runs, out, base_seed=None, overrides=(), workers=None, scheduler=None,
                 progress=True, chunk_size=25):
    """Run (or resume) a campaign; returns the aggregate summary (also written to out/summary.json).

    ``workers``: local processes (default: the machine's cores); ``scheduler``: the address of a
    Dask distributed scheduler ('tcp://host:8786'), or a ``distributed.Client``. Runs are sent in
    chunks of at most ``chunk_size`` that share the scenario's seed-free part.
    """
    if runs < 1:
        raise InputError(f"--runs must be at least 1, got {runs}")
    scenario = resolve_scenario(scenario, overrides)
    scenario.require_simulation("a Monte Carlo campaign")
    base_seed = scenario["seed"] if base_seed is None else int(base_seed)
    directory, request = _prepare(out, scenario, runs, base_seed)
    todo = pending_runs(directory, request)
    members = [(request["seeds"][k], str(directory / "runs" / RUN_FORMAT.format(k))) for k in todo]
    n_workers = 1 if workers == 1 else (workers or os.cpu_count() or 1)
    size = max(1, min(chunk_size, -(-len(members) // (4 * n_workers)) if members else 1))
    chunks = [members[i : i + size] for i in range(0, len(members), size)]
    bar = tqdm(total=request["runs"], initial=request["runs"] - len(todo), desc=f"{scenario.name} runs",
               unit="run", disable=not progress)
    try:
        if not chunks:
            pass
        elif scheduler is not None:
            _run_dask(scenario, chunks, scheduler, bar)
        elif n_workers == 1:
            for chunk in chunks:
                run_chunk(scenario.data, scenario.source, chunk)
                bar.update(len(chunk))
        else:
            with ProcessPoolExecutor(max_workers=n_workers) as pool:
                futures = {pool.submit(run_chunk, scenario.data, scenario.source, c): len(c) for c in chunks}
                for future in as_completed(futures):
                    future.result()
                    bar.update(futures[future])
    finally:
        bar.close()
    summary = aggregate(directory)
    write_json(directory / "summary.json", summary)
    return summary


def _run_dask(scenario, chunks, scheduler, bar):
    from distributed import Client
    from distributed import as_completed as dask_completed

    client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
    try:
        futures = [client.submit(run_chunk, scenario.data, scenario.source, chunk, pure=False) for chunk in chunks]
        sizes = {future.key: len(chunk) for future, chunk in zip(futures, chunks)}
        for future in dask_completed(futures):
            future.result()
            bar.update(sizes[future.key])
    finally:
        if client is not scheduler:
            client.close()


def _pool_frames(pooled, name, runs, keys):
    """pooled[name]: the frame-weighted pool of per-run lists, an RMS for keys marked True, a mean otherwise."""
    frames = sum(r["frames"] for r in runs)
    if not frames:
        return
    pooled[name] = {"frames": frames}
    for key, rms in keys.items():
        mean = sum(r["frames"] * (np.square(r[key]) if rms else np.asarray(r[key], dtype=float)) for r in runs) / frames
        pooled[name][key] = [float(v) for v in (np.sqrt(mean) if rms else mean)]


def _pooled_paper_comparison(summaries):
    """Pool the source-document experiments over runs: 004's dim-star RMS (frame-weighted) and 000's
    tracking-failure probes (trial-weighted), with their comparison rows."""
    out, rows = {}, []
    dim = [s["dim_star"] for s in summaries if "dim_star" in s]
    if dim:
        pooled = {}
        for name in (*DIM_STAR_SOLVERS, "crb_two_star", "crb_three_star"):
            runs = [d[name] for d in dim if name in d]
            keys = [k for k in ("rms_ra_dec_roll_arcsec", "rms_cross_roll_arcsec") if runs and all(k in r for r in runs)]
            _pool_frames(pooled, name, runs, {key: True for key in keys})
        _pool_frames(pooled, "stacked_centroid", [d["stacked_centroid"] for d in dim if "stacked_centroid" in d],
                     {"rms_error_px": True})
        _pool_frames(pooled, "off_axis_deg", [d["off_axis_deg"] for d in dim if "off_axis_deg" in d],
                     {"mean_bright_dim": False})
        for name in ("filter_with_stacking", "filter_without_stacking"):
            values = [d[name]["rms_xyz_arcsec"] for d in dim if name in d]
            if values:
                pooled[name] = {"rms_xyz_arcsec": [float(v) for v in np.sqrt(np.mean(np.square(values), axis=0))]}
        out["dim_star"] = pooled
        rows += paper004_comparison(pooled)
        out["notes"] = paper004_notes(pooled)
    probes = [s["tracking_failure_probes"] for s in summaries if "tracking_failure_probes" in s]
    if probes:
        trials = sum(p["trials"] for p in probes)
        pooled = {"trials": trials, "disturbance_deg_max": max(p["disturbance_deg_max"] for p in probes)}
        for method in ("subcatalog", "lost_in_space"):
            pooled[method] = {key: float(sum(p["trials"] * p[method][key] for p in probes) / trials)
                              for key in ("recognition_rate", "ms_mean")}
        pooled["time_ratio"] = pooled["subcatalog"]["ms_mean"] / pooled["lost_in_space"]["ms_mean"]
        out["tracking_failure_probes"] = pooled
        rows += paper000_comparison(pooled)
        out["notes"] = out.get("notes", []) + paper000_notes(pooled)
    if rows:
        out["paper_comparison"] = rows
    return out


def load_runs(directory):
    """(index, summary, series) of every finished run and (index, error) of every failed one."""
    directory = Path(directory)
    request = json.loads((directory / "campaign.json").read_text())
    finished, failed = [], []
    for k in range(request["runs"]):
        run_dir = directory / "runs" / RUN_FORMAT.format(k)
        if (run_dir / "summary.json").exists():
            finished.append((k, json.loads((run_dir / "summary.json").read_text()), read_npz(run_dir / "timeseries.npz")))
        elif (run_dir / "error.json").exists():
            failed.append((k, json.loads((run_dir / "error.json").read_text())["error"]))
    return request, finished, failed


def aggregate(directory):
    """Campaign statistics from the run files (deterministic: no wall-clock values)."""
    request, finished, failed = load_runs(directory)
    out = {
        "scenario": request["scenario"],
        "base_seed": request["base_seed"],
        "runs_requested": request["runs"],
        "runs_finished": len(finished),
        "runs_failed": len(failed),
        "failures": [{"run": k, "error": message} for k, message in failed],
    }
    if not finished:
        return out
    settle = request["scenario_data"]["settle_s"]
    errors, cross, roll, nees_runs, sigma_runs = [], [], [], [], []
    divergent = []
    for k, summary, series in finished:
        steady = series["t"] >= settle
        err = series["attitude_error"][steady]
        errors.append(err)
        cross.append(summary["cross_boresight_rms_arcsec"])
        roll.append(summary["roll_rms_arcsec"])
        nees_runs.append(series["nees"])
        sigma = np.sqrt(series["P_diag"][steady, :3])
        sigma_runs.append(sigma)
        if np.any(np.abs(err) > 5.0 * sigma) or summary["nees"]["mean"] > 5.0 * NEES_DOF:
            divergent.append(k)
    stacked = np.concatenate(errors)
    arcsec = units.rad_to_arcsec
    m = len(finished)
    lengths = {len(n) for n in nees_runs}
    nees_block = {}
    if len(lengths) == 1:
        mean_nees = np.mean(np.array(nees_runs), axis=0)
        t = finished[0][2]["t"]
        lo, hi = chi2.ppf([0.025, 0.975], m * NEES_DOF) / m
        steady = t >= settle
        nees_block = {
            "dof": NEES_DOF,
            "runs": m,
            "band_95": [float(lo), float(hi)],
            "mean": float(mean_nees[steady].mean()),
            "fraction_in_band": float(np.mean((mean_nees[steady] >= lo) & (mean_nees[steady] <= hi))),
        }
    out.update(
        {
            "attitude_error_rms_arcsec": {axis: float(arcsec(np.sqrt(np.mean(stacked[:, i] ** 2)))) for i, axis in enumerate("xyz")},
            "attitude_error_percentiles_arcsec": {
                axis: {f"p{p}": float(arcsec(np.percentile(np.abs(stacked[:, i]), p))) for p in (50, 95, 99)}
                for i, axis in enumerate("xyz")
            },
            "filter_sigma_mean_arcsec": {axis: float(arcsec(np.mean(np.concatenate([s[:, i] for s in sigma_runs]))))
                                         for i, axis in enumerate("xyz")},
            "cross_boresight_rms_arcsec": {"mean": float(np.mean(cross)), "p50": float(np.percentile(cross, 50)),
                                           "p95": float(np.percentile(cross, 95)), "max": float(np.max(cross))},
            "roll_rms_arcsec": {"mean": float(np.mean(roll)), "p50": float(np.percentile(roll, 50)),
                                "p95": float(np.percentile(roll, 95)), "max": float(np.max(roll))},
            "nees": nees_block,
            "updates": {
                "accepted": int(sum(s["updates"]["accepted"] for _, s, _ in finished)),
                "rejected": int(sum(s["updates"]["rejected"] for _, s, _ in finished)),
            },
            "divergent_runs": divergent,
        }
    )
    comparison = _pooled_paper_comparison([summary for _, summary, _ in finished])
    out.update(comparison)
    per_mode = {}
    for _, summary, _ in finished:
        for mode, stats in summary.get("identification", {}).get("per_mode", {}).items():
            per_mode[mode] = per_mode.get(mode, 0) + stats["frames"]
    if per_mode:
        frames = sum(per_mode.values())
        out["identification"] = {
            "frames_per_mode": per_mode,
            "fix_fraction": 1.0 - (per_mode.get("no_fix", 0) + per_mode.get("outage", 0) + per_mode.get("dropped", 0)) / frames,
        }
    return out
