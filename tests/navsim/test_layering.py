"""docs/design.md's floors of navsim: a module imports only from its own package or from a lower floor,
never upwards and never across one floor, so no two packages of navsim import each other (the graph of
packages has no cycle), no modules of one package import each other round, and startrack is reached only
through its public API (``startrack/__init__.py``). Every import counts
(tests/import_graph.py: at module level, inside functions, and the modules a package names in
``lazy_exports`` or ``importlib.import_module`` with a literal name)."""

from pathlib import Path

from tests.import_graph import floor_problems, imported_names, module_graph, modules

NAVSIM = Path(__file__).resolve().parents[2] / "navsim"

#: The floors, lowest first: each a set of navsim's packages and modules (``navsim`` itself, the lazy public
#: API, is above them all).
FLOORS = (
    {"kinematics", "kinematics_jit", "earth", "scenario"},   # geometry, numerics, the scenario files' machinery
    {"orbit"},                                               # a spacecraft's orbit and what it sees of the Earth
    {"truth", "sensors", "ins"},                             # the truth, the sensor models, the strapdown INS
    {"estimation", "inertial_log"},                          # the filters; the sensors' noise from recorded logs
    {"closed_loop", "records", "output", "places", "pooling", "analysis"},
    {"studies"},                                             # the source documents' experiments
    {"build", "typeset", "star_run"},                        # what the run kinds share
    {"attitude", "navigation", "replay"},                    # the run kinds, and the replays of recordings
    {"spacecraft"},                                          # the run kind that builds on the attitude kind
    {"kinds"},                                               # their registry
    {"simulation"},                                          # the front door
    {"campaign", "report", "imu_command"},
    {"cli"},
)
FLOOR = {name: level for level, names in enumerate(FLOORS) for name in names}
GRAPH = module_graph(NAVSIM)


def test_the_floors_hold():
    assert floor_problems(GRAPH, FLOOR) == []


def test_navsim_imports_startrack_only_through_its_public_api():
    offenders = []
    for path, module in modules(NAVSIM):
        for name in imported_names(path, module):
            base = name[0] if isinstance(name, tuple) else name
            if base.split(".")[0] == "startrack" and base != "startrack":
                offenders.append(f"{module} imports {base}")
    assert offenders == []


def test_the_scenario_schema_imports_no_numba():
    import subprocess
    import sys

    code = "import sys, navsim.scenario.schema; print(sorted(m for m in ('numba', 'navsim.estimation', 'navsim.studies') if m in sys.modules))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
