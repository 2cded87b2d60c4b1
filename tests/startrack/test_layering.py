"""docs/design.md's floors of startrack: startrack never imports navsim; a module imports only from its own
package or from a lower floor, never upwards or across one (so no two packages import each other), and no
modules of one package import each other round. Every import counts (tests/import_graph.py)."""

import ast
from pathlib import Path

from tests.import_graph import floor_problems, module_graph

STARTRACK = Path(__file__).resolve().parents[2] / "startrack"

#: The floors, lowest first, in the order the data flows (``startrack`` itself, the lazy public API, is above).
FLOORS = (
    {"base"},                               # errors, units, the cache directory, lazy exports, output paths
    {"compiled"},                           # numba's set-up, the compiled sorts, compiling ahead
    {"geometry", "photometry"},             # rotations and the sphere; bands, detectors, colours, a star's signal
    {"attitude", "catalog"},                # solvers from matched directions; the catalogs and their tables
    {"camera"},                             # the camera model, its file, WCS, projection kernels, the fit
    {"image"},                              # rendering, detection, the position fit, stacking, image files
    {"identify"},                           # star identification and the plate solver
    {"serve_client", "compile_tasks"},      # the application: the serve client, the compile-ahead tasks ...
    {"commands"},                           # ... the sub-commands ...
    {"cli"},                                # ... and the command line
)
FLOOR = {name: level for level, names in enumerate(FLOORS) for name in names}
GRAPH = module_graph(STARTRACK)
#: What startrack's root may hold besides its packages (issue 52: at most 8 modules).
ROOT_MODULES = 8


def test_startrack_never_imports_navsim():
    offenders = []
    for path in STARTRACK.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            offenders += [f"{path.name}: {name}" for name in names if name.split(".")[0] == "navsim"]
    assert offenders == []


def test_the_floors_hold():
    assert floor_problems(GRAPH, FLOOR) == []


def test_the_root_holds_few_modules():
    assert len(list(STARTRACK.glob("*.py"))) <= ROOT_MODULES


def test_the_walker_sees_every_kind_of_import_and_every_breach(tmp_path):
    package = tmp_path / "pkg"
    for name, text in {
        "__init__.py": "lazy_exports(__name__, {'pkg.low.a': ('x',)}, modules={'b': 'pkg.high.b'})\n",
        "low/__init__.py": "", "high/__init__.py": "",
        "low/a.py": "def f():\n    from pkg.high import b\n",                      # in a function, upwards
        "low/c.py": "import importlib\nimportlib.import_module('pkg.low.d')\n",         # a literal import_module
        "low/d.py": "from . import c\n",                                               # relative: c <-> d
        "high/b.py": "from pkg.low.a import f\n",
    }.items():
        (package / name).parent.mkdir(parents=True, exist_ok=True)
        (package / name).write_text(text)
    graph = module_graph(package)
    assert graph["pkg"] == {"pkg.low.a", "pkg.high.b"} and graph["pkg.low.a"] == {"pkg.high.b"}
    problems = floor_problems(graph, {"low": 0, "high": 1})
    assert problems == ["pkg.low.a (floor 0) imports pkg.high.b (floor 1)", "package cycle: high -> low -> high",
                        "module cycle: pkg.low.c -> pkg.low.d -> pkg.low.c"]
