"""The simulation package's modules import one another without a circle (the engine once
imported the events loop, which imported the engine back), counting imports inside
functions and under ``TYPE_CHECKING`` too."""

from __future__ import annotations

import ast
from pathlib import Path

import twolink_pin.simulation

PACKAGE = Path(twolink_pin.simulation.__file__).parent
PREFIX = "twolink_pin.simulation."


def _imports(path: Path) -> set[str]:
    """The sibling modules ``path`` imports (anywhere in the file)."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith(PREFIX):
            found.add(node.module[len(PREFIX) :].split(".")[0])
        elif isinstance(node, ast.Import):
            found |= {a.name[len(PREFIX) :].split(".")[0] for a in node.names if a.name.startswith(PREFIX)}
    return found


def test_no_import_circle_within_the_simulation_package() -> None:
    graph = {p.stem: _imports(p) for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    assert "engine" in graph["adaptive_step"]  # the scan sees imports (one is known to exist)
    state: dict[str, str] = {}

    def visit(module: str, path: list[str]) -> None:
        state[module] = "open"
        for other in sorted(graph.get(module, ())):
            assert state.get(other) != "open", f"import circle: {' -> '.join([*path, module, other])}"
            if other not in state:
                visit(other, [*path, module])
        state[module] = "done"

    for module in sorted(graph):
        if module not in state:
            visit(module, [])
    assert "engine" not in graph["events"]
