"""``twolink-pin report``: run everything and write the report folder.

Output in ``out_dir``: ``index.html`` (opens from ``file://``, no external request),
``report.md``, ``comparison.csv``, ``results.json``, ``figures/*.png`` and
``animation.html``. For the twolink the page follows the course report (Table 1, its
via points and coefficients, its Table 2 beside ours, the errata); for any other robot it
shows the same pipeline without the report's sections.

The folder is built in a staging folder and moved into place only when complete
(:func:`twolink_pin.files.output_directory`), so a failure, Ctrl-C or SIGTERM midway
leaves the previous report (or nothing) — never a half-written ``index.html`` and no
worker process behind.
"""

from __future__ import annotations

import inspect
import os
import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from twolink_pin import interrupts
from twolink_pin.contact_metrics import contact_metrics
from twolink_pin.errors import (
    ControllerError,
    InvalidURDFError,
    SimulationDivergedError,
)
from twolink_pin.feasibility import check_torques
from twolink_pin.files import output_directory
from twolink_pin.law_variant import Variant, file_stem, parse_variants
from twolink_pin.metrics import Metrics
from twolink_pin.report import facts, sim_to_sim
from twolink_pin.report.options import MAX_WORKERS, ReportOptions
from twolink_pin.report.pool import worker_pool
from twolink_pin.report.runs import reference_trajectory, run_law, trajectory_figures
from twolink_pin.report.within_limits import fill_report_runs, limits_section, reuses_report_runs
from twolink_pin.run_rows import Row, build_rows
from twolink_pin.run_spec import gains_used, plant_description
from twolink_pin.scenario import builtin_laws
from twolink_pin.simulation import SimulationResult
from twolink_pin.simulation.config import joint_offsets
from twolink_pin.studies.comparison import ComparisonTable
from twolink_pin.task_metrics import task_metrics
from twolink_pin.trajectory import default_via_points

MARKER = ".twolink-pin-report"
"""File that marks a directory as written by this command (safe to replace)."""
WORKERS_SHARE = ("twolink_pin.plotting.run", "scipy.interpolate", "scipy.optimize")
"""Modules every report's workers import (each law's figures; the limits section's retiming),
imported once in the report's process before they fork: ~0.7 s of CPU saved per worker."""
Progress = Callable[[str, int, int], None]

__all__ = ["MARKER", "MAX_WORKERS", "ReportOptions", "build_report", "laws_to_run"]


def laws_to_run(options: ReportOptions, robot: Any) -> tuple[Variant, ...]:
    """The rows the report runs (see :class:`ReportOptions`): the laws or variants asked for
    (``LAW@KEY=VALUE…``, :mod:`twolink_pin.law_variant`), else the robot profile's report
    laws, else every built-in law.

    Raises:
        InvalidParameterError: a bad variant, or the same one twice.
    """
    if options.controllers is not None:
        return parse_variants(options.controllers)
    laws = robot.profile.report.laws
    pressing = (
        options.run.plant.scene is not None
        and reference_trajectory(robot, options).force_reference is not None
    )
    return parse_variants(tuple(laws) if laws is not None else builtin_laws(pressing))


def build_report(
    out_dir: str | os.PathLike[str],
    options: ReportOptions | None = None,
    progress: Progress | None = None,
    command_line: str = "",
) -> dict[str, Any]:
    """Write the report into ``out_dir``; returns the ``results.json`` content.

    Raises:
        OutputError: ``out_dir`` is a file or a non-empty directory that holds no report,
            or it cannot be written.
        SimulationDivergedError, ControllerError: a run failed (the message names the law
            and the time); nothing is written.
    """
    options = options if options is not None else ReportOptions()
    started = time.perf_counter()
    robot = options.load_robot()
    sections = robot.profile.report.sections  # the robot's own sections (the twolink's course report)
    variants = laws_to_run(options, robot)
    laws = [v.law for v in variants]
    options.run.check_law_gains(laws)
    reference = reference_trajectory(robot, options)
    options.run.check_effective(robot, laws, reference)
    # every row's law built once, and its step checked, before any run
    rows = build_rows(options.run, variants, robot, trajectory=reference)
    steps = 4 + len(rows) + (1 if options.animation else 0) + (1 if options.limits_section else 0)
    steps += 1 if options.sim_to_sim else 0
    steps += sections.steps(options, laws) if sections else 0
    done = 0
    heard = len(interrupts.received)

    def tick(what: str) -> None:
        nonlocal done
        interrupts.check(since=heard)  # a signal some library caught on its way stops the report here
        done += 1
        if progress:
            progress(what, done, steps)

    with output_directory(out_dir, MARKER, "written by twolink-pin report\n") as stage:
        results = _build(stage, robot, rows, options, tick)
        results["total_seconds"] = time.perf_counter() - started
        results["command_line"] = command_line
        from twolink_pin.report.pages import write_pages

        write_pages(stage, results)
        tick("done")
    return results


def _build(
    stage: Path,
    robot: Any,
    rows: dict[str, Row],
    options: ReportOptions,
    tick: Callable[[str], None],
) -> dict[str, Any]:
    """The report's runs and figures written into ``stage``; returns ``results.json``'s content."""
    trajectory = reference_trajectory(robot, options)
    via = default_via_points(robot) if not options.trajectory else None
    check = check_torques(robot, trajectory)
    sections = robot.profile.report.sections
    names = list(rows)
    ran = _run_all(stage, robot, trajectory, via, rows, options, tick)
    runs = {n: ran.runs[n] for n in names if n in ran.runs}  # the order asked for
    cfg = options.run.simulation
    q0_offset = joint_offsets("q0_offset", cfg.q0_offset, robot.profile.q0_offset, robot.nv)
    task = {n: task_metrics(r[0], robot) for n, r in runs.items()}  # every law moves the end effector
    contact = {n: m for n, r in runs.items() if (m := contact_metrics(r[0], robot)) is not None}  # a scene
    table = ComparisonTable(
        {n: r[1] for n, r in runs.items()},
        {n: r[3] for n, r in runs.items()},
        cfg.duration,
        {n: ran.failed[n] for n in names if n in ran.failed},
        plants={n: plant_description(rows[n].scenario) for n in names},
        gains={n: gains_used(rows[n].scenario.controller) for n in names},
        task=task,
        contact=contact,
    )
    controllers, lams = _law_entries(runs, rows, task, contact)
    errata: list[dict[str, Any]] = []
    if sections:
        done_runs = {n: r[0] for n, r in runs.items()}
        laws = {n: row.variant.law for n, row in rows.items()}
        errata = sections.errata(robot, trajectory, done_runs, laws, options, q0_offset, lams)
    tick("errata")
    return {
        "robot": ran.model,
        "twolink": ran.own_facts,
        "trajectory": _trajectory_facts(trajectory, via, ran.trajectory_figures),
        "torque_check": facts.torque_facts(check),
        "simulation": asdict(cfg)
        | {
            "q0_offset": q0_offset.tolist(),
            "lambda": lams,
            "saturate": options.run.plant.saturate,
            "joint_stops": options.run.plant.position_stops,
            "friction_smoothing": options.run.friction_smoothing,
        },
        "run": options.run.as_dict(),
        "controllers": controllers,
        "failed": table.failed,
        "comparison": table.as_dict(),
        "comparison_markdown": table.markdown(),
        "contact_figure": _contact_figure(stage, robot, {n: runs[n][0] for n in contact}),
        "comparison_csv": table.csv(),
        "overlays": ran.overlays,
        "animation": ran.animation,
        "warnings": ran.warnings
        + [  # a run that passed a position range says so (the CLI prints them)
            f"{name}: {sentence}"
            for name, (result, metrics, *_) in runs.items()
            for sentence in metrics.crossings.sentences(result.joint_limits, ("position",))
        ],
        "animated": ran.animated,
        "errata": errata,
        "identification": ran.identification,
        "within_limits": ran.within_limits,
        "sim_to_sim": ran.sim_to_sim,
        "versions": facts.versions(),
    }


class _Ran(NamedTuple):
    """What the worker pool made: the laws' runs and the figures, animation and sections."""

    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]]
    """Each law that ran: its result, metrics, figure names and wall time [s], in run order."""
    failed: dict[str, str]
    """Each law whose run failed: the error."""
    warnings: list[str]
    """What the report goes without (an animation whose meshes are missing)."""
    animation: str | None
    """The animation's file name, None without."""
    animated: str
    """The law animated (the profile's, else the first that ran)."""
    trajectory_figures: list[str]
    """The desired trajectory's figure names."""
    identification: Any
    """The robot's own sections' identification results (None without)."""
    model: dict[str, Any]
    """The robot's facts."""
    own_facts: Any
    """The robot's own sections' facts (None without)."""
    overlays: dict[str, str]
    """Each law run as several variants: the figure of their runs overlaid (file name)."""
    within_limits: dict[str, Any] | None
    """The section "The reference within the limits" (:mod:`~twolink_pin.report.within_limits`),
    None without it."""
    sim_to_sim: dict[str, Any] | None
    """The section "Sim-to-sim" (:mod:`~twolink_pin.report.sim_to_sim`), None without it."""


def _run_all(
    stage: Path,
    robot: Any,
    trajectory: Any,
    via: Any,
    rows: dict[str, Row],
    options: ReportOptions,
    tick: Callable[[str], None],
) -> _Ran:
    """Every task of the worker pool: the robot's own sections, the limits section, each law's
    run and figures, the sim-to-sim rows; meanwhile in this process the facts, the desired
    trajectory's figures, the animation of the animated law (or, if it failed, of the first
    that ran) and the robot's own sections once the runs they read are in."""
    fig_dir = stage / "figures"
    fig_dir.mkdir()
    declared = robot.profile.report
    sections = declared.sections
    numbers = {k: dict(v) for k, v in declared.figure_numbers.items()}
    names = list(rows)
    animated = declared.animated_law if declared.animated_law in names else names[0]
    order = [animated, *(n for n in names if n != animated)]
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]] = {}
    failed: dict[str, str] = {}
    warnings: list[str] = []
    tried, shown = False, animated
    animation = None
    workers = min(options.workers or 1, len(order) + 1)  # None was resolved to the cores
    heard = len(interrupts.received)  # a signal from here on stops the waits below (result_of)
    limit_rows = [(n, rows[n].variant) for n in names]
    reused = options.limits_section and reuses_report_runs(options, trajectory)
    with worker_pool(workers, WORKERS_SHARE) as pool:
        submitted = _submit(pool, stage, sections, numbers, rows, order, options, reused)
        pending, limits_future, futures, sim_pending = submitted
        # This process's own work while the workers run: the facts, the trajectory's figures, the
        # animation and the robot's sections as soon as the runs they read are in (not after all).
        model = facts.model_facts(robot)
        own_facts = sections.facts(robot, via) if sections else None
        tick("model and trajectory")
        traj_figs = trajectory_figures(options, str(fig_dir), numbers.get("trajectory"))
        tick("trajectory figures")
        reads = set(sections.reads(names)) if sections and pending is not None else set()
        identification, collected = None, not (sections and pending is not None)
        for name in order:
            try:
                runs[name] = interrupts.result_of(futures[name], heard)
            except (SimulationDivergedError, ControllerError) as exc:  # the others' results are kept
                failed[name] = str(exc)
            tick(f"controller {name}")
            if options.animation and not tried and name in runs and (name == animated or animated in failed):
                tried, shown = True, name
                animation = _write_animation(stage, robot, trajectory, runs[name][0], options, warnings)
                tick("animation")
            if sections and not collected and reads <= set(runs) | set(failed):
                identification = sections.collect(pending, robot, options, str(fig_dir), _results(runs))
                collected = True
                tick("identification")
        if options.animation and not tried:
            tick("animation")  # every law failed: nothing to animate
        overlays = _write_overlays(fig_dir, rows, runs, options)
        within_limits = None
        if limits_future is not None:
            reused_runs = _results(runs) if reused else None
            within_limits = _limits_collected(limits_future, limit_rows, options, robot, reused_runs, heard)
            tick("the reference within the limits")
        sim_section = None
        if sim_pending is not None:
            sim_section = sim_to_sim.collect(sim_pending, robot, options, str(fig_dir), heard)
            tick("sim-to-sim")
    return _Ran(
        runs, failed, warnings, animation, shown, traj_figs, identification, model, own_facts, overlays,
        within_limits, sim_section,
    )  # fmt: skip


def _submit(
    pool: Any,
    stage: Path,
    sections: Any,
    numbers: dict[str, dict[str, int]],
    rows: dict[str, Row],
    order: list[str],
    options: ReportOptions,
    reused: bool,
) -> tuple[Any, Any, dict[str, Any], Any]:
    """Every worker task, longest first so that the short ones fill in at the end: the robot's own
    sections (the twolink's: 3 adaptive runs and a logged run of 30 s), the limits section (about
    as long as a law's run; its rows on the report's reference left to the laws' runs when
    ``reused``), each law's run and figures in ``order``, the sim-to-sim rows (short runs).
    Returns the sections' pending tasks, the limits section's future, each law's, the sim-to-sim's."""
    fig_dir, names = str(stage / "figures"), list(rows)
    pending = sections.submit(pool, options, fig_dir, names) if sections else None
    limits_future = (
        pool.submit(limits_section, [(n, rows[n].variant) for n in names], options, str(stage), reused)
        if options.limits_section
        else None
    )
    # the animated law first (its animation is written meanwhile), then the laws with the most state
    # (estimates, plans: each stage integrates it too, the longer runs) so that the short ones come last
    first = sorted(order[1:], key=lambda n: -rows[n].scenario.controller.state_size)
    futures = {
        n: pool.submit(run_law, rows[n].variant, options, fig_dir, numbers.get(n)) for n in order[:1] + first
    }
    variants = [(n, rows[n].variant) for n in names]
    sim_pending = sim_to_sim.submit(pool, variants, options) if options.sim_to_sim else None
    return pending, limits_future, futures, sim_pending


def _limits_collected(
    future: Any,
    rows: list[tuple[str, Any]],
    options: ReportOptions,
    robot: Any,
    reused: dict[str, SimulationResult] | None,
    heard: int,
) -> dict[str, Any]:
    """The limits section (waited for), its rows on the report's reference read from the laws'
    runs when it left them to them (``reused``: :func:`~twolink_pin.report.within_limits.fill_report_runs`)."""
    section: dict[str, Any] = interrupts.result_of(future, heard)
    return section if reused is None else fill_report_runs(section, rows, options, robot, reused)


def _results(
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]],
) -> dict[str, SimulationResult]:
    """Each law's simulation result, of its run's ``(result, metrics, figures, seconds)``."""
    return {name: run[0] for name, run in runs.items()}


def _write_overlays(
    fig_dir: Path,
    rows: dict[str, Row],
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]],
    options: ReportOptions,
) -> dict[str, str]:
    """``<law>_variants.png`` for each law run as several variants that finished: their runs
    overlaid (:func:`~twolink_pin.plotting.overlay.save_overlay_figure`); law → file name."""
    from twolink_pin.plotting.overlay import save_overlay_figure
    from twolink_pin.plotting.run import wrench_spans

    by_law: dict[str, dict[str, SimulationResult]] = {}
    for key, row in rows.items():
        if key in runs:
            by_law.setdefault(row.variant.name, {})[key] = runs[key][0]
    written = {}
    for law, results in by_law.items():
        if len(results) > 1:
            path = fig_dir / f"{file_stem(law)}_variants.png"
            title = f"{law}: {len(results)} runs overlaid"
            written[law] = save_overlay_figure(
                results, path, title, wrench_spans(options.run.plant.wrench)
            ).name
    return written


def _write_animation(
    stage: Path,
    robot: Any,
    trajectory: Any,
    result: SimulationResult,
    options: ReportOptions,
    warnings: list[str],
) -> str | None:
    """``animation.html`` of ``result`` with the end effector's via points and the push, if
    any; its name, or None (and a warning) when the robot's meshes are missing."""
    from twolink_pin.kinematics import joint_positions
    from twolink_pin.visualization import write_html

    points = joint_positions(robot, trajectory.via_q)[:, -1, :]  # the end effector's via points
    try:
        from twolink_pin.visualization.overlays import run_overlays

        write_html(
            robot,
            result.t,
            result.q,
            result.q_des,
            path=stage / "animation.html",
            via_points=points,
            **run_overlays(options.run.plant.wrench, result.t, options.run.plant.scene, result.wrench),
        )
    except InvalidURDFError as exc:  # a missing mesh: the report without its animation
        warnings.append(f"no animation: {exc}")
        return None
    return "animation.html"


def _law_entries(
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]],
    rows: dict[str, Row],
    task: dict[str, Any],
    contact: dict[str, Any],
) -> tuple[dict[str, dict[str, Any]], dict[str, float]]:
    """Each row that ran as ``results.json`` shows it (its law, gains, metrics, figures,
    estimates, limits, contact), and the λ [1/s] of those that have one."""
    controllers = {}
    lams: dict[str, float] = {}
    for name, (result, metrics, figures, seconds) in runs.items():
        row = rows[name]
        cls = row.variant.law_class()
        controller = row.scenario.controller  # the gains it ran with
        if cls.takes("lam"):
            lams[name] = float(np.max(controller.gains.lam))
        controllers[name] = {
            "title": cls.title,
            "law": inspect.getdoc(cls) or "",
            "variant": dict(row.variant.settings) if row.variant.settings else None,
            "gains": controller.gains.describe(),
            "metrics": metrics.as_dict(),
            "task_metrics": task[name].as_dict() if name in task else None,
            "contact_metrics": contact[name].as_dict() if name in contact else None,
            "figures": figures,
            "seconds": seconds,
            "p_hat_final": None if result.p_hat is None else result.p_hat[-1].tolist(),
            "p_true": None if result.p_true is None else result.p_true.tolist(),
            "parameter_names": list(result.parameter_names),
            "limit_exceeded": result.limit_exceeded.tolist(),
            "limit_exceeded_at": result.first_exceeded_at,
            "crossings": metrics.crossings.summary(),
            "crossed": metrics.crossings.sentences(result.joint_limits),
        }
    return controllers, lams


def _contact_figure(stage: Path, robot: Any, results: dict[str, SimulationResult]) -> str | None:
    """``figures/contact.png``: the runs against the scene drawn together (None without a scene)."""
    if not results:
        return None
    from twolink_pin.plotting.contact import save_contact_figure

    save_contact_figure(results, robot, stage / "figures" / "contact.png")
    return "contact.png"


def _trajectory_facts(trajectory: Any, via: Any, figures: list[str]) -> dict[str, Any]:
    """The reference as ``results.json`` shows it: via times [s] and joints [rad], the
    end effector's via points [m] (the robot's default reference), period [s], coefficients
    (None for a reference without: via poses, the straight lines of ``path = "lines"``)."""
    coefficients = getattr(trajectory, "coefficients", None)
    return {
        "times": trajectory.times.tolist(),
        "via_q": trajectory.via_q.tolist(),
        "via_xy": None if via is None else [list(p) for p in via.xy],
        "period_s": trajectory.period,
        "coefficients": None if coefficients is None else coefficients.tolist(),
        "figures": figures,
    }
