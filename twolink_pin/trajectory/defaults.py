"""Each robot's default reference: its profile's via points, else a swing about its home."""

from __future__ import annotations

import numpy as np

from twolink_pin.errors import require_type
from twolink_pin.kinematics import inverse_kinematics
from twolink_pin.limits import joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.cartesian import ViaPoints, cartesian_trajectory
from twolink_pin.trajectory.polynomial import JointTrajectory

NEUTRAL_AMPLITUDE = 0.4
"""Largest excursion [rad] of :func:`neutral_motion` from the robot's home."""
LIMIT_MARGIN = 0.9
""":func:`neutral_motion` uses at most this fraction of the room between home and a limit."""


def home_configuration(robot: RobotModel) -> np.ndarray:
    """The robot's home [rad] (:attr:`~twolink_pin.model.RobotModel.home`)."""
    return robot.home


def default_via_points(robot: RobotModel) -> ViaPoints | None:
    """The profile's planar end-effector via points as :class:`ViaPoints`, or None."""
    spec = robot.profile.trajectory
    if spec is None or spec.cartesian_points is None or len(spec.cartesian_points[0]) != 2:
        return None
    xy = tuple((float(p[0]), float(p[1])) for p in spec.cartesian_points)
    return ViaPoints(xy=xy, times=tuple(spec.times), branch=spec.branch, period=spec.period)


def default_trajectory(robot: RobotModel) -> JointTrajectory:
    """The robot's default reference: its profile's via points (joint, planar end-effector
    with the analytic IK, or 3-D end-effector), else :func:`neutral_motion`."""
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    spec = robot.profile.trajectory
    if spec is None:
        return neutral_motion(robot)
    if spec.joint_points is not None:
        return JointTrajectory.from_via_q(spec.times, np.array(spec.joint_points, dtype=float), spec.period)
    via = default_via_points(robot)
    if via is not None:
        return build_trajectory(robot, via)
    assert spec.cartesian_points is not None
    return cartesian_trajectory(robot, spec.times, spec.cartesian_points, spec.period)


def neutral_motion(robot: RobotModel, period: float = 4.0) -> JointTrajectory:
    """A periodic reference for any arm: each joint leaves its home
    (:func:`home_configuration`), swings ``+a_j``, back, ``−a_j`` and back, odd joints out
    of phase with even ones; ``a_j = min(A, 25 % of the range,
    LIMIT_MARGIN × the room from home to the nearer limit (allowing for the polynomial's
    overshoot of its via points), LIMIT_MARGIN × the amplitude at
    which the peak speed reaches the URDF's velocity limit)`` with ``A`` the profile's
    ``amplitude``, else :data:`NEUTRAL_AMPLITUDE` (a velocity limit of 0, as in a URDF that
    gives none, is no limit).
    """
    limits = joint_limits(robot)
    lower, upper = np.array(limits.position_lower), np.array(limits.position_upper)
    home = home_configuration(robot)
    with np.errstate(invalid="ignore"):
        span = np.where(np.isfinite(upper - lower), upper - lower, np.inf)
        room = np.minimum(home - lower, upper - home)
    times = tuple(period * k / 4 for k in range(5))
    shape = np.array([0.0, 1.0, 0.0, -1.0, 0.0])
    unit = JointTrajectory.from_via_q(times, shape[:, None])
    unit_sample = unit.sample(np.linspace(0.0, period, 801))
    unit_peak = float(np.abs(unit_sample.q).max())  # the polynomial overshoots its via points: rad per rad
    unit_speed = float(np.abs(unit_sample.v).max())  # rad/s per rad
    speed_limit = limits.velocity
    amplitude = np.minimum.reduce(
        [
            np.full(robot.nv, robot.profile.amplitude or NEUTRAL_AMPLITUDE),
            0.25 * span,
            LIMIT_MARGIN * room / unit_peak,
            LIMIT_MARGIN * speed_limit / unit_speed,
        ]
    )
    signs = np.where(np.arange(robot.nv) % 2 == 0, 1.0, -1.0)
    via_q = home + np.outer(shape, signs * amplitude)
    return JointTrajectory.from_via_q(times, via_q)


def build_trajectory(robot: RobotModel, via: ViaPoints | None = None) -> JointTrajectory:
    """Trajectory through end-effector via points of a planar 2R arm (IK branch
    ``via.branch``); default: the robot's own trajectory
    (:func:`~twolink_pin.trajectory.default_trajectory`).

    Raises:
        UnreachableTargetError: a via point is outside the reachable annulus.
    """
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    if via is None:
        return default_trajectory(robot)
    via_q = np.array([inverse_kinematics(robot, xy)[via.branch] for xy in via.xy])
    return JointTrajectory.from_via_q(via.times, via_q, via.period, via.boundary_order)
