"""The end effector of one run in Cartesian space: its path against the desired one, and the
distance between them over time."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.kinematics import joint_positions
from twolink_pin.model import RobotModel
from twolink_pin.plotting import _save
from twolink_pin.plotting._style import ACTUAL_COLOR, DESIRED_COLOR, ERROR_COLOR, LOG_FLOOR, new_figure
from twolink_pin.simulation import SimulationResult

CARTESIAN_FIGSIZE = (12.0, 5.0)
"""Size of the end-effector figure (path, distance) [in]."""
AXES = ("x", "y", "z")


def end_effector_paths(robot: RobotModel, result: SimulationResult) -> tuple[np.ndarray, np.ndarray]:
    """Actual and desired end-effector positions [m] at every sample, shapes (N, 3)."""
    if result.q.shape[1] != robot.nq:
        raise InvalidParameterError("result", result.robot, f"a run of {robot.name} (nq = {robot.nq})")
    return joint_positions(robot, result.q)[:, -1, :], joint_positions(robot, result.q_des)[:, -1, :]


def _end_effector_figure(robot: RobotModel, result: SimulationResult, title: str | None = None) -> Figure:
    actual, desired = end_effector_paths(robot, result)
    spread = np.ptp(desired, axis=0)
    h, v = (int(i) for i in np.sort(np.argsort(spread)[-2:]))  # the plane the desired path spans most
    fig = new_figure(CARTESIAN_FIGSIZE)
    path_ax, error_ax = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.4]})
    path_ax.set_label("path")
    error_ax.set_label("distance")
    path_ax.plot(desired[:, h], desired[:, v], color=DESIRED_COLOR, lw=1.2, ls="--", label="desired")
    path_ax.plot(actual[:, h], actual[:, v], color=ACTUAL_COLOR, lw=1.0, label="actual")
    path_ax.plot(actual[0, h], actual[0, v], "o", color=ACTUAL_COLOR, ms=5, label="start")
    path_ax.set_aspect("equal", adjustable="datalim")
    path_ax.set_xlabel(f"{AXES[h]} [m]")
    path_ax.set_ylabel(f"{AXES[v]} [m]")
    path_ax.set_title(f"end-effector path ({robot.ee_frame}) in the {AXES[h]}-{AXES[v]} plane", fontsize=10)
    path_ax.legend(loc="best", fontsize=8)
    path_ax.grid(True, alpha=0.3)
    distance = np.linalg.norm(actual - desired, axis=1)
    error_ax.semilogy(result.t, np.maximum(distance * 1e3, LOG_FLOOR), color=ERROR_COLOR, lw=1.0)
    error_ax.set_xlabel("t [s]")
    error_ax.set_ylabel("|x − x_d| [mm]")
    last = result.t >= result.t[-1] - result.reference_period
    error_ax.set_title(
        f"distance to the desired position (last period: max {distance[last].max() * 1e3:.3g} mm)",
        fontsize=10,
    )
    error_ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(title or f"controller {result.controller} on {robot.name}", fontsize=11)
    return fig


def save_end_effector_figure(
    robot: RobotModel, result: SimulationResult, path: str | os.PathLike[str], title: str | None = None
) -> Path:
    """Write the end-effector figure of ``result`` (a run of ``robot``) to ``path`` (PNG).

    Left: the actual and desired end-effector paths in the coordinate plane the desired
    path spans most. Right: ``|x − x_d|`` [mm] over time on a log scale, with the last
    period's maximum in the title.
    """
    return _save.save_figure(_end_effector_figure(robot, result, title), Path(path))
