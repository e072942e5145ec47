"""How the suite is spread over pytest-xdist's workers (``make test``: ``-n 2``, and
``--dist loadgroup`` from pyproject.toml): which tests share a worker, and which start first.

Nothing here selects, skips or changes a test; it only sets the order of the collection and
which tests xdist hands out together (without ``-n``, only the order applies).

- **Shared setup stays on one worker.** A module-scoped fixture or a ``functools.cache`` is
  made once per worker process; where it is expensive (a Dask scheduler and its workers, a
  report build, the executed tutorial and the site built from it, Chromium on a page), its
  tests are one unit of xdist's ``loadgroup`` scheduling (:data:`GROUPS`), so it is made once,
  not once per worker (or once per stretch of the module a worker gets).
- **The longest start first** (:data:`FIRST`, by the sum of their tests' durations in one
  ``-n 2`` run on the 2-core VM at load 4-6, 2026-12-02: 6238 s in all): xdist
  hands tests (and groups) out in collection order to whichever worker is free
  (``--no-loadscope-reorder``: not by group size), so the run does not end with one worker
  idle while the other is still in an 80-s test.

Whole modules move together (a module's fixtures are set up once per stretch of its tests).
"""

from __future__ import annotations

from typing import Any

import pytest

GROUPS: dict[str, str] = {
    "test_docs.py": "docs",  # the executed tutorial and the site built from it (tests/docs_build.py)
    "test_tutorial.py": "docs",
    "test_cluster.py": "cluster",  # a dask scheduler with 2 workers, the in-process reference sweep
    "test_report.py": "report",  # a report build, checked in Chromium
    "test_visualization.py": "visualization",  # Chromium, a live meshcat server, three pages
    "test_visualization_overlays.py": "visualization_overlays",  # Chromium on a page
    "test_bags.py": "bags",  # a 30-s log at 1 kHz and its identification
    "test_identification.py": "identification",  # a 30-s closed-loop log at 2 kHz
    "test_physical.py": "physical",  # identify --physical (cvxpy + Clarabel)
    "test_plotting.py": "plotting",  # closed-loop runs and their figures
    "test_controllers.py": "controllers",  # two 8-s adaptive runs (Lyapunov checks)
    "test_tune_browser.py": "tune",  # Chromium on two live tune servers
}
"""Test file → its xdist group: files whose expensive per-process setup is shared by their tests."""

FIRST: tuple[str, ...] = (
    "test_identification.py",  # the "identification" group: 724 s of test time at load ~6
    "test_report.py",  # 624 s: report builds, Chromium
    "test_cluster.py",  # 449 s: Ctrl-C on a cluster, the sweep-throughput benchmark (140 s), ...
    "test_docs_task_space.py",  # 549 s, ungrouped: compare alone 273 s
    "test_docs.py",  # the "docs" group, 248 s: the site build (178 s) and the tutorial
    "test_tutorial.py",
    "test_benchmark_script.py",  # 195 s: scripts/benchmark.py --quick
    "test_docs_images.py",  # 218 s
    "test_plotting.py",  # 210 s, grouped
    "test_new_laws.py",  # 345 s, ungrouped
    "test_visualization.py",  # 114 s, grouped
    "test_physical.py",  # 110 s, grouped
    "test_bags.py",  # 93 s, grouped
    "test_se3_trajectory.py",  # 95 s
)
"""Test files (or groups of them), longest first; the rest keep their collection order after them."""


def _file(item: pytest.Item) -> str:
    return item.nodeid.split("::", 1)[0].rsplit("/", 1)[-1]


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The files of :data:`FIRST` first, longest first (xdist schedules in this order)."""
    rank = {name: i for i, name in enumerate(FIRST)}
    items.sort(key=lambda item: rank.get(_file(item), len(FIRST)))  # stable: the rest keep their order


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """``--dist loadgroup`` with the groups of :data:`GROUPS` (by file) as well as ``xdist_group``
    marks. The marks alone do not group under pytest 9 with pytest-xdist 3.8: xdist tags a grouped
    test by assigning ``item._nodeid``, which pytest 9 no longer reads (node ids live in ``_id``)."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadGroupScheduling

    class FileGroupScheduling(LoadGroupScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return GROUPS.get(nodeid.split("::", 1)[0].rsplit("/", 1)[-1]) or super()._split_scope(nodeid)

    return FileGroupScheduling(config, log)
