"""The package's shape cannot get worse unnoticed: the number of functions over
:data:`LONG` lines and of imports that reach into another module's ``_private`` names may go
down, never up (issue 30; STYLE: functions short, no imports of another module's private names).

When a change lowers a count, lower its ceiling here in the same commit.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "twolink_pin"
LONG = 80
"""A function longer than this many lines (decorators excluded, docstring included) is long."""
MAX_LONG_FUNCTIONS = 0
"""Functions over :data:`LONG` lines (21 at 934c0e3; 19 after the merges of issues 28 and 30:
build_parser, cmd_identify, add_identification_commands and integrate_adaptive split; lower it
when one is split); 18 at the end of that round; 17 once the engine's ``integrate`` was split
(its run's pieces, a block's steps, a block's check; divergence in its own module); 11 once
the report's ``_build``, ``run_sweep``, ``simulate_batch``, the Dask engine's ``run`` and
``open_cluster`` and ``read_trajectory_file`` were split; 9 with ``cmd_excite`` and
``cmd_animate``; 0 once ``simulate``, ``pose_trajectory``, ``solve_position``, ``_identify``,
``cmd_sweep``, the parser's run and sweep commands, the parameter summary figure and
``start_bridge`` were split too: a new long function fails this test)."""
MAX_PRIVATE_IMPORTS = 3
"""Private names imported from another module of the package (80 at 934c0e3, in 33 module
pairs; 68 after camera, motion and cluster_startup made theirs public and the run was
assembled in one place; 60 once the CLI's shared helpers
(robot_from_args, trajectory_from_args, identified_parameters, run_record) were public; 59 once
the law's output check was ``containment.check_output``; 47 once the report's worker tasks and
pool and the sweep's shared pieces (``PreparedSweep``, ``RowSink``, ``json_row_writer``,
``write_figure``, ``law_source``, ``versions_text``) were public; 45 with ``gains_echo``; 3 once
the plotting helpers of ``_style`` and ``parameters``, the sweep's, the URDF checks',
``gain_spec`` and ``claimed_values`` were public: the three left import the ``_save`` module
itself (``_style`` until it was split), whose ``save_figure`` the plotting tests monkeypatch).
Lower it when one is."""


def _modules() -> list[tuple[str, ast.Module]]:
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        name = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
        out.append((name, ast.parse(path.read_text(encoding="utf-8"), str(path))))
    return out


def long_functions() -> list[str]:
    """``module.function (N lines)`` for every function or method over :data:`LONG` lines."""
    found = []
    for name, tree in _modules():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = (node.end_lineno or node.lineno) - node.lineno + 1
                if lines > LONG:
                    found.append(f"{name}.{node.name} ({lines} lines)")
    return found


def private_imports() -> list[str]:
    """``module: from other import _name`` for every import of another module's private name
    (relative to the package; ``__future__`` and dunder names aside)."""
    found = []
    for name, tree in _modules():
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom) or not node.module or node.level:
                continue
            if not node.module.startswith("twolink_pin") or node.module == name:
                continue
            for alias in node.names:
                if alias.name.startswith("_") and not alias.name.startswith("__"):
                    found.append(f"{name}: from {node.module} import {alias.name}")
    return found


def test_no_more_long_functions_than_before() -> None:
    found = long_functions()
    assert len(found) <= MAX_LONG_FUNCTIONS, "\n".join(found)


def test_no_more_private_imports_than_before() -> None:
    found = private_imports()
    assert len(found) <= MAX_PRIVATE_IMPORTS, "\n".join(found)


def test_the_counters_see_what_they_count(tmp_path: Path) -> None:
    """The counters find a long function and a private import in made-up source."""
    body = "\n".join(f"    x{i} = {i}" for i in range(LONG))
    tree = ast.parse(f"from twolink_pin.a import _b\ndef f():\n{body}\n")
    assert (tree.body[1].end_lineno or 0) - tree.body[1].lineno + 1 == LONG + 1
    assert isinstance(tree.body[0], ast.ImportFrom) and tree.body[0].names[0].name == "_b"


def test_every_folder_of_the_package_is_a_package_setuptools_installs() -> None:
    """Issue 38 §9: setuptools treats every folder under ``twolink_pin/`` as a package; one that
    ``pyproject.toml`` does not list (``report/templates``, ``identification/excitations``: data
    folders) printed a "Package would be ignored" warning per folder in ``make demo``."""
    import sys

    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import tomli as tomllib

    config = tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text(encoding="utf-8"))
    listed = set(config["tool"]["setuptools"]["packages"])
    folders = {
        ".".join(path.relative_to(PACKAGE.parent).parts)
        for path in [PACKAGE, *PACKAGE.rglob("*")]
        if path.is_dir() and path.name != "__pycache__"
    }
    assert folders - listed == set()
