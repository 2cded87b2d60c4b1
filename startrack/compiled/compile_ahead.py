"""Kernels compiled ahead, on every core, once per installation.

numba compiles a kernel at its first call, in the calling process, one kernel at a time: the first
image-fidelity run of an installation compiled ~60 s of kernels on one core while the other idled.
A *task* is a function of no arguments named ``"module:function"`` that calls some kernels through the
public constructors and methods that a run uses, on small made-up inputs (so with the argument types of
a run); a *lane* is a sequence of tasks run in order in one process.  :func:`compile_ahead` runs the
lanes at once -- the first in this process, each other in a spawned process -- and marks each task that
finished in the kernel cache folder (:mod:`startrack.compiled.numba_setup`, keyed by the sources, so an
edit starts afresh): a later run skips it.  What a child compiles reaches this process through numba's
on-disk cache.  Lanes are ordered so that a kernel two of them call is compiled by the one that gets
there first and loaded by the other (numba saves each kernel as soon as it is compiled).

With one core, in a worker process (a campaign's pool: its parent compiled ahead) or with the JIT
disabled, the lanes run one after the other here, which costs what compiling at first call costs.
A task that fails is reported in one line and left unmarked: the run then compiles as it goes.
"""

from __future__ import annotations

import importlib
import multiprocessing
import os
import sys
import time
from pathlib import Path

import numba

import startrack.compiled.numba_setup  # noqa: F401  (sets numba's cache folder)


def compile_ahead(lanes, stream=None) -> None:
    """Run the tasks of ``lanes`` (sequences of ``"module:function"``) not yet marked, the lanes in
    parallel; say on ``stream`` (default stderr) what is compiled and how long it took."""
    lanes = [tuple(task for task in lane if not marker(task).exists()) for lane in lanes]
    lanes = [lane for lane in lanes if lane]
    if not lanes or numba.config.DISABLE_JIT:
        return
    stream = sys.stderr if stream is None else stream
    names = ", ".join(task.rsplit(":", 1)[1].replace("_", " ") for lane in lanes for task in lane)
    print(f"compiling kernels, once for this installation: {names} ...", file=stream, flush=True)
    start = time.perf_counter()
    parallel = len(lanes) > 1 and len(os.sched_getaffinity(0)) > 1 and multiprocessing.parent_process() is None
    children = [_spawn(lane) for lane in lanes[1:]] if parallel else []
    try:
        for lane in lanes[:1] if parallel else lanes:
            _run_lane(lane, stream)
        for child in children:
            child.join()
            if child.exitcode:
                print(f"compiling ahead: the lane {', '.join(child.lane)} ended with exit code {child.exitcode}; "
                      "kernels compile at first call", file=stream, flush=True)
    except BaseException:
        for child in children:
            child.terminate()
            child.join()
        raise
    print(f"compiled in {time.perf_counter() - start:.0f} s", file=stream, flush=True)


def marker(task: str) -> Path:
    """The file that marks ``task`` done for this installation's kernels."""
    return Path(numba.config.CACHE_DIR) / "ahead" / task.replace(":", ".")


def _run_lane(lane, stream=None) -> None:
    """Run the tasks of ``lane`` in order, marking each that finishes; a failure is one line on ``stream``."""
    stream = sys.stderr if stream is None else stream
    for task in lane:
        module, function = task.split(":")
        try:
            getattr(importlib.import_module(module), function)()
        except Exception as error:  # the run still works: it compiles at first call
            print(f"compiling ahead: {task} failed ({type(error).__name__}: {error}); kernels compile at first call",
                  file=stream, flush=True)
            continue
        path = marker(task)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.touch()


def _child(lane):
    try:
        _run_lane(lane)
    except KeyboardInterrupt:  # the parent stops too
        sys.exit(130)


def _spawn(lane):
    process = multiprocessing.get_context("spawn").Process(target=_child, args=(lane,), name="compile-ahead")
    process.lane = lane
    process.start()
    return process
