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
from collections.abc import Callable, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import (
    ControllerError,
    InvalidParameterError,
    InvalidURDFError,
    SimulationDivergedError,
)
from twolink_pin.feasibility import check_torques
from twolink_pin.files import output_directory
from twolink_pin.metrics import Metrics
from twolink_pin.model import load_robot
from twolink_pin.report import facts
from twolink_pin.report.identification import (
    _identification_section,
    _reuses_adaptive_run,
    _submit_identification,
)
from twolink_pin.report.options import MAX_WORKERS, ReportOptions
from twolink_pin.report.pool import _pool
from twolink_pin.report.runs import _reference, _run, _trajectory_figures
from twolink_pin.scenario import builtin_laws, law_class, make_scenario
from twolink_pin.simulation import SimulationResult
from twolink_pin.simulation.config import joint_offsets
from twolink_pin.studies.comparison import ComparisonTable
from twolink_pin.trajectory import default_trajectory, default_via_points

MARKER = ".twolink-pin-report"
"""File that marks a directory as written by this command (safe to replace)."""
ANIMATED = "adaptive"
"""The law whose run the report animates (the first law if it is not run)."""

Progress = Callable[[str, int, int], None]

__all__ = ["MARKER", "MAX_WORKERS", "ReportOptions", "build_report", "laws_to_run"]


def laws_to_run(options: ReportOptions, is_twolink: bool) -> tuple[str, ...]:
    """The laws the report runs (see :class:`ReportOptions`)."""
    if options.controllers is not None:
        names = tuple(law_class(spec).name for spec in options.controllers)
        if len(set(names)) != len(names):
            raise InvalidParameterError("controllers", list(options.controllers), "each law at most once")
        return tuple(options.controllers)
    if is_twolink:
        from twolink_pin.twolink.reference import REPORT_CONTROLLERS

        return REPORT_CONTROLLERS
    return builtin_laws()


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
    robot = load_robot(options.robot, payload=options.payload)
    is_twolink = robot.name == "twolink"
    specs = laws_to_run(options, is_twolink)
    options.run.check_law_gains(specs)
    steps = (
        4 + len(specs) + (1 if options.animation else 0) + (1 if is_twolink and options.identification else 0)
    )
    done = 0

    def tick(what: str) -> None:
        nonlocal done
        done += 1
        if progress:
            progress(what, done, steps)

    with output_directory(out_dir, MARKER, "written by twolink-pin report\n") as stage:
        results = _build(stage, robot, is_twolink, specs, options, tick)
        results["total_seconds"] = time.perf_counter() - started
        results["command_line"] = command_line
        from twolink_pin.report.pages import write_pages

        write_pages(stage, results)
        tick("done")
    return results


def _build(
    stage: Path,
    robot: Any,
    is_twolink: bool,
    specs: Sequence[str],
    options: ReportOptions,
    tick: Callable[[str], None],
) -> dict[str, Any]:
    fig_dir = stage / "figures"
    fig_dir.mkdir()
    trajectory = _reference(robot, options)
    via = default_via_points(robot) if not options.trajectory else None
    check = check_torques(robot, trajectory)
    numbers: dict[str, dict[str, int]] = {}
    if is_twolink:
        from twolink_pin.twolink.reference import REPORT_FIGURES

        numbers = REPORT_FIGURES
    names = [law_class(spec).name for spec in specs]
    animated = ANIMATED if ANIMATED in names else names[0]
    order = [animated, *(n for n in names if n != animated)]
    by_name = dict(zip(names, specs))
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]] = {}
    failed: dict[str, str] = {}
    warnings: list[str] = []
    tried, shown = False, animated
    animation = None
    workers = min(options.workers, len(order) + 1)
    with _pool(workers) as pool:
        # The identification's runs first: they are the longest tasks (3 adaptive runs and a
        # logged run of 30 s), so the laws' runs fill the other worker meanwhile.
        reused = "adaptive" in names and _reuses_adaptive_run(options)
        ident_futures = (
            _submit_identification(pool, options, str(fig_dir), reused)
            if is_twolink and options.identification
            else None
        )
        futures = {n: pool.submit(_run, by_name[n], options, str(fig_dir), numbers.get(n)) for n in order}
        traj_future = pool.submit(_trajectory_figures, options, str(fig_dir), numbers.get("trajectory"))
        model = facts.model_facts(robot)
        twolink: dict[str, Any] | None = None
        if is_twolink:
            twolink = {
                "closed_form_check": facts.twolink_closed_form_check(robot),
                "table1": None if via is None else facts.table1(robot, via),  # None: another trajectory
            }
        tick("model and trajectory")
        for name in order:
            try:
                runs[name] = futures[name].result()
            except (SimulationDivergedError, ControllerError) as exc:  # the others' results are kept
                failed[name] = str(exc)
            tick(f"controller {name}")
            if options.animation and not tried and name in runs and (name == animated or animated in failed):
                from twolink_pin.visualization import write_html

                tried, shown = True, name
                res = runs[name][0]
                from twolink_pin.kinematics import joint_positions

                points = joint_positions(robot, trajectory.via_q)[:, -1, :]  # the end effector's via points
                try:
                    write_html(
                        robot, res.t, res.q, res.q_des, path=stage / "animation.html", via_points=points
                    )
                    animation = "animation.html"
                except InvalidURDFError as exc:  # a missing mesh: the report without its animation
                    warnings.append(f"no animation: {exc}")
                tick("animation")
        if options.animation and not tried:
            tick("animation")  # every law failed: nothing to animate
        traj_figs = traj_future.result()
        tick("trajectory figures")
        identification = None
        if ident_futures is not None:
            runs_future, fit_future = ident_futures
            excitation_runs = {key: f.result() for key, f in runs_future.items()}
            if reused and "adaptive" in runs:  # the report's own adaptive run is the one along its trajectory
                result = runs["adaptive"][0]
                assert result.p_hat is not None
                own = (np.asarray(result.t), np.asarray(result.p_hat)[:, : np.asarray(robot.p).size])
                excitation_runs = {"report": own, **excitation_runs}
            identification = _identification_section(
                options,
                str(fig_dir),
                excitation_runs,
                None if fit_future is None else fit_future.result(),
            )
            tick("identification")
    runs = {n: runs[n] for n in names if n in runs}  # the order asked for
    table = ComparisonTable(
        {n: r[1] for n, r in runs.items()},
        {n: r[3] for n, r in runs.items()},
        options.config.duration,
        {n: failed[n] for n in names if n in failed},
    )
    cfg = options.config
    q0_offset = joint_offsets("q0_offset", cfg.q0_offset, robot.profile.q0_offset, robot.nv)
    controllers = {}
    lams: dict[str, float] = {}
    for name, (result, metrics, figures, seconds) in runs.items():
        cls = law_class(by_name[name])
        controller = options.run.for_law(by_name[name]).build(robot).controller  # the gains it ran with
        if cls.takes("lam"):
            lams[name] = float(np.max(controller.gains.lam))
        controllers[name] = {
            "title": cls.title,
            "law": inspect.getdoc(cls) or "",
            "gains": controller.gains.describe(),
            "metrics": metrics.as_dict(),
            "figures": figures,
            "seconds": seconds,
            "p_hat_final": None if result.p_hat is None else result.p_hat[-1].tolist(),
            "p_true": None if result.p_true is None else result.p_true.tolist(),
            "parameter_names": list(result.parameter_names),
            "limit_exceeded": result.limit_exceeded.tolist(),
            "limit_exceeded_at": result.first_exceeded_at,
        }
    errata: list[dict[str, Any]] = []
    if is_twolink:
        lam = next(iter(lams.values()), 5.0)
        errata = _twolink_errata(robot, trajectory, runs, by_name, options, q0_offset, lam)
    tick("errata")
    out: dict[str, Any] = {
        "robot": model,
        "twolink": twolink,
        "trajectory": {
            "times": trajectory.times.tolist(),
            "via_q": trajectory.via_q.tolist(),
            "via_xy": None if via is None else [list(p) for p in via.xy],
            "period_s": trajectory.period,
            "coefficients": trajectory.coefficients.tolist(),
            "figures": traj_figs,
        },
        "torque_check": facts.torque_facts(check),
        "simulation": asdict(cfg)
        | {
            "q0_offset": q0_offset.tolist(),
            "lambda": lams,
            "saturate": options.saturate,
            "friction_smoothing": options.friction_smoothing,
        },
        "run": options.run.as_dict(),
        "controllers": controllers,
        "failed": table.failed,
        "comparison": table.as_dict(),
        "comparison_markdown": table.markdown(),
        "comparison_csv": table.csv(),
        "animation": animation,
        "warnings": warnings,
        "animated": shown,
        "errata": errata,
        "identification": identification,
        "versions": facts.versions(),
    }
    if is_twolink:
        from twolink_pin.twolink.reference import (
            REPORT_COEFFICIENTS,
            REPORT_P,
            REPORT_TABLE2,
            REPORT_TABLE2_COLUMNS,
        )

        assert twolink is not None
        twolink["report_p"] = REPORT_P
        twolink["report_coefficients"] = [list(c) for c in REPORT_COEFFICIENTS]
        twolink["report_table2"] = {n: list(v) for n, v in REPORT_TABLE2.items()}
        twolink["report_table2_columns"] = list(REPORT_TABLE2_COLUMNS)
    return out


def _twolink_errata(
    robot: Any,
    trajectory: Any,
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]],
    by_name: dict[str, str],
    options: ReportOptions,
    q0_offset: np.ndarray,
    lam: float,
) -> list[dict[str, Any]]:
    from twolink_pin.twolink import errata

    report_trajectory = default_trajectory(robot)  # the errata are about the report's own trajectory
    items = [
        errata.third_via_point(robot),
        errata.printed_coefficients(report_trajectory),
        errata.y3_sign(robot),
    ]
    items.append(errata.unstated_settings(lam, tuple(q0_offset.tolist())))
    if "robust" in runs:
        items.append(errata.robust_naming(runs["robust"][0]))
    if "adaptive" in runs:
        cls = law_class(by_name["adaptive"])
        controller = make_scenario(cls, robot, lam=options.lam).controller
        items.append(errata.parameter_convergence(runs["adaptive"][0], controller, trajectory))  # type: ignore[arg-type]
    return [e._asdict() for e in items]
