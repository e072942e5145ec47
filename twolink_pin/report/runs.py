"""The report's tasks for the laws: the reference, one law's run with its figures (a worker
task: picklable arguments only), the desired trajectory's figures."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from twolink_pin.errors import InvalidParameterError
from twolink_pin.feasibility import check_torques
from twolink_pin.law_variant import Variant, file_stem
from twolink_pin.metrics import Metrics, compute_metrics
from twolink_pin.report.options import ReportOptions
from twolink_pin.simulation import SimulationResult, simulate
from twolink_pin.trajectory import default_trajectory


def reference_trajectory(robot: Any, options: ReportOptions) -> Any:
    """The trajectory the runs track: the options' file, else the robot's default."""
    from twolink_pin.trajectory import read_trajectory_file

    reference = (
        read_trajectory_file(options.trajectory, robot) if options.trajectory else default_trajectory(robot)
    )
    if not hasattr(reference, "via_q"):
        raise InvalidParameterError(
            "trajectory",
            options.trajectory,
            "a via-point trajectory file (the report shows its via points and coefficients); a Fourier "
            "excitation is for identify --trajectory, simulate, compare and animate",
        )
    return reference


def run_law(
    variant: Variant,
    options: ReportOptions,
    fig_dir: str,
    figure_numbers: dict[str, int] | None,
) -> tuple[SimulationResult, Metrics, list[str], float]:
    """Worker: one row's run (a law, or a variant of it), metrics and figures (picklable
    arguments only); its figures are prefixed by the row's name
    (:func:`~twolink_pin.law_variant.file_stem`)."""
    from twolink_pin.plotting import save_simulation_figures
    from twolink_pin.plotting.run import wrench_spans

    start = time.perf_counter()
    robot = options.load_robot()
    cls, key = variant.law_class(), variant.key
    prefix, title = file_stem(key), cls.title if key == cls.name else f"{cls.title}, {key}"
    controller, plant = options.run.for_law(variant).build(robot)
    result = simulate(controller, plant, reference_trajectory(robot, options), options.run.simulation)
    metrics = compute_metrics(result)
    spans = wrench_spans(options.run.plant.wrench)  # a push shaded where it acts
    paths = save_simulation_figures(
        result, Path(fig_dir), prefix=prefix, figure_numbers=figure_numbers, title=title, spans=spans
    )
    if cls.task_space:  # the law's class declares it: its task errors beside the joint figures
        from twolink_pin.plotting import save_task_error_figure

        path = Path(fig_dir) / f"{prefix}_task_error.png"
        paths.append(save_task_error_figure(robot, result, path, title, spans))
    return result, metrics, [Path(p).name for p in paths], time.perf_counter() - start


def trajectory_figures(
    options: ReportOptions, fig_dir: str, figure_numbers: dict[str, int] | None
) -> list[str]:
    """The desired trajectory's figures (the report makes them in its own process while the
    workers run the laws)."""
    from twolink_pin.plotting import save_trajectory_figures

    robot = options.load_robot()
    trajectory = reference_trajectory(robot, options)
    check = check_torques(robot, trajectory)
    paths = save_trajectory_figures(robot, trajectory, check, Path(fig_dir), figure_numbers=figure_numbers)
    return [p.name for p in paths]
