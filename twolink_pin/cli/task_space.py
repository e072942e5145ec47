"""What ``simulate`` and ``compare`` add for a task-space law (one whose class declares
``task_space = True``): its task-space metrics (position error [mm], orientation error [deg]:
RMS, max, last period; :func:`~twolink_pin.task_metrics.task_metrics`) in the summary and
``--json``, and the task-error figure beside the joint ones in ``--plot``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from twolink_pin.controllers import Controller
    from twolink_pin.model import RobotModel
    from twolink_pin.simulation import SimulationResult
    from twolink_pin.task_metrics import TaskMetrics


def is_task_space(controller: Controller | type) -> bool:
    """Whether the law (an instance or its class) declares ``task_space = True``."""
    return bool(getattr(controller, "task_space", False))


def task_summary(controller: Controller, result: SimulationResult, robot: RobotModel) -> TaskMetrics | None:
    """The run's task-space metrics for a task-space law, else None."""
    if not is_task_space(controller):
        return None
    from twolink_pin.task_metrics import task_metrics

    return task_metrics(result, robot)


def task_lines(metrics: TaskMetrics | None) -> list[str]:
    """The summary's lines for ``metrics`` (none for None)."""
    if metrics is None:
        return []
    m = metrics
    return [
        f"  task |p − p_d| RMS {m.position_rms_mm:.4g} mm   max {m.position_max_mm:.4g} mm   "
        f"last period max {m.position_last_period_max_mm:.4g} mm",
        f"  task angle     RMS {m.orientation_rms_deg:.4g} deg  max {m.orientation_max_deg:.4g} deg  "
        f"last period max {m.orientation_last_period_max_deg:.4g} deg",
    ]


def save_task_figure(
    robot: RobotModel, result: SimulationResult, folder: Path, prefix: str, title: str | None = None
) -> Path:
    """``<prefix>_task_error.png`` in ``folder`` (:func:`~twolink_pin.plotting.save_task_error_figure`)."""
    from twolink_pin.plotting import save_task_error_figure

    name = f"{prefix}_task_error.png" if prefix else "task_error.png"
    return save_task_error_figure(robot, result, Path(folder) / name, title)
