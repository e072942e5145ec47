"""The executed tutorial and the built site, each made once per test session.

``tests/test_tutorial.py`` and ``tests/test_docs.py`` share them: the tutorial is run on a
fresh kernel by the site's own hook (``docs/hooks/tutorial_page.py``), and the site is then
built in strict mode (``mkdocs build --strict``, as ``make docs``) showing that very run,
so the figures the tests check are the ones the site shows.
"""

from __future__ import annotations

import atexit
import functools
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import ModuleType
from typing import Any, NamedTuple

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "examples" / "tutorial.ipynb"
SCRIPT = ROOT / "examples" / "tutorial.py"


def _scratch(prefix: str) -> Path:
    path = Path(tempfile.mkdtemp(prefix=prefix))
    atexit.register(shutil.rmtree, path, ignore_errors=True)
    return path


def hook(name: str) -> ModuleType:
    """A module of ``docs/hooks/`` (they are files, not a package)."""
    spec = importlib.util.spec_from_file_location(f"docs_hook_{name}", ROOT / "docs" / "hooks" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class Executed(NamedTuple):
    notebook: Any
    """The executed notebook (nbformat v4)."""
    path: Path
    """Where it was saved."""
    seconds: float
    """Wall time of the run [s], kernel start included."""


@functools.cache
def executed_tutorial() -> Executed:
    """``examples/tutorial.ipynb`` run top to bottom on a fresh kernel (nbclient)."""
    import nbformat

    start = time.monotonic()
    notebook = hook("tutorial_page").execute_notebook(NOTEBOOK, timeout=300)
    seconds = time.monotonic() - start
    path = _scratch("twolink-tutorial-") / "tutorial.executed.ipynb"
    nbformat.write(notebook, path)
    return Executed(notebook, path, seconds)


class Site(NamedTuple):
    path: Path
    """The built site (``site/`` of ``make docs``)."""
    returncode: int
    output: str
    """mkdocs' stdout and stderr."""


@functools.cache
def built_site() -> Site:
    """The site built as ``make docs`` does, strict, showing :func:`executed_tutorial`."""
    executed = executed_tutorial()
    out = _scratch("twolink-site-") / "site"
    env = dict(os.environ, TWOLINK_PIN_EXECUTED_TUTORIAL=str(executed.path), NO_MKDOCS_2_WARNING="1")
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(out)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    return Site(out, done.returncode, done.stdout + done.stderr)
