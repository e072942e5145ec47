"""The task-space error of one run: the end effector's position error [mm] and orientation
error [deg] over time (beside the joint figures of :mod:`twolink_pin.plotting.run`)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.model import RobotModel
from twolink_pin.plotting import _save
from twolink_pin.plotting._panels import shade_spans
from twolink_pin.plotting._style import ERROR_COLOR, LOG_FLOOR, new_figure
from twolink_pin.simulation import SimulationResult
from twolink_pin.task_metrics import task_errors, task_metrics

TASK_FIGSIZE = (8.0, 6.0)
"""Size of the task-error figure [in]."""


def _task_error_figure(robot: RobotModel, result: SimulationResult, title: str | None = None) -> Figure:
    errors = task_errors(robot, np.asarray(result.q), np.asarray(result.q_des))
    m = task_metrics(result, robot)  # the titles' numbers: the one definition of the tables
    t = np.asarray(result.t)
    position = 1e3 * np.linalg.norm(errors.position, axis=1)
    angle = np.degrees(np.linalg.norm(errors.orientation, axis=1))
    fig = new_figure(TASK_FIGSIZE)
    axes = fig.subplots(2, 1, sharex=True)
    for ax, values, label, unit, (rms, peak, late) in (
        (axes[0], position, "position error |p − p_d|", "mm", m[0:3]),
        (axes[1], angle, "orientation error |log(R R_dᵀ)|", "deg", m[3:6]),
    ):
        ax.set_label(unit)
        ax.semilogy(t, np.maximum(values, LOG_FLOOR), color=ERROR_COLOR, lw=1.0)
        ax.set_ylabel(f"[{unit}]")
        ax.set_title(
            f"{label}: RMS {rms:.3g} {unit}, max {peak:.3g} {unit}, last period max {late:.3g} {unit}",
            fontsize=10,
        )
        ax.grid(True, which="both", alpha=0.3)
    axes[1].set_xlabel("t [s]")
    fig.suptitle(title or f"controller {result.controller} on {robot.name}: task-space error", fontsize=11)
    return fig


def save_task_error_figure(
    robot: RobotModel,
    result: SimulationResult,
    path: str | os.PathLike[str],
    title: str | None = None,
    spans: Sequence[tuple[float, float]] = (),
) -> Path:
    """Write the task-error figure of ``result`` (a run of ``robot``) to ``path`` (PNG): the
    end effector's position error [mm] and orientation error [deg] against the desired
    frame (:func:`~twolink_pin.task_metrics.task_errors`) over time on log scales, with
    RMS, max and last-period max (:func:`~twolink_pin.task_metrics.task_metrics`) in the
    titles; ``spans`` (``(start, stop)`` [s], a wrench acting) shaded."""
    fig = _task_error_figure(robot, result, title)
    shade_spans(fig, spans, np.asarray(result.t))
    return _save.save_figure(fig, Path(path))
