"""A run compiles nothing after its compile-ahead lanes (each kind's ``lanes``): the tasks call the kernels
with the argument types of a run, so the run loads them all (``startrack.compiled.compile_ahead``)."""

import subprocess
import sys
from pathlib import Path

import pytest

from navsim.attitude.run import IMAGE_LANES as ATTITUDE_IMAGE
from navsim.attitude.run import VECTOR_LANES as ATTITUDE_VECTOR
from navsim.kinds import resolve_scenario, run_kind
from navsim.navigation.run import IMAGE_LANES as NAVIGATION_IMAGE
from navsim.navigation.run import VECTOR_LANES as NAVIGATION_VECTOR
from tests.support import HANG_S

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"

#: In a fresh process: the scenario's lanes, then the run, its compilations recorded.
RUN_AFTER_LANES = """
import sys
from numba.core import event
import navsim
from navsim.kinds import resolve_scenario, run_kind
from startrack.compiled.compile_ahead import compile_ahead

scenario = resolve_scenario(sys.argv[1], sys.argv[2:])
compile_ahead(run_kind(scenario, "a run").lanes(scenario))
compiled = []

class Compiled(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__qualname__)

    def on_end(self, ev):
        pass

event.register("numba:compile", Compiled())
navsim.run(scenario, seed=0)
print("compiled:", " ".join(compiled))
"""


def test_an_image_run_compiles_nothing_after_its_lanes():
    # 25 s of the demo: full-sky acquisition, tracking, the 5 deg knock at 20 s and the sub-catalog's re-acquisition
    done = subprocess.run([sys.executable, "-c", RUN_AFTER_LANES, str(SCENARIOS / "demo.toml"), "duration_s=25"],
                          capture_output=True, text=True, timeout=HANG_S, cwd=SCENARIOS.parent)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1].split() == ["compiled:"]


@pytest.mark.parametrize("name, lanes", [("demo.toml", ATTITUDE_IMAGE), ("paper000_high_dynamic.toml", ATTITUDE_VECTOR),
                                         ("sins_cns_aircraft.toml", NAVIGATION_IMAGE),
                                         ("sins_cns_aircraft_vector.toml", NAVIGATION_VECTOR),
                                         ("free_ins_navigation_aircraft.toml", NAVIGATION_VECTOR)])
def test_each_kind_has_its_lanes(name, lanes):
    scenario = resolve_scenario(SCENARIOS / name)
    assert run_kind(scenario, "a run").lanes(scenario) == lanes


def test_every_task_names_a_function():
    import importlib

    for lane in ATTITUDE_IMAGE + ATTITUDE_VECTOR + NAVIGATION_IMAGE + NAVIGATION_VECTOR:
        for task in lane:
            module, function = task.split(":")
            assert callable(getattr(importlib.import_module(module), function)), task
