"""docs/design.md's layering: startrack (the star sensor) never imports navsim (the system)."""

import ast
from pathlib import Path

STARTRACK = Path(__file__).resolve().parents[2] / "startrack"


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
