"""How the suite is spread over pytest-xdist's workers (``make test``: ``-n 2``, and
``--dist loadgroup`` from pyproject.toml): which tests share a worker, and which start first.

Nothing here skips or changes a test; it sets the order of the collection, which tests xdist
hands out together (without ``-n``, only the order applies), and the markers that let
``make check`` leave out what needs a Dask cluster, a docs, tutorial or report build
(:data:`MARKS`; ``browser`` and ``slow`` are marked on the tests themselves).

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

import signal
from typing import Any

import pytest

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    # pytest started as a background job (`make test &` from a script: the shell ignores SIGINT
    # there, and every process started inherits that): the commands the Ctrl-C tests start
    # would ignore Ctrl-C as a background job should (twolink_pin.cli) and run to their end.
    signal.signal(signal.SIGINT, signal.default_int_handler)

GROUPS: dict[str, str] = {
    "test_docs.py": "docs",  # the executed tutorial and the site built from it (tests/docs_build.py)
    "test_tutorial.py": "docs",
    "test_cluster.py": "cluster",  # a dask scheduler with 2 workers, the in-process reference sweep
    "test_report.py": "report",  # a report build, checked in Chromium
    "test_report_within_limits.py": "report_within_limits",  # a report build with the section
    "test_visualization.py": "visualization",  # Chromium, a live meshcat server, three pages
    "test_visualization_overlays.py": "visualization_overlays",  # Chromium on a page
    "test_bags.py": "bags",  # a 30-s log at 1 kHz and its identification
    "test_identification.py": "identification",  # a 30-s closed-loop log at 2 kHz
    "test_physical.py": "physical",  # identify --physical (cvxpy + Clarabel)
    "test_plotting.py": "plotting",  # closed-loop runs and their figures
    "test_controllers.py": "controllers",  # two 8-s adaptive runs (Lyapunov checks)
    "test_simulation.py": "simulation",  # the cached 3-s DOP853 reference runs (conftest_sim.run)
    "test_tune_browser.py": "tune",  # Chromium on two live tune servers
    "test_tune_page.py": "tune_page",  # one Chromium page on a live tuner, its tests in order
    "test_tune_layout.py": "tune_layout",  # Chromium at 1366x768 on a live mpc tuner
    "test_tune_page_periods.py": "tune_page_periods",  # one Chromium for its tuners
}
"""Test file → its xdist group: files whose expensive per-process setup is shared by their tests."""

MARKS: dict[str, tuple[str, ...]] = {
    "test_cluster.py": ("cluster",),  # a dask scheduler and workers
    "test_interrupt_workers.py": ("cluster", "report"),  # Ctrl-C while a report or a LocalCluster forks
    "test_docs.py": ("docs",),  # the strict site build on the executed tutorial
    "test_tutorial.py": ("docs",),  # the tutorial on a fresh kernel
    "test_docs_task_space.py": ("docs",),  # the page's commands: four 16-s UR5 runs and a sweep
    "test_docs_images.py": ("docs",),  # an image maker of scripts/docs_images.py
    "test_docs_limits.py": ("docs",),  # the page's commands: two 2.5-s Panda runs, one failing at 0.12 s
    "test_report.py": ("report",),  # report builds
    "test_report_within_limits.py": ("report",),  # two short report builds, one with the section
    "test_benchmark_script.py": ("slow",),  # scripts/benchmark.py --quick: minutes
}
"""Test file → markers added to each of its tests (``make check`` deselects them: pyproject's markers)."""

SLOW: tuple[str, ...] = (
    # whole files whose shared setup is itself slow (a 30-s log at 2 kHz, cvxpy, figures of runs)
    "tests/test_identification.py::",
    "tests/test_bags.py::",
    "tests/test_physical.py::",
    "tests/test_plotting.py::",
    # tests of 15 s or more in a `make check` run at load ~13 on the 2-core VM (2026-12-03)
    "tests/test_task_cli.py::test_compare_tabulates_the_task_space_laws",
    "tests/test_task_cli.py::test_simulate_shows_a_task_space_laws_errors_in_mm_and_deg",
    "tests/test_new_laws.py::test_impedance_settles_at_the_stiffness_inverse_times_the_wrench",
    "tests/test_new_laws.py::test_pid_removes_the_steady_error_of_a_constant_disturbance_pd_keeps",
    "tests/test_new_laws.py::test_every_new_law_runs_on_every_robot_and_reduces_the_error",
    "tests/test_new_laws.py::test_osc_position_error_follows_the_designed_linear_dynamics",
    "tests/test_new_laws.py::test_batch_equals_single_runs",
    "tests/test_batch.py::test_a_run_does_not_depend_on_its_batch_nor_on_threads",
    "tests/test_plant_events.py::test_adaptive_reconverges_after_a_payload_step_computed_torque_does_not",
    "tests/test_controllers.py::test_adaptive_lyapunov_function_never_increases",
    "tests/test_cli.py::test_console_script_runs_as_a_process",
    "tests/test_cli.py::test_animate_live_serves_on_loopback_and_stops_cleanly_on_ctrl_c",
    "tests/test_cli.py::test_simulate_last_period_line_says_when_the_run_is_shorter_than_a_period",
    "tests/test_cli.py::test_simulate_takes_a_law_from_a_users_file",
    "tests/test_simulation.py::test_rk4_gap_to_adaptive_step_shrinks_like_dt_to_the_fourth",
    "tests/test_simulation.py::test_smoothed_friction_with_adaptive_step_matches_exact_sgn_with_rk4",
    "tests/test_simulation.py::test_rk4_and_adaptive_step_method_agree",
    "tests/test_simulation.py::test_stiff_gain_with_the_adaptive_method_stops_instead_of_hanging",
    "tests/test_simulation.py::test_a_stiff_law_with_the_adaptive_method_is_recognised_from_its_pace",
    "tests/test_plant.py::test_work_of_the_applied_torque_equals_the_energy_change",
    "tests/test_variants.py::test_written_payload_urdf_gives_the_same_p_as_load_robot",
    "tests/test_entry.py::test_stages_are_reported_in_order",
    "tests/test_example_sliding_mode.py::test_it_tracks_the_reports_trajectory",
    "tests/test_sweep_wrench.py::",
    "tests/test_run_spec.py::test_animate_from_a_saved_ur5_run_needs_nothing_else",
    "tests/test_openmp.py::test_pinocchio_imported_first_keeps_its_policy",
    "tests/test_openmp.py::test_a_wait_policy_the_user_chose_is_kept",
    "tests/test_openmp.py::test_importing_the_package_sets_the_passive_wait_policy_before_pinocchio_loads",
    "tests/test_any_robot.py::test_adaptive_tracks_under_gravity_with_v_dot_le_0",
    "tests/test_corpus.py::test_command_line[dataloss-compare-twice-no-stale-figures]",
    "tests/test_corpus.py::test_command_line[hang-simulate-adaptive-",
    "tests/test_corpus.py::test_command_line[hang-compare-adaptive-",
    "tests/test_corpus.py::test_command_line[hang-animate-from-zip-bomb]",
    "tests/test_corpus.py::test_command_line[hang-identify-data-npz-bomb]",
    "tests/test_corpus.py::test_command_line[traceback-report-qp-osc-",  # a Panda report: 15 s of CPU
)
"""Node-id prefixes marked ``slow`` here (``make check`` leaves them to ``make test``), beside
the tests marked ``slow`` in their own files."""

CLUSTER_TESTS: tuple[str, ...] = ("tests/test_run_timeout.py::test_a_sweep_on_dask_workers",)
"""Node-id prefixes outside test_cluster.py that start Dask workers."""

PROCESS_RUNS = ("proc", "signal", "setpriv", "fullfs", "devsandbox")
"""Corpus cases run as processes of their own (signals, limits, sandboxes): ``slow`` (111
cases, about a third of ``make check``'s time; ``make test`` runs them)."""
CLUSTER_OPTIONS = ("--workers", "--scheduler")
"""A corpus case whose command has one of these starts Dask workers: marked ``cluster``."""

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
    "test_simulation.py",  # 49 s quiet, grouped
    "test_visualization.py",  # 114 s, grouped
    "test_physical.py",  # 110 s, grouped
    "test_bags.py",  # 93 s, grouped
    "test_se3_trajectory.py",  # 95 s
)
"""Test files (or groups of them), longest first; the rest keep their collection order after them."""


def _file(item: pytest.Item) -> str:
    return item.nodeid.split("::", 1)[0].rsplit("/", 1)[-1]


def _mark(item: pytest.Item) -> None:
    for name in MARKS.get(_file(item), ()):
        item.add_marker(name)
    node = item.nodeid if item.nodeid.startswith("tests/") else f"tests/{item.nodeid}"
    if node.startswith(SLOW):
        item.add_marker("slow")
    if node.startswith(CLUSTER_TESTS):
        item.add_marker("cluster")
    case = item.callspec.params.get("case") if hasattr(item, "callspec") else None
    if _file(item) != "test_corpus.py" or not hasattr(case, "argv"):
        return
    if case.run in PROCESS_RUNS:
        item.add_marker("slow")  # a process of its own (~1–3 s each): make test's, not make check's
    commands = [case.argv, *(step.arg for step in case.setup if step.kind == "cli")]
    if any(argv[:1] == ("sweep",) and any(o in argv for o in CLUSTER_OPTIONS) for argv in commands):
        item.add_marker("cluster")  # workers start before the options are all checked
    if any(argv[:1] == ("report",) for argv in commands[1:]) or (
        case.argv[:1] == ("report",) and case.exits != (2,)
    ):
        item.add_marker("report")  # a report is built, whole or in part (a refusal is not)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The markers of :data:`MARKS`; the files of :data:`FIRST` first, longest first (xdist
    schedules in this order)."""
    for item in items:
        _mark(item)
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


@pytest.fixture(autouse=True)
def _signals_left_as_found() -> Any:
    """A test leaves SIGINT's handler and the main thread's signal mask as it found them: a
    process started later inherits both (SIGINT ignored or blocked there, a Ctrl-C test's
    command would run to its end and exit 0)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = (signal.getsignal(signal.SIGINT), signal.pthread_sigmask(signal.SIG_BLOCK, []))
    yield
    after = (signal.getsignal(signal.SIGINT), signal.pthread_sigmask(signal.SIG_BLOCK, []))
    assert after == before, f"SIGINT's handler or the signal mask changed: {before} -> {after}"


@pytest.fixture(autouse=True, scope="session")
def _equations_cache_of_the_run(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """The symbolic equations' cache (twolink_pin/symbolic/cache.py) in a folder of this test
    run, not the user's ~/.cache: the report, the tutorial and the CLI tests derive through it
    (subprocesses inherit the variable). A test that needs its own sets it again."""
    import os

    if "TWOLINK_PIN_CACHE" not in os.environ:
        os.environ["TWOLINK_PIN_CACHE"] = str(tmp_path_factory.mktemp("equations-cache"))
    return os.environ["TWOLINK_PIN_CACHE"]
