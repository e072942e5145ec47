"""Trajectories through end-effector via points: a planar 2R arm's analytic IK, or any arm's
damped least-squares IK (:func:`~twolink_pin.kinematics.solve_position`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from twolink_pin.errors import InvalidParameterError, InverseKinematicsError
from twolink_pin.kinematics import solve_position
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.polynomial import JointTrajectory, check_period, check_times


@dataclass(frozen=True)
class ViaPoints:
    """End-effector via points of a planar 2R arm and their timing.

    Attributes:
        xy: Via points ``(x, y)`` [m]; for a periodic trajectory the last equals the first.
        times: Strictly increasing times [s], one per via point.
        branch: IK elbow branch: 0 for ``q2 >= 0`` (the report's choice), 1 for ``q2 <= 0``.
        period: Repetition period [s] (>= ``times[-1] − times[0]``; the arm rests at the
            last point for the difference); ``None`` means ``times[-1] − times[0]``.
        boundary_order: Highest derivative set to zero at both ends (3: up to jerk).
    """

    xy: tuple[tuple[float, float], ...]
    times: tuple[float, ...]
    branch: int = 0
    period: float | None = None
    boundary_order: int = 3

    def __post_init__(self) -> None:
        check_times(self.times, len(self.xy), "xy")
        for point in self.xy:
            if len(point) != 2 or not all(math.isfinite(c) for c in point):
                raise InvalidParameterError("xy", self.xy, "via points of two finite coordinates (x, y) [m]")
        if self.branch not in (0, 1):
            raise InvalidParameterError("branch", self.branch, "0 (q2 >= 0) or 1 (q2 <= 0)")
        check_period(self.period, self.times)
        if not (isinstance(self.boundary_order, int) and 0 <= self.boundary_order <= 6):
            raise InvalidParameterError("boundary_order", self.boundary_order, "an integer from 0 to 6")


def cartesian_via_q(
    robot: RobotModel, points: Sequence[Sequence[float]] | np.ndarray, seed: np.ndarray | None = None
) -> np.ndarray:
    """Joint via points [rad], shape (n, nv), reaching each end-effector point [m] in turn:
    the first from ``seed`` (default the robot's home, see
    :attr:`~twolink_pin.model.RobotModel.home`), each next from the one
    before, so that the arm stays on one IK branch; a point equal to the first gets the
    first's configuration (a redundant arm could reach it in another).

    Raises:
        InverseKinematicsError: a point is out of reach or reached only at a singular
            configuration; the message says which point (0-based) and why.
    """
    q = robot.home if seed is None else np.asarray(seed, dtype=float)
    rows: list[np.ndarray] = []
    for k, point in enumerate(points):
        if k > 0 and np.array_equal(np.asarray(point, dtype=float), np.asarray(points[0], dtype=float)):
            rows.append(rows[0])  # a closing point: the same configuration, not another IK branch
            continue
        try:
            q = solve_position(robot, np.asarray(point, dtype=float), q)
        except InverseKinematicsError as err:
            raise InverseKinematicsError(err.target, f"via point {k}: {err.reason}", err.q) from None
        rows.append(q)
    return np.array(rows)


def cartesian_trajectory(
    robot: RobotModel,
    times: Sequence[float],
    points: Sequence[Sequence[float]],
    period: float | None = None,
    seed: np.ndarray | None = None,
) -> JointTrajectory:
    """Trajectory of any arm through end-effector via points ``points`` [m] (2 or 3
    coordinates each) at ``times`` [s]: joint via points from :func:`cartesian_via_q`,
    then one polynomial per joint (between via points the end effector follows the
    joint-space interpolation, not a straight line)."""
    check_times(tuple(float(t) for t in times), len(points), "points")
    return JointTrajectory.from_via_q(tuple(times), cartesian_via_q(robot, points, seed), period)
