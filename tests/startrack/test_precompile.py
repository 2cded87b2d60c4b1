"""Kernels compiled ahead (``startrack.compiled.compile_ahead``): lanes run at once, finished tasks are marked and
skipped afterwards, a failing task is one line and no failure of the run."""

import io
from pathlib import Path

import numba

from startrack.compiled.compile_ahead import compile_ahead, marker

TWICE, THRICE, FAILS = "tests.compile_tasks:twice", "tests.compile_tasks:thrice", "tests.compile_tasks:fails"


def _unmarked(*tasks):
    for task in tasks:
        marker(task).unlink(missing_ok=True)


def test_lanes_run_once_and_are_marked():
    _unmarked(TWICE, THRICE)
    stream = io.StringIO()
    compile_ahead([(TWICE,), (THRICE,)], stream)  # the second lane in a spawned process
    said = stream.getvalue()
    assert said.startswith("compiling kernels, once for this installation: twice, thrice ...") and "compiled in" in said
    assert marker(TWICE).exists() and marker(THRICE).exists()
    again = io.StringIO()
    compile_ahead([(TWICE,), (THRICE,)], again)
    assert again.getvalue() == ""


def test_the_marks_live_with_the_kernels_they_stand_for():
    assert marker(TWICE).parent.parent == Path(numba.config.CACHE_DIR)


def test_a_failing_task_is_one_line_and_stays_unmarked():
    _unmarked(FAILS, TWICE)
    stream = io.StringIO()
    compile_ahead([(FAILS, TWICE)], stream)
    lines = stream.getvalue().splitlines()
    assert lines[1] == ("compiling ahead: tests.compile_tasks:fails failed (RuntimeError: made to fail); "
                        "kernels compile at first call")
    assert not marker(FAILS).exists() and marker(TWICE).exists()  # the lane goes on after a failure
