"""``simulate``, ``compare``, ``report``: one law or several, run and shown (``animate``: animate.py)."""

from __future__ import annotations

import argparse
import shlex
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.cli.commands.common import (
    gains_echo,
    identified_parameters,
    robot_from_args,
    run_spec,
    trajectory_from_args,
)
from twolink_pin.cli.contact_summary import ContactRuns, contact_summary, save_run_contact_figure
from twolink_pin.cli.output import emit, fmt, progress_bar
from twolink_pin.cli.task_space import is_task_space, save_task_figure, task_lines, task_summary

if TYPE_CHECKING:
    from twolink_pin.metrics import Metrics
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationResult
    from twolink_pin.task_metrics import TaskMetrics


def _result_payload(result: SimulationResult, metrics: Metrics) -> dict[str, Any]:
    return {
        "controller": result.controller,
        "robot": result.robot,
        "duration": result.duration,
        "dt": result.dt,
        "metrics": metrics.as_dict(),
        "peak_torque": np.abs(result.tau).max(axis=0).tolist(),
        "peak_command": np.abs(result.tau_command).max(axis=0).tolist(),
        "torque_limits": result.torque_limits.tolist(),
        "limit_exceeded": result.limit_exceeded.tolist(),
        "limit_exceeded_at": result.first_exceeded_at,
        "limits": result.joint_limits.as_dict(),
        "crossings": metrics.crossings.summary(),
        "relaxed": None if result.relaxed is None else result.relaxed.summary(),
        "within_limits": metrics.crossings.within_limits,  # every kind; limit_exceeded: the effort alone
        "joint_stops": result.position_stops,
        "parameter_names": list(result.parameter_names),
        "p_true": None if result.p_true is None else result.p_true.tolist(),
        "p_hat_final": None if result.p_hat is None else result.p_hat[-1].tolist(),
    }


def cmd_simulate(args: argparse.Namespace) -> int:
    from twolink_pin.metrics import compute_metrics
    from twolink_pin.run_spec import plant_description
    from twolink_pin.simulation import simulate
    from twolink_pin.simulation.config import joint_offsets

    robot = robot_from_args(args)
    spec = run_spec(args, args.controller)
    reference = trajectory_from_args(args, robot)
    spec.check_effective(robot, trajectory=reference)
    scenario = spec.build(robot, identified_parameters(spec, robot))
    result = simulate(*scenario, reference, spec.simulation)
    metrics = compute_metrics(result)
    for warning in position_warnings(result.controller, result):
        print(warning, file=sys.stderr)
    payload = _result_payload(result, metrics)
    task = task_summary(result, robot)  # every law: the end effector's errors
    payload["task_metrics"] = task.as_dict()
    payload["contact_metrics"], contact = contact_summary(result, robot)  # a scene: the force held
    q0_offset = joint_offsets("q0_offset", spec.simulation.q0_offset, robot.profile.q0_offset, robot.nv)
    gains, gains_text = gains_echo(scenario.controller)
    payload |= {
        "gains": gains,
        "plant": plant_description(scenario),
        "plant_friction": scenario.plant.friction_dict(),
        "believed": _believed(spec),
        "q0_offset": q0_offset.tolist(),
        "run": spec.as_dict(),
    }
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting import save_simulation_figures
        from twolink_pin.plotting.run import wrench_spans

        spans = wrench_spans(spec.plant.wrench)  # a push shaded where it acts
        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_simulation_figures(result, folder, spans=spans)]
            if is_task_space(scenario.controller):
                figures.append(str(save_task_figure(robot, result, folder, result.controller, spans=spans)))
            figures += save_run_contact_figure(result, robot, folder, result.controller)
    if args.save:
        from twolink_pin.simulation.storage import save_result

        save_result(result, args.save, record=run_record(args, spec))
    payload["figures"] = figures
    lines = [
        f"controller {result.controller} on {result.robot}: {result.duration:g} s, dt = {result.dt:g} s ({result.method})",
        f"  gains {gains_text}",
        f"  plant {scenario.plant.describe(values=True)}; start q(0) − q_des(0) {fmt(q0_offset, 4)} rad",
        *([] if spec.parameters is None else [f"  {_believed_text(spec, robot.name)}"]),
        f"  RMS  e {fmt(metrics.rms.e, 5)} rad   edot {fmt(metrics.rms.edot, 5)} rad/s   tau {fmt(metrics.rms.tau, 3)} N·m",
        f"  max  e {fmt(metrics.max.e, 5)} rad   edot {fmt(metrics.max.edot, 5)} rad/s   tau {fmt(metrics.max.tau, 3)} N·m",
        f"  last period max |e| ({', '.join(f'{x:.4g}' for x in metrics.final_period_max_abs_e)}) rad"
        + (
            f" (the run is shorter than one {result.reference_period:g}-s period: over the whole run)"
            if result.duration < result.reference_period
            else ""
        ),
        *task_lines(task),
        *contact,
    ]
    lines += _limit_and_estimate_lines(result, metrics)
    lines += [f"  figure {f}" for f in figures]
    if args.save:
        lines.append(f"  saved {args.save}")
    emit(args, payload, "\n".join(lines))
    return 0


def position_warnings(name: str, result: SimulationResult) -> list[str]:
    """One warning per joint of the run of law ``name`` that passed its position range (joint,
    first time, largest excess), for stderr: a plant never lets it pass silently."""
    return [
        f"twolink-pin: warning: {name}: {sentence} (the plant has no stop there: --joint-stops makes "
        "the range a hard stop)"
        for sentence in result.crossings.sentences(result.joint_limits, ("position",))
    ]


def _limit_and_estimate_lines(result: Any, metrics: Metrics) -> list[str]:
    """The summary's lines on the limits (position range and velocity crossed; torque exceeded,
    clipped, absent) and, for an adaptive law, its estimates at the end against the truth."""
    out: list[str] = [f"  {s}" for s in metrics.crossings.sentences(result.joint_limits)]
    relaxed = result.relaxed
    if relaxed is not None and relaxed.relaxed:
        out += [f"  {line}" for line in relaxed.text(result.joint_names or None).splitlines()]
    if result.position_stops:
        out.append("  joint stops: each position range a hard stop (--joint-stops)")
    for j, (over, at) in enumerate(zip(result.limit_exceeded, result.first_exceeded_at)):
        if over:
            out.append(
                f"  joint {j + 1}: commanded torque exceeded its {result.torque_limits[j]:g} N·m limit "
                f"(first at t = {at:.3f} s, by up to {result.limit_excess[j]:.3g} N·m"
                + (
                    ", clipped by the plant)"
                    if result.saturate
                    else "; not saturated: add --saturate to clip)"
                )
            )
    if not np.isfinite(result.torque_limits).any():
        out.append("  no effort limits in the model: torques are not checked against limits")
    if result.p_hat is not None and result.p_true is not None:
        if len(result.parameter_names) <= 8:
            out.append(f"  p_hat(end) {fmt(result.p_hat[-1])}  true {fmt(result.p_true)}")
        else:
            err = np.abs(result.p_hat[-1] - result.p_true)
            out.append(
                f"  {len(result.parameter_names)} estimates; max |p_hat − p| at the end {err.max():.4g}"
            )
    return out


def _believed(spec: RunSpec) -> dict[str, str] | None:
    """``--model`` / ``--p0``: the file the law's model believes or its estimates start at."""
    if spec.parameters is None:
        return None
    return {"file": spec.parameters, "use": spec.parameters_use}


def _believed_text(spec: RunSpec, robot: str) -> str:
    kind = (
        "the inertias of the URDF" if str(spec.parameters).lower().endswith(".urdf") else "the parameters of"
    )
    if spec.parameters_use == "model":
        return f"law's model believes {kind} {spec.parameters} (--model); the plant is {robot}'s own"
    return f"estimates start at {kind} {spec.parameters} (--p0); the plant is {robot}'s own"


def cmd_compare(args: argparse.Namespace) -> int:
    from twolink_pin.files import output_directory
    from twolink_pin.law_variant import parse_variants
    from twolink_pin.run_rows import build_rows
    from twolink_pin.run_spec import gains_used, plant_description
    from twolink_pin.scenario import builtin_laws
    from twolink_pin.studies.comparison import run_comparison

    robot = robot_from_args(args)
    shared = run_spec(args)
    reference = trajectory_from_args(args, robot)
    pressing = shared.plant.scene is not None and reference.force_reference is not None  # the force laws too
    variants = parse_variants(args.controllers or list(builtin_laws(pressing)))  # LAW or LAW@KEY=VALUE…
    laws = [v.law for v in variants]
    shared.check_law_gains(laws)
    shared.check_effective(robot, laws, reference)
    rows = build_rows(shared, variants, robot, lambda spec: identified_parameters(spec, robot), reference)
    warnings: list[str] = []  # printed once the progress bar is gone
    with output_directory(args.out, ".twolink-pin-compare") as stage:
        bar = progress_bar(len(rows), "run", "compare")
        figures = _ComparisonFigures(args, shared, rows, robot, stage / "figures")
        tasks: dict[str, TaskMetrics] = {}
        contacts = ContactRuns(robot)  # a scene: each law's force held, drawn together

        def run(key: str) -> SimulationResult:
            from twolink_pin.simulation import simulate
            from twolink_pin.task_metrics import task_metrics

            row = rows[key]
            result = simulate(*row.scenario, reference, row.spec.simulation)
            tasks[key] = task_metrics(result, robot)  # every law moves the same end effector
            contacts.add(key, result)
            return result

        relaxed: dict[str, Any] = {}

        def on_result(key: str, result: SimulationResult) -> None:
            warnings.extend(position_warnings(key, result))
            figures.add(key, result)
            if result.relaxed is not None:
                relaxed[key] = result.relaxed

        def progress(name: str, result: SimulationResult | None) -> None:
            if result is not None:
                bar.update(1)
            else:
                bar.set_postfix_str(name)

        try:
            table = run_comparison(run, list(rows), progress, on_result)
            figures.overlay()
            contacts.figure(stage / "figures", figures.on)
        finally:
            bar.close()
            for warning in warnings:
                print(warning, file=sys.stderr)
        table = replace(
            table,
            plants={k: plant_description(r.scenario) for k, r in rows.items()},
            gains={k: gains_used(r.scenario.controller) for k, r in rows.items()},
            task=tasks,
            contact=contacts.metrics,
            relaxed=relaxed,
        )
        files = [Path(args.out) / p.name for p in table.write(stage)]
    if table.failed:  # a failed run: one line on stderr, nothing on stdout; the folder holds the rest
        _say_failed(table.failed, f"the other laws' results are in {args.out}")
        return 1
    payload = table.as_dict() | {"believed": _believed(shared), "files": [str(f) for f in files]}
    said = [] if shared.parameters is None else [_believed_text(shared, robot.name)]
    emit(args, payload, table.markdown() + "\n" + "\n".join([*said, *(f"wrote {f}" for f in files)]))
    return 0


class _ComparisonFigures:
    """``compare``'s figures: each row's (prefixed by its name, :func:`~twolink_pin.law_variant.file_stem`)
    as it finishes, then the variants of each law overlaid (``<law>_variants.png``) once all ran.
    Nothing with ``--no-plot``."""

    def __init__(
        self, args: argparse.Namespace, shared: RunSpec, rows: dict[str, Any], robot: Any, folder: Path
    ):
        from twolink_pin.plotting.run import wrench_spans

        self.on = not args.no_plot
        self.rows, self.robot, self.folder = rows, robot, folder
        self.spans = wrench_spans(shared.plant.wrench)
        laws = [row.variant.name for row in rows.values()]
        self.shared_laws = {law for law in laws if laws.count(law) > 1}  # laws run more than once
        self.kept: dict[str, SimulationResult] = {}

    def add(self, key: str, result: SimulationResult) -> None:
        """Write the figures of row ``key``'s run (and keep it for the overlay, if its law has variants)."""
        if not self.on:
            return
        from twolink_pin.law_variant import file_stem
        from twolink_pin.plotting import save_simulation_figures

        row = self.rows[key]
        cls, prefix = row.variant.law_class(), file_stem(key)
        title = cls.title if key == row.variant.name else f"{cls.title}, {key}"
        save_simulation_figures(result, self.folder, prefix=prefix, title=title, spans=self.spans)
        if is_task_space(cls):
            save_task_figure(self.robot, result, self.folder, prefix, title, self.spans)
        if row.variant.name in self.shared_laws:
            self.kept[key] = result

    def overlay(self) -> None:
        """``<law>_variants.png`` for each law with several rows that finished."""
        from twolink_pin.law_variant import file_stem
        from twolink_pin.plotting.overlay import save_overlay_figure

        for law in sorted(self.shared_laws):
            runs = {k: r for k, r in self.kept.items() if self.rows[k].variant.name == law}
            if len(runs) > 1:
                path = self.folder / f"{file_stem(law)}_variants.png"
                save_overlay_figure(runs, path, f"{law}: {len(runs)} runs overlaid", self.spans)
            for key in runs:
                del self.kept[key]


def _say_failed(failed: dict[str, str], where: str) -> None:
    """One line on stderr for the laws that did not finish (each with what happened and when)."""
    what = "; ".join(f"{name}: {text}" for name, text in failed.items())
    print(f"twolink-pin: {len(failed)} law(s) did not finish ({what}); {where}", file=sys.stderr)


def cmd_report(args: argparse.Namespace) -> int:
    from twolink_pin.report import ReportOptions, build_report

    options = ReportOptions(
        run=run_spec(args),
        robot=args.robot,
        payload=args.payload,
        controllers=None if args.controllers is None else tuple(args.controllers),
        workers=args.workers,
        animation=not args.no_animation,
        identification=not args.no_identification,
        limits_section=not args.no_limits_section,
        sim_to_sim=not args.no_sim_to_sim,
        sim_to_sim_all=args.sim_to_sim_all,
        trajectory=args.trajectory,
        repair_inertias=args.repair_inertias or None,
    )
    command = "twolink-pin " + " ".join(shlex.quote(a) for a in (args.argv or []))
    bar = progress_bar(1, "step", "report")

    def progress(what: str, done: int, total: int) -> None:
        bar.total = total
        bar.set_postfix_str(what)
        bar.update(done - bar.n)

    try:
        results = build_report(args.out, options, progress=progress, command_line=command)
    finally:
        bar.close()
    index = Path(args.out) / "index.html"
    failed = results.get("failed") or {}
    for warning in results.get("warnings") or []:
        print(f"twolink-pin: warning: {warning}", file=sys.stderr)
    if failed:  # a failed run: one line on stderr, nothing on stdout; the page holds the rest
        _say_failed(failed, f"the report with the others is {index}")
        return 1
    emit(
        args,
        {"index": str(index), "total_seconds": results["total_seconds"]},
        f"report written to {index} in {results['total_seconds']:.1f} s",
    )
    return 0


def run_record(args: argparse.Namespace, spec: RunSpec) -> dict[str, Any]:
    """What a saved result records beside its arrays: the robot (as given: a catalog name or a
    URDF path), its payload, the trajectory file and the run's spec."""
    from pathlib import Path as _Path

    robot = args.robot
    if robot is not None and (robot.endswith((".urdf", ".toml")) or "/" in robot):
        robot = str(_Path(robot).resolve())
    trajectory = getattr(args, "trajectory", None)
    return {
        "robot": robot,
        "payload": args.payload,
        "repair_inertias": bool(getattr(args, "repair_inertias", False)),
        "trajectory": None if trajectory is None else str(_Path(trajectory).resolve()),
        "run": spec.as_dict(),
    }
