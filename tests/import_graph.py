"""The import walker of the floors tests of navsim and startrack (tests/*/test_layering.py).

Every import counts: at module level and inside functions, relative or absolute, the modules a package names in
``lazy_exports`` and those ``importlib.import_module`` is given as a literal string. A name is resolved to the
longest module of the package it names (``from startrack.camera.model import Camera`` is the module
``startrack.camera.model``; ``from startrack.geometry import rotation`` the module ``startrack.geometry.rotation``).
"""

import ast
from collections import defaultdict
from pathlib import Path


def modules(package_dir):
    """[(path, dotted module name)] of every ``.py`` file of the package at ``package_dir``."""
    package_dir = Path(package_dir)
    found = []
    for path in sorted(package_dir.rglob("*.py")):
        parts = path.relative_to(package_dir.parent).with_suffix("").parts
        found.append((path, ".".join(parts[:-1] if parts[-1] == "__init__" else parts)))
    return found


def imported_names(path, module):
    """The dotted names ``path`` (module ``module``) imports, wherever it imports them; ``from X import y`` gives
    the pair (X, y): the module X.y if there is one, else X."""
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[: len(parts) - node.level + 1] + ([base] if base else []))
            found |= {(base, alias.name) for alias in node.names}
        elif isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", "")) in (
                "lazy_exports", "import_module"):
            for arg in [*node.args, *(keyword.value for keyword in node.keywords)]:
                if isinstance(arg, ast.Dict):  # the modules of an exports dict (keys), of a namespaces dict (values)
                    found |= {k.value for k in [*arg.keys, *arg.values] if isinstance(k, ast.Constant)
                              and isinstance(k.value, str)}
                elif isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    found.add(arg.value)
    return found


def module_graph(package_dir):
    """{module: {modules of the same top package it imports}} (names resolved to their longest module)."""
    known = {module for _, module in modules(package_dir)}
    top = Path(package_dir).name
    graph = defaultdict(set)
    for path, module in modules(package_dir):
        graph[module]
        for name in imported_names(path, module):
            if isinstance(name, tuple):
                name = f"{name[0]}.{name[1]}" if f"{name[0]}.{name[1]}" in known else name[0]
            while name and name not in known:
                name = name.rsplit(".", 1)[0] if "." in name else ""
            if name and name != module and name.split(".")[0] == top:
                graph[module].add(name)
    return graph


def unit(module):
    """The floor's unit of a dotted module name: its package (or module) right below the top package."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def find_cycle(graph):
    """A cycle of ``graph`` ({node: {node}}) as a list of nodes (the first closing back), or None."""
    state = {}

    def visit(node, trail):
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return [*trail, node, nxt]
            if nxt not in state:
                cycle = visit(nxt, [*trail, node])
                if cycle:
                    return cycle
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            cycle = visit(node, [])
            if cycle:
                return cycle
    return None


def unit_graph(graph):
    """{unit: {units it imports}} of a module graph, each unit's own imports left out."""
    units = defaultdict(set)
    for module, targets in graph.items():
        units[unit(module)] |= {unit(t) for t in targets} - {unit(module)}
    return units


def upward_imports(graph, floor):
    """'module (floor i) imports name (floor j)' for every import of a unit from its own floor or above
    (``floor``: {unit: level}; the top package itself is above every floor)."""
    top = min(graph, key=len)
    offenders = []
    for module, targets in sorted(graph.items()):
        if module == top:
            continue
        for target in sorted(targets):
            if unit(target) == unit(module):
                continue
            if target == top or floor[unit(target)] >= floor[unit(module)]:
                offenders.append(f"{module} (floor {floor[unit(module)]}) imports {target} (floor "
                                 f"{'top' if target == top else floor[unit(target)]})")
    return offenders


def cycles_inside_packages(graph):
    """A module cycle inside one unit (a package's modules importing each other round), or None."""
    inside = {m: {t for t in targets if unit(t) == unit(m)} for m, targets in graph.items()}
    return find_cycle(inside)


def floor_problems(graph, floor):
    """Every breach of the floors ``floor`` ({unit: level}) in ``graph``: units without a floor and floors naming
    nothing, imports upwards or across a floor, a package cycle, a module cycle inside a package."""
    units = {unit(module) for module in graph} - {min(graph, key=len)}
    problems = [f"packages without a floor: {sorted(units - set(floor))}"] if units - set(floor) else []
    problems += [f"floors naming nothing: {sorted(set(floor) - units)}"] if set(floor) - units else []
    problems += upward_imports(graph, floor) if not problems else []
    for kind, cycle in (("package", find_cycle(unit_graph(graph))), ("module", cycles_inside_packages(graph))):
        problems += [f"{kind} cycle: {' -> '.join(cycle)}"] if cycle else []
    return problems
