"""What a via file may add to its motion (:mod:`twolink_pin.trajectory.file`): straight lines
between its points (``path = "lines"``) and a force reference (its ``force`` column)."""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError, InverseKinematicsError
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.cartesian import cartesian_via_q
from twolink_pin.trajectory.file_values import check_trajectory_limits, parse_numbers
from twolink_pin.trajectory.force import MAX_FORCE, ForceReference, with_force
from twolink_pin.trajectory.se3 import PoseTrajectory, pose_trajectory

TrajectoryT = TypeVar("TrajectoryT", bound=Trajectory)
PATHS = ("polynomial", "lines")
"""A ``positions`` file's ``path``: one polynomial per joint through the via points (default),
or straight lines between them (:class:`~twolink_pin.trajectory.se3.PoseTrajectory`, position only)."""


def path_kind(file: Path, document: dict[str, Any]) -> str:
    """The file's ``path`` (:data:`PATHS`), checked."""
    path = document.get("path", "polynomial")
    if path not in PATHS or ("joints" in document and path != "polynomial"):
        raise InvalidParameterError(
            f"{file}: path",
            path,
            f"one of {PATHS} ('lines' with 'positions' only: straight lines between them)",
        )
    return str(path)


def line_file(
    file: Path, robot: RobotModel, times: np.ndarray, points: np.ndarray, seed: np.ndarray | None, period: Any
) -> PoseTrajectory:
    """Straight lines between the via positions (``path = "lines"``): the position-only
    :class:`PoseTrajectory` through them, the orientations there the forward kinematics'."""
    try:
        via_q = cartesian_via_q(robot, points, seed)
    except InverseKinematicsError as err:
        raise InverseKinematicsError(err.target, f"{file}: {err.reason}", err.q) from None
    data = robot.model.createData()
    poses = []
    for q in via_q:
        pin.framesForwardKinematics(robot.model, data, q)
        poses.append(data.oMf[robot.ee_frame_id].copy())
    positions = np.array([pose.translation for pose in poses])
    positions[:, : points.shape[1]] = points  # exactly the file's (the IK reaches them to its tolerance)
    rotations = np.array([pose.rotation for pose in poses])
    rotations[-1] = rotations[0]
    try:
        trajectory = pose_trajectory(
            robot, tuple(times), positions, rotations, None if period is None else float(period), via_q[0],
            position_rows=points.shape[1],
        )  # fmt: skip
    except InvalidParameterError as err:
        raise InvalidParameterError(f"{file}: {err.name}", err.value, err.expected) from None
    except InverseKinematicsError as err:
        raise InverseKinematicsError(err.target, f"{file}: {err.reason}", err.q) from None
    check_trajectory_limits(robot, trajectory, f"{file}")
    return trajectory


def carrying(trajectory: TrajectoryT, file: Path, document: dict[str, Any], times: np.ndarray) -> TrajectoryT:
    """``trajectory`` carrying the file's ``force`` column [N] (one value per via time, on the
    surface ``force_surface``; :mod:`~twolink_pin.trajectory.force`), if it has one."""
    if "force" not in document:
        if "force_surface" in document:
            raise InvalidParameterError(
                f"{file}: force_surface", document["force_surface"], "a 'force' column [N] beside it"
            )
        return trajectory
    values = parse_numbers(file, "force", document["force"], "one normal force [N] per time", MAX_FORCE, "N")
    if values.shape != times.shape:
        raise InvalidParameterError(
            f"{file}: force", document["force"], f"one normal force [N] per time ({times.size})"
        )
    surface = document.get("force_surface")
    try:
        reference = ForceReference(tuple(times), tuple(values), surface, trajectory.period)
    except InvalidParameterError as err:
        raise InvalidParameterError(f"{file}: {err.name}", err.value, err.expected) from None
    return with_force(trajectory, reference)


__all__ = ["PATHS", "carrying", "line_file", "path_kind"]
