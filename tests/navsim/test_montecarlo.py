"""Campaigns: resumable after SIGKILL, failures recorded, same results on every backend; batches."""

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import navsim.campaign.montecarlo as mc
from navsim.simulation import run, run_batch
from startrack.base.errors import InputError
from tests.support import HANG_S, finished_runs, wait_for

ROOT = Path(__file__).resolve().parents[2]


def write_scenario(path, base):
    import copy

    data = copy.deepcopy(base)
    data.update(duration_s=60.0)
    lines = []

    def emit(prefix, table):
        scalars = {k: v for k, v in table.items() if not isinstance(v, dict)}
        if prefix:
            lines.append(f"[{prefix}]")
        for key, value in scalars.items():
            lines.append(f"{key} = {json.dumps(value)}")
        for key, value in table.items():
            if isinstance(value, dict):
                emit(f"{prefix}.{key}" if prefix else key, value)

    emit("", data)
    path.write_text("\n".join(lines) + "\n")
    return path


def test_seeds_do_not_depend_on_the_campaign_size():
    assert [mc.run_seed(7, k) for k in range(3)] == [mc.run_seed(7, k) for k in range(5)][:3]
    assert len({mc.run_seed(7, k) for k in range(100)}) == 100


def test_killed_campaign_resumes_to_the_same_summary(tmp_path, base_scenario):
    """SIGKILL part way (after at least 3 finished runs), rerun: the summary equals an uninterrupted one."""
    runs = 60  # star-vector runs of 60 s: tens of ms each, so the kill lands part way
    base_scenario["star_sensor"].update(measurement="stars", star_sigma_arcsec=5.0)
    scenario = write_scenario(tmp_path / "s.toml", base_scenario)
    reference = mc.run_campaign(scenario, runs, tmp_path / "reference", workers=1, progress=False)
    out = tmp_path / "killed"
    command = [sys.executable, "-m", "navsim.cli", "montecarlo", str(scenario), "--runs", str(runs), "--out", str(out),
               "--workers", "1"]
    process = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               start_new_session=True)
    wait_for(lambda: len(finished_runs(out)) >= 3, "3 finished runs")
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    finished_before = len(finished_runs(out))
    assert 3 <= finished_before < runs
    assert not (out / "summary.json").exists()
    resumed = mc.run_campaign(scenario, runs, out, workers=1, progress=False)
    assert resumed == reference
    assert not list((out / "runs").glob("*.partial"))


def test_a_run_that_raises_is_recorded_and_the_others_finish(tmp_path, base_scenario, monkeypatch):
    bad_seed = mc.run_seed(0, 2)
    real_simulate = mc.simulate

    def flaky(prepared, seed):
        if seed == bad_seed:
            raise RuntimeError("sensor model exploded")
        return real_simulate(prepared, seed)

    monkeypatch.setattr(mc, "simulate", flaky)
    summary = mc.run_campaign(base_scenario, 4, tmp_path / "c", base_seed=0, workers=1, progress=False)
    assert summary["runs_finished"] == 3 and summary["runs_failed"] == 1
    assert summary["failures"] == [{"run": 2, "error": "RuntimeError: sensor model exploded", "cause": "scenario"}]
    assert (tmp_path / "c" / "runs" / "run_00002" / "error.json").exists()


def test_failures_outside_the_scenario_are_retried_on_resume(tmp_path, base_scenario, monkeypatch):
    """A full disk (OSError) is the environment's fault: the next resume runs it again by itself; a
    failure of the scenario waits for --retry-failed."""
    real_simulate = mc.simulate
    failing = {mc.run_seed(0, 1): OSError(28, "No space left on device"), mc.run_seed(0, 2): RuntimeError("bad model")}

    def flaky(prepared, seed):
        if seed in failing:
            raise failing[seed]
        return real_simulate(prepared, seed)

    monkeypatch.setattr(mc, "simulate", flaky)
    summary = mc.run_campaign(base_scenario, 3, tmp_path / "c", base_seed=0, workers=1, progress=False)
    assert [(f["run"], f["cause"]) for f in summary["failures"]] == [(1, "environment"), (2, "scenario")]
    failing.clear()  # the disk has room again, the model is fixed
    summary = mc.run_campaign(base_scenario, 3, tmp_path / "c", base_seed=0, workers=1, progress=False)
    assert [f["run"] for f in summary["failures"]] == [2]
    summary = mc.run_campaign(base_scenario, 3, tmp_path / "c", base_seed=0, workers=1, progress=False,
                              retry_failed=True)
    assert summary["runs_finished"] == 3 and summary["failures"] == []


def test_an_interrupt_inside_a_compiled_kernel_stops_the_campaign_and_records_nothing(tmp_path, base_scenario,
                                                                                      monkeypatch):
    """Ctrl-C inside a numba kernel reaches Python as a SystemError caused by the KeyboardInterrupt (seen in a
    campaign interrupted under load): it stops the campaign as an interrupt, the run stays pending (no error.json,
    no .partial) and a resume finishes it."""
    interrupted_seed = mc.run_seed(0, 1)
    real_simulate = mc.simulate

    def interrupted(prepared, seed):
        if seed == interrupted_seed:
            try:
                raise KeyboardInterrupt
            except KeyboardInterrupt as interrupt:
                raise SystemError("CPUDispatcher(<function run_stars>) returned a result with an exception set") from interrupt
        return real_simulate(prepared, seed)

    monkeypatch.setattr(mc, "simulate", interrupted)
    with pytest.raises(KeyboardInterrupt):
        mc.run_campaign(base_scenario, 3, tmp_path / "c", base_seed=0, workers=1, progress=False)
    assert sorted(p.name for p in (tmp_path / "c" / "runs").iterdir()) == ["run_00000"]
    assert mc.pending_runs(tmp_path / "c", {"runs": 3}) == [1, 2]
    monkeypatch.setattr(mc, "simulate", real_simulate)
    summary = mc.run_campaign(base_scenario, 3, tmp_path / "c", base_seed=0, workers=1, progress=False)
    assert summary["runs_finished"] == 3 and summary["failures"] == []


def test_pool_and_dask_give_identical_results(tmp_path, base_scenario):
    distributed = pytest.importorskip("distributed")
    base_scenario.update(duration_s=10.0)
    pooled = mc.run_campaign(base_scenario, 6, tmp_path / "pool", workers=2, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
                                  processes=True) as cluster, distributed.Client(cluster) as client:
        dasked = mc.run_campaign(base_scenario, 6, tmp_path / "dask", scheduler=client, progress=False)
    assert pooled == dasked
    for k in range(6):
        a = np.load(tmp_path / "pool" / "runs" / f"run_{k:05d}" / "timeseries.npz")
        b = np.load(tmp_path / "dask" / "runs" / f"run_{k:05d}" / "timeseries.npz")
        np.testing.assert_array_equal(a["q_est"], b["q_est"])


def test_a_directory_holding_another_campaign_is_refused(tmp_path, base_scenario):
    base_scenario.update(duration_s=2.0)
    mc.run_campaign(base_scenario, 1, tmp_path / "c", workers=1, progress=False)
    base_scenario["gyro"]["rate_hz"] = 20.0
    with pytest.raises(InputError, match="holds a different campaign"):
        mc.run_campaign(base_scenario, 1, tmp_path / "c", workers=1, progress=False)


def test_campaign_statistics_follow_the_runs(tmp_path, base_scenario):
    summary = mc.run_campaign(base_scenario, 8, tmp_path / "c", workers=1, progress=False)
    assert summary["runs_finished"] == 8
    lo, hi = summary["nees"]["band_95"]
    assert lo < summary["nees"]["mean"] < hi
    per_run = [json.loads(p.read_text())["cross_boresight_rms_arcsec"]
               for p in sorted((tmp_path / "c" / "runs").glob("run_*/summary.json"))]
    assert summary["cross_boresight_rms_arcsec"]["mean"] == pytest.approx(np.mean(per_run))
    assert summary["divergent_runs"] == []


def test_batch_of_one_equals_a_single_run(base_scenario):
    single = run(base_scenario, seed=11)
    [batched] = run_batch(base_scenario, [11])
    for key in single.series:
        np.testing.assert_array_equal(single.series[key], batched.series[key])
    threaded = run_batch(base_scenario, [11, 12, 13], threads=2)
    np.testing.assert_array_equal(threaded[0].series["q_est"], single.series["q_est"])
    np.testing.assert_array_equal(threaded[2].series["q_est"], run(base_scenario, seed=13).series["q_est"])


def test_ctrl_c_cancels_the_pending_runs_and_keeps_the_finished(tmp_path, base_scenario):
    """SIGINT to the campaign's process group (Ctrl-C in a terminal) with two workers: the pending runs
    are cancelled, the workers stop, one line says so (exit 130); the finished runs stay and a rerun
    completes the campaign."""
    runs = 400
    base_scenario["star_sensor"].update(measurement="stars", star_sigma_arcsec=5.0)
    scenario = write_scenario(tmp_path / "s.toml", base_scenario)
    out = tmp_path / "interrupted"
    command = [sys.executable, "-m", "navsim.cli", "montecarlo", str(scenario), "--runs", str(runs), "--out", str(out),
               "--workers", "2"]
    # SIGINT handled as in a terminal even when the suite itself runs with it ignored (a background job)
    process = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    wait_for(lambda: len(finished_runs(out)) >= 3, "3 finished runs")  # runs in place, not a .partial
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=HANG_S)
    assert process.returncode == 130
    assert err.strip().splitlines()[-1] == "navsim: interrupted" and "Traceback" not in err
    assert 3 <= len(finished_runs(out)) < runs
    assert not (out / "campaign.lock").exists()
    resumed = mc.run_campaign(scenario, runs, out, workers=1, progress=False)
    assert resumed["runs_finished"] == runs and not list(out.glob("runs/*.partial"))


def test_a_run_is_tested_for_divergence_on_every_frame():
    """The run's test sees the one frame a campaign's 2000 kept frames would miss, at the threshold of all its samples."""
    from navsim.pooling import diverged, divergence, divergence_sigmas

    rng = np.random.default_rng(5)
    errors, sigmas = 0.5 * rng.standard_normal((6000, 3)), np.full((6000, 3), 1.0)
    errors[4001, 1] = 6.0
    test = divergence(errors, sigmas)
    assert test["samples"] == 18000 and test["threshold"] == divergence_sigmas(18000) > 5.0
    assert test["max_normalised_error"] == 6.0
    nees = {"mean": 6.0, "dof": 6}
    assert diverged({"divergence": test, "nees": nees})
    assert not diverged({"divergence": divergence(errors[::3], sigmas[::3]), "nees": nees})
