"""docs/design.md's floors of navsim: a module imports only from its own package or from a lower floor,
never upwards and never across one floor, so no two packages of navsim import each other (the graph of
packages has no cycle). Every import counts: at module level, inside functions, and the modules a
package names in ``lazy_exports`` or ``importlib.import_module`` with a literal name."""

import ast
from collections import defaultdict
from pathlib import Path

NAVSIM = Path(__file__).resolve().parents[2] / "navsim"

#: The floors, lowest first: each a set of navsim's packages and modules (``navsim`` itself, the lazy public
#: API, is above them all).
FLOORS = (
    {"kinematics", "kinematics_jit", "earth", "scenario"},   # geometry, numerics, the scenario files' machinery
    {"orbit"},                                               # a spacecraft's orbit and what it sees of the Earth
    {"truth", "sensors", "ins"},                             # the truth, the sensor models, the strapdown INS
    {"estimation"},                                          # the filters
    {"closed_loop", "records", "output", "places", "pooling", "analysis"},
    {"studies"},                                             # the source documents' experiments
    {"build", "typeset", "star_run"},                        # what the run kinds share
    {"attitude", "navigation"},                              # the run kinds
    {"spacecraft"},                                          # the run kind that builds on the attitude kind
    {"kinds"},                                               # their registry
    {"simulation"},                                          # the front door
    {"campaign", "report"},
    {"cli"},
)
FLOOR = {name: level for level, names in enumerate(FLOORS) for name in names}


def _unit(module):
    """The floor's unit of a dotted module name: its package (or module) right below navsim."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "navsim"


def _imports(path, module):
    """The navsim modules ``path`` (module ``module``) imports, wherever it imports them."""
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1] + ([base] if base else []))
            found |= {f"{base}.{alias.name}" for alias in node.names} | ({base} if base != "navsim" else set())
        elif isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", "")) in (
                "lazy_exports", "import_module"):
            for arg in node.args:
                if isinstance(arg, ast.Dict):
                    found |= {k.value for k in arg.keys if isinstance(k, ast.Constant)}
                elif isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    found.add(arg.value)
    return {name for name in found if name.split(".")[0] == "navsim"}


def _modules():
    for path in sorted(NAVSIM.rglob("*.py")):
        parts = path.relative_to(NAVSIM.parent).with_suffix("").parts
        yield path, ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_every_package_has_a_floor():
    units = {_unit(module) for _, module in _modules()} - {"navsim"}
    assert units == set(FLOOR), f"packages without a floor: {sorted(units - set(FLOOR))}; floors naming nothing: " \
                                f"{sorted(set(FLOOR) - units)}"


def test_no_import_goes_up_or_across_a_floor():
    offenders = []
    for path, module in _modules():
        unit = _unit(module)
        if unit == "navsim":
            continue
        for name in _imports(path, module):
            target = _unit(name)
            if target == unit:
                continue
            if target == "navsim" or FLOOR[target] >= FLOOR[unit]:
                offenders.append(f"{module} (floor {FLOOR[unit]}) imports {name} (floor "
                                 f"{'top' if target == 'navsim' else FLOOR[target]})")
    assert offenders == []


def test_no_package_cycle():
    graph = defaultdict(set)
    for path, module in _modules():
        for name in _imports(path, module):
            if _unit(name) != _unit(module):
                graph[_unit(module)].add(_unit(name))
    state = {}

    def visit(node, trail):
        state[node] = "open"
        for nxt in graph[node]:
            assert state.get(nxt) != "open", f"package cycle: {' -> '.join([*trail, node, nxt])}"
            if nxt not in state:
                visit(nxt, [*trail, node])
        state[node] = "done"

    for node in list(graph):
        if node not in state:
            visit(node, [])


def test_the_scenario_schema_imports_no_numba():
    import subprocess
    import sys

    code = "import sys, navsim.scenario.schema; print(sorted(m for m in ('numba', 'navsim.estimation', 'navsim.studies') if m in sys.modules))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
